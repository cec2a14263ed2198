"""Straighten a chain of bones along its principal axis: the thesis's colon uncoiled (section 5.3).

    bones + a chain (first .. last bone, each the child of the one before)
        --principal_axis--> u: the first principal component of the chain's joints, pointing from its first
                            joint to its last
        --straight_rotations--> each bone's global rotation: the least rotation taking its rest direction to u
        --local = parent's^T @ global--> pose_matrices (FK): the chain laid along u from its first joint, each
                            bone keeping its length; bones hanging off the chain follow their parents

The first joint stays where it is, so the straightened body starts where the curved one did. Each bone is
turned by the least rotation (about the axis perpendicular to both directions), so a tube's cross-sections
are carried along without a twist the user did not ask for.
"""

from __future__ import annotations

import numpy as np

from volanim_core.rig.bones import BoneSkeleton
from volanim_core.rig.pose import least_rotation, pose_matrices


def chain(bones: BoneSkeleton, first: str | None = None, last: str | None = None) -> list[int]:
    """The bones from ``first`` down to ``last``, each the child of the one before (indices). Without names,
    the whole skeleton when it is one chain (a colon, a tail, a tube)."""
    parents = bones.parents()
    if first is None and last is None:
        roots = [i for i, p in enumerate(parents) if p is None]
        leaves = bones.leaves()
        if len(roots) != 1 or len(leaves) != 1:
            raise ValueError(f"the skeleton is not one chain ({len(roots)} roots, {len(leaves)} ends): name the "
                             f"chain's first and last bones")
        first, last = bones.bones[roots[0]].label, bones.bones[leaves[0]].label
    if first is None or last is None:
        raise ValueError("name both the chain's first and last bones")
    labels = [x.label for x in bones.bones]
    for name in (first, last):
        if name not in labels:
            raise ValueError(f"no bone named {name!r}; bones are {', '.join(labels)}")
    a, b = bones.index(first), bones.index(last)
    out = [b]
    while out[-1] != a:
        p = parents[out[-1]]
        if p is None:
            raise ValueError(f"{last} does not hang below {first}: no chain runs from one to the other")
        out.append(p)
    return out[::-1]


def principal_axis(points: np.ndarray) -> np.ndarray:
    """The unit first principal component of ``points``, pointing from the first point towards the last."""
    p = np.asarray(points, np.float64)
    _, _, vt = np.linalg.svd(p - p.mean(axis=0), full_matrices=False)
    u = vt[0]
    return u if np.dot(p[-1] - p[0], u) >= 0 else -u


def straighten(bones: BoneSkeleton, first: str | None = None, last: str | None = None,
               axis: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, list[int]]:
    """Pose matrices (``(B, 4, 4)``, as :func:`~volanim_core.rig.pose.pose_matrices` makes) that lay the chain
    ``first`` .. ``last`` straight along ``axis`` (default: its principal axis); that axis; the chain's bones."""
    ids = chain(bones, first, last)
    segments = [bones.segment(i) for i in ids]
    joints = np.array([segments[0][0], *(d for _, d in segments)])
    u = principal_axis(joints) if axis is None else np.asarray(axis, np.float64) / np.linalg.norm(axis)
    rotations, parent_global = {}, np.eye(3)
    for i, (p, d) in zip(ids, segments):
        global_rotation = least_rotation(np.asarray(d, np.float64) - p, u)
        rotations[i] = parent_global.T @ global_rotation  # FK composes the parent's rotation after the bone's own
        parent_global = global_rotation
    return pose_matrices(bones, rotations), u, ids
