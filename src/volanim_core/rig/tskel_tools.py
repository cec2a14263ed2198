"""Tools on ``.connect``/``.trans``/``.tskel`` data (the old pipeline's little programs).

    connect_to_tskel(conn, trans)   connect2tskel: attach a frame's matrices
    identity_tskel(conn)            connect2identitytskel: every matrix the identity
    coarse_tskel(tskel, factor)     the frame on a coarser grid (previews, scans)
    sort_tskel(tskel)               sorttskel: points of each bone by decreasing DT
    reconstruct.grid_bounds         tskelbounds
"""

from __future__ import annotations

import numpy as np

from volanim_core.rig.connectivity import Connectivity, Trans, Tskel


def check_root_order(conn_bones, trans_bones, what: str = ".trans", first: str = ".connect") -> None:
    """Raise ValueError saying how two files' bones differ: the bones only one of them has, two bones listed in
    other orders, or the first bone whose joints moved (by how much), and what to do. The caller names the
    files (the CLI's error prefix, or ``what``/``first``)."""
    if len(conn_bones) == len(trans_bones) and all(a.same_segment(b, tol=1e-3)
                                                    for a, b in zip(conn_bones, trans_bones)):
        return  # the usual answer, once per frame of a clip: the pairwise search below is for saying what differs
    fix = (f"the {what} was written for another bone skeleton: write the frames from the bones of this "
           f"{first} (volanim pose, keys or bvh2trans with its .bones)")
    only_theirs = [b for b in trans_bones if not any(b.same_segment(a, tol=1e-3) for a in conn_bones)]
    only_ours = [a for a in conn_bones if not any(a.same_segment(b, tol=1e-3) for b in trans_bones)]
    if len(conn_bones) != len(trans_bones):
        extra = "; ".join(filter(None, (_listed(only_theirs, f"only in the {what}"),
                                        _listed(only_ours, f"only in the {first}"))))
        raise ValueError(f"the {first} has {len(conn_bones)} bones but the {what} has {len(trans_bones)}"
                         + (f" ({extra})" if extra else "") + f"; {fix}")
    for i, (a, b) in enumerate(zip(conn_bones, trans_bones)):
        if a.same_segment(b, tol=1e-3):
            continue
        if not any(b is x for x in only_theirs):  # b is another bone of ours: the same bones, listed in another order
            j = next(k for k, c in enumerate(conn_bones) if c.same_segment(b, tol=1e-3))
            raise ValueError(f"the bones are listed in other orders: bone {i} is {_named(a)} in the {first} but "
                             f"{_named(b)} in the {what} (the {first}'s bone {j}); list them in the {first}'s "
                             f"root order, or {fix}")
        moved = max(np.abs(a.proximal - b.proximal).max(), np.abs(a.distal - b.distal).max())
        how = (f"its joints moved by up to {moved:g} voxels" if a.name == b.name and a.name else
               f"the {what} has {_named(b)} there, which the {first} does not have")
        raise ValueError(f"bone {i} differs: the {first} has {_named(a)}, {how} ({_coords(b)}); {fix}")


def _named(b) -> str:
    return f"{b.label} ({_coords(b)})" if b.name else f"bone {_coords(b)}"


def _listed(bones, where: str) -> str:
    if not bones:
        return ""
    names = ", ".join(_named(b) for b in bones[:3]) + (f" and {len(bones) - 3} more" if len(bones) > 3 else "")
    return f"{names} {'is' if len(bones) == 1 else 'are'} {where}"


def _coords(b) -> str:
    return " ".join(f"{v:g}" for v in b.proximal) + " :: " + " ".join(f"{v:g}" for v in b.distal)


def connect_to_tskel(conn: Connectivity, trans: Trans) -> Tskel:
    """One frame ready to reconstruct: the connectivity with the frame's matrices (the frame taken onto the
    connectivity's grid first, :meth:`~volanim_core.rig.connectivity.Trans.on_grid`)."""
    trans = trans.on_grid(conn.geometry)
    check_root_order(conn.bones, trans.bones)
    return conn.posed(trans.matrices)


def identity_tskel(conn: Connectivity) -> Tskel:
    """The rest frame: every matrix the identity (reconstructs the original shape)."""
    return conn.posed(np.tile(np.eye(4), (len(conn.bones), 1, 1)))


def coarse_tskel(tskel: Tskel, factor: int) -> Tskel:
    """The frame on a ``factor``-times coarser grid: matrices followed by a 1/factor scale, radii alike, its
    rig's ownership pooled (live previews and the clip scan: factor^3 fewer voxels, the same shape).
    Smooth joints keep the fine frame's blend weights: the coarse frame bends exactly as the full one does."""
    if factor == 1:
        return tskel
    from volanim_core.rig.pose import scaled

    out = Tskel(tskel.bones, scaled(tskel.matrices, factor), tskel.points, tskel.dt / factor, tskel.thinness,
                tskel.bone, tskel.metric, tskel.geometry.with_spacing(np.multiply(tskel.geometry.spacing, factor)),
                joints=tskel.joints, skin=tskel.skin if tskel.joints.smooth else None)
    if tskel.ownership is not None:  # the owned body on the coarse grid too: a half-size preview is no sphere body
        out.ownership = tskel.ownership.coarse(factor)
    return out


def sort_tskel(tskel: Tskel) -> Tskel:
    """Points grouped by bone in root order, each bone's by decreasing DT (stable)."""
    return tskel.take(np.lexsort((-tskel.dt, tskel.bone)))
