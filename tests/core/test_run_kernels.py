"""A label grid's pieces found on its rows' runs (volanim_core/_run_kernels.py, ``by_value``: each label's own
26-connected pieces), against cc3d's labelling of the same grid: the same pieces, numbered alike."""

from __future__ import annotations

import cc3d
import numpy as np
import pytest
from tests import naive

from volanim_core._run_kernels import label_runs


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("labels", [2, 3, 7])
def test_each_labels_pieces_are_cc3ds_in_the_same_order(seed, labels):
    rng = np.random.default_rng(seed)
    shape = tuple(int(v) for v in rng.integers(1, 24, 3))
    zyx = rng.integers(1, labels + 1, shape).astype(np.uint8)
    zyx[rng.random(shape) < 0.4] = 0
    first, x0, x1, piece, n = label_runs(zyx, True)
    want, m = cc3d.connected_components(zyx, connectivity=26, return_N=True)
    assert n == m
    np.testing.assert_array_equal(naive.paint_runs(shape, first, x0, x1, piece), want)


def test_a_run_touches_the_second_of_two_runs_side_by_side_in_the_row_before_it_at_a_corner():
    # row 0: label 2 over x 0..4; row 1: label 1 over x 0..4, then label 2 over x 5..8, which touches row 0's
    # run at a corner (x 4 -> 5). A sweep that, both runs ending at x 4, moved on in row 0 never compared row 1's
    # second run with it: label 2 came back in two pieces
    zyx = np.zeros((1, 2, 9), np.uint8)
    zyx[0, 0, :5], zyx[0, 1, :5], zyx[0, 1, 5:] = 2, 1, 2
    first, x0, x1, piece, n = label_runs(zyx, True)
    assert n == 2
    np.testing.assert_array_equal(naive.paint_runs(zyx.shape, first, x0, x1, piece),
                                  [[[1] * 5 + [0] * 4, [2] * 5 + [1] * 4]])
