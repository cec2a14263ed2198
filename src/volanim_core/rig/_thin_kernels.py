"""Numba kernels of the thin flesh a turned bone pushes forward (rig/ownership.py's thin() and diagonals(),
read by reconstruct/_owned_kernels.splat_turned).

    (each bone's thin voxels: rig/_table_kernels.flagged_voxels, on the labels' runs)
    diagonal_bits(labels, flags, thin, voxels, diagonals, out)
        per such voxel, the edge and corner neighbours whose midpoint the splat pushes too
"""

from __future__ import annotations

from numba import njit


@njit(cache=True, nogil=True)
def diagonal_bits(labels, flags, thin, voxels, diagonals, out):
    """``out[i]`` (uint32, zeroed): bit ``d`` where voxel ``voxels[i]``'s neighbour ``+ diagonals[d]`` (an edge
    or corner step) holds its label and no face neighbour on the way (one step along one of the step's axes)
    is a voxel of its label whose ``flags`` have ``thin``. Outside ``labels``: no label."""
    nx, ny, nz = labels.shape
    for i in range(len(voxels)):
        x, y, z = voxels[i, 0], voxels[i, 1], voxels[i, 2]
        v = labels[x, y, z]
        bits = 0
        for d in range(len(diagonals)):
            sx, sy, sz = diagonals[d, 0], diagonals[d, 1], diagonals[d, 2]
            bx, by, bz = x + sx, y + sy, z + sz
            if not (0 <= bx < nx and 0 <= by < ny and 0 <= bz < nz) or labels[bx, by, bz] != v:
                continue
            joined = False
            for a in range(3):  # the face steps the edge or corner is made of: inside, as the neighbour is
                if diagonals[d, a] == 0:
                    continue
                fx, fy, fz = x + (sx if a == 0 else 0), y + (sy if a == 1 else 0), z + (sz if a == 2 else 0)
                if labels[fx, fy, fz] == v and flags[fx, fy, fz] & thin:
                    joined = True
            if not joined:
                bits |= 1 << d
        out[i] = bits
