"""One-voxel spheres follow the flesh they lie on: the smooth-joint weights of the skeleton's thinnest points.

    Skin of every reached point (rig/skinning.py), the links' graph
      --specks: each group of linked points whose spheres are all one voxel (dt < SPECK), linked to
        nothing thicker, so no bone reaches it: the whole group takes the weights of the one thicker
        sphere that holds it best (holder: the least |p - c| - r over its points)
      --surface: each linked group of one-voxel points of one bone, in a body, that all overlap one
        thicker sphere of that bone (the one holding the group best): that sphere's weights; a group
        spreading beyond one sphere is a thin sheet and keeps its own
      --> the same Skin, those rows replaced (own bone first, with weight 0 where the host has none)

Why. A one-voxel sphere is the skeleton's noise at a scan's surface: it carries no shape of its own,
and its overlap with the flesh around it is a voxel or less. Its weights, made from its own position
like every point's, can differ from those of the sphere it lies in by as much as 0.2 between
neighbours (measured), and a 90-degree bend then moves the two 2-3 voxels apart: the speck is torn
off as a piece of its own (mannequin-large's ankle, the ant's waist, the rabbit's hind leg). Moving
exactly as the sphere that holds it, it keeps its place in it whatever the pose. A group moves as
one: its points lying deepest in different spheres with different weights tore the group apart (the
rabbit's six-point speck at the hip). The surface rule keeps to the point's own bone, so a thin limb
(an antenna, all one-voxel spheres) is never taken over by the thick body it starts from.
"""

from __future__ import annotations

import numpy as np

from volanim_core.rig.skin import INFLUENCES, Skin

SPECK = 2.0  # spheres thinner than this are one voxel: the surface's noise
NEAREST = 16  # centres examined per point for the sphere that holds it best (with the deepest by power)


def deepest_sphere(centres: np.ndarray, radii: np.ndarray, points: np.ndarray) -> np.ndarray:
    """For each of ``points``, the sphere it lies deepest in, or nearest outside, by power distance
    ``|p - c|^2 - r^2``: the nearest neighbour of ``(p, 0)`` among the lifted centres
    ``(c, sqrt(R^2 - r^2))`` (``R`` the largest radius), one KD-tree query for all."""
    from scipy.spatial import cKDTree

    lift = np.sqrt(np.maximum(radii.max() ** 2 - radii ** 2, 0.0))
    tree = cKDTree(np.column_stack([centres, lift]))
    return tree.query(np.column_stack([points, np.zeros(len(points))]))[1]


def holder(centres: np.ndarray, radii: np.ndarray, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each of ``points``, the sphere whose surface is furthest inside it or, outside all, nearest:
    least ``|p - c| - r`` among its ``NEAREST`` nearest centres and the one it lies deepest in by power
    distance (:func:`deepest_sphere`, which finds a big sphere's centre however far); of equal gaps, the
    first sphere. With its ``gap`` (negative inside). The sphere a point keeps in touch with best when
    it moves as that sphere."""
    from scipy.spatial import cKDTree

    k = min(NEAREST, len(centres))
    _, nn = cKDTree(centres).query(points, k=k)
    cand = np.column_stack([nn.reshape(len(points), k), deepest_sphere(centres, radii, points)])
    gap = np.linalg.norm(points[:, None, :] - centres[cand], axis=2) - radii[cand]
    least = gap.min(1)
    best = np.where(gap <= least[:, None] + 1e-12, cand, len(centres)).min(1)  # ties: the first sphere
    return best, least


def with_thin_spheres(skin, points, dt, bone, graph):
    """``skin`` with every speck group and every one-voxel surface point moving as its host (the module's
    docstring); ``graph``: the links (a sparse matrix over the points)."""
    from scipy.sparse.csgraph import connected_components

    if not len(skin):
        return skin
    _, part = connected_components(graph, directed=False)
    held = np.zeros(part.max() + 1, bool)  # groups with a thicker sphere in them
    np.logical_or.at(held, part, dt >= SPECK)
    speck, speck_host = _speck_hosts(points, dt, part, held)
    thin, thin_host = _surface_hosts(points, dt, bone, held[part], graph)
    return _copied(skin, np.r_[speck, thin], np.r_[speck_host, thin_host], bone)


def _speck_hosts(points, dt, part, held):
    """Each speck point and the sphere outside any speck that holds its group best (one per group:
    :func:`holder` of its points, the least gap of all)."""
    speck = np.flatnonzero(~held[part])
    body = np.flatnonzero(held[part])
    if not len(speck) or not len(body):
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    at, gap = holder(points[body], dt[body], points[speck])
    return speck, _best_of_group(part[speck], gap, body[at])


def _surface_hosts(points, dt, bone, in_body, graph):
    """The one-voxel points of groups with thicker spheres, in linked groups of their own bone that all
    overlap one thicker sphere of that bone (the one that holds the group best), and that sphere. A group
    that spreads beyond one sphere is no speck on it but a thin sheet of its own (the frog's webbing):
    its points keep their weights, which change smoothly along it."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    n = len(dt)
    thin = (dt < SPECK) & in_body
    g = graph.tocoo()
    same = thin[g.row] & thin[g.col] & (bone[g.row] == bone[g.col])
    _, group = connected_components(coo_matrix((np.ones(int(same.sum())), (g.row[same], g.col[same])),
                                               shape=(n, n)), directed=False)
    idx = np.flatnonzero(thin)
    take, host = [], []
    for b in np.unique(bone[idx]):
        t = idx[bone[idx] == b]
        h = np.flatnonzero((dt >= SPECK) & (bone == b))
        if not len(h):
            continue
        at, gap = holder(points[h], dt[h], points[t])
        best = _best_of_group(group[t], gap, h[at])
        over = np.linalg.norm(points[t] - points[best], axis=1) - dt[best] < dt[t]
        whole = np.ones(n, bool)
        np.logical_and.at(whole, group[t], over)
        ok = whole[group[t]]
        take.append(t[ok])
        host.append(best[ok])
    if not take:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    return np.concatenate(take), np.concatenate(host)


def _best_of_group(group: np.ndarray, gap: np.ndarray, host: np.ndarray) -> np.ndarray:
    """Per point, the host of the point of its group with the least gap."""
    order = np.lexsort((gap, group))  # by group, the best held first
    g = group[order]
    first = np.r_[True, g[1:] != g[:-1]]
    best = np.empty(len(group), np.int64)
    start = np.cumsum(first) - 1  # each sorted point's group number among the firsts
    best[order] = host[order][first][start]
    return best


def _copied(skin, take, host, bone):
    """The skin in which each point of ``take`` has the weights of its ``host``: own bone first, where it
    is among the host's bones, or in the last place with weight 0. A host with no row (rigid on its bone)
    makes a point of its own bone rigid too; a speck whose host is rigid on another bone keeps its own
    bone (what a rigid frame does with it)."""
    n = len(bone)
    row = np.full(n, -1, np.int64)
    row[skin.index] = np.arange(len(skin))
    rigid_same = (row[host] < 0) & (bone[host] == bone[take])
    moved = take[(row[host] >= 0) | rigid_same]  # every point whose row changes
    take, host = take[row[host] >= 0], host[row[host] >= 0]
    influence, weight = skin.influence[row[host]].copy(), skin.weight[row[host]].copy()
    own = bone[take]
    has = influence == own[:, None]
    at = np.where(has.any(1), has.argmax(1), INFLUENCES - 1)
    r = np.arange(len(take))
    weight[r, at] *= has.any(1)
    influence[r, at] = own
    col = np.arange(INFLUENCES)[None, :]
    order = np.where(col == 0, at[:, None], col - (col <= at[:, None]))  # at, then the others in order
    influence, weight = np.take_along_axis(influence, order, 1), np.take_along_axis(weight, order, 1)
    weight /= weight.sum(1, keepdims=True)
    mine = weight[:, 0] < 1.0  # a host rigid on the point's own bone leaves it rigid
    take, influence, weight = take[mine], influence[mine], weight[mine]
    keep = np.setdiff1d(np.arange(len(skin)), row[moved[row[moved] >= 0]])  # the old rows give way
    index = np.concatenate([skin.index[keep], take])
    order = np.argsort(index, kind="stable")
    return Skin(index[order], np.concatenate([skin.influence[keep], influence])[order],
                np.concatenate([skin.weight[keep], weight])[order])
