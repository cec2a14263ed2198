"""Volume files: .vol/.VOL conventions, VTK formats, slice folders, streaming tools."""

from __future__ import annotations

import numpy as np
import pytest

from volanim_core import io
from volanim_core.errors import FormatError
from volanim_core.geometry import Geometry
from volanim_core.io import raw_volumes


@pytest.fixture
def vol(rng):
    return np.asfortranarray(rng.integers(0, 256, size=(7, 5, 3), dtype=np.uint8))


# spec: docs/formats.md#vol
def test_vol_bytes_are_x_fastest(tmp_path):
    v = np.zeros((3, 2, 2), np.uint8)
    v[1, 0, 0], v[0, 1, 0], v[0, 0, 1] = 1, 2, 3
    io.write_raw(tmp_path / "a.3x2x2.vol", v)
    data = (tmp_path / "a.3x2x2.vol").read_bytes()
    assert data[1] == 1 and data[3] == 2 and data[6] == 3


# spec: docs/formats.md#vol
def test_vol_round_trip_with_name_dims(tmp_path, vol):
    path = tmp_path / "a.7x5x3.vol"
    io.write_volume(path, vol)
    assert np.array_equal(io.read_volume(path), vol)


# spec: docs/formats.md#vol
def test_vol_needs_dims(tmp_path, vol):
    io.write_volume(tmp_path / "a.vol", vol)
    with pytest.raises(FormatError, match="unknown dimensions"):
        io.read_volume(tmp_path / "a.vol")
    assert np.array_equal(io.read_volume(tmp_path / "a.vol", dims=(7, 5, 3)), vol)


# spec: docs/formats.md#vol
def test_vol_size_mismatch_states_both_sizes(tmp_path, vol):
    io.write_volume(tmp_path / "a.vol", vol)
    with pytest.raises(FormatError, match=r"file has 105 bytes, expected 120"):
        io.read_volume(tmp_path / "a.vol", dims=(8, 5, 3))


# spec: docs/formats.md#vol
def test_vol_with_header_gets_hint(tmp_path, vol):
    io.write_volume(tmp_path / "a.VOL", vol)
    (tmp_path / "a.VOL").rename(tmp_path / "b.7x5x3.vol")
    with pytest.raises(FormatError, match="looks like a .VOL with a 100-byte header"):
        io.read_volume(tmp_path / "b.7x5x3.vol")


# spec: docs/formats.md#VOL-header
def test_VOL_header_layout_and_round_trip(tmp_path, vol):
    path = tmp_path / "a.VOL"
    io.write_volume(path, vol)
    data = path.read_bytes()
    assert len(data) == 100 + vol.size
    assert data[:100] == b"7 5 3".ljust(99) + b"\n"
    assert path.read_text(errors="replace").splitlines()[0].strip() == "7 5 3"
    assert np.array_equal(io.read_volume(path), vol)


# spec: docs/formats.md#VOL-header
def test_VOL_header_reader_ignores_rest(tmp_path, vol):
    head = b"7 5 3 extra words 99\nmore".ljust(100, b"\0")
    (tmp_path / "h.VOL").write_bytes(head + np.ascontiguousarray(vol.T).tobytes())
    assert np.array_equal(io.read_volume(tmp_path / "h.VOL"), vol)


# spec: docs/formats.md#VOL-header
@pytest.mark.parametrize("head", [b"", b"abc", b"x y z".ljust(100)])
def test_VOL_bad_header(tmp_path, head):
    (tmp_path / "h.VOL").write_bytes(head)
    with pytest.raises(FormatError, match="h.VOL"):
        io.read_volume(tmp_path / "h.VOL")


# spec: docs/formats.md#VOL-header
def test_VOL_truncated(tmp_path, vol):
    io.write_volume(tmp_path / "a.VOL", vol)
    data = (tmp_path / "a.VOL").read_bytes()
    (tmp_path / "a.VOL").write_bytes(data[:-1])
    with pytest.raises(FormatError, match="expected 205"):
        io.read_volume(tmp_path / "a.VOL")


# spec: docs/formats.md#VOL-header
def test_header_add_remove_streaming_round_trip(tmp_path, vol, monkeypatch):
    monkeypatch.setattr(raw_volumes, "CHUNK", 16)  # force many chunks
    io.write_volume(tmp_path / "a.7x5x3.vol", vol)
    io.add_header(tmp_path / "a.7x5x3.vol", tmp_path / "b.VOL")
    assert np.array_equal(io.read_volume(tmp_path / "b.VOL"), vol)
    io.remove_header(tmp_path / "b.VOL", tmp_path / "c.7x5x3.vol")
    assert (tmp_path / "c.7x5x3.vol").read_bytes() == (tmp_path / "a.7x5x3.vol").read_bytes()
    counts = io.histogram_file(tmp_path / "b.VOL")
    assert np.array_equal(counts, np.bincount(vol.ravel(), minlength=256))


# spec: docs/formats.md#other-volumes
@pytest.mark.parametrize("suffix", [".vti", ".nrrd"])
def test_vtk_format_round_trip(tmp_path, vol, suffix):
    path = tmp_path / f"a{suffix}"
    io.write_volume(path, vol, Geometry(origin=(1.0, 2.0, 3.0), spacing=(1.0, 1.0, 1.5)))
    data, geometry, _ = io.read_scan(path)
    assert np.array_equal(data, vol)
    assert np.allclose(geometry.origin, (1, 2, 3)) and np.allclose(geometry.spacing, (1, 1, 1.5))


# spec: docs/formats.md#other-volumes
@pytest.mark.parametrize("suffix", [".nii", ".nii.gz", ".mha"])
def test_read_other_vtk_formats(tmp_path, vol, suffix):
    import pyvista as pv

    img = pv.ImageData(dimensions=vol.shape)
    img.point_data["v"] = vol.ravel(order="F")
    path = tmp_path / f"a{suffix}"
    if suffix == ".mha":  # pyvista has no .mha writer; VTK has
        from vtkmodules.vtkIOImage import vtkMetaImageWriter

        writer = vtkMetaImageWriter()
        writer.SetFileName(str(path))
        writer.SetCompression(False)
        writer.SetInputData(img)
        writer.Write()
    else:
        img.save(str(path))
    assert np.array_equal(io.read_volume(path), vol)


# spec: docs/formats.md#other-volumes
def test_non_uint8_rescaled_only_when_asked(tmp_path):
    v = np.linspace(-1, 1, 60, dtype=np.float32).reshape((5, 4, 3), order="F")
    io.write_volume(tmp_path / "f.nrrd", v)
    raw = io.read_volume(tmp_path / "f.nrrd")
    assert raw.dtype == np.float32 and np.allclose(raw, v)
    scaled = io.read_volume(tmp_path / "f.nrrd", rescale=True)
    assert scaled.dtype == np.uint8 and scaled.min() == 0 and scaled.max() == 255


# spec: docs/formats.md#other-volumes
def test_image_folder_stacks_along_z_in_natural_order(tmp_path, vol):
    from skimage import io as skio

    for z in range(vol.shape[2]):
        skio.imsave(tmp_path / f"slice{z * 5}.png", vol[:, :, z].T, check_contrast=False)
    assert np.array_equal(io.read_volume(tmp_path), vol)  # slice10 after slice5


# spec: docs/formats.md#other-volumes
def test_image_folder_errors(tmp_path):
    with pytest.raises(FormatError, match="no slice images"):
        io.read_volume(tmp_path)
    from skimage import io as skio

    skio.imsave(tmp_path / "a1.png", np.zeros((4, 5), np.uint8), check_contrast=False)
    skio.imsave(tmp_path / "a2.png", np.zeros((4, 6), np.uint8), check_contrast=False)
    with pytest.raises(FormatError, match="a2.png: slice is"):
        io.read_volume(tmp_path)


# spec: docs/formats.md#other-volumes
def test_unknown_and_garbage_volume_files(tmp_path):
    (tmp_path / "x.abc").write_bytes(b"hello")
    with pytest.raises(FormatError, match="unknown volume format"):
        io.read_volume(tmp_path / "x.abc")
    (tmp_path / "y.vti").write_bytes(b"\x00garbage\xff" * 10)
    with pytest.raises(FormatError, match="y.vti"):
        io.read_volume(tmp_path / "y.vti")
    with pytest.raises(FormatError, match="no such file"):
        io.read_volume(tmp_path / "missing.VOL")


# spec: docs/formats.md#vol
def test_write_raw_refuses_float(tmp_path):
    with pytest.raises(ValueError, match="float2uchar|float_to_uint8"):
        io.write_volume(tmp_path / "a.VOL", np.zeros((2, 2, 2), np.float32) + 0.5)


# spec: docs/formats.md#other-volumes
@pytest.mark.parametrize("header", [
    b"NRRD0004\ntype: uchar\nsizes: 2 2 2\nspace directions: (a,b) x\n\n",
    b"NRRD0004\ntype: uchar\nsizes: 2 2 2\nencoding: gzip\n\n",
    b"NRRD0004\ntype: quaternion\nsizes: 2 2 2\n\n",
    b"NRRD0004\ntype: uchar\nsizes: 2 2\n\n",
])
def test_bad_nrrd_headers(tmp_path, header):
    (tmp_path / "b.nrrd").write_bytes(header + b"\0" * 8)
    with pytest.raises(FormatError, match="b.nrrd"):
        io.read_volume(tmp_path / "b.nrrd")


# spec: docs/formats.md#vol
def test_saturate_for_raw_clips_counts_and_says_so():
    counts = np.array([0, 7, 300], np.uint16).reshape(3, 1, 1)
    out, note = io.saturate_for_raw("hot.VOL", counts)
    assert out.dtype == np.uint8 and out.ravel().tolist() == [0, 7, 255] and "max 300" in note
    out, note = io.saturate_for_raw("hot.vti", counts)
    assert out is counts and note is None
    out, note = io.saturate_for_raw("ok.vol", np.array([1, 2], np.uint16).reshape(2, 1, 1))
    assert out.dtype == np.uint8 and note is None
