"""Palette orderings, so a renderer that interpolates voxel indices shows smooth colour.

A renderer interpolates the *index* between two voxels and then looks the colour
up; halfway between indices 3 and 200 it shows whatever colour sits at 101. An
ordering is good when colours that meet in the volume sit at nearby indices.

The thesis's sorts (section 4.2) under the thesis's names, as the thesis describes them (#66; the
distances are in RGB, as the thesis's were):

=================  =========================================================
method             ordering
=================  =========================================================
unsorted           as built
intensity          by R + G + B, the thesis's intensity
rgb-radix          by red, then green, then blue (a radix sort on R, G, B)
cluster-seeds      ClusterSort: a seed every ``interval`` colours of the
                   intensity order (adjustable), each colour in the cell of
                   its nearest seed; the seeds in intensity order, each
                   followed by its cell ordered by distance from the seed
gradient-penalty   GradientSort: a greedy walk from the darkest colour,
                   each next colour the one of least D + 2P -- D the step's
                   length, P the part of the step that turns back in any of
                   R, G or B against the step before (``penalty`` 2)
supergradient      SuperGradientSort: a walk that extrapolates the last two
                   colours (2 a[1] - a[0]) and takes the first unused colour
                   within a step of that line, looking up to 20 steps along
                   it (GetClosestFuturePoint); the nearest colour when none
=================  =========================================================

volanim's own, and what these names meant in volanim before #66:

=================  =========================================================
lightness          by CIELAB lightness (``intensity`` before)
farthest-seeds     colours grouped round far-apart seeds; groups chained
                   nearest-first from the darkest, each dark to light
                   (``cluster-seeds`` before)
darker-penalty     a greedy walk to the nearest next colour (CIEDE2000) with
                   a penalty for each step darker (``gradient-penalty``)
moved              lightness, then each colour moved to where it fits best
                   while that helps (``supergradient`` before)
ramp               ours (the default): lightness order as the backbone, then
                   runs of 1-3 colours moved (either way round) to where they
                   fit best while that helps (Or-opt)
path               ours: a shortest Hamiltonian path through the palette in
                   CIEDE2000 -- nearest-neighbour starts, then 2-opt and
                   Or-opt to a local optimum -- dark end first
=================  =========================================================

The thesis's texts give no code; where they leave a detail open (which end a walk starts from, what
"a change of direction" weighs, when GetClosestFuturePoint gives up), the reading above is ours and
the tests name it.

Measured (benchmarks/bench_colour.py): ``path`` has the smallest steps between
neighbouring indices, but it wanders through colour space, so two colours that
touch in the volume can sit far apart with unrelated colours between them, and
its midpoint error loses to SuperGradientSort on some pictures. ``ramp`` keeps
the light-to-dark backbone that bounds that error: it beats SuperGradientSort
on the sum and the maximum everywhere measured and on the midpoint error on
most (within 5 % where it does not).

Every ordering is a permutation ``order`` with ``order[new] = old``.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from volanim_core.colour import _tour_kernels as T
from volanim_core.colour.space import delta_e_lab, to_lab

METHODS = ("unsorted", "intensity", "rgb-radix", "cluster-seeds", "gradient-penalty", "supergradient",
           "lightness", "farthest-seeds", "darker-penalty", "moved", "ramp", "path")
CLUSTER_INTERVAL = 16  # ClusterSort's seed interval: a seed every 16 colours of the intensity order
GRADIENT_PENALTY = 2.0  # GradientSort's weight of P in D + 2P
FUTURE_STEPS = 20  # how far SuperGradientSort looks along its extrapolated line (GetClosestFuturePoint)
DEFAULT_METHOD = "ramp"


def distance_matrix(lab: np.ndarray) -> np.ndarray:
    """CIEDE2000 between every two colours (``(N, N)``, symmetric, zero diagonal)."""
    n = len(lab)
    a = np.broadcast_to(lab[:, None, :], (n, n, 3))
    b = np.broadcast_to(lab[None, :, :], (n, n, 3))
    d = delta_e_lab(a.reshape(-1, 3), b.reshape(-1, 3)).reshape(n, n)
    return np.ascontiguousarray(np.maximum(d, d.T))  # CIEDE2000 is symmetric up to rounding


def sort_palette(palette: np.ndarray, method: str = DEFAULT_METHOD, *, keep_first: bool = False,
                 starts: int = 8, interval: int = CLUSTER_INTERVAL, penalty: float = GRADIENT_PENALTY,
                 steps: int = FUTURE_STEPS) -> np.ndarray:
    """The ordering ``order`` (``order[new] = old``) of ``palette`` by ``method``.

    ``keep_first`` keeps index 0 where it is (a background colour that a transfer
    function makes transparent) and orders the rest. ``interval`` is ClusterSort's seed interval,
    ``penalty`` GradientSort's weight of P, ``steps`` how far SuperGradientSort looks along its line;
    ``starts`` how many greedy paths ``path`` improves.
    """
    if method not in METHODS:
        raise ValueError(f"sort method must be one of {', '.join(METHODS)}, got {method!r}")
    palette = np.asarray(palette, np.uint8).reshape(-1, 3)
    first = 1 if keep_first else 0
    rest = palette[first:]
    if len(rest) <= 1:
        return np.arange(len(palette))
    lab = to_lab(rest)
    options = {"starts": starts, "interval": interval, "penalty": penalty, "steps": steps}
    order = _ORDERINGS[method](rest, lab, options)
    return np.concatenate((np.arange(first), np.asarray(order, np.int64) + first))


def _unsorted(rgb, lab, options):
    return np.arange(len(rgb))


def _intensity(rgb, lab, options):
    """The thesis's intensity: R + G + B."""
    return np.argsort(np.asarray(rgb, np.int64).sum(axis=1), kind="stable")


def _lightness(rgb, lab, options):
    return np.argsort(lab[:, 0], kind="stable")


def thesis_cluster(rgb: np.ndarray, interval: int = CLUSTER_INTERVAL) -> np.ndarray:
    """ClusterSort: a seed every ``interval`` colours of the intensity (R + G + B) order; each colour joins
    its nearest seed (RGB distance; a tie goes to the earlier seed); the seeds in intensity order, each
    followed by the rest of its cell, nearest to the seed first."""
    if interval < 1:
        raise ValueError(f"the seed interval is at least 1, got {interval}")
    rgb = np.asarray(rgb, np.float64)
    by_intensity = _intensity(rgb, None, None)
    seeds = by_intensity[::interval]
    d = np.linalg.norm(rgb[:, None, :] - rgb[None, seeds, :], axis=2)  # (N, seeds)
    cell = np.argmin(d, axis=1)  # argmin: the first of equal distances, the earlier seed
    cell[seeds] = np.arange(len(seeds))  # a seed is its own cell's first
    order = []
    for k, seed in enumerate(seeds):
        members = np.flatnonzero(cell == k)
        members = members[members != seed]
        order += [seed, *members[np.argsort(d[members, k], kind="stable")]]
    return np.array(order, np.int64)


def thesis_gradient(rgb: np.ndarray, penalty: float = GRADIENT_PENALTY) -> np.ndarray:
    """GradientSort: from the darkest colour (least R + G + B), each next colour the unused one of least
    ``D + penalty * P``: D the step's RGB length, P the part of the step that turns back against the step
    before, summed over R, G and B (|step_c| where step_c and the previous step_c have opposite signs)."""
    rgb = np.asarray(rgb, np.float64)
    left = np.ones(len(rgb), bool)
    order = [int(np.argmin(rgb.sum(axis=1)))]
    left[order[0]] = False
    before = np.zeros(3)
    for _ in range(len(rgb) - 1):
        step = rgb - rgb[order[-1]]
        turn = np.where(step * before < 0, np.abs(step), 0.0).sum(axis=1)
        cost = np.linalg.norm(step, axis=1) + penalty * turn
        cost[~left] = np.inf
        nxt = int(np.argmin(cost))
        before = step[nxt]
        order.append(nxt)
        left[nxt] = False
    return np.array(order, np.int64)


def thesis_supergradient(rgb: np.ndarray, steps: int = FUTURE_STEPS) -> np.ndarray:
    """SuperGradientSort: from the darkest colour and its nearest, each next colour found along the line
    the last two make: at t = 1 .. ``steps`` the point ``a1 + t (a1 - a0)`` (t = 1: ``2 a1 - a0``), the
    first unused colour within one step's length of it (GetClosestFuturePoint); when the line finds
    none, the unused colour nearest to ``a1``."""
    rgb = np.asarray(rgb, np.float64)
    left = np.ones(len(rgb), bool)
    first = int(np.argmin(rgb.sum(axis=1)))
    left[first] = False
    order = [first]
    while left.any():
        a1 = rgb[order[-1]]
        unused = np.flatnonzero(left)
        nxt = None
        if len(order) >= 2:
            trend = a1 - rgb[order[-2]]
            reach = np.linalg.norm(trend)
            for t in range(1, steps + 1) if reach > 0 else ():
                d = np.linalg.norm(rgb[unused] - (a1 + t * trend), axis=1)
                if d.min() <= reach:
                    nxt = int(unused[np.argmin(d)])
                    break
        if nxt is None:
            nxt = int(unused[np.argmin(np.linalg.norm(rgb[unused] - a1, axis=1))])
        order.append(nxt)
        left[nxt] = False
    return np.array(order, np.int64)


def _thesis_cluster(rgb, lab, options):
    return thesis_cluster(rgb, options["interval"])


def _thesis_gradient(rgb, lab, options):
    return thesis_gradient(rgb, options["penalty"])


def _thesis_supergradient(rgb, lab, options):
    return thesis_supergradient(rgb, options["steps"])


def _rgb_radix(rgb, lab, options):
    return np.lexsort((rgb[:, 2], rgb[:, 1], rgb[:, 0]))


def _cluster_seeds(rgb, lab, options):
    n = len(lab)
    k = max(2, int(round(np.sqrt(n))))
    seeds = [int(np.argmin(lab[:, 0]))]
    d = np.linalg.norm(lab - lab[seeds[0]], axis=1)
    while len(seeds) < k:  # farthest-point seeds: spread over the palette
        seeds.append(int(np.argmax(d)))
        d = np.minimum(d, np.linalg.norm(lab - lab[seeds[-1]], axis=1))
    _, group = cKDTree(lab[seeds]).query(lab)
    chain = T.nearest_neighbour_path(distance_matrix(lab[seeds]), 0)
    return np.concatenate([np.flatnonzero(group == g)[np.argsort(lab[group == g, 0], kind="stable")]
                           for g in chain])


def _gradient_penalty(rgb, lab, options, penalty: float = 1.0):
    D = distance_matrix(lab)
    light = lab[:, 0]
    left = np.ones(len(lab), bool)
    order = [int(np.argmin(light))]
    left[order[0]] = False
    for _ in range(len(lab) - 1):
        cur = order[-1]
        cost = D[cur] + penalty * np.maximum(0.0, light[cur] - light)
        cost[~left] = np.inf
        order.append(int(np.argmin(cost)))
        left[order[-1]] = False
    return np.array(order)


def _with_dummy(D: np.ndarray) -> np.ndarray:
    n = len(D)
    out = np.zeros((n + 1, n + 1))
    out[:n, :n] = D
    return out


def _moved_from_lightness(lab, max_run: int) -> np.ndarray:
    """Lightness order, then runs of up to ``max_run`` colours moved while that shortens the path."""
    n = len(lab)
    P = np.concatenate(([n], _lightness(None, lab, None), [n])).astype(np.int64)
    T.or_opt(_with_dummy(distance_matrix(lab)), P, max_run)
    return P[1:-1]


def _moved(rgb, lab, options):
    return _moved_from_lightness(lab, 1)


def _ramp(rgb, lab, options):
    return _moved_from_lightness(lab, 3)


def _path(rgb, lab, options):
    starts = options["starts"]
    D = distance_matrix(lab)
    Dd = _with_dummy(D)
    n = len(lab)
    greedy = [T.nearest_neighbour_path(D, s) for s in range(n)]
    lengths = np.array([T.path_length(D, p) for p in greedy])
    best, best_len = None, np.inf
    for s in np.argsort(lengths, kind="stable")[:starts]:  # the shortest greedy paths, each improved
        P = np.concatenate(([n], greedy[s], [n])).astype(np.int64)
        T.improve(Dd, P, 3)
        length = T.path_length(D, P[1:-1])
        if length < best_len - 1e-9:
            best, best_len = P[1:-1].copy(), length
    if lab[best[0], 0] > lab[best[-1], 0]:  # dark end first, as the other orderings
        best = best[::-1]
    return best


_ORDERINGS = {"unsorted": _unsorted, "intensity": _intensity, "rgb-radix": _rgb_radix,
              "cluster-seeds": _thesis_cluster, "gradient-penalty": _thesis_gradient,
              "supergradient": _thesis_supergradient, "lightness": _lightness, "farthest-seeds": _cluster_seeds,
              "darker-penalty": _gradient_penalty, "moved": _moved, "ramp": _ramp, "path": _path}


def remap_table(order: np.ndarray) -> np.ndarray:
    """The 256-entry table old index -> new index of an ordering (unused indices stay put)."""
    table = np.arange(256)
    table[np.asarray(order)] = np.arange(len(order))
    return table


def neighbour_differences(palette: np.ndarray, order: np.ndarray) -> np.ndarray:
    """CIEDE2000 between each two neighbouring indices of the ordered palette."""
    lab = to_lab(np.asarray(palette)[np.asarray(order)])
    return delta_e_lab(lab[:-1], lab[1:])


def colour_pairs(index_volume: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Pairs of different indices that touch in ``index_volume`` (face neighbours) and how often:
    ``(pairs (K, 2), counts (K,))``, each pair with its smaller index first."""
    counts = np.zeros(n * n, np.int64)
    vol = np.asarray(index_volume)
    for axis in range(3):
        a = np.moveaxis(vol, axis, 0)
        lo, hi = a[:-1].ravel().astype(np.int64), a[1:].ravel().astype(np.int64)
        differ = lo != hi
        lo, hi = lo[differ], hi[differ]
        counts += np.bincount(np.minimum(lo, hi) * n + np.maximum(lo, hi), minlength=n * n)
    keys = np.flatnonzero(counts)
    return np.stack([keys // n, keys % n], axis=1), counts[keys]


def near_pairs(palette: np.ndarray, k: int = 4) -> tuple[np.ndarray, np.ndarray]:
    """Without a volume: each colour with its ``k`` nearest palette colours, the colours most likely
    to meet in a smooth body (each pair once, weight 1)."""
    lab = to_lab(np.asarray(palette))
    k = min(k, len(lab) - 1)
    if k < 1:
        return np.zeros((0, 2), np.int64), np.zeros(0)
    _, nbr = cKDTree(lab).query(lab, k + 1)
    pairs = np.unique(np.sort(np.stack([np.repeat(np.arange(len(lab)), k), nbr[:, 1:].ravel()], axis=1), axis=1),
                      axis=0)
    return pairs, np.ones(len(pairs))


def midpoint_error(palette: np.ndarray, order: np.ndarray, pairs: np.ndarray, weights: np.ndarray) -> float:
    """Mean CIEDE2000 (weighted) between what a renderer shows halfway between two touching voxels
    and their true blend. The renderer interpolates the index, so it shows the ordered palette at
    the mean of the two new indices (linear between entries, as a colour transfer function does);
    the true blend is the mean of the two colours."""
    if len(pairs) == 0:
        return 0.0
    palette = np.asarray(palette, np.float64)
    ordered = palette[np.asarray(order)]
    pos = np.empty(len(order), np.int64)
    pos[np.asarray(order)] = np.arange(len(order))
    mid = (pos[pairs[:, 0]] + pos[pairs[:, 1]]) / 2.0
    lo = np.floor(mid).astype(np.int64)
    frac = (mid - lo)[:, None]
    shown = ordered[lo] * (1 - frac) + ordered[np.minimum(lo + 1, len(order) - 1)] * frac
    truth = (palette[pairs[:, 0]] + palette[pairs[:, 1]]) / 2.0
    lab_shown, lab_truth = to_lab(shown), to_lab(truth)
    return float(np.average(delta_e_lab(lab_shown, lab_truth), weights=weights))


def score(palette: np.ndarray, order: np.ndarray, pairs=None, weights=None) -> dict:
    """Sum and maximum CIEDE2000 between neighbouring indices, and the midpoint error
    (over ``pairs`` from :func:`colour_pairs`, or :func:`near_pairs` when not given)."""
    if pairs is None:
        pairs, weights = near_pairs(palette)
    de = neighbour_differences(palette, order)
    return {"sum": float(de.sum()), "max": float(de.max()) if len(de) else 0.0,
            "midpoint": midpoint_error(palette, order, pairs, weights)}
