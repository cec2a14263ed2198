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


def check_root_order(conn_bones, trans_bones, what: str = ".trans") -> None:
    """Raise ValueError naming the first bone whose joints differ between two files."""
    if len(conn_bones) != len(trans_bones):
        raise ValueError(f"the .connect has {len(conn_bones)} bones but the {what} has {len(trans_bones)}")
    for i, (a, b) in enumerate(zip(conn_bones, trans_bones)):
        if not a.same_segment(b, tol=1e-3):
            raise ValueError(f"root order differs at bone {i}: the .connect has {a.label} "
                             f"({_coords(a)}), the {what} has {b.label} ({_coords(b)})")


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
