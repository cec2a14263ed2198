"""The square faces between filled and empty voxels as plain arrays, each coloured by its filled voxel: the live
preview's surface (``render/surfaces.voxel_faces`` makes it a pyvista mesh). Below ``render/``, as
``isosurface.py`` is, so the warm-up can compile it.

    face_arrays: the volume [z, y, x] --_face_kernels.row_extents--> each row's filled extent
                 --_face_kernels.faces_per_slice--> faces a slice --> offsets
                 --_face_kernels.fill_faces--> points, faces, colours

    KeptFaces.update(volume, changed slices) --the slab of changed slices and their neighbours, as above-->
                 its faces spliced between the kept faces of the slices before and after it

Why a drag keeps faces: a live picture redoes the box of the bones that moved (#85), and the surface of the
whole body was made again around it -- the mannequin's full-size faces were more than half of a live
picture's stages. A slice's faces depend on that slice and the two beside it, so the slices a frame left
alone keep theirs, face for face (the tests compare every update with ``face_arrays`` of the whole).
"""

from __future__ import annotations

import numpy as np

from volanim_core._face_kernels import CORNERS, faces_per_slice, fill_faces, row_extents


def _labels(volume: np.ndarray) -> np.ndarray:
    vol = np.ascontiguousarray(np.asarray(volume).T)  # [z, y, x]: no copy for a picture's [x, y, z] view
    if vol.ndim != 3 or vol.dtype.kind not in "biu":
        raise ValueError(f"voxel faces take a label volume [x, y, z] of integers, got {vol.dtype} {vol.shape[::-1]}")
    return vol.view(np.uint8) if vol.dtype == bool else vol


def _rows(table: np.ndarray | None) -> np.ndarray:
    # a user's transfer function gives RGBA rows: its opacity is kept (a faint bone stays faint while dragged)
    return np.zeros((1, 3), np.uint8) if table is None else np.ascontiguousarray(table, np.uint8)


def _quads(n: int) -> np.ndarray:
    """``(n, 4)``: face f's corners are points 4f..4f+3, as the kernel writes them."""
    return np.arange(4 * n, dtype=np.int64).reshape(n, 4)


def _slab_faces(vol: np.ndarray, z0: int, z1: int, origin, spacing, rows: np.ndarray, clear=None
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The faces of slices ``z0 <= z < z1`` of ``vol [z, y, x]`` (the slices beside them read as neighbours):
    ``(points, rgb, counts a slice)``. ``clear[label]``: labels drawn as empty."""
    slab = _Slab(vol, z0, z1, clear)
    n = int(slab.counts.sum())
    points = np.empty((4 * n, 3), np.float32)
    rgb = np.empty((4 * n, rows.shape[1]), np.uint8)
    slab.fill(0, origin, spacing, rows, points, rgb)
    return points, rgb, slab.counts


class _Slab:
    """Slices ``z0 <= z < z1`` of ``vol [z, y, x]`` with the slice each side they meet, their rows' filled extents
    and each slice's face count: :meth:`fill` writes their faces into arrays a caller made for them."""

    def __init__(self, vol: np.ndarray, z0: int, z1: int, clear=None):
        h0, h1 = max(z0 - 1, 0), min(z1 + 1, vol.shape[0])  # the slab and the slice each side it meets
        self.slab = vol[h0:h1] if clear is None else np.where(clear[vol[h0:h1]], 0, vol[h0:h1]).astype(vol.dtype)
        self.lo, self.hi = np.empty(self.slab.shape[:2], np.int32), np.empty(self.slab.shape[:2], np.int32)
        row_extents(self.slab, self.lo, self.hi)
        self.z0, self.z1, self.h0 = z0, z1, h0
        self.counts = np.empty(z1 - z0, np.int64)
        faces_per_slice(self.slab, self.lo, self.hi, z0 - h0, z1 - h0, self.counts)

    def fill(self, first: int, origin, spacing, rows: np.ndarray, points: np.ndarray, rgb: np.ndarray) -> None:
        """The slab's faces written as faces ``first, first + 1, ...`` of ``points`` and ``rgb``."""
        starts = first + np.concatenate([[0], np.cumsum(self.counts)])
        fill_faces(self.slab, self.lo, self.hi, self.z0 - self.h0, self.z1 - self.h0, self.h0, starts, CORNERS,
                   np.asarray(origin, np.float64), np.asarray(spacing, np.float64), rows, points, rgb)


def face_arrays(volume: np.ndarray, origin, spacing, table: np.ndarray | None = None
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(points (4F, 3) float32, faces (F, 4) int64, rgb (4F, 3 or 4) uint8)``: each face between a non-zero voxel of
    ``volume`` (labels ``[x, y, z]``) and an empty one or the grid's edge, its corners in world units
    (``origin + spacing * voxel``) and their colour ``table[label]`` (the table's last row past its end; zeros
    without a table)."""
    vol = _labels(volume)
    points, rgb, _ = _slab_faces(vol, 0, vol.shape[0], origin, spacing, _rows(table))
    return points, _quads(len(points) // 4), rgb


class KeptFaces:
    """:func:`face_arrays` of one grid's volume frame after frame, redoing only the slices a frame changed.

    ``origin``, ``spacing`` and ``table`` are ``face_arrays``'s, fixed for the grid (another grid, spacing or
    colour table: another ``KeptFaces``); ``clear[label]``: labels drawn as empty (a transfer function's clear
    ones), as if the volume held 0 there.
    """

    def __init__(self, origin, spacing, table: np.ndarray | None = None, clear: np.ndarray | None = None):
        self.origin = np.asarray(origin, np.float64)
        self.spacing = np.asarray(spacing, np.float64)
        self.rows, self.clear = _rows(table), clear
        self._shape: tuple | None = None
        self._starts: np.ndarray | None = None  # each slice's first face (and one past the last)
        self._points: np.ndarray | None = None
        self._rgb: np.ndarray | None = None
        self.redone = 0  # slices whose faces the last update made again

    def update(self, volume: np.ndarray, changed: tuple[int, int] | None | str = "all"
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``face_arrays(volume, ...)``, given that only the z-slices ``changed = (first, last)`` (inclusive) of
        ``volume [x, y, z]`` differ from the last update's (None: none; ``"all"``, or a first update or another
        shape: every slice)."""
        vol = _labels(volume)
        nz = vol.shape[0]
        if self._starts is None or vol.shape != self._shape or isinstance(changed, str):
            a, b = 0, nz
        elif changed is None:
            a = b = 0
        else:  # the changed slices and one each side: their faces towards the changed ones may differ
            a, b = max(int(changed[0]) - 1, 0), min(int(changed[1]) + 2, nz)
        if b <= a:
            self.redone = 0
        elif a == 0 and b == nz:
            self._points, self._rgb, counts = _slab_faces(vol, 0, nz, self.origin, self.spacing, self.rows,
                                                                self.clear)
            self._starts = np.concatenate([[0], np.cumsum(counts)])
            self._shape, self.redone = vol.shape, nz
        else:  # the slab's faces written in place between the kept ones, in new arrays (the last are drawn)
            slab, s = _Slab(vol, a, b, self.clear), self._starts
            grew = int(slab.counts.sum()) - int(s[b] - s[a])
            points = np.empty((len(self._points) + 4 * grew, 3), np.float32)
            rgb = np.empty((len(self._rgb) + 4 * grew, self._rgb.shape[1]), np.uint8)
            for new, old in ((points, self._points), (rgb, self._rgb)):
                new[:4 * s[a]] = old[:4 * s[a]]
                new[4 * (s[b] + grew):] = old[4 * s[b]:]
            slab.fill(int(s[a]), self.origin, self.spacing, self.rows, points, rgb)
            self._points, self._rgb = points, rgb
            self._starts = np.concatenate([s[:a + 1], s[a] + np.cumsum(slab.counts), s[b + 1:] + grew])
            self.redone = b - a
        return self._points, _quads(len(self._points) // 4), self._rgb
