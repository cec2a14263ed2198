"""A frame's bones in physical space, for 3D Slicer and ITK: per-bone affines and a dense field.

    bone matrix M (row vectors, rest voxel -> posed voxel, the frame's grid G)
        --G's affine A--> F = A M^T A^-1      rest mm -> posed mm (LPS), column vectors
        --inverse-->      posed mm -> rest mm: what ITK and Slicer store (the resampling direction)

    posed bone reconstruction (which bone owns each posed voxel, as sampled mode decides)
        --each voxel of the target grid: its owner's posed -> rest map-->
        displacement d(p) = rest(p) - p  (LPS mm): an ITK displacement field, Slicer's grid transform

Why the resampling direction: ITK's ResampleImageFilter, and Slicer's transform
files, map each *output* point back into the input; so resampling the rest scan
through the field gives the scan in the pose, whatever it holds (CT, labels, dose).

Outside the posed body no bone owns a voxel. ``outside='empty'`` points those
voxels far outside any image (they read the resampler's default value), so the
rest-pose body does not stay behind as a ghost; ``'identity'`` leaves them in place.
"""

from __future__ import annotations

import numpy as np

from volanim_core.geometry import Geometry
from volanim_core.rig.connectivity import Connectivity, Trans
from volanim_core.rig.tskel_tools import connect_to_tskel

OUTSIDE = ("empty", "identity")
SLAB_VOXELS = 4_000_000  # target voxels per step: the field's temporaries stay ~300 MB


def physical_matrices(matrices: np.ndarray, geometry: Geometry) -> np.ndarray:
    """``(B, 4, 4)`` column-vector affines in LPS mm (rest -> posed) of row-vector voxel matrices on ``geometry``."""
    a = geometry.affine
    return a @ np.transpose(np.asarray(matrices, np.float64), (0, 2, 1)) @ np.linalg.inv(a)


def transforms(conn: Connectivity, trans: Trans) -> dict[str, np.ndarray]:
    """Bone label -> the 4x4 posed -> rest affine in LPS mm (ITK's and Slicer's transform-file direction)."""
    tskel = connect_to_tskel(conn, trans)
    forward = physical_matrices(tskel.matrices, conn.geometry)
    return {b.label: np.linalg.inv(f) for b, f in zip(conn.bones, forward)}


def displacement(conn: Connectivity, trans: Trans, shape, geometry: Geometry, *, outside: str = "empty",
                 progress=None, cancel=None) -> np.ndarray:
    """The dense posed -> rest displacement field on the grid ``(shape, geometry)`` (a scan's):
    ``(X, Y, Z, 3)`` float64, LPS mm, as ``volanim displacement`` writes it."""
    from volanim_core.progress import Reporter
    from volanim_core.reconstruct.engine import reconstruct

    if outside not in OUTSIDE:
        raise ValueError(f"outside must be one of {', '.join(OUTSIDE)}, got {outside!r}")
    shape = tuple(int(n) for n in shape)
    tskel = connect_to_tskel(conn, trans)
    owner = reconstruct(tskel, mode="bone", cancel=cancel)
    inverse = np.linalg.inv(tskel.matrices)  # row vectors: posed voxel -> rest voxel, per bone
    to_grid = geometry.index_map(conn.geometry)  # target indices -> the frame's grid
    far = geometry.to_physical(-2.0 * np.array(shape, np.float64)[None])[0]  # outside any image of this grid
    field = np.zeros((*shape, 3), np.float64)
    report = Reporter(progress, cancel)
    step = max(1, SLAB_VOXELS // max(shape[0] * shape[1], 1))
    ii, jj = np.meshgrid(np.arange(shape[0]), np.arange(shape[1]), indexing="ij")
    for z0 in range(0, shape[2], step):
        report(z0, shape[2])
        z1 = min(shape[2], z0 + step)
        idx = np.stack([np.broadcast_to(ii[..., None], (*ii.shape, z1 - z0)),
                        np.broadcast_to(jj[..., None], (*jj.shape, z1 - z0)),
                        np.broadcast_to(np.arange(z0, z1), (*ii.shape, z1 - z0))], -1).reshape(-1, 3)
        here = geometry.to_physical(idx)
        q = np.column_stack([idx, np.ones(len(idx))]) @ to_grid  # on the frame's grid, row vectors
        k = np.rint(q[:, :3]).astype(np.int64) - np.asarray(owner.origin)
        inside = np.all((k >= 0) & (k < owner.volume.shape), axis=1)
        bone = np.zeros(len(idx), np.int64)
        bone[inside] = owner.volume[tuple(k[inside].T)]
        d = np.zeros((len(idx), 3)) if outside == "identity" else far - here
        body = bone > 0
        rest = np.einsum("ni,nij->nj", q[body], inverse[bone[body] - 1])[:, :3]
        d[body] = conn.geometry.to_physical(rest) - here[body]
        field[:, :, z0:z1] = d.reshape(shape[0], shape[1], z1 - z0, 3)
    report(shape[2], shape[2])
    return field
