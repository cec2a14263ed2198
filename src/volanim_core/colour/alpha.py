"""Alpha maps and transfer functions for index volumes (the thesis's InterpolateAlpha,
AlphaFactor and MergeMaps).

An alpha map is ``(indices, alphas)``: opacity 0..1 at control indices, linear
between and held beyond the ends (``io.palette_files``). Merged with a palette it
becomes a :class:`~volanim_core.transfer_function.TransferFunction` with
one point per palette index, which ``volanim render --tf`` draws.
"""

from __future__ import annotations

import numpy as np

from volanim_core.transfer_function import TransferFunction


def _check(indices, alphas) -> tuple[np.ndarray, np.ndarray]:
    v, a = np.asarray(indices, np.float64).reshape(-1), np.asarray(alphas, np.float64).reshape(-1)
    if len(v) == 0 or len(v) != len(a):
        raise ValueError(f"an alpha map needs one alpha per index, got {len(v)} indices and {len(a)} alphas")
    if np.any(np.diff(v) <= 0):
        raise ValueError("alpha map indices must ascend")
    if np.any((a < 0) | (a > 1)) or not np.all(np.isfinite(a)):
        raise ValueError("alphas must be between 0 and 1")
    return v, a


MAX_BETWEEN = 100_000  # maps between two looks: a fade over an hour of frames; 10^9 allocated 7 GB first


def interpolate_alpha(first, second, n: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """``n`` alpha maps evenly between two (InterpolateAlpha): map k of n is
    ``(1 - t) * first + t * second`` with ``t = k / (n + 1)``, on the union of both maps' indices
    (so a fade from one look to another over ``n`` frames has no jumps)."""
    if isinstance(n, bool) or not isinstance(n, int | np.integer) or not 1 <= n <= MAX_BETWEEN:
        raise ValueError(f"the number of maps between two must be a whole number 1..{MAX_BETWEEN}, got {n!r}")
    (v1, a1), (v2, a2) = _check(*first), _check(*second)
    v = np.union1d(v1, v2)
    s1, s2 = np.interp(v, v1, a1), np.interp(v, v2, a2)
    return [(v, (1 - t) * s1 + t * s2) for t in np.arange(1, n + 1) / (n + 1)]


def alpha_factor(alpha_map, factor: float) -> tuple[np.ndarray, np.ndarray]:
    """Every alpha times ``factor``, clipped to 0..1 (AlphaFactor)."""
    if not np.isfinite(factor) or factor < 0:
        raise ValueError(f"the factor must be a finite number >= 0, got {factor}")
    v, a = _check(*alpha_map)
    return v, np.clip(a * factor, 0.0, 1.0)


def black_indices(palette: np.ndarray) -> np.ndarray:
    """Indices of pure black in a palette: a scan's background, usually made transparent."""
    return np.flatnonzero(~np.asarray(palette).reshape(-1, 3).any(axis=1))


def merge_maps(palette: np.ndarray, alpha_map, clear=()) -> TransferFunction:
    """A palette and an alpha map as one RGBA transfer function, a point per index (MergeMaps).

    ``clear``: indices made fully transparent whatever the alpha map says (e.g. :func:`black_indices`).
    """
    palette = np.asarray(palette, np.float64).reshape(-1, 3)
    v, a = _check(*alpha_map)
    index = np.arange(len(palette), dtype=np.float64)
    alpha = np.interp(index, v, a)
    clear = np.asarray(clear, np.int64).reshape(-1)
    if clear.size and (clear.min() < 0 or clear.max() >= len(palette)):
        raise ValueError(f"indices to clear must be 0..{len(palette) - 1}, got {clear.min()}..{clear.max()}")
    alpha[clear] = 0.0
    rgba = np.column_stack([palette / 255.0, alpha])
    if len(index) == 1:  # a transfer function needs ascending values: one colour spans 0..1
        return TransferFunction(np.array([0.0, 1.0]), np.repeat(rgba, 2, axis=0))
    return TransferFunction(index, rgba)
