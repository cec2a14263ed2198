"""The mannequin's analytic body: its bones, a tapered capsule per bone, painted on any grid, at rest or posed.

    mannequin_bones() -----------------------> 18 bones (root order spine, head, arms, legs)
    _mannequin_parts: a capsule per bone part (start, end, radii, squash, bone rod)
    paint_mannequin(bones, scale, shape, origin, matrices)
        each grid voxel --[q 1] @ M^-1 of each capsule's bone--> its rest point --> depth in the capsule
        --> (tissue, part) of the capsule it lies deepest in: the rest body (no matrices) or the posed one

Because the body is built analytically, posing the capsules with the bones' matrices gives the body's
true posed shape and tissue for any pose (:mod:`volanim_core.posed_truth`): rigid parts meeting at ball
joints, with no skin stretch. :mod:`volanim_core.samples` makes the demo volumes from it.
"""

from __future__ import annotations

import numpy as np

from volanim_core.rig.bones import Bone, BoneSkeleton

# Tissue values: distinct so sampled reconstruction shows the interior moving.
SKIN, FAT, MUSCLE_A, MUSCLE_B, BONE, SKULL, BRAIN = 210, 90, 130, 165, 250, 235, 110
MANNEQUIN_SHAPE = (160, 100, 300)
LARGE_SHAPE = (290, 169, 940)  # the thesis's half-size Visible Human
FULL_SHAPE = (580, 338, 1880)  # the thesis's full Visible Human grid: 368 M voxels
MID_X = (MANNEQUIN_SHAPE[0] - 1) / 2  # 79.5: the volume's mid-plane, the studio's default symmetry plane


def _mirror(x: float) -> float:
    return 2 * MID_X - x


def mannequin_bones() -> BoneSkeleton:
    """The mannequin's bone skeleton: 18 bones, root order spine, head, arms, legs."""
    j = {
        "PELVIS": (MID_X, 50, 140), "NECK": (MID_X, 50, 234), "HEAD": (MID_X, 50, 288),
        "L_SHOULDER": (108, 50, 226), "L_ELBOW": (124, 50, 178), "L_WRIST": (139, 50, 133),
        "L_FINGERS": (144, 50, 115),
        "L_HIP": (94, 50, 138), "L_KNEE": (96, 50, 78), "L_ANKLE": (97, 50, 16), "L_TOE": (97, 26, 6),
    }
    for name in [k for k in j if k.startswith("L_")]:
        x, y, z = j[name]
        j["R_" + name[2:]] = (_mirror(x), y, z)
    bones = [Bone("PELVIS", "NECK", "SPINE"), Bone("NECK", "HEAD", "HEAD")]
    for s in ("L_", "R_"):
        bones += [
            Bone("NECK", s + "SHOULDER", s + "CLAVICLE"), Bone(s + "SHOULDER", s + "ELBOW", s + "UPPERARM"),
            Bone(s + "ELBOW", s + "WRIST", s + "FOREARM"), Bone(s + "WRIST", s + "FINGERS", s + "HAND"),
        ]
    for s in ("L_", "R_"):
        bones += [
            Bone("PELVIS", s + "HIP", s + "PELVIS"), Bone(s + "HIP", s + "KNEE", s + "THIGH"),
            Bone(s + "KNEE", s + "ANKLE", s + "SHIN"), Bone(s + "ANKLE", s + "TOE", s + "FOOT"),
        ]
    return BoneSkeleton(j, bones)


# (bone name, start, end, radius at start, radius at end, y squash, bone-rod radius)
def _mannequin_parts(bones: BoneSkeleton):
    J = bones.joints
    parts = [
        ("SPINE", (MID_X, 50, 136), (MID_X, 50, 226), 21, 25, 0.62, 0),
        ("HEAD", (MID_X, 50, 230), (MID_X, 50, 250), 8, 8, 1.0, 0),
        ("HEAD", (MID_X, 50, 266), (MID_X, 50, 272), 17, 17, 0.95, 0),
    ]
    for s in ("L_", "R_"):
        parts += [
            (s + "CLAVICLE", J["NECK"] + (0, 0, -6), J[s + "SHOULDER"], 9, 10, 0.9, 0),
            (s + "UPPERARM", J[s + "SHOULDER"], J[s + "ELBOW"], 9, 7, 1.0, 2.5),
            (s + "FOREARM", J[s + "ELBOW"], J[s + "WRIST"], 7, 5, 1.0, 2.0),
            (s + "HAND", J[s + "WRIST"], J[s + "FINGERS"], 5, 4, 0.6, 0),
            (s + "PELVIS", J["PELVIS"], J[s + "HIP"], 13, 12, 0.8, 0),
            (s + "THIGH", J[s + "HIP"], J[s + "KNEE"], 12, 9, 1.0, 3.5),
            (s + "SHIN", J[s + "KNEE"], J[s + "ANKLE"], 8, 6, 1.0, 2.5),
            (s + "FOOT", J[s + "ANKLE"], J[s + "TOE"], 6, 5, 1.0, 0),
        ]
    return parts


def _scaled(p, scale) -> tuple[float, ...]:
    """A mannequin-voxel position on a grid ``scale`` times finer (voxel centres stay centres)."""
    return tuple(float(v) for v in (np.asarray(p, float) + 0.5) * scale - 0.5)


def mannequin_bones_at(scale) -> BoneSkeleton:
    """The mannequin's bones on a grid ``scale`` times finer than the mannequin's (1: its own)."""
    small = mannequin_bones()
    scale = np.asarray(scale, float)
    return small if (scale == 1).all() else \
        BoneSkeleton({k: _scaled(v, scale) for k, v in small.joints.items()}, small.bones)


def capsule_boxes(bones: BoneSkeleton, scale, matrices=None) -> list[tuple[np.ndarray, np.ndarray]]:
    """Each capsule's box ``(lo, hi)`` in whole voxels of the grid ``scale`` times finer than the mannequin's,
    moved by its bone's matrix when ``matrices`` are given (the box of its moved box's corners)."""
    scale, boxes = np.asarray(scale, float), []
    for label, a, b, ra, rb, _squash, _rod in _mannequin_parts(mannequin_bones()):
        r = max(ra, rb)
        lo = np.floor((np.minimum(a, b) - r - 0.5) * scale - 0.5)
        hi = np.ceil((np.maximum(a, b) + r + 1.5) * scale - 0.5)
        if matrices is not None:
            m = np.asarray(matrices, np.float64)[bones.index(label)]
            corners = np.array([[(lo, hi)[c >> i & 1][i] for i in range(3)] for c in range(8)]) @ m[:3, :3] + m[3, :3]
            lo, hi = np.floor(corners.min(0)), np.ceil(corners.max(0))
        boxes.append((lo.astype(int), hi.astype(int)))
    return boxes


def paint_mannequin(bones: BoneSkeleton, scale, shape, origin=(0, 0, 0), matrices=None, progress=None):
    """``(tissue, part)`` volumes of ``shape`` whose voxel ``[0, 0, 0]`` is voxel ``origin`` of the rest grid:
    each voxel gets the tissue and the part (bone index + 1) of the capsule it lies deepest in.

    ``matrices`` (B, 4, 4), rest voxels -> posed (``[x y z 1] @ M``, a ``.trans``'s): each capsule moved by
    its bone's matrix, so the grid shows the body's true posed shape (:mod:`volanim_core.posed_truth`);
    None: the rest pose. A voxel is read at the rest point its bone's matrix brings to it, so at identity
    matrices the posed body is the rest body voxel for voxel.
    """
    scale = np.asarray(scale, float)
    origin = np.asarray(origin, int)
    vol = np.zeros(shape, np.uint8, order="F")
    part = np.zeros(shape, np.uint8, order="F")
    best = np.full(shape, -np.inf, np.float32, order="F")
    parts = _mannequin_parts(mannequin_bones())
    for k, ((label, a, b, ra, rb, squash, rod), box) in enumerate(zip(parts, capsule_boxes(bones, scale, matrices))):
        a, b = np.asarray(a, float), np.asarray(b, float)
        m = None if matrices is None else np.asarray(matrices, np.float64)[bones.index(label)]
        lo = np.maximum(box[0] - origin, 0)
        hi = np.minimum(box[1] - origin, np.array(shape) - 1)
        if (hi < lo).any():  # the moved capsule misses the grid
            lo = hi + 1
        axes = [np.arange(lo[i], hi[i] + 1, dtype=np.float64) + origin[i] for i in range(3)]
        if m is None:
            x, y, z = np.meshgrid(*((axes[i] + 0.5) / scale[i] - 0.5 for i in range(3)), indexing="ij")
        else:  # each posed voxel's rest point: [q 1] @ M^-1
            q = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1)
            inv = np.linalg.inv(m)
            rest = q @ inv[:3, :3] + inv[3, :3]
            x, y, z = ((rest[..., i] + 0.5) / scale[i] - 0.5 for i in range(3))
        # the part is built in mannequin-voxel units at this grid's voxel centres
        ab = b - a
        length = float(np.linalg.norm(ab))
        t = np.clip(((x - a[0]) * ab[0] + (y - a[1]) * ab[1] + (z - a[2]) * ab[2]) / length**2, 0, 1)
        dx, dy, dz = x - (a[0] + t * ab[0]), (y - (a[1] + t * ab[1])) / squash, z - (a[2] + t * ab[2])
        d = np.sqrt(dx * dx + dy * dy + dz * dz)
        radius = ra + (rb - ra) * t
        depth = (radius - d).astype(np.float32)
        sl = tuple(slice(lo[i], hi[i] + 1) for i in range(3))
        win = (depth > 0) & (depth > best[sl])
        stripe = ((t * length) // 5).astype(int) % 2 == 0
        tissue = np.where(depth < 1.5, SKIN, np.where(depth < 4, FAT, np.where(stripe, MUSCLE_A, MUSCLE_B)))
        if rod:
            tissue = np.where(d < rod, BONE, tissue)
        if label == "HEAD" and k == 2:
            tissue = np.where(depth < 1.5, SKIN, np.where(depth < 4, SKULL, np.where(stripe, BRAIN, BRAIN + 12)))
        best[sl] = np.where(win, depth, best[sl])
        vol[sl] = np.where(win, tissue, vol[sl])
        part[sl] = np.where(win, bones.index(label) + 1, part[sl])
        if progress is not None:
            progress(k + 1, len(parts))
    return vol, part
