"""Keyframed animation without motion capture: pose keys, slerp between them, optional ease.

    key at frame k:  per bone a local rotation (x, y, z degrees, as the pose
                     sliders give it) and a shift, keyed by the bone's joints
                     (PROXIMAL, DISTAL) so renaming or reordering bones keeps it
    frame f between keys a < f < b:
        t = (f - a) / (b - a)            (eased: t^2 (3 - 2t), slow in and out)
        R_bone(f) = slerp(R_a, R_b, t)   shortest arc, per bone, in the bone's parent frame
        shift(f)  = lerp(shift_a, shift_b, t)
    before the first key / after the last: held

Interpolating *local* rotations and then running forward kinematics keeps
every bone length (a child turns with its parent), which interpolating the
final matrices would not. A bone missing from a key is at rest in that key.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation, Slerp

from volanim_core.rig.bones import BoneSkeleton
from volanim_core.rig.key_pose import MAX_FRAMES, BoneKey, KeyPose
from volanim_core.rig.pose import pose_frames


def bone_keys(bones: BoneSkeleton) -> list[BoneKey]:
    return [(b.proximal, b.distal) for b in bones.bones]


def interpolate(bones: BoneSkeleton, keys: dict[int, KeyPose], frames, *, ease: bool = False) -> np.ndarray:
    """``(F, B, 4, 4)`` pose matrices (``.trans``) at ``frames`` from the keys (frame -> KeyPose)."""
    frames = np.asarray(frames, np.float64).reshape(-1)
    n = len(bones)
    if not np.isfinite(frames).all():  # SciPy said "Interpolation times must be within the range" (#89)
        i = int(np.flatnonzero(~np.isfinite(frames))[0])
        raise ValueError(f"frames: item {i} is {frames[i]}; the frames asked for must be finite numbers")
    if not keys:
        return pose_frames(bones, np.tile(np.eye(3), (len(frames), n, 1, 1)))
    bad = [k for k in keys if not np.isfinite(float(k)) or float(k) != round(float(k)) or not 0 <= k <= MAX_FRAMES]
    if bad:
        raise ValueError(f"keys: a key at frame {bad[0]}; keys sit at whole frames 0 to {MAX_FRAMES}")
    at = np.array(sorted(keys), np.float64)
    poses = [keys[int(k)] for k in at]
    names = bone_keys(bones)
    # eased times: each frame's position between its two keys, reshaped, put back on the key axis
    t = np.clip(frames, at[0], at[-1])
    if len(at) > 1:
        seg = np.clip(np.searchsorted(at, t, side="right") - 1, 0, len(at) - 2)
        a, b = at[seg], at[seg + 1]
        u = (t - a) / (b - a)
        if ease:
            u = u * u * (3.0 - 2.0 * u)
        t = a + u * (b - a)
    rot = np.empty((len(frames), n, 3, 3))
    shift = np.empty((len(frames), n, 3))
    for i, name in enumerate(names):
        angles = np.array([p.angles.get(name, np.zeros(3)) for p in poses])
        shifts = np.array([p.shifts.get(name, np.zeros(3)) for p in poses])
        r = Rotation.from_euler("xyz", angles, degrees=True)
        rot[:, i] = (Slerp(at, r)(t) if len(at) > 1 else r[np.zeros(len(t), int)]).as_matrix()
        shift[:, i] = np.column_stack([np.interp(t, at, shifts[:, c]) for c in range(3)])
    return pose_frames(bones, rot, shift)


def keys(keys: dict[int, KeyPose], bones: BoneSkeleton, *, length: int | None = None, fps: float | None = None,
         key_fps: float = 24.0, key_length: int | None = None, ease: bool = False) -> np.ndarray:
    """The frames of a keyed animation (``volanim keys``): ``(F, B, 4, 4)`` pose matrices.

    Keys sit at frames counted at ``key_fps`` (a ``.keys`` file's ``fps``, else 24); the output has
    ``fps`` frames per second (default ``key_fps``), so ``fps=12`` makes half as many frames of the same
    motion. ``length``: output frames (default: the span of ``key_length`` frames at ``key_fps``, a
    ``.keys`` file's ``length``; else through the last key). ``ease``: slow in and out.
    """
    if not keys:
        raise ValueError("no key to animate")
    fps = key_fps if fps is None else fps
    for what, v in (("fps", fps), ("key_fps", key_fps)):
        if not 1 <= v <= 1000:
            raise ValueError(f"{what} must be 1 to 1000 frames per second, got {v:g}")
    if length is None:  # n frames span (n - 1) / fps seconds: the same span at the output's rate
        last = max(keys) if key_length is None else key_length - 1
        length = int(np.floor(last * fps / key_fps + 1e-9)) + 1
    if not 1 <= length <= MAX_FRAMES:
        raise ValueError(f"length must be 1 to {MAX_FRAMES} frames (7 minutes at 24 fps, a file each), got {length}")
    return interpolate(bones, keys, np.arange(length) * (key_fps / fps), ease=ease)
