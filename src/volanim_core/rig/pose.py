"""Posing a bone skeleton: forward kinematics to one 4x4 matrix per bone.

Each bone may rotate about its proximal joint; a child moves with its parent:

    L_b = translate(-j_b) . R_b . translate(j_b)      local, rest frame
    M_b = L_b . M_parent(b)                            row-vector order

so ``[x y z 1] @ M_b`` first turns the point about the bone's own joint and
then applies every ancestor's motion. Rigid motions keep bone lengths.
"""

from __future__ import annotations

import warnings

import numpy as np
from scipy.spatial.transform import Rotation

from volanim_core.rig.bones import BoneSkeleton
from volanim_core.rig.connectivity import BoneSegment


def apply_matrices(points: np.ndarray, bone: np.ndarray, matrices: np.ndarray) -> np.ndarray:
    """Each point moved by its bone's matrix, ``[x y z 1] @ M[bone]``: ``(N, 3)`` float64.

    One product per bone rather than a matrix per point (the frog has 137 k points, ~10 bones).
    """
    p = np.asarray(points, np.float64).reshape(-1, 3)
    bone = np.asarray(bone)
    out = np.empty_like(p)
    if len(bone) and (bone[1:] >= bone[:-1]).all():  # grouped by bone (a .tskel's order): slices, no masks
        starts = np.concatenate(([0], np.flatnonzero(bone[1:] != bone[:-1]) + 1, [len(bone)]))
        for a, z in zip(starts[:-1], starts[1:]):
            m = matrices[bone[a]]
            np.matmul(p[a:z], m[:3, :3], out=out[a:z])
            for k in range(3):  # column by column: a (3,) broadcast over (N, 3) is 4x slower (3-long loops)
                out[a:z, k] += m[3, k]
        return out
    for b in np.unique(bone):
        sel = bone == b
        m = matrices[b]
        out[sel] = p[sel] @ m[:3, :3] + m[3, :3]
    return out


def apply_rows(points: np.ndarray, row: np.ndarray, table: np.ndarray, n_bones: int) -> np.ndarray:
    """Each point moved by its row of ``table``: the first ``n_bones`` rows are bone matrices shared by
    many points (:func:`apply_matrices`), later ones a point's own (smooth joints' blended motions)."""
    row = np.asarray(row, np.int64)
    own = np.flatnonzero(row >= n_bones)
    if not len(own):
        return apply_matrices(points, row, table)
    # every point by a bone matrix first (the own rows given their predecessor's, so grouped points stay
    # sorted for apply_matrices' fast path; no masked copies of 10^5 points), then the few own ones
    last = np.arange(len(row))
    last[own] = 0
    np.maximum.accumulate(last, out=last)  # each point's latest shared row at or before it
    shared = row[last]
    shared[shared >= n_bones] = 0  # own rows before any shared one
    out = apply_matrices(points, shared, table)
    m = table[row[own]]
    p = np.asarray(points, np.float64).reshape(-1, 3)[own]
    out[own] = np.einsum("ni,nij->nj", p, m[:, :3, :3]) + m[:, 3, :3]
    return out


def euler(degrees) -> np.ndarray:
    """3x3 rotation from x, y, z angles in degrees (extrinsic, applied x then y then z)."""
    return Rotation.from_euler("xyz", np.asarray(degrees, np.float64), degrees=True).as_matrix()


def least_rotation(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The smallest rotation (3x3, column convention) taking direction ``a`` onto ``b``: about ``a x b``, so
    nothing turns about the direction itself (a retargeted bone's rest, a straightened chain's bones)."""
    from scipy.spatial.transform import Rotation

    a = np.asarray(a, np.float64) / np.linalg.norm(a)
    b = np.asarray(b, np.float64) / np.linalg.norm(b)
    axis = np.cross(a, b)
    s, c = np.linalg.norm(axis), float(np.clip(a @ b, -1, 1))
    if s < 1e-12:
        if c > 0:
            return np.eye(3)
        other = np.eye(3)[np.argmin(np.abs(a))]  # opposite: half a turn about any perpendicular
        axis = np.cross(a, other)
        return Rotation.from_rotvec(np.pi * axis / np.linalg.norm(axis)).as_matrix()
    return Rotation.from_rotvec(axis / s * np.arctan2(s, c)).as_matrix()


def bend_across(bones: BoneSkeleton, label: str, degrees: float) -> np.ndarray:
    """The 3x3 rotation bending bone ``label`` by ``degrees`` towards the grid axis most across it, about
    an axis across the bone: a real bend whichever way the bone lies (a fixed ``0,45,0`` only twists a
    bone that lies along y). For :func:`pose_matrices`."""
    b = bones.bones[bones.index(label)]
    along = bones.joints[b.distal] - bones.joints[b.proximal]
    axis = np.cross(along, np.eye(3)[int(np.argmin(np.abs(along)))])
    return Rotation.from_rotvec(np.radians(degrees) * axis / (np.linalg.norm(axis) or 1)).as_matrix()


def parents_first(parents: list[int | None]) -> list[int]:
    """Bone indices with every parent before its children (the forest may list them in any order)."""
    done: list[int] = []
    placed = [False] * len(parents)
    for start in range(len(parents)):  # iterative: a 3000-bone chain listed leaf first must not recurse
        chain, i = [], start
        while i is not None and not placed[i]:
            if len(chain) > len(parents):
                raise ValueError(f"the bone hierarchy has a cycle through bone {i}")
            chain.append(i)
            i = parents[i]
        for j in reversed(chain):
            placed[j] = True
            done.append(j)
    return done


def pose_matrices(bones: BoneSkeleton, rotations: dict | None = None, translations: dict | None = None) -> np.ndarray:
    """Forward kinematics: ``(B, 4, 4)`` matrices, rest voxel coordinates -> posed.

    Parameters
    ----------
    bones : BoneSkeleton
    rotations : dict, optional
        Bone index or name -> 3x3 rotation matrix (column convention) or three
        Euler angles in degrees, applied about the bone's proximal joint.
    translations : dict, optional
        Bone index or name -> a shift (voxels) applied after its rotation; its
        children move with it (a root's walk in motion data).
    """
    n = len(bones)
    local = [np.eye(3) for _ in range(n)]
    for key, rot in (rotations or {}).items():
        i = key if isinstance(key, int | np.integer) else bones.index(key)
        if not 0 <= i < n:
            raise ValueError(f"no bone {key!r}")
        rot = np.asarray(rot, np.float64)
        local[i] = euler(rot) if rot.shape == (3,) else rot
        if local[i].shape != (3, 3):
            raise ValueError(f"rotation of bone {key!r} must be 3x3 or three angles")
    shift = [np.zeros(3) for _ in range(n)]
    for key, t in (translations or {}).items():
        i = key if isinstance(key, int | np.integer) else bones.index(key)
        shift[i] = np.asarray(t, np.float64).reshape(3)
    return pose_frames(bones, np.reshape(local, (1, n, 3, 3)), np.reshape(shift, (1, n, 3)))[0]


def pose_frames(bones: BoneSkeleton, rotations: np.ndarray, shifts: np.ndarray | None = None) -> np.ndarray:
    """Forward kinematics for many frames at once: ``(F, B, 4, 4)`` from local rotations.

    ``rotations`` is ``(F, B, 3, 3)`` (column convention, about each bone's
    proximal joint) and ``shifts`` ``(F, B, 3)``; one batched product per bone,
    so a 1000-frame keyframed clip costs what 18 single poses do.
    """
    rot = np.asarray(rotations, np.float64)
    n_frames, n = rot.shape[:2]
    shift = np.zeros((n_frames, n, 3)) if shifts is None else np.asarray(shifts, np.float64)
    parents = bones.parents()
    out = np.zeros((n_frames, n, 4, 4))
    for i in parents_first(parents):
        j = bones.joints[bones.bones[i].proximal]
        m = np.zeros((n_frames, 4, 4))
        m[:, :3, :3] = np.swapaxes(rot[:, i], 1, 2)
        m[:, 3, :3] = j - np.einsum("k,fkl->fl", j, m[:, :3, :3]) + shift[:, i]
        m[:, 3, 3] = 1.0
        out[:, i] = m if parents[i] is None else m @ out[:, parents[i]]
    return out


def local_motion(bones: BoneSkeleton, matrices: np.ndarray) -> tuple[dict, dict]:
    """Invert :func:`pose_matrices`: per bone, Euler angles (degrees) and the shift that give ``matrices``.

    Loading a ``.trans`` into the pose sliders uses this; for matrices made
    by FK it round-trips exactly (up to float rounding).
    """
    parents = bones.parents()
    angles, shifts = {}, {}
    for i, b in enumerate(bones.bones):
        m = np.asarray(matrices[i], np.float64)
        local = m if parents[i] is None else m @ np.linalg.inv(matrices[parents[i]])
        r = local[:3, :3].T  # row-vector matrix -> column-convention rotation
        u, _, vt = np.linalg.svd(r)  # nearest rotation, in case of float drift
        r = u @ vt
        with warnings.catch_warnings():  # at +-90 degrees about y any split of x and z is right: take one
            warnings.filterwarnings("ignore", "Gimbal lock", UserWarning)
            angles[i] = Rotation.from_matrix(r).as_euler("xyz", degrees=True)
        j = bones.joints[b.proximal]
        shifts[i] = local[3, :3] - (j - j @ r.T)
    return angles, shifts


def scaled(matrices: np.ndarray, factor: float) -> np.ndarray:
    """Matrices followed by a uniform scale 1/factor: a ``factor``-times coarser output grid (previews)."""
    s = np.eye(4)
    s[:3, :3] /= factor
    return np.asarray(matrices) @ s


def root_bones(bones: BoneSkeleton) -> list[BoneSegment]:
    """The ``Root:`` records of a bone skeleton, in root order."""
    return [BoneSegment(*bones.segment(i), b.label) for i, b in enumerate(bones.bones)]


def joint_bones(bones: BoneSkeleton) -> list[int]:
    """Per joint (in ``bones.joints`` order), the bone whose matrix places it: the first bone that starts at
    it, else (a tip: a hand's end) the bone that ends at it.

    The one rule for where a posed joint is (#68): the studio's bones and names, the breakage report's
    joints and ``trans2positions`` all use it. A bone's own matrix carries its start, so a shifted child
    bone (a keyed translation) takes its joint with it; the parent's far end and the child's start agree
    whenever nothing is shifted."""
    first_start, end = {}, {}
    for i, b in enumerate(bones.bones):
        first_start.setdefault(b.proximal, i)
        end[b.distal] = i
    return [first_start.get(name, end.get(name, -1)) for name in bones.joints]


def joint_positions(bones: BoneSkeleton, matrices: np.ndarray) -> np.ndarray:
    """Every joint's posed place, ``(J, 3)`` for one frame's ``(B, 4, 4)`` matrices or ``(F, J, 3)`` for
    ``(F, B, 4, 4)``, in ``bones.joints`` order (:func:`joint_bones` says which bone places each)."""
    m = np.asarray(matrices, np.float64)
    which = np.array(joint_bones(bones), np.int64)
    rest = np.array([bones.joints[n] for n in bones.joints], np.float64).reshape(-1, 3)
    if (which < 0).any():  # (a .bones file's every joint is on a bone; only a hand-made skeleton lacks one)
        raise ValueError("a joint is on no bone: " + ", ".join(n for n, w in zip(bones.joints, which) if w < 0))
    rot, shift = m[..., which, :3, :3], m[..., which, 3, :3]
    return np.einsum("jk,...jkl->...jl", rest, rot) + shift


def posed_joints(bones: BoneSkeleton, matrices: np.ndarray) -> dict[str, np.ndarray]:
    """Where each joint goes in one frame, by name (:func:`joint_positions`)."""
    return dict(zip(bones.joints, joint_positions(bones, matrices)))
