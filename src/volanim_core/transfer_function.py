"""A user transfer function: value -> colour and opacity, linear between points (the old icol/MergeMaps maps).

``TransferFunction(values, rgba)``: ``values`` ascending, ``rgba`` rows of red,
green, blue (0..1) and alpha (opacity, 0..1). Files are ``.tf`` text (io.render_files).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

MAX_POINTS = 4096  # one per grey value of 12 bits; VTK's piecewise functions hung `render` on 100 000


@dataclass(frozen=True, eq=False)
class TransferFunction:
    values: np.ndarray  # (N,) strictly ascending
    rgba: np.ndarray  # (N, 4) in 0..1

    def __post_init__(self):
        v = np.asarray(self.values, np.float64).reshape(-1)
        c = np.asarray(self.rgba, np.float64).reshape(-1, 4)
        if len(v) == 0 or len(v) != len(c):
            raise ValueError(f"a transfer function needs one RGBA per value, got {len(v)} values, {len(c)} colours")
        if len(v) > MAX_POINTS:
            raise ValueError(f"a transfer function has at most {MAX_POINTS} points, got {len(v)}")
        if not np.all(np.isfinite(v)):
            raise ValueError("transfer function values must be finite numbers")
        if np.any(np.diff(v) <= 0):
            raise ValueError("transfer function values must be strictly ascending")
        if np.any((c < 0) | (c > 1)) or not np.all(np.isfinite(c)):
            raise ValueError("transfer function colours and opacities must be between 0 and 1")
        object.__setattr__(self, "values", v)
        object.__setattr__(self, "rgba", c)

    def __eq__(self, other) -> bool:
        return (isinstance(other, TransferFunction) and np.array_equal(self.values, other.values)
                and np.array_equal(self.rgba, other.rgba))

    def __call__(self, x) -> np.ndarray:
        """RGBA of ``x`` (linear between points, held beyond the ends), shape ``x.shape + (4,)``."""
        x = np.asarray(x, np.float64)
        return np.stack([np.interp(x, self.values, self.rgba[:, k]) for k in range(4)], axis=-1)

