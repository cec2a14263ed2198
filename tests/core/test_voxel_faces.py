"""Kept faces (#85): a drag's surface redoes only the slices a frame changed, and is every time the faces of the
whole volume made afresh, in the same order (the faces themselves are checked against NumPy in
tests/core/render/test_surfaces.py)."""

from __future__ import annotations

import numpy as np

from volanim_core.voxel_faces import KeptFaces, face_arrays

ORIGIN, SPACING = (10.1, -4.3, 2.7), (0.7, 1.1, 0.3)  # not binary fractions: the same sums, or not the same
TABLE = np.array([[0, 0, 0, 0], [200, 10, 10, 255], [10, 200, 10, 255], [10, 10, 200, 40]], np.uint8)


def picture(shape=(14, 11, 16)) -> np.ndarray:
    """A body of labels, as a live picture holds it: the [x, y, z] view of a [z, y, x] array."""
    x, y, z = np.ogrid[: shape[0], : shape[1], : shape[2]]
    body = ((x - 7) ** 2 + (y - 5) ** 2 + (z - 8) ** 2 <= 30).astype(np.uint8)
    body[:, :, 9:] *= 2
    body[6:8, 4:6, :] = 3  # a limb through the grid's first and last slices
    return np.ascontiguousarray(body.T).T


def same(got, want) -> bool:
    return all(np.array_equal(g, w) for g, w in zip(got, want))


def test_kept_faces_are_the_whole_volumes_faces_after_each_frame_whatever_slices_it_changed():
    rng = np.random.default_rng(3)
    vol = picture()
    kept = KeptFaces(ORIGIN, SPACING, TABLE)
    assert same(kept.update(vol), face_arrays(vol, ORIGIN, SPACING, TABLE))
    assert kept.redone == vol.shape[2]
    nz = vol.shape[2]
    # a slab inside, the first slice, the last one, one slice, the whole grid, a slab emptied
    for z0, z1 in [(5, 8), (0, 2), (nz - 3, nz - 1), (7, 7), (0, nz - 1), (3, 12), (nz - 1, nz - 1), (0, 0)]:
        slab = vol[:, :, z0:z1 + 1]
        slab[...] = rng.integers(0, 4, slab.shape) * (rng.random(slab.shape) < 0.5)
        got = kept.update(vol, (z0, z1))
        assert same(got, face_arrays(vol, ORIGIN, SPACING, TABLE)), (z0, z1)
        assert kept.redone == min(z1 + 2, nz) - max(z0 - 1, 0)  # the slab and the slice each side of it
    vol[:, :, 4:6] = 0
    assert same(kept.update(vol, (4, 5)), face_arrays(vol, ORIGIN, SPACING, TABLE))


def test_kept_faces_redo_nothing_when_nothing_changed_and_everything_for_another_grid():
    vol = picture()
    kept = KeptFaces(ORIGIN, SPACING, TABLE)
    first = kept.update(vol)
    again = kept.update(vol, None)
    assert kept.redone == 0 and same(again, first)
    bigger = picture((14, 11, 20))
    assert same(kept.update(bigger, (2, 3)), face_arrays(bigger, ORIGIN, SPACING, TABLE))  # another shape: all
    assert kept.redone == 20
    empty = np.zeros((3, 4, 5), np.uint8)
    points, faces, rgb = kept.update(empty, (0, 1))
    assert len(points) == len(faces) == len(rgb) == 0


def test_row_extents_are_numpys_first_and_last_filled_voxel_at_every_width_and_place():
    """row_extents skips empty runs STRIDE voxels a step: rows narrower than it, as wide, and wider, each voxel filled
    alone, and pairs either side of a stride's edge, in bytes and in 16-bit labels, against NumPy."""
    from volanim_core._face_kernels import STRIDE, row_extents

    for nx in (1, STRIDE - 1, STRIDE, STRIDE + 1, 2 * STRIDE, 3 * STRIDE + 5):
        rows = [np.zeros(nx, np.uint16)]
        for a in range(nx):
            row = np.zeros(nx, np.uint16)
            row[a] = 300
            rows.append(row)
            for b in (a + 1, a + STRIDE - 1, a + STRIDE, nx - 1):
                if a < b < nx:
                    row = np.zeros(nx, np.uint16)
                    row[[a, b]] = 1
                    rows.append(row)
        for dtype in (np.uint8, np.uint16):
            vol = np.stack(rows).astype(dtype)[None]  # [z, y, x]: one slice of these rows
            lo, hi = np.empty(vol.shape[:2], np.int32), np.empty(vol.shape[:2], np.int32)
            row_extents(vol, lo, hi)
            for y, row in enumerate(vol[0]):
                filled = np.flatnonzero(row)
                want = (filled[0], filled[-1] + 1) if len(filled) else (0, 0)
                assert (lo[0, y], hi[0, y]) == want, (nx, dtype, row.nonzero())
