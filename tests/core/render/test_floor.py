"""``volanim render --floor``: a ground plane under the body (#43, the crumble's floor).

The oracle: the floor's four corners by the documented rule (the face of the body's lowest voxels,
a square centred under it, twice its wider side across), projected with NumPy through the saved
camera (tests/picture_oracle.py) and filled -- against the pixels that change when the floor is
added, less those the body hides.
"""

from __future__ import annotations

import imageio.v3 as iio
import numpy as np
import pytest
from skimage.draw import polygon

from picture_oracle import compare, foreground, to_pixels
from runnable import volanim
from volanim_core import io
from volanim_core.geometry import Geometry

SPACING, ORIGIN = (1.0, 1.0, 3.0), (10.0, 20.0, 30.0)  # mm: anisotropic, away from the origin
LO, HI = (12, 20, 5), (27, 31, 24)  # the filled block's first and last voxel indices


def floor_pixels(down: str, camera, size) -> np.ndarray:
    """``(H, W)`` bool: the documented floor, projected -- computed here, not by volanim."""
    axis = "xyz".index(down[-1])
    origin_vox = np.array(ORIGIN) / np.array(SPACING)
    lo, hi = origin_vox + np.array(LO) - 0.5, origin_vox + np.array(HI) + 0.5  # voxel faces, in voxels
    u, v = [a for a in range(3) if a != axis]
    half = max(hi[u] - lo[u], hi[v] - lo[v])
    centre = (lo + hi) / 2
    corners = []
    for du, dv in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
        c = centre.copy()
        c[axis] = lo[axis] if down.startswith("-") else hi[axis]
        c[u] += du * half
        c[v] += dv * half
        corners.append(c * np.array(SPACING))
    px, ahead = to_pixels(np.array(corners), camera, size)
    assert ahead.all()
    rows, cols = polygon(px[:, 1], px[:, 0], shape=(size[1], size[0]))
    out = np.zeros((size[1], size[0]), bool)
    out[rows, cols] = True
    return out


@pytest.mark.parametrize("down, view", [("-z", "three-quarter"), ("-x", "side")])
def test_the_floor_lies_under_the_body_where_the_rule_puts_it(tmp_path, down, view):
    block = np.zeros((40, 50, 30), np.uint8)
    block[LO[0]:HI[0] + 1, LO[1]:HI[1] + 1, LO[2]:HI[2] + 1] = 200
    io.write_volume(tmp_path / "block.nrrd", block, Geometry(SPACING, ORIGIN))
    common = ["block.nrrd", "--view", view, "--size", "320x240", "--save-camera", "c.camera"]
    for name, extra in (("bare.png", []), ("floor.png", ["--floor", down])):
        r = volanim("render", *common, "-o", name, *extra, cwd=tmp_path)
        assert r.returncode == 0, r.stderr
    bare, floor = (iio.imread(tmp_path / n)[..., :3].astype(np.int16) for n in ("bare.png", "floor.png"))
    camera = io.read_camera(tmp_path / "c.camera").scaled(SPACING)  # camera files are in voxels
    changed = np.abs(floor - bare).max(axis=2) > 12
    expected = floor_pixels(down, camera, (320, 240)) & ~foreground(bare)  # the body hides what is behind it
    got = compare(changed, expected)
    assert got["silhouette_px"] > 2000, got  # the floor is in the picture, not a sliver seen edge-on
    assert got["iou_rim"] > 0.97 and got["stray"] < 0.005, got
    body = foreground(bare)
    assert np.abs(floor - bare)[body].max(axis=1).mean() < 3  # the body is drawn as before, not through it
    grey = floor[changed & ~body]
    assert np.all(np.ptp(grey, axis=1) <= 12)  # grey (the light kit warms it a little), not another colour


def test_a_bad_floor_axis_is_an_argument_error(tmp_path):
    io.write_volume(tmp_path / "block.nrrd", np.ones((4, 4, 4), np.uint8))
    r = volanim("render", "block.nrrd", "-o", "x.png", "--floor", "w", cwd=tmp_path)
    assert r.returncode == 2 and "--floor" in r.stderr and "an axis is x, y or z" in r.stderr
    assert not (tmp_path / "x.png").exists()
