"""The rows a slice's cut planes leave (``_kernels.slice_cuts``), against a brute force over the disc's
voxels: every row that holds a kept voxel is visited (a row left out would lose its owner), and the
bound is tight within two rows of the kept part (else it saves nothing: a full-size walk frame tested
142 M rows for 34 M runs without it)."""

from __future__ import annotations

import numpy as np
import pytest

from volanim_core.reconstruct._kernels import slice_cuts


def _kept_rows(radius, dz, planes):
    """Rows (relative to the centre) holding a point of the slice's disc on every plane's kept side,
    sampled on a grid 16 times finer than the voxels."""
    r2 = radius * radius - dz * dz
    u = np.arange(-radius, radius + 1e-9, 1 / 16)
    x, y = np.meshgrid(u, u, indexing="ij")
    kept = x * x + y * y < r2
    for a0, a1, a2, w, _ in planes:
        kept &= a0 * x + a1 * y + (a2 * dz + w) <= 0.0
    return y[kept]


def _plane(rng, radius):
    """A plane as build_halfspaces writes it (a = 2 d, w = -|d|^2 - shift, column 4 = |(a_x, a_y)|)
    against a neighbour at distance 0.2-1.6 radii in a random direction."""
    d = rng.normal(size=3)
    d *= rng.uniform(0.2, 1.6) * radius / np.linalg.norm(d)
    a = 2 * d
    return [a[0], a[1], a[2], -(d @ d) - rng.uniform(0, 0.3) * radius**2, np.hypot(a[0], a[1])]


@pytest.mark.parametrize("seed", range(4))
def test_every_row_holding_a_kept_voxel_is_visited_and_the_bound_is_tight(seed):
    rng = np.random.default_rng(seed)
    n_checked = 0
    for _ in range(150):
        radius = rng.uniform(6, 40)
        dz = rng.uniform(-0.9, 0.9) * radius
        planes = np.array([_plane(rng, radius) for _ in range(rng.integers(1, 9))])
        start = np.array([0, len(planes)], np.int64)
        scratch = [np.empty(len(planes)) for _ in range(3)] + [np.empty(len(planes), np.int8)]
        yhalf = np.sqrt(radius**2 - dz**2)
        n_cut, lo, hi = slice_cuts(0, dz, yhalf, start, planes, *scratch)
        rows = _kept_rows(radius, dz, planes)
        if n_cut < 0:  # one plane covers the disc
            assert len(rows) == 0
            continue
        if len(rows) == 0:
            continue
        n_checked += 1
        assert lo <= rows.min() and rows.max() <= hi  # never a row too few
        assert rows.min() - lo <= 2.0 + 1 / 16 or n_cut > 1  # one plane: its bound is the kept part's, plus a row
        assert hi - rows.max() <= 2.0 + 1 / 16 or n_cut > 1
    assert n_checked > 100


def test_a_plane_keeping_the_top_of_the_disc_leaves_only_its_rows():
    # keeps y >= 10 of a radius-20 disc: a = (0, -2, 0), w = 20 (the plane -2 y + 20 <= 0)
    planes = np.array([[0.0, -2.0, 0.0, 20.0, 2.0]])
    scratch = [np.empty(1) for _ in range(3)] + [np.empty(1, np.int8)]
    n_cut, lo, hi = slice_cuts(0, 0.0, 20.0, np.array([0, 1], np.int64), planes, *scratch)
    assert n_cut == 1 and lo == pytest.approx(9.0) and hi == 20.0
