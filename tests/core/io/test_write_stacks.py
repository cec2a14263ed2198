"""3-D TIFF and slice stacks written (the thesis's Toolbar), read back by tifffile and imageio themselves."""

from __future__ import annotations

import imageio.v3 as iio
import numpy as np
import tifffile

from runnable import volanim
from volanim_core import io
from volanim_core.geometry import Geometry


def test_a_3d_tiff_is_what_tifffile_and_imagej_read(tmp_path):
    v = np.random.default_rng(4).integers(0, 256, (7, 5, 3), dtype=np.uint8)
    io.write_volume(tmp_path / "v.tif", v, Geometry(spacing=(0.5, 0.25, 2.0)))
    with tifffile.TiffFile(tmp_path / "v.tif") as tif:
        assert tif.is_imagej and tif.imagej_metadata["spacing"] == 2.0
        pages = tif.asarray()
        assert tif.pages[0].tags["XResolution"].value == (2, 1)  # pixels per mm: 1 / 0.5
    assert pages.shape == (3, 5, 7) and np.array_equal(pages, v.transpose(2, 1, 0))  # pages z, rows y, columns x
    back = io.read_scan(tmp_path / "v.tif")
    assert np.array_equal(back.data, v) and np.allclose(back.geometry.spacing, (0.5, 0.25, 2.0))


def test_a_slice_stack_is_one_image_a_slice_and_reads_back_as_the_volume(tmp_path):
    v = np.random.default_rng(5).integers(0, 256, (6, 4, 5), dtype=np.uint8)
    io.write_volume(tmp_path / "v.nrrd", v)
    r = volanim("convert", tmp_path / "v.nrrd", tmp_path / "slices" / "v%03d.png")
    assert r.returncode == 0, r.stderr
    files = sorted((tmp_path / "slices").iterdir())
    assert [f.name for f in files] == [f"v{z:03d}.png" for z in range(5)]
    for z, f in enumerate(files):
        assert np.array_equal(iio.imread(f), v[:, :, z].T)  # rows y, columns x
    assert np.array_equal(io.read_volume(tmp_path / "slices"), v)


def test_a_shorter_stack_over_a_longer_one_leaves_only_itself(tmp_path):
    """#64: slices were written one by one over the old ones: a 4-slice stack written where a 10-slice one was
    left slices 4..9 of the old, and the folder read back as a 10-slice volume of two stacks."""
    rng = np.random.default_rng(7)
    old, new = (rng.integers(0, 256, (6, 5, n), dtype=np.uint8) for n in (10, 4))
    io.write_volume(tmp_path / "s" / "frog%04d.png", old)
    io.write_volume(tmp_path / "s" / "frog%04d.png", new)
    assert sorted(p.name for p in (tmp_path / "s").iterdir()) == [f"frog{k:04d}.png" for k in range(4)]
    theirs = np.stack([iio.imread(tmp_path / "s" / f"frog{k:04d}.png") for k in range(4)], axis=2).swapaxes(0, 1)
    assert np.array_equal(theirs, new) and np.array_equal(io.read_volume(tmp_path / "s"), new)
