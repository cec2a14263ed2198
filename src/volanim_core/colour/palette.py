"""Build a palette of at most 255 colours for a colour volume, and map voxels to it.

    voxels --unique_colours--> colours + counts --build_palette--> (N, 3) uint8
    voxels --NearestColour--> uint8 indices (nearest palette colour in CIELAB)

The thesis made its palette with ``MapImages`` and mapped voxels through
``InvCMap``'s 256^3 inverse-colour table. We work on the distinct colours of a
sample, weighted by how often they occur: a volume with at most N distinct
colours gets exactly those colours (reproduced without error), and k-means runs
on thousands of colours instead of millions of voxels.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from volanim_core.colour.space import delta_e, from_lab, to_lab
from volanim_core.progress import CancelFn, ProgressFn, Reporter

METHODS = ("kmeans", "median-cut")


def pack(rgb: np.ndarray) -> np.ndarray:
    """``[..., 3]`` uint8 colours as one 24-bit key each (R high)."""
    rgb = np.asarray(rgb, np.uint32)
    return (rgb[..., 0] << 16) | (rgb[..., 1] << 8) | rgb[..., 2]


def unpack(keys: np.ndarray) -> np.ndarray:
    keys = np.asarray(keys, np.uint32)
    return np.stack([(keys >> 16) & 255, (keys >> 8) & 255, keys & 255], axis=-1).astype(np.uint8)


def unique_colours(rgb: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The distinct colours of ``[..., 3]`` data and how often each occurs."""
    counts = np.bincount(pack(rgb).ravel(), minlength=1 << 24) if np.size(rgb) > (1 << 22) else None
    if counts is not None:  # many voxels: one pass over a 16M-bin histogram beats sorting them
        keys = np.flatnonzero(counts)
        return unpack(keys), counts[keys]
    keys, counts = np.unique(pack(rgb).ravel(), return_counts=True)
    return unpack(keys), counts


def build_palette(colours: np.ndarray, counts: np.ndarray, n: int = 255, *, method: str = "kmeans",
                  seed: int = 0, iterations: int = 40, progress: ProgressFn | None = None,
                  cancel: CancelFn | None = None) -> np.ndarray:
    """At most ``n`` colours (``(N, 3)`` uint8) standing for ``colours`` weighted by ``counts``.

    ``kmeans``: weighted k-means in CIELAB (k-means++ seeds, Lloyd steps); ``median-cut``:
    Heckbert's median cut in RGB (faster, coarser). Fewer distinct colours than ``n``:
    those colours themselves, so such a volume is reproduced exactly.

    The colours come in the order the method made them, which is no order a renderer can
    blend (the thesis's MapImages palettes were the same): :mod:`.sort` orders them.
    ``progress``/``cancel`` are called after each k-means step (a few seconds on a large sample).
    """
    if method not in METHODS:
        raise ValueError(f"palette method must be one of {', '.join(METHODS)}, got {method!r}")
    if not 1 <= n <= 256:
        raise ValueError(f"a palette has 1..256 colours, got {n}")
    colours, counts = np.asarray(colours, np.uint8).reshape(-1, 3), np.asarray(counts, np.float64).reshape(-1)
    if len(colours) == 0:
        raise ValueError("no voxels to build a palette from")
    if len(counts) != len(colours) or not np.all(np.isfinite(counts)) or np.any(counts < 0) or counts.sum() <= 0:
        raise ValueError(f"counts must be one finite number >= 0 per colour ({len(colours)}), not all 0; got "
                         f"{len(counts)} counts from {counts.min() if len(counts) else 'none'}")
    if len(colours) <= n:
        return colours
    if method == "median-cut":
        return _median_cut(colours, counts, n)
    return _kmeans(colours, counts, n, np.random.default_rng(seed), iterations, Reporter(progress, cancel))


def _kmeans(colours, weights, n, rng, iterations, report) -> np.ndarray:
    lab = to_lab(colours)
    centres = _kmeans_pp(lab, weights, n, rng)
    for step in range(iterations):
        report(step, iterations)
        _, label = cKDTree(centres).query(lab)
        mass = np.bincount(label, weights, minlength=n)
        sums = np.stack([np.bincount(label, weights * lab[:, k], minlength=n) for k in range(3)], axis=1)
        empty = mass == 0
        new = np.where(empty[:, None], centres, sums / np.maximum(mass, 1e-12)[:, None])
        if empty.any():  # re-seed an empty cluster at the colour worst served now
            dist = cKDTree(new).query(lab)[0] * weights
            new[empty] = lab[np.argsort(dist)[::-1][: int(empty.sum())]]
        moved = float(np.abs(new - centres).max())
        centres = new
        if moved < 0.05:  # well under one sRGB step
            break
    report(iterations, iterations)
    return _lab_to_palette(centres)


def _kmeans_pp(lab, weights, n, rng) -> np.ndarray:
    """k-means++ seeds, each drawn with probability weight x squared distance to the nearest seed."""
    first = rng.choice(len(lab), p=weights / weights.sum())
    centres = [lab[first]]
    d2 = ((lab - lab[first]) ** 2).sum(axis=1)
    for _ in range(n - 1):
        p = weights * d2
        pick = rng.choice(len(lab), p=p / p.sum()) if p.sum() > 0 else int(np.argmax(weights))
        centres.append(lab[pick])
        d2 = np.minimum(d2, ((lab - lab[pick]) ** 2).sum(axis=1))
    return np.array(centres)


def _distinct(palette: np.ndarray) -> np.ndarray:
    """The palette without repeats (two centres that round to one 8-bit colour), order kept."""
    _, first = np.unique(palette, axis=0, return_index=True)
    return palette[np.sort(first)]


def _lab_to_palette(centres) -> np.ndarray:
    """Cluster centres as 8-bit sRGB, in the order k-means made them."""
    return _distinct(from_lab(centres))


def _median_cut(colours, counts, n) -> np.ndarray:
    """Split the box with the widest colour range (times the root of its voxels) at its weighted median."""
    def span(box):
        return float(np.ptp(colours[box], axis=0).max()) * counts[box].sum() ** 0.5 if len(box) > 1 else -1.0

    boxes = [np.arange(len(colours))]
    spans = [span(boxes[0])]
    while len(boxes) < n:
        k = int(np.argmax(spans))
        if spans[k] < 0:
            break
        box = boxes.pop(k)
        spans.pop(k)
        axis = int(np.argmax(np.ptp(colours[box], axis=0)))
        box = box[np.argsort(colours[box, axis], kind="stable")]
        cum = np.cumsum(counts[box])
        cut = int(np.clip(np.searchsorted(cum, cum[-1] / 2), 1, len(box) - 1))
        boxes += [box[:cut], box[cut:]]
        spans += [span(box[:cut]), span(box[cut:])]
    means = np.array([np.average(colours[b].astype(float), axis=0, weights=counts[b]) for b in boxes])
    return _distinct(np.clip(np.rint(means), 0, 255).astype(np.uint8))


class NearestColour:
    """Voxel colours -> the index of the nearest palette colour (Euclidean in CIELAB).

    Like ``InvCMap``'s inverse-colour table, but filled on demand: each distinct colour
    is looked up in a KD-tree once and remembered in a 2^24-entry table (32 MiB), so a
    volume costs one table read per voxel plus one tree query per new colour.
    """

    def __init__(self, palette: np.ndarray):
        self.palette = np.asarray(palette, np.uint8).reshape(-1, 3)
        if not 1 <= len(self.palette) <= 256:
            raise ValueError(f"a palette has 1..256 colours, got {len(self.palette)}")
        self.tree = cKDTree(to_lab(self.palette))
        self._table = None  # made at the first volume: per_voxel() callers never need its 32 MiB

    @property
    def table(self) -> np.ndarray:
        if self._table is None:
            self._table = np.full(1 << 24, -1, np.int16)
        return self._table

    def __call__(self, rgb: np.ndarray) -> np.ndarray:
        keys = pack(rgb)
        index = self.table[keys]
        missing = index < 0
        if missing.any():
            new = np.unique(keys[missing])
            self.table[new] = self.tree.query(to_lab(unpack(new)))[1]
            index = self.table[keys]
        return index.astype(np.uint8)

    def per_voxel(self, rgb: np.ndarray) -> np.ndarray:
        """The same indices by one tree query per voxel (the baseline the table is measured against)."""
        rgb = np.asarray(rgb)
        return self.tree.query(to_lab(rgb.reshape(-1, 3)))[1].astype(np.uint8).reshape(rgb.shape[:-1])

    def full_table(self) -> np.ndarray:
        """InvCMap's complete table: all 2^24 colours looked up at once (for the benchmark)."""
        keys = np.arange(1 << 24, dtype=np.uint32)
        for start in range(0, len(keys), 1 << 20):
            part = keys[start:start + (1 << 20)]
            self.table[part] = self.tree.query(to_lab(unpack(part)))[1]
        return self.table


def colour_errors(colours: np.ndarray, palette: np.ndarray) -> np.ndarray:
    """CIEDE2000 between each colour and the palette colour it maps to (one tree query a colour)."""
    palette = np.asarray(palette, np.uint8).reshape(-1, 3)
    return delta_e(colours, palette[NearestColour(palette).per_voxel(colours)])


def weighted_error(errors: np.ndarray, counts: np.ndarray) -> tuple[float, float]:
    """Mean and 95th percentile of per-colour ``errors`` weighted by how many voxels have each colour."""
    order = np.argsort(errors)
    cum = np.cumsum(np.asarray(counts, np.float64)[order])
    p95 = float(errors[order][np.searchsorted(cum, 0.95 * cum[-1])])
    return float(np.average(errors, weights=counts)), p95


def quantisation_error(colours: np.ndarray, counts: np.ndarray, palette: np.ndarray) -> tuple[float, float]:
    """Mean and 95th-percentile CIEDE2000 between voxels and their palette colour (weighted by counts)."""
    return weighted_error(colour_errors(colours, palette), counts)
