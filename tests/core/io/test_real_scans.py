"""Real scans against the readers the field trusts (docs/formats.md, "Physical space").

Every reader's voxels *and* their placement are compared with another project's own reader:
nibabel (NIfTI, MGH), SimpleITK (ITK, which 3D Slicer uses: NIfTI, NRRD, MetaImage, DICOM),
pynrrd (NRRD) and pydicom (DICOM), on files those projects ship in their wheels or write
themselves. "Placement" is the physical point (LPS mm) of voxel indices, compared with
SimpleITK's ``TransformIndexToPhysicalPoint`` or nibabel's affine.
"""

from __future__ import annotations

import gzip
import random
import re
from pathlib import Path

import nibabel as nib
import numpy as np
import pydicom
import pytest
import SimpleITK as sitk

from volanim_core import io
from volanim_core.errors import FormatError
from volanim_core.geometry import Geometry

NIBABEL_DATA = Path(nib.__file__).parent / "tests" / "data"
PYDICOM_DATA = Path(pydicom.__file__).parent / "data" / "test_files"
RAS_TO_LPS = np.diag([-1.0, -1.0, 1.0, 1.0])


def corners_and_samples(shape, n=20, seed=0):
    """Voxel indices to compare placement at: the 8 corners and some inside."""
    rng = np.random.default_rng(seed)
    corners = np.array([[x, y, z] for x in (0, shape[0] - 1) for y in (0, shape[1] - 1) for z in (0, shape[2] - 1)])
    return np.vstack([corners, rng.integers(0, shape, (n, 3))])


def assert_same_as_sitk(scan, image: sitk.Image):
    """Same voxels at the same indices, and each index at the same physical point, as SimpleITK."""
    expected = sitk.GetArrayFromImage(image).T  # [z, y, x] -> [x, y, z]
    assert scan.data.shape == expected.shape
    # NaN is background: ITK reads resampled_anat_moved.nii's NaN voxels as 0, nibabel (and we) keep NaN
    ours = np.where(np.isnan(scan.data), 0, scan.data) if scan.data.dtype.kind == "f" else scan.data
    np.testing.assert_allclose(ours, expected, rtol=1e-6)
    idx = corners_and_samples(scan.data.shape)
    theirs = np.array([image.TransformContinuousIndexToPhysicalPoint([float(v) for v in i]) for i in idx])
    np.testing.assert_allclose(scan.geometry.to_physical(idx), theirs, atol=1e-4)


# --- NIfTI and MGH: nibabel's test files --------------------------------------------------------

# spec: docs/formats.md#physical-space
@pytest.mark.parametrize("name", ["anatomical.nii", "standard.nii.gz", "reoriented_anat_moved.nii",
                                  "resampled_anat_moved.nii"])
def test_nifti_test_files_match_nibabel_and_simpleitk(name):
    path = NIBABEL_DATA / name
    scan = io.read_scan(path)
    img = nib.load(path)
    np.testing.assert_allclose(scan.data, np.asanyarray(img.dataobj), rtol=1e-6)
    idx = corners_and_samples(scan.data.shape)
    ras = nib.affines.apply_affine(img.affine, idx)
    np.testing.assert_allclose(scan.geometry.to_physical(idx), ras * [-1, -1, 1], atol=1e-4)
    assert_same_as_sitk(scan, sitk.ReadImage(str(path)))


def test_anatomical_nii_is_not_flipped():
    """The bug: z reversed against nibabel and SimpleITK, origin 0. In LPS, as SimpleITK and Slicer
    report it, the origin is (-32, 40, -16) (nibabel's RAS (32, -40, -16))."""
    scan = io.read_scan(NIBABEL_DATA / "anatomical.nii")
    assert np.allclose(scan.geometry.origin, (-32, 40, -16))
    assert np.allclose(scan.geometry.spacing, (2, 2, 2))
    assert np.array_equal(scan.data, np.asanyarray(nib.load(NIBABEL_DATA / "anatomical.nii").dataobj))


def test_nifti_scaling_is_applied(tmp_path):
    raw = np.arange(4 * 5 * 6, dtype=np.int16).reshape(4, 5, 6)
    img = nib.Nifti1Image(raw, np.diag([0.7, 0.7, 2.5, 1]))
    img.header.set_slope_inter(1.0, -1024.0)  # a CT's intercept
    path = tmp_path / "ct.nii.gz"
    nib.save(img, path)
    scan = io.read_scan(path)
    assert scan.data.min() == -1024 and np.allclose(scan.data, raw - 1024.0)
    assert scan.data.dtype == np.int16  # Hounsfield units as a DICOM CT gives them, not float
    assert_same_as_sitk(scan, sitk.ReadImage(str(path)))


def test_four_d_nifti_is_refused_with_the_file_named():
    with pytest.raises(FormatError, match="example4d.nii.gz"):
        io.read_scan(NIBABEL_DATA / "example4d.nii.gz")


def test_mgh_and_mgz_match_nibabel(tmp_path):
    rng = np.random.default_rng(1)
    data = rng.integers(0, 200, (6, 7, 8)).astype(np.uint8)
    affine = np.array([[0, 0, -1.5, 20], [1.0, 0, 0, -30], [0, -1.2, 0, 40], [0, 0, 0, 1]])
    for suffix in (".mgh", ".mgz"):
        path = tmp_path / f"brain{suffix}"
        nib.save(nib.MGHImage(data, affine), path)
        scan = io.read_scan(path)
        assert np.array_equal(scan.data, data)
        idx = corners_and_samples(data.shape)
        raw = gzip.decompress(path.read_bytes()) if suffix == ".mgz" else path.read_bytes()
        theirs = nib.MGHImage.from_bytes(raw)  # nib.load leaves an MGH file open (a ResourceWarning)
        assert np.array_equal(np.asanyarray(theirs.dataobj), data)
        ras = nib.affines.apply_affine(theirs.affine, idx)
        np.testing.assert_allclose(scan.geometry.to_physical(idx), ras * [-1, -1, 1], atol=1e-4)


@pytest.mark.parametrize("suffix", [".nii", ".nii.gz"])
def test_nifti_written_here_reads_the_same_in_nibabel_and_simpleitk(tmp_path, suffix):
    vol = np.random.default_rng(2).integers(0, 255, (5, 6, 7)).astype(np.uint8)
    g = Geometry((0.7, 0.8, 2.5), (-40, -25, -900), (0, 1, 0, -1, 0, 0, 0, 0, 1))
    path = tmp_path / f"out{suffix}"
    io.write_volume(path, vol, g)
    image = sitk.ReadImage(str(path))
    scan = io.read_scan(path)
    assert np.array_equal(scan.data, vol) and np.allclose(scan.geometry.affine, g.affine, atol=1e-5)
    assert_same_as_sitk(scan, image)


# --- NRRD: pynrrd writes every variant; SimpleITK checks the geometry --------------------------

@pytest.mark.parametrize("options", [
    {"encoding": "raw"}, {"encoding": "gzip"}, {"encoding": "bzip2"}, {"encoding": "ascii"},
    {"encoding": "raw", "detached_header": True}, {"encoding": "gzip", "detached_header": True},
])
def test_nrrd_variants_written_by_pynrrd(tmp_path, options):
    import nrrd

    vol = np.random.default_rng(3).integers(-500, 1500, (5, 6, 7)).astype(np.int16)
    header = {"space": "right-anterior-superior", "space origin": np.array([10.0, -20.0, 30.0]),
              "space directions": np.array([[0.0, -0.5, 0.0], [0.5, 0.0, 0.0], [0.0, 0.0, 1.5]])}
    path = tmp_path / ("scan.nhdr" if options.get("detached_header") else "scan.nrrd")
    nrrd.write(str(path), vol, {**header, "encoding": options["encoding"]},
               detached_header=options.get("detached_header", False))
    read_path = path
    scan = io.read_scan(read_path)
    theirs, their_header = nrrd.read(str(read_path))
    assert np.array_equal(scan.data, theirs)
    # RAS directions as columns: index axis k's vector in space is row k of pynrrd's array
    ras = np.eye(4)
    ras[:3, :3] = their_header["space directions"].T
    ras[:3, 3] = their_header["space origin"]
    np.testing.assert_allclose(scan.geometry.affine, RAS_TO_LPS @ ras, atol=1e-9)
    if options["encoding"] in ("raw", "gzip"):
        assert_same_as_sitk(scan, sitk.ReadImage(str(read_path)))


def test_nrrd_line_and_byte_skip(tmp_path):
    vol = np.arange(2 * 3 * 4, dtype=np.uint8).reshape(2, 3, 4, order="F")
    body = b"a text line to skip\nanother one\n" + b"\xff" * 5 + vol.tobytes(order="F")
    (tmp_path / "data.raw").write_bytes(body)
    (tmp_path / "scan.nhdr").write_text("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 3 4\nencoding: raw\n"
                                        "line skip: 2\nbyte skip: 5\ndata file: data.raw\n")
    assert np.array_equal(io.read_volume(tmp_path / "scan.nhdr"), vol)
    (tmp_path / "tail.nhdr").write_text("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 3 4\nencoding: raw\n"
                                        "byte skip: -1\ndata file: data.raw\n")
    assert np.array_equal(io.read_volume(tmp_path / "tail.nhdr"), vol)


def test_layered_slicer_segmentation(tmp_path):
    """A 4-D .seg.nrrd as 3D Slicer writes it: two layers, three segments (two share a layer)."""
    layers = np.zeros((2, 4, 5, 6), np.uint8)  # [layer, x, y, z] (NRRD's first axis fastest)
    layers[0, 0:2, :, :] = 1  # Liver, layer 0 label 1
    layers[0, 2:3, :, :] = 2  # Spleen, layer 0 label 2
    layers[1, 1:4, 0:2, :] = 1  # Tumour overlaps the liver, on layer 1
    header = ("NRRD0004\ntype: uchar\ndimension: 4\nspace: left-posterior-superior\nsizes: 2 4 5 6\n"
              "space directions: none (0.5,0,0) (0,0.5,0) (0,0,2)\nkinds: list domain domain domain\n"
              "encoding: raw\nspace origin: (1,2,3)\n"
              "Segment0_Name:=Liver\nSegment0_Layer:=0\nSegment0_LabelValue:=1\n"
              "Segment1_Name:=Spleen\nSegment1_Layer:=0\nSegment1_LabelValue:=2\n"
              "Segment2_Name:=Tumour\nSegment2_Layer:=1\nSegment2_LabelValue:=1\n\n")
    path = tmp_path / "organs.seg.nrrd"
    path.write_bytes(header.encode() + np.ascontiguousarray(layers.transpose(3, 2, 1, 0)).tobytes())
    scan = io.read_scan(path)
    assert scan.segments == {1: "Liver", 2: "Spleen", 3: "Tumour"}
    assert scan.data.shape == (4, 5, 6) and np.allclose(scan.geometry.spacing, (0.5, 0.5, 2))
    assert (scan.data[0, 3] == 1).all() and (scan.data[2, 3] == 2).all() and (scan.data[1:4, 0:2] == 3).all()


# --- MetaImage: SimpleITK writes, we read; we write, SimpleITK reads ---------------------------

@pytest.mark.parametrize("compress", [False, True])
def test_metaimage_from_simpleitk(tmp_path, compress):
    arr = np.random.default_rng(4).integers(0, 4000, (7, 6, 5)).astype(np.uint16)  # [z, y, x]
    image = sitk.GetImageFromArray(arr)
    image.SetSpacing((0.7, 0.8, 2.5))
    image.SetOrigin((-40.0, -25.0, -900.0))
    image.SetDirection((0, 0, 1, 1, 0, 0, 0, 1, 0))
    path = tmp_path / "scan.mha"
    sitk.WriteImage(image, str(path), compress)
    assert_same_as_sitk(io.read_scan(path), image)


def test_metaimage_written_here_reads_in_simpleitk(tmp_path):
    vol = np.random.default_rng(5).normal(size=(5, 6, 7)).astype(np.float32)
    g = Geometry((0.5, 0.6, 0.7), (1, 2, 3), (0, -1, 0, 1, 0, 0, 0, 0, 1))
    io.write_volume(tmp_path / "out.mha", vol, g)
    assert_same_as_sitk(io.read_scan(tmp_path / "out.mha"), sitk.ReadImage(str(tmp_path / "out.mha")))


def test_vti_keeps_direction(tmp_path):
    vol = np.arange(60, dtype=np.uint8).reshape(3, 4, 5)
    g = Geometry((0.5, 0.5, 2), (1, 2, 3), (0, 1, 0, -1, 0, 0, 0, 0, 1))
    io.write_volume(tmp_path / "a.vti", vol, g)
    scan = io.read_scan(tmp_path / "a.vti")
    assert np.array_equal(scan.data, vol) and scan.geometry == g


# --- DICOM ------------------------------------------------------------------------------------

def write_ct_series(folder: Path, volume_hu: np.ndarray, *, spacing=(0.7, 0.7, 2.5), origin=(-40.0, -25.0, -900.0),
                    series_uid=None, shuffle=True):
    """A synthetic CT as a DICOM series (pydicom, through volanim's writer; SimpleITK and pydicom are
    the oracles): stored = HU + 1024, file names shuffled so only ImagePositionPatient gives the order."""
    from pydicom.uid import generate_uid

    from volanim_core.io.dicom_files import write_dicom_series

    names = [f"IM{k:04d}.dcm" for k in range(volume_hu.shape[2])]
    if shuffle:
        random.Random(7).shuffle(names)
    series_uid = series_uid or generate_uid()
    write_dicom_series(folder, volume_hu, Geometry(spacing, origin), description="synthetic body",
                       series_uid=series_uid, names=names)
    return series_uid


def synthetic_ct(shape=(24, 20, 12)):
    hu = np.full(shape, -1000, np.int16)
    hu[4:20, 3:17, 2:10] = 40  # soft tissue
    hu[10:14, 8:12, 2:10] = 700  # bone
    hu[0, 0, :] = np.arange(shape[2])  # tells the slices apart
    return hu


def test_dicom_series_with_shuffled_names_origin_spacing_and_intercept(tmp_path):
    hu = synthetic_ct()
    write_ct_series(tmp_path / "ct", hu)
    scan = io.read_scan(tmp_path / "ct")
    assert np.array_equal(scan.data, hu) and scan.data.dtype == np.int16
    assert np.allclose(scan.geometry.spacing, (0.7, 0.7, 2.5)) and np.allclose(scan.geometry.origin, (-40, -25, -900))
    reader = sitk.ImageSeriesReader()
    reader.SetFileNames(sitk.ImageSeriesReader.GetGDCMSeriesFileNames(str(tmp_path / "ct")))
    assert_same_as_sitk(scan, reader.Execute())


def test_a_folder_of_two_series_lists_them_and_reads_the_one_chosen(tmp_path):
    hu = synthetic_ct((8, 6, 4))
    first = write_ct_series(tmp_path / "both", hu)
    second_folder = tmp_path / "second"
    second = write_ct_series(second_folder, hu + 5)
    for f in second_folder.iterdir():
        f.rename(tmp_path / "both" / f"B{f.name}")
    with pytest.raises(FormatError, match="2 DICOM series") as err:
        io.read_scan(tmp_path / "both")
    assert first in str(err.value) and second in str(err.value)
    assert np.array_equal(io.read_scan(tmp_path / "both", series=second).data, hu + 5)
    assert io.read_scan(tmp_path / "both", series="1").data.shape == hu.shape


def test_dicom_series_with_a_missing_slice_is_refused(tmp_path):
    write_ct_series(tmp_path / "ct", synthetic_ct((8, 6, 5)), shuffle=False)
    (tmp_path / "ct" / "IM0002.dcm").unlink()
    with pytest.raises(FormatError, match="not evenly spaced"):
        io.read_scan(tmp_path / "ct")


@pytest.mark.parametrize("name", ["CT_small.dcm", "MR_small.dcm"])
def test_pydicom_test_files_match_simpleitk(name):
    path = PYDICOM_DATA / name
    scan = io.read_scan(path)
    image = sitk.ReadImage(str(path))
    ds = pydicom.dcmread(path)
    assert np.array_equal(scan.data[:, :, 0], (ds.pixel_array * float(ds.get("RescaleSlope", 1))
                                               + float(ds.get("RescaleIntercept", 0))).T)
    assert_same_as_sitk(scan, sitk.Cast(image, sitk.sitkFloat64))


def test_multiframe_rt_dose_frames_are_placed_by_their_offsets():
    path = PYDICOM_DATA / "rtdose.dcm"
    scan = io.read_scan(path)
    ds = pydicom.dcmread(path)
    assert scan.data.shape == (ds.Columns, ds.Rows, ds.NumberOfFrames)
    np.testing.assert_allclose(scan.data[:, :, 0], ds.pixel_array[0].T * float(ds.DoseGridScaling), rtol=1e-6)
    assert np.allclose(scan.geometry.origin, [float(v) for v in ds.ImagePositionPatient])
    offsets = np.asarray(ds.GridFrameOffsetVector, float)
    assert np.isclose(scan.geometry.spacing[2], offsets[1] - offsets[0])


def test_enhanced_ct_is_in_hounsfield_units_as_simpleitk_reads_it():
    """pydicom-data's enhanced (multi-frame) CT keeps its rescale (intercept -1024) in the shared functional
    groups and nowhere else: it read 0 .. 1196, every value 1024 too high. SimpleITK gives -1024 .. 172."""
    from pydicom.data import get_testdata_file

    path = get_testdata_file("eCT_Supplemental.dcm")
    scan = io.read_scan(path)
    image = sitk.ReadImage(str(path))
    assert scan.data.min() == -1024 and scan.data.max() == 172
    # ITK stacks the frames up z with a left-handed direction; we along the frame normal (row x column, here
    # -z): the same voxel at the same physical point, each grid's index of it found through its own geometry
    theirs = sitk.GetArrayFromImage(image).T
    idx = np.argwhere(np.ones(scan.data.shape, bool))[::97]
    points = scan.geometry.to_physical(idx)
    at = np.array([image.TransformPhysicalPointToIndex([float(v) for v in p]) for p in points])
    np.testing.assert_array_equal(scan.data[tuple(idx.T)], theirs[tuple(at.T)])


def test_enhanced_ct_with_a_rescale_per_frame(tmp_path):
    """Per-frame functional groups may carry each frame's own rescale: each frame is rescaled by its own,
    the others by the shared one (the frames as pydicom decodes them, times the slope, plus the intercept)."""
    from pydicom.data import get_testdata_file
    from pydicom.dataset import Dataset
    from pydicom.sequence import Sequence

    ds = pydicom.dcmread(get_testdata_file("eCT_Supplemental.dcm"))
    own = Dataset()
    own.RescaleIntercept, own.RescaleSlope, own.RescaleType = "-1000", "2", "US"
    ds.PerFrameFunctionalGroupsSequence[1].PixelValueTransformationSequence = Sequence([own])
    ds.save_as(tmp_path / "per_frame.dcm")
    scan = io.read_scan(tmp_path / "per_frame.dcm")
    raw = ds.pixel_array.astype(np.float64)
    iop = np.asarray(ds.SharedFunctionalGroupsSequence[0].PlaneOrientationSequence[0].ImageOrientationPatient, float)
    normal = np.cross(iop[:3], iop[3:])
    along = [np.asarray(g.PlanePositionSequence[0].ImagePositionPatient, float) @ normal
             for g in ds.PerFrameFunctionalGroupsSequence]
    want = {0: raw[0] - 1024, 1: raw[1] * 2 - 1000}
    for z, k in enumerate(np.argsort(along, kind="stable")):  # frames in order along the normal
        np.testing.assert_array_equal(scan.data[:, :, z], want[int(k)].T)


# --- TIFF stacks ------------------------------------------------------------------------------

def test_multipage_tiff_with_imagej_spacing(tmp_path):
    import tifffile

    zyx = np.random.default_rng(6).integers(0, 255, (5, 6, 7)).astype(np.uint8)
    tifffile.imwrite(tmp_path / "stack.tif", zyx, imagej=True, resolution=(1 / 0.4, 1 / 0.4),
                     metadata={"spacing": 1.2, "unit": "mm"})
    scan = io.read_scan(tmp_path / "stack.tif")
    assert np.array_equal(scan.data, zyx.T) and np.allclose(scan.geometry.spacing, (0.4, 0.4, 1.2))


def test_an_int32_ct_converts_to_tiff_as_int16_and_one_that_does_not_fit_is_refused_plainly(tmp_path, capsys):
    """`volanim convert CT.nrrd ct.tif` on int32 Hounsfield units printed tifffile's "the ImageJ format does
    not support data type 'i'". Values that fit a type ImageJ holds are written in it exactly (tifffile reads
    them back); values that fit none are refused, naming the types and what to write instead."""
    import nrrd
    import tifffile

    from volanim_core.cli import main

    hu = np.random.default_rng(9).integers(-1024, 3072, (6, 5, 4)).astype(np.int32)
    nrrd.write(str(tmp_path / "ct.nrrd"), hu, {"space": "left-posterior-superior",
                                                 "space directions": np.diag([0.5, 0.5, 2.0]),
                                                 "space origin": np.zeros(3)})
    assert main(["convert", str(tmp_path / "ct.nrrd"), str(tmp_path / "ct.tif")]) == 0
    with tifffile.TiffFile(tmp_path / "ct.tif") as tif:
        back = tif.asarray()
        assert back.dtype == np.int16 and tif.imagej_metadata["spacing"] == 2.0
    np.testing.assert_array_equal(back, hu.T)
    nrrd.write(str(tmp_path / "big.nrrd"), hu * 100, {"space": "left-posterior-superior",
                                                        "space directions": np.eye(3), "space origin": np.zeros(3)})
    capsys.readouterr()
    assert main(["convert", str(tmp_path / "big.nrrd"), str(tmp_path / "big.tif")]) == 2
    said = capsys.readouterr().err
    assert "uint8, uint16, int16 or float32" in said and "int32" in said and ".nrrd" in said
    assert not (tmp_path / "big.tif").exists()


# --- NaN and infinity -------------------------------------------------------------------------

def test_nan_voxels_are_background_not_a_black_volume(tmp_path, capsys):
    from volanim_core.cli import main

    vol = np.linspace(0, 100, 4 * 5 * 6, dtype=np.float32).reshape(4, 5, 6)
    vol[0, 0, :] = np.nan
    vol[1, 0, 0] = np.inf
    nib.save(nib.Nifti1Image(vol, np.eye(4)), tmp_path / "mri.nii")
    assert main(["info", str(tmp_path / "mri.nii")]) == 0
    text = capsys.readouterr().out
    values = next(line for line in text.splitlines() if line.startswith("values"))
    assert "7 NaN or infinite" in values and "nan" not in values.replace("NaN", "")  # was "values nan .. nan"
    assert main(["convert", str(tmp_path / "mri.nii"), str(tmp_path / "mri.nrrd"), "--rescale"]) == 0
    out = io.read_volume(tmp_path / "mri.nrrd")
    assert out.max() == 255 and out[0, 0, 0] == 0 and np.count_nonzero(out) > 0.9 * out.size


@pytest.mark.parametrize("signed", [0, 1])
def test_12_bit_pixels_read_like_pydicom(tmp_path, signed):
    """Our fast path for plain slices against pydicom's decoder: 12 of 16 bits, high bits set."""
    hu = synthetic_ct((8, 6, 3))
    write_ct_series(tmp_path / "ct", hu, shuffle=False)
    for f in sorted((tmp_path / "ct").iterdir()):
        ds = pydicom.dcmread(f)
        raw = np.frombuffer(ds.PixelData, "<u2").copy()
        ds.BitsStored, ds.HighBit, ds.PixelRepresentation = 12, 11, signed
        ds.PixelData = (raw | 0xF000).astype("<u2").tobytes()  # garbage above bit 11
        ds.save_as(f)
    scan = io.read_scan(tmp_path / "ct")
    for z, f in enumerate(sorted((tmp_path / "ct").iterdir())):
        ds = pydicom.dcmread(f)
        assert np.array_equal(scan.data[:, :, z], ds.pixel_array.T.astype(np.int32) + int(ds.RescaleIntercept))


@pytest.mark.parametrize("name", ["JPEG2000.dcm", "JPEG-lossy.dcm", "MR_small_RLE.dcm"])
def test_compressed_dicom_reads_as_pydicom_decodes_it_or_is_refused_by_name(name):
    """Compressed transfer syntaxes go through pydicom's decoders: where this machine has one the
    voxels are pydicom's own; where it has none the refusal names the file and the syntax."""
    path = PYDICOM_DATA / name
    ds = pydicom.dcmread(path)
    try:
        expected = ds.pixel_array
    except Exception:  # no decoder plugin installed for this syntax
        syntax = ds.file_meta.TransferSyntaxUID.name
        with pytest.raises(FormatError, match=re.escape(f"{name}: its pixel data cannot be decoded ({syntax})")):
            io.read_scan(path)
        return
    scan = io.read_scan(path)
    slope, intercept = float(ds.get("RescaleSlope", 1)), float(ds.get("RescaleIntercept", 0))
    assert np.allclose(scan.data[:, :, 0], expected.reshape(ds.Rows, ds.Columns).T * slope + intercept)
