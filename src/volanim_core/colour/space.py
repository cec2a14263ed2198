"""Colour spaces and colour differences, on ``[..., 3]`` uint8 sRGB arrays.

CIELAB and CIEDE2000 are scikit-image's (``skimage.color``); linear light is the
sRGB transfer curve, what averaging of colours has to happen in.
"""

from __future__ import annotations

import numpy as np


def to_lab(rgb: np.ndarray) -> np.ndarray:
    """CIELAB (D65) of 8-bit sRGB colours, ``[..., 3]`` float64."""
    from skimage.color import rgb2lab

    rgb = np.asarray(rgb)
    return rgb2lab(rgb.reshape(-1, 1, 3) / 255.0).reshape(rgb.shape).astype(np.float64)


def from_lab(lab: np.ndarray) -> np.ndarray:
    """8-bit sRGB of CIELAB colours (out-of-gamut colours clipped)."""
    from skimage.color import lab2rgb

    lab = np.asarray(lab, np.float64)
    rgb = lab2rgb(lab.reshape(-1, 1, 3)).reshape(lab.shape)
    return np.clip(np.rint(rgb * 255), 0, 255).astype(np.uint8)


def delta_e(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """CIEDE2000 between 8-bit sRGB colours ``a`` and ``b`` (same shape ``[..., 3]``)."""
    from skimage.color import deltaE_ciede2000

    return deltaE_ciede2000(to_lab(a), to_lab(b))


def delta_e_lab(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """CIEDE2000 between CIELAB colours."""
    from skimage.color import deltaE_ciede2000

    return deltaE_ciede2000(a, b)


def to_linear(srgb: np.ndarray) -> np.ndarray:
    """8-bit sRGB -> linear light 0..1 (float32): the space in which colours average like light."""
    c = np.asarray(srgb, np.float32) / 255.0
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4).astype(np.float32)


def from_linear(linear: np.ndarray) -> np.ndarray:
    """Linear light 0..1 -> 8-bit sRGB (rounded)."""
    c = np.clip(np.asarray(linear, np.float64), 0.0, 1.0)
    s = np.where(c <= 0.0031308, c * 12.92, 1.055 * c ** (1 / 2.4) - 0.055)
    return np.clip(np.rint(s * 255.0), 0, 255).astype(np.uint8)
