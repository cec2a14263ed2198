"""Colours: one per bone in root order, grey for unconnected points, colour maps for scalars.

The bone palette was picked once by greedy farthest-point sampling in CIELAB
(skimage ``rgb2lab``/``deltaE_ciede2000``) over a 16-level RGB grid, keeping
colours light and saturated enough for a dark 3-D background (50 < L < 92,
chroma > 25): any two of the first 24 differ by ΔE2000 >= 15.6, of all 32 by
>= 14.1. (The studio's old 16 colours repeated from bone 16 on: SPINE and
R_SHIN shared red.) Past 32 bones the palette repeats.
"""

from __future__ import annotations

import numpy as np

BONE_PALETTE = (
    "#ee2244", "#00ff00", "#00bbff", "#ffaa00", "#eeccff", "#008866", "#bb22ff", "#00ffee",
    "#887733", "#ffaa99", "#5577cc", "#ddddaa", "#aa7799", "#cc6611", "#77aa33", "#228899",
    "#ff77ff", "#77bb99", "#eeee00", "#ff0099", "#aa99ff", "#bbaa11", "#ff88aa", "#aa6655",
    "#88ddee", "#88ffbb", "#bb9966", "#ffcc99", "#ff6644", "#aaccff", "#338822", "#ff9955",
)
UNCONNECTED = "#8c8c8c"
SKIN = "#e8c9a0"  # one-colour surfaces (binary previews)


def rgb(hex_colour: str) -> tuple[float, float, float]:
    """``"#rrggbb"`` -> (r, g, b) in 0..1."""
    h = hex_colour.lstrip("#")
    return tuple(int(h[i : i + 2], 16) / 255.0 for i in (0, 2, 4))


def bone_colour(index: int) -> str:
    """Bone ``index``'s colour as ``"#rrggbb"``."""
    return BONE_PALETTE[index % len(BONE_PALETTE)]


def bone_colours(n: int) -> np.ndarray:
    """``(n, 3)`` float RGB in 0..1, bone 0 first."""
    return np.array([rgb(bone_colour(i)) for i in range(n)], np.float64).reshape(n, 3)


def label_table(n_bones: int) -> np.ndarray:
    """``(n_bones + 1, 3)`` uint8: row 0 the unconnected grey, row b + 1 bone b.

    Index it with ``bone + 1`` (unattached points are -1) or with a bone-mode
    reconstruction's voxel values (0 empty, b + 1 bone b).
    """
    table = np.vstack([[rgb(UNCONNECTED)], bone_colours(n_bones)])
    return np.round(table * 255).astype(np.uint8)


def scalar_colours(values: np.ndarray, cmap: str = "viridis") -> np.ndarray:
    """``(N, 3)`` uint8 colours of ``values`` stretched over a matplotlib colour map."""
    from matplotlib import colormaps

    values = np.asarray(values, np.float64)
    lo, hi = (float(values.min()), float(values.max())) if values.size else (0.0, 0.0)
    t = (values - lo) / (hi - lo) if hi > lo else np.zeros(len(values))
    return (colormaps[cmap](t)[:, :3] * 255).astype(np.uint8)
