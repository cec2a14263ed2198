"""A pose key: per bone, Euler angles and a shift, keyed by the bone's joints (what ``.keys`` files and
the studio's timeline hold; :mod:`volanim_core.motion.keyframes` slerps between them).

Here, in the rig, so that the ``.keys`` reader in ``io`` and the keyframing in ``motion`` share the type
without ``io`` importing ``motion``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

MAX_FRAMES = 10_000  # a keyed animation writes a .trans per frame: 100 000 took minutes of files
BoneKey = tuple[str, str]  # (proximal joint, distal joint)


@dataclass
class KeyPose:
    """One key: per bone, Euler angles (degrees, extrinsic x-y-z as the sliders) and a shift (voxels)."""

    angles: dict[BoneKey, np.ndarray] = field(default_factory=dict)
    shifts: dict[BoneKey, np.ndarray] = field(default_factory=dict)

    def to_json(self) -> list:
        """``[[PROXIMAL, DISTAL, rx, ry, rz, tx, ty, tz], ...]`` for the bones this key moves."""
        out = []
        for k in sorted(set(self.angles) | set(self.shifts)):
            a = self.angles.get(k, np.zeros(3))
            t = self.shifts.get(k, np.zeros(3))
            out.append([k[0], k[1], *(float(v) for v in a), *(float(v) for v in t)])
        return out

    @classmethod
    def from_json(cls, rows, where: str) -> KeyPose:
        """Inverse of :meth:`to_json`; ``where`` names the key in errors (ValueError)."""
        if not isinstance(rows, list):
            raise ValueError(f"{where}: expected a list of [PROXIMAL, DISTAL, rx, ry, rz, tx, ty, tz]")
        key = cls()
        for row in rows:
            ok = (isinstance(row, list) and len(row) == 8 and all(isinstance(v, str) for v in row[:2])
                  and all(isinstance(v, int | float) and not isinstance(v, bool) for v in row[2:]))
            values = np.asarray(row[2:], np.float64) if ok else None
            if not ok or not np.isfinite(values).all() or np.abs(values).max() > 1e9:
                raise ValueError(f"{where}: expected [PROXIMAL, DISTAL, rx, ry, rz, tx, ty, tz] "
                                 f"with finite numbers, got {str(row)[:80]}")
            k = (row[0], row[1])
            if k in key.angles:
                raise ValueError(f"{where}: bone {k[0]}-{k[1]} is keyed twice")
            key.angles[k], key.shifts[k] = values[:3], values[3:]
        return key
