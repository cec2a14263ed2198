"""A colour volume as one byte a voxel: palette indices, with the palette beside them.

    rgb [x, y, z, 3] --black: 0 (the background); other colours: unique_colours --build_palette (<= 255)-->
        palette rows 1..N --NearestColour--> index 1..N
    --> Indexed(indices [x, y, z] uint8, palette (256, 3) uint8; row 0 black, rows past N black)

Why: a sequence holds one value a voxel (its store, its verdicts, its render's transfer function),
and a colour body's movie must still be in colour (#61). Indices are what the thesis's own pipeline
sequenced (``MapImages`` + ``InvCMap``), and sampling them at the nearest voxel moves them exactly as
it moves the colours: a volume with at most 255 colours besides black comes back voxel for voxel;
one with more is quantised by weighted k-means in CIELAB (:func:`.palette.build_palette`), and
``Indexed.error`` says by how much (:func:`.palette.quantisation_error`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from volanim_core.colour.palette import NearestColour, build_palette, pack, quantisation_error, unique_colours
from volanim_core.progress import CancelFn, ProgressFn, Reporter
from volanim_core.transfer_function import MAX_POINTS, TransferFunction
from volanim_core.volume import to_grey

#: Indices a byte holds besides the background's 0.
COLOURS = 255


@dataclass(frozen=True)
class Indexed:
    indices: np.ndarray  # [x, y, z] uint8; 0 wherever the colour volume is black
    palette: np.ndarray  # (256, 3) uint8: any byte indexes it; row 0 is black
    colours: int  # palette rows in use besides row 0
    exact: bool  # every voxel's colour is its palette colour
    error: tuple[float, float] = (0.0, 0.0)  # CIEDE2000 mean and 95th percentile over the body's voxels

    def colour(self, indices: np.ndarray) -> np.ndarray:
        """``[..., 3]`` uint8 colours of indices (a frame sampled from :attr:`indices`)."""
        return self.palette[np.asarray(indices, np.uint8)]


def index_colours(rgb: np.ndarray, *, progress: ProgressFn | None = None,
                  cancel: CancelFn | None = None) -> Indexed:
    """``rgb`` (``[x, y, z, 3]`` uint8) as palette indices; see the module docstring."""
    rgb = np.asarray(rgb)
    if rgb.ndim != 4 or rgb.shape[3] != 3 or rgb.dtype != np.uint8:
        raise ValueError(f"a colour volume is [x, y, z, 3] uint8, got {rgb.shape} {rgb.dtype}")
    report = Reporter(progress, cancel)
    report(0, 3)
    colours, counts = unique_colours(rgb)
    keep = pack(colours) != 0  # black is the background: index 0, never a palette colour
    colours, counts = colours[keep], counts[keep]
    report(1, 3)
    palette = np.zeros((256, 3), np.uint8)
    if len(colours) == 0:
        return Indexed(np.zeros(rgb.shape[:3], np.uint8, order="F"), palette, 0, True)
    used = build_palette(colours, counts, COLOURS, cancel=cancel)
    palette[1:len(used) + 1] = used
    exact = len(colours) <= COLOURS
    # the error over the distinct colours already counted: no second pass over the voxels
    error = (0.0, 0.0) if exact else quantisation_error(colours, counts, used)
    report(2, 3)
    index = NearestColour(used)(rgb) + np.uint8(1)  # per distinct colour once, then a table read a voxel
    index[(rgb == 0).all(axis=3)] = 0
    report(3, 3)
    return Indexed(np.asfortranarray(index), palette, len(used), exact, error)


def through_palette(tf: TransferFunction, palette: np.ndarray) -> TransferFunction:
    """``tf`` over a colour volume's luminance, as a function of its palette indices: index k maps to
    ``tf(luminance(palette[k]))``. A colour sequence stores indices (``volanim_core.colour.indexed``), so a
    movie drawn with this shows each voxel as ``tf`` shows the colour volume itself (the studio's preview
    draws a colour volume through ``tf`` by its luminance, rounded as ``to_grey`` rounds it)."""
    palette = np.asarray(palette).reshape(-1, 3)
    if not 1 <= len(palette) <= MAX_POINTS:
        raise ValueError(f"a palette of {len(palette)} colours cannot become a transfer function "
                         f"(1..{MAX_POINTS} points)")
    return TransferFunction(np.arange(len(palette), dtype=np.float64), tf(to_grey(palette).astype(np.float64)))
