"""Our bone skeleton and its motion as a BVH clip, for an animation package (the thesis handed its
skeleton to Maya; today's animators refine a clip in Blender and bring it back with ``bvh2trans``).

    .bones + (F, B, 4, 4) matrices  --bvh_text-->  HIERARCHY (a joint per bone) + MOTION (a row per frame)

- **A joint per bone**, named by the bone, at its proximal joint; a bone with no
  children ends in an ``End Site`` at its distal joint. A BVH joint's rotation
  turns everything below it, and bones that leave one joint (a pelvis's spine
  and legs) may turn differently, so joints cannot stand for our joints.
- **The root.** When every top-level bone leaves one joint (a humanoid's
  pelvis), the ROOT is that joint, named by it, moving and turning as the first
  top-level bone does; the top-level bones are its children at offset 0, so the
  clip reads as motion capture does (hips, then spine and legs). Otherwise a
  ``ROOT`` at the origin that never moves holds them, each with position
  channels (read as the joint's position, as Blender does).
- **Rotations** are each bone's rotation relative to its parent's, as
  ``Zrotation Xrotation Yrotation`` (intrinsic, degrees: the CMU clips' order);
  the rest pose (every matrix the identity) is all zeros, so the clip's rest pose
  is our bones' rest pose. Positions are in the bones' units (voxels) times
  ``scale``, z up as in our files.
- **What BVH cannot hold:** a child bone's own translation (BVH moves children
  only through their parents' rotations). :func:`bvh_text` returns the largest
  distance between where a bone's joint is in our frames and where the clip puts
  it, so a stretched retarget is reported, never silently changed.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from volanim_core.rig.bones import BoneSkeleton

ORDER = "ZXY"  # Zrotation Xrotation Yrotation: intrinsic, as the CMU clips write them


def _rotation(m: np.ndarray) -> np.ndarray:
    """A row-vector matrix's rotation in column-vector form (``p' = R p + t``), scale removed."""
    r = np.asarray(m[:3, :3], np.float64).T
    return r / np.cbrt(np.linalg.det(r))


def _euler(r: np.ndarray) -> np.ndarray:
    from scipy.spatial.transform import Rotation

    return Rotation.from_matrix(r).as_euler(ORDER, degrees=True)


def _layout(bones: BoneSkeleton):
    """(parent of each bone's BVH joint, its children, the top-level bones, the ROOT's name, whether the
    top-level bones move on their own under a still ROOT)."""
    parents = bones.parents()
    tops = [i for i, p in enumerate(parents) if p is None]
    if not tops:
        raise ValueError("the bones have no top-level bone (a bone whose proximal joint ends no other bone)")
    children = {i: [j for j, p in enumerate(parents) if p == i] for i in range(len(parents))}
    parent = {c: p for p, cs in children.items() for c in cs}
    shared = {bones.bones[i].proximal for i in tops}
    if len(shared) == 1:
        (joint,) = shared
        root = joint if joint not in {b.label for b in bones.bones} else f"{joint}_ROOT"  # names are unique
        return parent, children, tops, root, False
    return parent, children, tops, "ROOT", True


def bvh_text(bones: BoneSkeleton, matrices: np.ndarray, fps: float, scale: float = 1.0) -> tuple[str, float]:
    """The BVH clip of ``matrices`` (``(F, B, 4, 4)``, row-vector, rest -> posed, our root order) and the
    largest distance (bones' units) between a joint's place in ``matrices`` and in the clip."""
    matrices = np.asarray(matrices, np.float64)
    if matrices.ndim != 4 or matrices.shape[1:] != (len(bones), 4, 4) or not len(matrices):
        raise ValueError(f"expected (frames, {len(bones)}, 4, 4) matrices, got {matrices.shape}")
    if not (np.isfinite(fps) and fps > 0):
        raise ValueError(f"the frame rate must be above 0, got {fps}")
    parent, children, tops, root, moving_tops = _layout(bones)
    rest = np.array([bones.joints[b.proximal] for b in bones.bones], np.float64)
    tip = np.array([bones.joints[b.distal] for b in bones.bones], np.float64)
    names = [b.label for b in bones.bones]
    channels6 = "CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation"

    def num(v):
        return " ".join(f"{x * scale:.6f}" for x in v)

    # the ROOT's OFFSET is 0 and its position channels say where it is: readers that add the two and readers
    # that take the channels alone (Blender) then agree
    lines = ["HIERARCHY", f"ROOT {root}", "{", "  OFFSET 0 0 0", f"  {channels6}"]
    rotations3 = "CHANNELS 3 Zrotation Xrotation Yrotation"
    order = []

    def write(i, depth):
        order.append(i)
        pad = "  " * depth
        offset = rest[i] - rest[parent[i]] if i in parent else (rest[i] if moving_tops else np.zeros(3))
        lines.extend([f"{pad}JOINT {names[i]}", f"{pad}{{", f"{pad}  OFFSET {num(offset)}"])
        lines.append(f"{pad}  {channels6 if moving_tops and i not in parent else rotations3}")
        for c in children[i]:
            write(c, depth + 1)
        if not children[i]:
            lines.extend([f"{pad}  End Site", f"{pad}  {{", f"{pad}    OFFSET {num(tip[i] - rest[i])}", f"{pad}  }}"])
        lines.append(f"{pad}}}")

    for t in tops:
        write(t, 1)
    lines += ["}", "MOTION", f"Frames: {len(matrices)}", f"Frame Time: {1.0 / fps:.8f}"]
    worst = 0.0
    for m in matrices:
        rot = [_rotation(m[b]) for b in range(len(bones))]
        placed = np.array([m[b, :3, :3].T @ rest[b] + m[b, 3, :3] for b in range(len(bones))])  # posed joints
        if moving_tops:
            root_rot, row = np.eye(3), [0.0] * 6
        else:  # the root moves and turns as the first top-level bone
            root_rot = rot[tops[0]]
            row = [*(placed[tops[0]] * scale), *_euler(root_rot)]
        where, locals_ = {}, []
        for i in order:
            if i in parent:
                p = parent[i]
                locals_.append(rot[p].T @ rot[i])
                where[i] = where[p] + rot[p] @ (rest[i] - rest[p])
            else:
                locals_.append(root_rot.T @ rot[i])
                where[i] = placed[i] if moving_tops else placed[tops[0]]
        angles = _euler(np.array(locals_))  # one call a frame: the clip's angles, joint by joint
        for k, i in enumerate(order):
            if moving_tops and i not in parent:
                row.extend(placed[i] * scale)
            row.extend(angles[k])
        worst = max(worst, max(float(np.linalg.norm(where[i] - placed[i])) for i in order))
        lines.append(" ".join(f"{v:.6f}" for v in row))
    return "\n".join(lines) + "\n", worst


def write_bvh(path: str | Path, bones: BoneSkeleton, matrices: np.ndarray, fps: float, scale: float = 1.0) -> float:
    """Write ``bvh_text``'s clip atomically; returns the largest joint distance it could not hold."""
    from volanim_core.io.atomic import atomic_write_text

    text, worst = bvh_text(bones, matrices, fps, scale)
    atomic_write_text(path, text)
    return worst
