"""Bilateral symmetry by the ``L_`` / ``R_`` naming convention (as Blender's Symmetrize).

Names in, names out; positions mirrored across the plane ``x = plane_x`` and
snapped to the nearest skeleton point on the other side. :func:`mirror` copies
the attachments of sided bones to their twins (the studio's Mirror
connectivity and ``volanim mirror``):

    points on L_X --mirror across x = plane--> nearest point within 1.5 voxels
                  --> attached to R_X (points with no partner are counted, left alone)
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from volanim_core.rig.bones import BoneSkeleton
from volanim_core.rig.connectivity import Connectivity

PARTNER_DISTANCE = 1.5  # voxels: a mirrored point farther than this from every point has no partner

SIDES = (("L_", "R_"), ("R_", "L_"), ("l_", "r_"), ("r_", "l_"), ("Left", "Right"), ("Right", "Left"))


def side_of(name: str) -> str | None:
    """'L' or 'R' for a sided name, None for a centre name."""
    for a, _ in SIDES:
        if name.startswith(a):
            return "L" if a.lower().startswith("l") else "R"
    return None


def mirror_name(name: str) -> str:
    """``L_ELBOW`` -> ``R_ELBOW`` (and back); centre names are their own mirror."""
    for a, b in SIDES:
        if name.startswith(a):
            return b + name[len(a):]
    return name


def mirror_point(p, plane_x: float) -> np.ndarray:
    p = np.array(p, np.float64)
    p[..., 0] = 2.0 * plane_x - p[..., 0]
    return p


def snap(points: np.ndarray, target) -> np.ndarray:
    """The skeleton point nearest to ``target`` (or ``target`` itself without points)."""
    if points is None or not len(points):
        return np.asarray(target, np.float64)
    d = ((points - np.asarray(target)) ** 2).sum(1)
    return points[int(np.argmin(d))].astype(np.float64)


def twin_of(bones: BoneSkeleton, b: int) -> int:
    """The bone whose joints are bone ``b``'s mirrored names (ValueError when there is none)."""
    bone = bones.bones[b]
    twin = (mirror_name(bone.proximal), mirror_name(bone.distal))
    k = [i for i, x in enumerate(bones.bones) if (x.proximal, x.distal) == twin]
    if not k or k[0] == b:
        raise ValueError(f"bone {bone.label} has no L_/R_ twin; symmetrize the bones first")
    return k[0]


def plane_of(bones: BoneSkeleton) -> float:
    """The x of the bones' own symmetry plane: the mean midpoint of each L_/R_ pair of joints."""
    mids = [(xyz[0] + bones.joints[mirror_name(n)][0]) / 2.0 for n, xyz in bones.joints.items()
            if side_of(n) == "L" and mirror_name(n) in bones.joints]
    if not mids:
        raise ValueError("the bones have no L_/R_ pair of joints to find the symmetry plane by; give the plane")
    return float(np.mean(mids))


def mirrored_attachments(points: np.ndarray, bone: np.ndarray, bones: BoneSkeleton, which, plane_x: float,
                         ) -> tuple[np.ndarray, np.ndarray, int]:
    """For the bones ``which``: the points their mirrored points land on, the twin bone for each, and
    how many had no partner within :data:`PARTNER_DISTANCE` -- ``(indices, bones, lonely)``."""
    from scipy.spatial import cKDTree

    tree = cKDTree(points)
    targets, values, lonely = [], [], 0
    for b in which:
        twin = twin_of(bones, b)
        src = np.flatnonzero(bone == b)
        d, j = tree.query(mirror_point(points[src], plane_x))
        ok = d <= PARTNER_DISTANCE
        lonely += int((~ok).sum())
        targets.append(j[ok])
        values.append(np.full(int(ok.sum()), twin, np.int32))
    idx = np.concatenate(targets) if targets else np.zeros(0, np.int64)
    return idx, (np.concatenate(values) if values else np.zeros(0, np.int32)), lonely


@dataclass(frozen=True)
class MirrorReport:
    copied: int  # points now on a twin bone
    changed: int  # of them, points that were on another bone before
    lonely: int  # mirrored points with no partner (left as they were)
    plane_x: float

    def __str__(self) -> str:
        return (f"{self.copied} points mirrored ({self.changed} changed bone), {self.lonely} with no partner "
                f"within {PARTNER_DISTANCE} voxels; plane x = {self.plane_x:g}")


def mirror(conn: Connectivity, bones: BoneSkeleton, *, side: str = "L", only=None,
           plane: float | None = None) -> tuple[Connectivity, MirrorReport]:
    """Copy the attachments of one side's bones to their twins on the other (``volanim mirror``).

    Parameters
    ----------
    conn : the connectivity; its bones must be ``bones`` in the same root order
    bones : the bone skeleton, for the joints' names (``L_``/``R_``, ``Left``/``Right``)
    side : ``'L'`` copies left to right, ``'R'`` right to left
    only : bone labels to mirror (default: every bone of ``side``)
    plane : x of the mirror plane in the connectivity's voxels (default: :func:`plane_of` the bones)
    """
    if side not in ("L", "R"):
        raise ValueError(f"side must be 'L' or 'R', got {side!r}")
    check_same_bones(conn, bones)
    if only:
        which = [bones.index(label) for label in only]
    else:
        which = [i for i, b in enumerate(bones.bones) if side_of(b.distal) == side]
    if not which:
        raise ValueError(f"no bone on side {side} to mirror (joint names start L_/R_ or Left/Right)")
    plane_x = plane_of(bones) if plane is None else float(plane)
    idx, values, lonely = mirrored_attachments(conn.points, conn.bone, bones, which, plane_x)
    new = conn.bone.copy()
    changed = int((new[idx] != values).sum())
    new[idx] = values
    out = Connectivity(conn.bones, conn.points, conn.dt, conn.thinness, new, conn.metric, conn.thinness_threshold,
                       conn.geometry)
    return out, MirrorReport(len(idx), changed, lonely, plane_x)


def check_same_bones(conn: Connectivity, bones: BoneSkeleton) -> None:
    """ValueError unless ``conn``'s bones are ``bones``' segments in the same order (on its grid)."""
    from volanim_core.rig.pose import root_bones
    from volanim_core.rig.tskel_tools import check_root_order

    check_root_order(conn.bones, root_bones(bones.on_grid(conn.geometry)), ".bones")
