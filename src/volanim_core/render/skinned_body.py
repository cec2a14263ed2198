"""The posed body for any glTF viewer: the rest body's surface, skinned to the bones by ownership, and the
bones' motion as a glTF animation (``volanim export-gltf``, the studio's *File → Export animated glTF…*).

    .connect (+ NAME.owners.nrrd)             frames (F, B, 4, 4), row-vector voxel matrices, + fps
      --labels--> each rest voxel's bone         |
      --flying edges, Taubin smoothing,          |
        quadric decimation--> surface            |
      --weights--> up to 4 bones a vertex        --joint tree--> each bone a joint at its proximal joint,
                   (near a joint: both bones)                    under the bone it hangs from; local T, R
      --axes--> metres, Y up, feet on the floor at the origin
      --io.gltf_export.write_glb--> NAME.glb (atomic)

**Decided here** (docs/formats.md#gltf-out):

- Labels: the rig's ownership (``NAME.owners.nrrd``, the default of ``volanim connect``); a rig without one
  is re-grown at rest in ``bone`` mode (the thesis's spheres), each voxel its sphere's bone.
- Weights: a vertex takes every bone whose owned voxels lie within a few voxels, ``exp(-(d / blend)²)`` of
  the distance ``d`` to them (``blend`` 2 voxels by default), the four largest, summing to 1. Deep in a
  bone its vertices follow it alone; across a joint they blend, so a bend folds the skin instead of
  tearing it (linear blend skinning: what every viewer does).
- Joints: bone b is joint b, placed at its proximal joint, the child of the bone whose distal joint is
  its proximal joint (else of a bone leaving the same joint, else of the root), named as the bone.
- Axes and units: the rig's grid in millimetres (its spacing; 1 mm a voxel without one) to metres; LPS's
  superior is glTF's +Y, anterior +Z; the rest body stands on y = 0, centred on the origin.
"""

from __future__ import annotations

import numpy as np

from volanim_core.io.gltf_export import JointAnimation, SkinnedMesh, write_glb
from volanim_core.isosurface import flying_edges
from volanim_core.progress import CancelFn, ProgressFn, Reporter
from volanim_core.rig.connectivity import Connectivity

MAX_TRIANGLES = 200_000
BLEND = 2.0
#: LPS (x left, y posterior, z superior) to glTF (x left, y up, z forward): -90 degrees about x
LPS_TO_GLTF = np.array([[1.0, 0, 0, 0], [0, 0, 1, 0], [0, -1, 0, 0], [0, 0, 0, 1]])


def body_labels(conn: Connectivity) -> tuple[np.ndarray, np.ndarray]:
    """Each rest voxel's bone + 1 (0 outside) in a box, and the box's first voxel."""
    own = conn.ownership
    if own is not None and own.factor == 1:
        return own.labels, np.asarray(own.origin)
    from volanim_core.reconstruct import reconstruct
    from volanim_core.rig.tskel_tools import identity_tskel

    rec = reconstruct(identity_tskel(conn), mode="bone", method="spheres")
    return rec.volume, np.asarray(rec.origin)


def body_surface(labels: np.ndarray, origin, max_triangles: int = MAX_TRIANGLES
                 ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The body's boundary in rest voxel coordinates: vertices, unit normals, triangles (at most
    ``max_triangles``: quadric decimation keeps the shape where a viewer looks)."""
    import pyvista as pv

    mask = np.pad(labels > 0, 1).astype(np.uint8)
    vertices, faces = flying_edges(mask, np.asarray(origin) - 1)
    if not len(faces):
        raise ValueError("the rig's body is empty: nothing to export")
    surf = pv.PolyData(vertices, np.hstack([np.full((len(faces), 1), 3), faces]).ravel())
    surf = surf.smooth_taubin(n_iter=20, pass_band=0.1)  # the voxels' stair steps, not the shape
    if surf.n_cells > max_triangles:
        surf = surf.decimate(1.0 - max_triangles / surf.n_cells * 0.98)
    surf = surf.compute_normals(cell_normals=False, split_vertices=False, auto_orient_normals=True)
    tris = surf.faces.reshape(-1, 4)[:, 1:]
    return np.asarray(surf.points, np.float64), np.asarray(surf.point_data["Normals"], np.float64), tris


def skin_weights(vertices: np.ndarray, labels: np.ndarray, origin, n_bones: int, blend: float = BLEND
                 ) -> tuple[np.ndarray, np.ndarray]:
    """``(V, 4)`` bones and ``(V, 4)`` weights of each vertex (see the module's "Decided here")."""
    import edt

    reach = int(np.ceil(3 * blend)) + 2
    # the surface lies half a voxel out: its first and last layers round to just outside the box
    idx = np.clip(np.rint(vertices - origin).astype(np.int64), 0, np.array(labels.shape) - 1)
    dist = np.full((len(vertices), n_bones), np.inf)
    for b in range(n_bones):
        where = np.argwhere(labels == b + 1)
        if not len(where):
            continue
        lo, hi = np.maximum(where.min(0) - reach, 0), np.minimum(where.max(0) + reach + 1, labels.shape)
        box = labels[lo[0]:hi[0], lo[1]:hi[1], lo[2]:hi[2]] != b + 1
        d = edt.edt(box.astype(np.uint8), black_border=False, parallel=1)
        inside = np.all((idx >= lo) & (idx < hi), axis=1)
        k = idx[inside] - lo
        dist[inside, b] = d[k[:, 0], k[:, 1], k[:, 2]]
    order = np.argsort(dist, axis=1)[:, :4]
    near = np.take_along_axis(dist, order, 1)
    w = np.exp(-np.square(near / blend))
    w[:, 0] = np.where(w.sum(1) > 0, w[:, 0], 1.0)  # a vertex far from every bone: its nearest alone
    w = np.where(np.isfinite(near), w, 0.0)
    w = (w / w.sum(1, keepdims=True)).astype(np.float32)
    w[w < 1e-6] = 0.0  # a joint named with no weight is an error in glTF's validator's eyes: drop both
    w /= w.sum(1, keepdims=True)
    return np.where(w > 0, order, 0).astype(np.uint16), w


def joint_parents(conn: Connectivity) -> list[int]:
    """Each bone's parent bone (-1: none), from where the bones' joints meet; parents come first."""
    prox = np.array([b.proximal for b in conn.bones])
    dist = np.array([b.distal for b in conn.bones])
    parents = []
    for b in range(len(conn.bones)):
        ends = [a for a in range(b) if np.allclose(dist[a], prox[b])]
        twins = [a for a in range(b) if np.allclose(prox[a], prox[b])]
        parents.append(ends[0] if ends else parents[twins[0]] if twins else -1)
    return parents


def scene_axes(conn: Connectivity, vertices: np.ndarray) -> np.ndarray:
    """Column-vector 4x4 from rest voxel coordinates to the glTF scene: metres, Y up, the rest surface
    ``vertices`` standing on y = 0 and centred on the origin."""
    g = conn.geometry
    physical = np.eye(4)
    physical[:3, :3] = np.asarray(g.direction, np.float64).reshape(3, 3) * np.asarray(g.spacing)
    physical[:3, 3] = g.origin
    axes = np.diag([1e-3, 1e-3, 1e-3, 1.0]) @ LPS_TO_GLTF @ physical
    placed = vertices @ axes[:3, :3].T + axes[:3, 3]
    lo, hi = placed.min(0), placed.max(0)
    axes[:3, 3] -= [(lo[0] + hi[0]) / 2, lo[1], (lo[2] + hi[2]) / 2]
    return axes


def joint_animation(conn: Connectivity, frames: np.ndarray, fps: float, name: str) -> JointAnimation:
    """The bones' motion as joints' local translations and rotations (rigid frames only: ValueError)."""
    from scipy.spatial.transform import Rotation

    parents = joint_parents(conn)
    joints = np.array([b.proximal for b in conn.bones], np.float64)
    n_frames, n = frames.shape[:2]
    world = np.zeros((n_frames, n, 4, 4))
    world[..., :3, :3] = np.swapaxes(frames[..., :3, :3], -1, -2)  # row-vector [x 1] @ M -> column M^T
    world[..., :3, 3] = np.einsum("bi,fbij->fbj", joints, frames[..., :3, :3]) + frames[..., 3, :3]  # joints go
    world[..., 3, 3] = 1.0
    rot = world[..., :3, :3]
    if not np.allclose(rot @ np.swapaxes(rot, -1, -2), np.eye(3), atol=1e-5) or (np.linalg.det(rot) < 0).any():
        raise ValueError("a frame's bone matrix is not a rigid motion: glTF joints turn and move, they do not "
                         "shear or mirror")
    rest = np.tile(np.eye(4), (n, 1, 1))
    rest[:, :3, 3] = [joints[b] - (joints[p] if p >= 0 else 0) for b, p in enumerate(parents)]
    local = world.copy()
    for b, p in enumerate(parents):
        if p >= 0:
            local[:, b] = np.linalg.inv(world[:, p]) @ world[:, b]
    quats = Rotation.from_matrix(local[..., :3, :3].reshape(-1, 3, 3)).as_quat().reshape(n_frames, n, 4)
    flip = np.cumsum(np.r_[np.zeros((1, n)), (quats[1:] * quats[:-1]).sum(-1) < 0], axis=0) % 2 == 1
    quats[flip] *= -1  # each key the short way from the last: a viewer's slerp turns as we do
    return JointAnimation([b.name or f"bone{k}" for k, b in enumerate(conn.bones)], parents, rest,
                          np.arange(n_frames) / fps, local[..., :3, 3], quats, name)


def export_gltf(conn: Connectivity, frames: np.ndarray, fps: float, path, name: str = "clip",
                max_triangles: int = MAX_TRIANGLES, blend: float = BLEND, progress: ProgressFn | None = None,
                cancel: CancelFn | None = None) -> dict:
    """Write ``path`` (``.glb``): the rest body skinned to ``conn``'s bones, moved by ``frames`` (``(F, B, 4,
    4)`` row-vector matrices of the rig's voxels, as ``.trans`` files hold) at ``fps``. What it holds.
    ``cancel()`` True between stages raises Cancelled, nothing written."""
    frames = np.asarray(frames, np.float64)
    if frames.ndim != 4 or frames.shape[1:] != (len(conn.bones), 4, 4) or not len(frames):
        raise ValueError(f"frames must be (F, {len(conn.bones)}, 4, 4) matrices of the rig's bones, "
                         f"got {frames.shape}")
    report = Reporter(progress, cancel)
    anim = joint_animation(conn, frames, fps, name)
    labels, origin = body_labels(conn)
    report(10, 100)
    vertices, normals, tris = body_surface(labels, origin, max_triangles)
    report(60, 100)
    joints, weights = skin_weights(vertices, labels, origin, len(conn.bones), blend)
    report(90, 100)
    axes = scene_axes(conn, vertices)
    scene = vertices @ axes[:3, :3].T + axes[:3, 3]
    turned = normals @ axes[:3, :3].T
    turned /= np.maximum(np.linalg.norm(turned, axis=1, keepdims=True), 1e-12)
    write_glb(path, SkinnedMesh(scene, turned, tris, joints, weights), anim, axes)
    if progress is not None:  # written: a Cancel now comes too late to be honoured
        progress(100, 100)
    return {"vertices": len(vertices), "triangles": len(tris), "joints": len(conn.bones), "frames": len(frames),
            "axes": axes}
