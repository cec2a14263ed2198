"""Dual-quaternion blending of bone motions (Kavan et al. 2007), vectorised over points.

    bone matrices (B, 4, 4) --rigid_parts--> uniform scale s, rigid matrices
                            --dual_quaternions--> (B, 8): rotation q, dual part 0.5 (0, t) q
    per point: sum_k w_k (+-)dq[bone_k] --normalise--> one rigid motion --matrix--> (K, 4, 4)

Why dual quaternions and not a weighted sum of matrices: linear blending of a
bone twisted 90 degrees against its parent passes through matrices that are
not rotations and shrinks the joint (the "candy wrapper"); a normalised blend
of dual quaternions is always a rotation plus a translation, so a sphere in the
blend zone keeps its place on the body and its size.

Matrices are volanim's row-vector ones (``[x y z 1] @ M``, translation in row
4). A uniform scale common to every bone (the ``1/factor`` of a coarse preview
frame, :func:`~volanim_core.rig.pose.scaled`) is taken out before blending and
put back after.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

RIGID_TOLERANCE = 1e-4  # |A^T A / s^2 - I| allowed: float noise of chained rotations, not a shear


def rigid_parts(matrices: np.ndarray, names=None) -> tuple[float, np.ndarray]:
    """``(s, rigid)``: the uniform scale every matrix shares and the matrices with it divided out.

    A matrix that is not a rotation times that scale (a shear, a mirror, a bone scaled on
    its own) cannot be blended as a rigid motion: ValueError naming the bone."""
    m = np.asarray(matrices, np.float64)
    if not len(m):
        return 1.0, m
    a = m[:, :3, :3]
    det = np.linalg.det(a)
    scale = np.cbrt(det)
    s = float(np.median(scale))
    for b in range(len(m)):
        gram = a[b] @ a[b].T / (s * s) if s > 0 else np.full((3, 3), np.inf)
        if not (det[b] > 0 and abs(scale[b] - s) <= RIGID_TOLERANCE * s
                and np.abs(gram - np.eye(3)).max() <= RIGID_TOLERANCE):
            who = names[b] if names is not None else f"bone {b}"
            raise ValueError(f"{who}: its matrix is not a rotation (times the scale {s:g} the other bones "
                             "share); smooth joints blend rigid motions only -- use --joints rigid for "
                             "frames that shear, mirror or scale a bone")
    out = m.copy()
    out[:, :3, :3] /= s
    out[:, 3, :3] /= s
    return s, out


def quaternion_product(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Hamilton products ``p q`` of ``(..., 4)`` quaternions stored ``(w, x, y, z)``."""
    pw, px, py, pz = np.moveaxis(p, -1, 0)
    qw, qx, qy, qz = np.moveaxis(q, -1, 0)
    return np.stack([pw * qw - px * qx - py * qy - pz * qz,
                     pw * qx + px * qw + py * qz - pz * qy,
                     pw * qy - px * qz + py * qw + pz * qx,
                     pw * qz + px * qy - py * qx + pz * qw], axis=-1)


def dual_quaternions(rigid: np.ndarray) -> np.ndarray:
    """``(B, 8)``: each rigid row-vector matrix as a unit dual quaternion ``(q, 0.5 (0, t) q)``, w first."""
    rot = Rotation.from_matrix(np.swapaxes(rigid[:, :3, :3], 1, 2))  # row-vector -> column convention
    xyzw = rot.as_quat()
    q = np.concatenate([xyzw[:, 3:], xyzw[:, :3]], axis=1)
    t = np.concatenate([np.zeros((len(rigid), 1)), rigid[:, 3, :3]], axis=1)
    return np.concatenate([q, 0.5 * quaternion_product(t, q)], axis=1)


def blend(dq: np.ndarray, influence: np.ndarray, weight: np.ndarray) -> np.ndarray:
    """``(K, 4, 4)`` rigid row-vector matrices: per row of ``influence``/``weight`` (``(K, J)``, bone
    indices with -1 for none, and weights), the normalised weighted sum of the bones' dual
    quaternions. Each is first turned to the hemisphere of the row's first bone (``q`` and ``-q``
    are one rotation; blending across hemispheres would take the long way round)."""
    parts = dq[np.maximum(influence, 0)]  # (K, J, 8)
    w = np.where(influence >= 0, weight, 0.0)
    sign = np.sign(np.einsum("kjc,kc->kj", parts[:, :, :4], parts[:, 0, :4]))
    sign[sign == 0] = 1.0
    b = np.einsum("kj,kjc->kc", w * sign, parts)
    norm = np.linalg.norm(b[:, :4], axis=1, keepdims=True)
    q, d = b[:, :4] / norm, b[:, 4:] / norm
    conj = q * np.array([1.0, -1.0, -1.0, -1.0])
    t = 2.0 * quaternion_product(d, conj)[:, 1:]
    out = np.zeros((len(b), 4, 4))
    out[:, :3, :3] = np.swapaxes(Rotation.from_quat(np.concatenate([q[:, 1:], q[:, :1]], axis=1)).as_matrix(), 1, 2)
    out[:, 3, :3] = t
    out[:, 3, 3] = 1.0
    return out


def blended_matrices(matrices: np.ndarray, influence: np.ndarray, weight: np.ndarray, names=None) -> np.ndarray:
    """One matrix per row of ``influence``/``weight``: the dual-quaternion blend of the bones' ``matrices``
    (any uniform scale they share kept)."""
    s, rigid = rigid_parts(matrices, names)
    out = blend(dual_quaternions(rigid), influence, weight) if len(influence) else np.zeros((0, 4, 4))
    out[:, :3, :3] *= s
    out[:, 3, :3] *= s
    return out
