"""What the glTF and FBX readers share: key sampling, the clip's frame times, and the bake of its joints'
world matrices into a BVH-style :class:`Motion`.

    keys (times, values; LINEAR / STEP / CUBICSPLINE, quaternions slerped)
      --frame_times--> the clip's frames (a baked clip at its key rate, sparse keyframes at 30 a second)
      --sample_keys--> every animated value at those frames
      (the reader composes its nodes into world matrices, rest and per frame)
      --bake_motion--> a Motion whose rest (every channel zero) is the file's rest pose

**Decided here** (docs/formats.md, glTF clips; FBX clips read the same way): BVH's joints rest unturned;
glTF's and FBX's rest turned. So a joint's world rotation is taken from its rest, ``G_j(f) = R_j(f)
R_j(rest)^T``, and its channels hold the turn from its parent's, ``G_p^T G_j`` (Z X Y Euler degrees,
intrinsic, as ``trans2bvh`` writes them). Its OFFSET is where it sits from its parent at rest, in world
axes. A joint whose distance from its parent changes (a stretch) also gets position channels.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from volanim_core.io.bvh_files import Motion

MAX_FRAMES = 1_000_000  # nine hours at 30 frames a second: key times past that are no clip (1e30 s froze the read)
BAKED_RATE, SAMPLED_RATE = 24.0, 30.0
ROOT_CHANNELS = ["xposition", "yposition", "zposition", "zrotation", "xrotation", "yrotation"]


def quaternion_matrices(q: np.ndarray) -> np.ndarray:
    """``(n, 3, 3)`` rotations of quaternions ``(x, y, z, w)`` (glTF's order), normalised first."""
    q = np.asarray(q, np.float64).reshape(-1, 4)
    norm = np.linalg.norm(q, axis=1, keepdims=True)
    if (norm < 1e-12).any():
        raise ValueError("a zero quaternion is no rotation")
    x, y, z, w = (q / norm).T
    return np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w),
                     2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w),
                     2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)], 1).reshape(-1, 3, 3)


def frame_times(key_times: list[np.ndarray], fail: Callable[[str], Exception]) -> tuple[np.ndarray, float]:
    """The frames' times and rate: keys 24 or more a second apart (the median step of the densest channel)
    are a baked clip, read a frame per key; sparser keyframes are sampled at 30 frames a second. The clip
    runs from its earliest key to its last. ``fail(message)`` makes the reader's error."""
    if not key_times:
        raise fail("its animation has no keys")
    for t in key_times:
        if len(t) > 1 and not (np.diff(t) > 0).all():
            raise fail("an animation's key times do not increase")
    t0, t1 = min(t[0] for t in key_times), max(t[-1] for t in key_times)
    densest = max(key_times, key=len)
    step = np.median(np.diff(densest)) if len(densest) > 1 else 0.0
    rate = 1.0 / step if step > 0 and 1.0 / step >= 0.99 * BAKED_RATE else SAMPLED_RATE
    rate = float(np.round(rate)) if abs(rate - np.round(rate)) < 1e-3 else rate  # float32 key times: 23.99999994
    span = (t1 - t0) * rate
    if span >= MAX_FRAMES:
        raise fail(f"its keys span {t1 - t0:,.6g} s: {span:,.0f} frames at {rate:g} a second; a clip has at most "
                   f"{MAX_FRAMES:,} (are its key times in seconds?)")
    n = int(np.floor(span + 1e-6)) + 1
    return t0 + np.arange(n) / rate, rate


def sample_keys(t: np.ndarray, v: np.ndarray, times: np.ndarray, how: str = "LINEAR", rotation: bool = False,
                tangent_in: np.ndarray | None = None, tangent_out: np.ndarray | None = None) -> np.ndarray:
    """Keys ``v`` at increasing times ``t`` read at ``times`` (held before the first key and after the
    last); rotations ``(x, y, z, w)`` go the short way round."""
    if len(t) == 1:
        return np.repeat(v[:1], len(times), 0)
    i = np.clip(np.searchsorted(t, times, "right") - 1, 0, len(t) - 2)
    dt = t[i + 1] - t[i]
    u = np.clip((times - t[i]) / dt, 0.0, 1.0)[:, None]
    a, b = v[i], v[i + 1]
    if how == "STEP":
        return np.where(u >= 1.0, b, a)
    if how == "CUBICSPLINE":
        u2, u3 = u * u, u * u * u
        return ((2 * u3 - 3 * u2 + 1) * a + (u3 - 2 * u2 + u) * dt[:, None] * tangent_out[i]
                + (-2 * u3 + 3 * u2) * b + (u3 - u2) * dt[:, None] * tangent_in[i + 1])
    if rotation:
        b = np.where((a * b).sum(1, keepdims=True) < 0, -b, b)
        cos = np.clip((a * b).sum(1, keepdims=True), -1.0, 1.0)
        angle = np.arccos(cos)
        sin = np.sin(angle)
        near = sin < 1e-9
        wa = np.where(near, 1 - u, np.sin((1 - u) * angle) / np.where(near, 1, sin))
        wb = np.where(near, u, np.sin(u * angle) / np.where(near, 1, sin))
        return wa * a + wb * b
    return (1 - u) * a + u * b


def rotations(m: np.ndarray) -> np.ndarray:
    """The rotation of each ``(..., 3, 3)`` matrix without its scale (the polar factor)."""
    u, _, vt = np.linalg.svd(m)
    r = u @ vt
    flip = np.linalg.det(r) < 0  # a mirroring scale: keep a proper rotation
    u[flip, :, 2] *= -1
    return np.where(flip[..., None, None], u @ vt, r)


def zxy_degrees(r: np.ndarray) -> np.ndarray:
    """Intrinsic Z X Y Euler degrees of rotations ``(n, 3, 3)``: ``euler_matrices("ZXY", out)`` gives them back."""
    x = np.arcsin(np.clip(r[:, 2, 1], -1.0, 1.0))
    locked = np.abs(r[:, 2, 1]) > 1 - 1e-12
    z = np.where(locked, np.arctan2(r[:, 1, 0], r[:, 0, 0]), np.arctan2(-r[:, 0, 1], r[:, 1, 1]))
    y = np.where(locked, 0.0, np.arctan2(-r[:, 2, 0], r[:, 2, 2]))
    return np.degrees(np.unwrap(np.stack([z, x, y], 1), axis=0))


def ancestors(parent, k: int) -> list[int]:
    """Node ``k``'s ancestors, nearest first (``parent[j]`` -1 for a root): both readers' trees."""
    out = []
    while parent[k] >= 0:
        k = parent[k]
        out.append(k)
    return out


def unique_names(names: list[str]) -> list[str]:
    """``names`` with repeats numbered (``Bone``, ``Bone_2``): a Motion's joints need distinct names."""
    seen: dict[str, int] = {}
    out = []
    for n in names:
        seen[n] = seen.get(n, 0) + 1
        out.append(n if seen[n] == 1 else f"{n}_{seen[n]}")
    return out


def bake_motion(names: list[str], parent: list[int], rest: np.ndarray, world: np.ndarray, rate: float,
                animation: str) -> Motion:
    """A Motion from joints' world matrices: ``rest`` ``(J, 4, 4)``, ``world`` ``(F, J, 4, 4)``, parents
    first (``parent[k] < k``, -1 for the root). ValueError for what no Motion holds."""
    turn = rotations(world[..., :3, :3]) @ np.swapaxes(rotations(rest[:, :3, :3]), -1, -2)
    pos, rest_pos = world[..., :3, 3], rest[:, :3, 3]
    size = max(float(np.ptp(rest_pos, axis=0).max()), 1e-9)
    offsets, channels, columns = np.zeros((len(names), 3)), [], []
    for k, p in enumerate(parent):
        if p < 0:
            offsets[k] = rest_pos[k]
            channels.append(list(ROOT_CHANNELS))
            columns += [pos[:, k] - rest_pos[k], zxy_degrees(turn[:, k])]
            continue
        offsets[k] = rest_pos[k] - rest_pos[p]
        local = (np.swapaxes(turn[:, p], -1, -2) @ (pos[:, k] - pos[:, p])[..., None])[..., 0]
        stretch = bool(np.abs(local - offsets[k]).max() > 1e-6 * size)
        channels.append(ROOT_CHANNELS[:3] * stretch + ROOT_CHANNELS[3:])
        columns += [local] * stretch + [zxy_degrees(np.swapaxes(turn[:, p], -1, -2) @ turn[:, k])]
    return Motion(unique_names(names), np.asarray(parent), offsets, channels, 1.0 / rate, np.hstack(columns),
                  animation=animation)
