"""Peers the shape benchmark scores beside volanim's own methods (#60): how two other tools would pose the
same spheres, on the same connectivity and the same matrices.

    lbs ..... linear-blend skinning of the sphere centres, what Blender's armature deformation does
              (without "Preserve Volume"): smooth joints' weights (rig/skinning.py, blend 1), each centre
              moved by the weighted sum of its bones' matrices, c' = sum_k w_k [c 1] M_k
    bender .. Kitware Bender's weights (ArmatureWeight): the body partitioned by the nearest bone (what
              `volanim connect` gives); each part's bone tissue is the hot source of its bone's heat (1
              there, 0 on every other part's source; a part with no bone tissue: its points a thickness
              from the other parts); the heat diffused over the links between points to its steady state
              (a harmonic function, one sparse solve for all bones); weights are the heats (they sum to 1),
              at most INFLUENCES a point, own bone first; blended as dual quaternions, as Bender's
              PoseLabelmap does
    --> a rigid frame in which each blended point is a bone of its own, moved by its blended matrix, so the
        engine grows the peer's spheres itself (radii unchanged: neither peer thins anything)

What these are not: Bender poses each voxel of the labelmap by its interpolated weights; here its weights
move the same spheres every volanim method grows, so the comparison is of the weights and the blend alone.
"""

from __future__ import annotations

import numpy as np

PEERS = ("lbs", "bender")
BONE_TISSUE = (250, 235)  # the mannequins' bone and skull (mannequin_body.py): Bender's "bone voxels"


def lbs_frame(conn, matrices: np.ndarray):
    """The frame linear-blend skinning gives: smooth joints' weights, matrices summed."""
    from volanim_core.rig.skinning import Joints, cached_skin

    return _frame(conn, matrices, cached_skin(conn, Joints("smooth")), linear=True)


def bender_frame(conn, matrices: np.ndarray, skin):
    """The frame Bender's weights give (``skin``: :func:`bender_skin` of ``conn``), blended as dual quaternions."""
    return _frame(conn, matrices, skin, linear=False)


def bender_skin(conn, volume: np.ndarray):
    """Bender's heat weights of ``conn``'s points; ``volume`` the rest sample (its bone tissue is the source)."""
    from scipy.sparse import coo_matrix, diags
    from scipy.sparse.csgraph import connected_components, dijkstra
    from scipy.sparse.linalg import splu

    from volanim_core.rig.skinning import INFLUENCES, MIN_WEIGHT, Skin, links

    points, bone, n_bones = conn.points, conn.bone, len(conn.bones)
    n = len(points)
    at = np.clip(np.rint(points).astype(np.int64), 0, np.array(volume.shape) - 1)
    source = np.isin(volume[tuple(at.T)], BONE_TISSUE)
    i, j, d = links(points, conn.dt)
    graph = coo_matrix((d, (i, j)), shape=(n, n)).tocsr()  # the links' lengths
    a = graph.copy()
    a.data = 1.0 / np.maximum(a.data, 1e-6)  # conductances: closer neighbours conduct more
    a = (a + a.T).tocsr()
    # a part with no bone tissue (the mannequin's torso, pelvis, clavicles, hands, feet, head: its bone rods are
    # in the limbs only) is its own source away from its joints: its points more than its thickness (thickest
    # sphere) along the links from any other part
    for k in range(n_bones):
        mine = bone == k
        if mine.any() and not source[mine].any():
            far = dijkstra(graph, directed=False, indices=np.flatnonzero(~mine), min_only=True,
                           limit=float(conn.dt[mine].max()))
            source |= mine & ~np.isfinite(far)
    laplacian = (diags(np.asarray(a.sum(1)).ravel()) - a).tocsr()
    # a linked group with no bone tissue has no source: its points keep their own bone (Bender leaves them at 0)
    _, group = connected_components(a, directed=False)
    sourced = np.isin(group, np.unique(group[source]))
    free = np.flatnonzero(sourced & ~source)
    fixed = np.flatnonzero(source)
    heat = np.zeros((n, n_bones))
    heat[np.arange(n), bone] = 1.0  # sources (own part's bone tissue) and unsourced points: their own bone
    if len(free):
        lu = splu(laplacian[free][:, free].tocsc() + 1e-9 * diags(np.ones(len(free))).tocsc())
        heat[free] = lu.solve(-(laplacian[free][:, fixed] @ heat[fixed]))
    heat = np.clip(heat, 0.0, None)
    heat[heat < MIN_WEIGHT] = 0.0
    heat[np.arange(n), bone] = np.maximum(heat[np.arange(n), bone], 1e-12)  # own bone always listed
    order = np.argsort(-heat, axis=1, kind="stable")
    own_first = np.concatenate([bone[:, None], order[order != bone[:, None]].reshape(n, n_bones - 1)], axis=1)
    influence = own_first[:, :INFLUENCES].copy()
    weight = np.take_along_axis(heat, influence, axis=1)
    influence[weight <= 0] = -1
    weight[weight <= 0] = 0.0
    weight /= weight.sum(1, keepdims=True)
    blended = weight[:, 0] < 1.0
    return Skin(np.flatnonzero(blended), influence[blended], weight[blended])


def _frame(conn, matrices: np.ndarray, skin, linear: bool):
    """A rigid frame the engine grows as is: every blended point becomes a bone of its own whose matrix is its
    blended one (the linear sum of its bones' matrices, or their dual-quaternion blend); the others keep
    their bone. Only the shape is measured, so the extra bones' labels do not matter."""
    from volanim_core.rig.connectivity import BoneSegment, Tskel
    from volanim_core.rig.dual_quaternion import blended_matrices

    m = np.asarray(matrices, np.float64)
    if linear:
        blended = np.zeros((len(skin), 4, 4))
        for col in range(skin.influence.shape[1]):
            k = skin.influence[:, col]
            ok = k >= 0
            blended[ok] += skin.weight[ok, col, None, None] * m[k[ok]]
    else:
        blended = blended_matrices(m, skin.influence, skin.weight, [b.label for b in conn.bones])
    bone = conn.bone.copy()
    bone[skin.index] = len(conn.bones) + np.arange(len(skin))
    own = conn.bones
    extra = [BoneSegment(own[b].proximal, own[b].distal, f"{own[b].label}#{i}")
             for i, b in enumerate(conn.bone[skin.index])]
    return Tskel(own + extra, np.concatenate([m, blended]), conn.points, conn.dt, conn.thinness, bone,
                 conn.metric, conn.geometry)
