"""Sampled reconstruction on a colour source: three channels through one owner map."""

from __future__ import annotations

import numpy as np
import pytest
from test_engine import random_tskel

from volanim_core.colour.space import from_linear
from volanim_core.reconstruct.engine import grid_bounds, reconstruct
from volanim_core.reconstruct.sampling import _LINEAR, LINEAR_SCALE


@pytest.mark.parametrize("kernel", [1, 3, 5])
def test_rgb_sampled_equals_three_single_channel_reconstructions(rng, kernel):
    rgb = rng.integers(0, 256, (14, 14, 14, 3)).astype(np.uint8)
    for case in range(4):
        t = random_tskel(rng, quarter_turns=case % 2 == 0)
        b = grid_bounds(t, padding=1)
        got = reconstruct(t, mode="sampled", source=rgb, kernel=kernel, bounds=b)
        assert got.volume.shape == (*b.shape, 3) and got.volume.dtype == np.uint8
        for c in range(3):
            if kernel == 1:  # nearest voxel: exactly the grey reconstruction of that channel
                want = reconstruct(t, mode="sampled", source=rgb[..., c], bounds=b).volume
            else:  # averaged in linear light: the channel decoded, reconstructed, encoded again
                linear = reconstruct(t, mode="sampled", source=_LINEAR[rgb[..., c]], kernel=kernel, bounds=b).volume
                want = from_linear(linear / LINEAR_SCALE)
            assert np.array_equal(got.volume[..., c], want), (case, c)


def test_linear_averaging_keeps_an_edge_between_two_colours_bright():
    """Red next to green, kernel 3: the last red column gets about a quarter of its neighbour's
    green by weight. Averaged in linear light that shows as green 131, as bright as the two colours
    look side by side; averaged on sRGB bytes it would be 58, a dark seam."""
    from volanim_core.rig.connectivity import BoneSegment, Tskel

    src = np.zeros((12, 12, 12, 3), np.uint8)
    src[:6, ..., 0] = 255
    src[6:, ..., 1] = 255
    t = Tskel([BoneSegment((0, 0, 0), (1, 0, 0))], np.eye(4)[None], [[6, 6, 6]], [5.0], None, [0])
    r = reconstruct(t, mode="sampled", source=src, kernel=3, padding=0)
    at = (5 - r.origin[0], 6 - r.origin[1], 6 - r.origin[2])  # the last red column
    bytes_average = reconstruct(t, mode="sampled", source=src[..., 1], kernel=3, padding=0).volume[at]
    assert r.volume[at][0] == 228 and r.volume[at][1] == 131 and r.volume[at][2] == 0
    assert bytes_average == 58


def test_a_colour_source_must_be_bytes():
    from volanim_core.rig.connectivity import BoneSegment, Tskel

    t = Tskel([BoneSegment((0, 0, 0), (1, 0, 0))], np.eye(4)[None], [[5, 5, 5]], [2.0], None, [0])
    with pytest.raises(ValueError, match="8-bit RGB"):
        reconstruct(t, mode="sampled", source=np.zeros((9, 9, 9, 3), np.float32))
    with pytest.raises(ValueError, match="3-D RGB"):
        reconstruct(t, mode="sampled", source=np.zeros((9, 9, 9, 2), np.uint8))
