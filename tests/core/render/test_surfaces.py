"""The label surface (studio live preview, render surface style) is coloured by the filled voxels only."""

from __future__ import annotations

import numpy as np

from volanim_core.render.surfaces import label_surface


def test_every_surface_point_takes_the_colour_of_the_filled_voxel_it_bounds():
    x, y, z = np.ogrid[:40, :40, :40]
    vol = np.where((x - 20) ** 2 + (y - 20) ** 2 + (z - 20) ** 2 <= 15**2, 1, 0).astype(np.uint8)
    vol[21:] *= 2  # the +x half is label 2
    table = np.array([[9, 9, 9], [255, 0, 0], [0, 0, 255]], np.uint8)
    surf = label_surface(vol, (100, 0, -5), (1, 1, 1), table)
    rgb = np.asarray(surf.point_data["rgb"])
    px = np.asarray(surf.points)[:, 0] - 100
    assert surf.n_points > 1000
    assert not np.any(np.all(rgb == table[0], axis=1))  # never the empty voxel's colour (half were, before)
    assert np.all(rgb[px < 20] == table[1]) and np.all(rgb[px > 21] == table[2])
