"""Fault cases for the scan readers (#35): DICOM, NIfTI/MGH through nibabel, 3-D TIFF, detached and
compressed NRRD, Slicer segmentations, MetaImage geometry, and the ``# geometry:`` header line.

Each is a file (or a folder) a user could be handed; each must be refused with the file named,
within the worker's memory cap and time, or (where it is legitimate) read right.
"""

from __future__ import annotations

import bz2
import gzip
import io as bytes_io
import struct

import numpy as np

from .cases import BIG, Case, mha, nrrd


def dicom(rows=4, cols=5, *, pixels: bytes | None = None, z=0.0, uid="1.2.3", iop=(1, 0, 0, 0, 1, 0),
          bits=16, frames: int | None = None) -> bytes:
    """One CT slice as DICOM bytes (pydicom), with the fields a hostile file would lie in."""
    from pydicom.dataset import FileDataset, FileMetaDataset
    from pydicom.uid import CTImageStorage, ExplicitVRLittleEndian

    meta = FileMetaDataset()
    meta.MediaStorageSOPClassUID, meta.MediaStorageSOPInstanceUID = CTImageStorage, f"{uid}.{int(z * 10)}"
    meta.TransferSyntaxUID = ExplicitVRLittleEndian
    ds = FileDataset("x.dcm", {}, file_meta=meta, preamble=b"\0" * 128)
    ds.SOPClassUID, ds.SOPInstanceUID = CTImageStorage, meta.MediaStorageSOPInstanceUID
    ds.Modality, ds.SeriesInstanceUID = "CT", uid
    ds.Rows, ds.Columns = rows, cols
    ds.PixelSpacing = [0.7, 0.7]
    ds.ImageOrientationPatient = list(iop)
    ds.ImagePositionPatient = [0, 0, z]
    ds.SamplesPerPixel, ds.PhotometricInterpretation = 1, "MONOCHROME2"
    ds.BitsAllocated, ds.BitsStored, ds.HighBit, ds.PixelRepresentation = bits, bits, bits - 1, 0
    if frames is not None:
        ds.NumberOfFrames = frames
    ds.PixelData = pixels if pixels is not None else b"\1" * (rows * cols * bits // 8)
    out = bytes_io.BytesIO()
    ds.save_as(out, enforce_file_format=True)
    return out.getvalue()


def mgh(dims, dtype_code=0, data: bytes = b"") -> bytes:
    """An MGH header (big-endian: version, dims, type, dof, goodRAS) padded to 284 bytes, then data."""
    head = struct.pack(">7i", 1, *dims, 1, dtype_code, 0) + b"\0" * (284 - 28)
    return head + data


def tiff_stack(shape=(3, 4, 5)) -> bytes:
    import tifffile

    out = bytes_io.BytesIO()
    tifffile.imwrite(out, np.ones(shape, np.uint8), photometric="minisblack")
    return out.getvalue()


def seg_nrrd(layers: str, body: bytes = b"", pairs: str = "") -> bytes:
    return (f"NRRD0004\ntype: uchar\ndimension: 4\nsizes: {layers} 2 2 2\nkinds: list domain domain domain\n"
            f"encoding: raw\n{pairs}\n").encode() + body


def scan_cases() -> list[Case]:
    slices = {f"ct/{k}.dcm": dicom(z=2.5 * k) for k in range(3)}
    return [
        # DICOM
        Case("DICOM slice claims 65535 x 65535 pixels", "read_volume",
             {"d.dcm": dicom(65535, 65535, pixels=b"\0" * 16)}, "d.dcm"),
        Case("DICOM pixel data short", "read_volume", {"d.dcm": dicom(pixels=b"\1" * 7)}, "d.dcm"),
        Case("DICOM frames claim 2^31", "read_volume", {"d.dcm": dicom(frames=2**31 - 1)}, "d.dcm"),
        Case("DICOM series with a duplicate slice", "read_volume",
             {**slices, "ct/dup.dcm": dicom(z=2.5, uid="1.2.3")}, "ct"),
        Case("DICOM series orientation not unit", "read_volume",
             {**slices, "ct/2.dcm": dicom(z=5.0, iop=(2, 0, 0, 0, 1, 0))}, "ct"),
        Case("DICOM series orientation NaN", "read_volume",
             {f"ct/{k}.dcm": dicom(z=2.5 * k, iop=(float("nan"), 0, 0, 0, 1, 0)) for k in range(2)}, "ct"),
        Case("DICOM series one slice another size", "read_volume",
             {**slices, "ct/2.dcm": dicom(5, 4, z=5.0)}, "ct"),
        Case("DICOM folder of two series, none chosen", "read_volume",
             {**slices, "ct/other.dcm": dicom(z=0.0, uid="9.9.9")}, "ct"),
        Case("DICM mark, garbage after", "read_volume", {"d.dcm": b"\0" * 128 + b"DICM" + b"\xff" * 300}, "d.dcm"),
        Case("DICOM empty file", "read_volume", {"d.dcm": b""}, "d.dcm"),
        Case("DICOM series of three slices", "read_volume", slices, "ct", "accept", "shape_5_4_3"),
        # MGH / MGZ (nibabel)
        Case("MGH dims 2^31 cubed", "read_volume", {"f.mgh": mgh((2**31 - 1,) * 3)}, "f.mgh"),
        Case("MGH data truncated", "read_volume", {"f.mgh": mgh((10, 10, 10), data=b"\1" * 100)}, "f.mgh"),
        Case("MGH header truncated", "read_volume", {"f.mgh": mgh((2, 2, 2))[:40]}, "f.mgh"),
        Case("MGZ bomb", "read_volume", {"f.mgz": gzip.compress(mgh((2, 2, 2)) + b"\0" * (64 << 20))}, "f.mgz"),
        Case("MGZ not gzip", "read_volume", {"f.mgz": b"not gzip at all"}, "f.mgz"),
        # 3-D TIFF
        Case("TIFF garbage", "read_volume", {"f.tif": b"II*\0" + b"\xff" * 64}, "f.tif"),
        Case("TIFF truncated", "read_volume", {"f.tif": tiff_stack()[:60]}, "f.tif"),
        Case("TIFF stack of 3 pages", "read_volume", {"f.tif": tiff_stack()}, "f.tif", "accept", "shape_5_4_3"),
        # NRRD: detached data, skips, encodings
        Case("NHDR data file missing", "read_volume",
             {"f.nhdr": b"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\ndata file: gone.raw\n"},
             "f.nhdr"),
        Case("NHDR data file a list", "read_volume",
             {"f.nhdr": b"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\ndata file: LIST\n"},
             "f.nhdr"),
        Case("NRRD line skip past the end", "read_volume", {"f.nrrd": nrrd("2 2 2", b"\0" * 8, "line skip: 99")},
             "f.nrrd"),
        Case("NRRD byte skip -2", "read_volume", {"f.nrrd": nrrd("2 2 2", b"\0" * 8, "byte skip: -2")}, "f.nrrd"),
        Case(f"NRRD byte skip {BIG}", "read_volume", {"f.nrrd": nrrd("2 2 2", b"\0" * 8, f"byte skip: {BIG}")},
             "f.nrrd"),
        Case("NRRD bzip2 bomb", "read_volume",
             {"f.nrrd": nrrd("10 10 10", bz2.compress(b"\0" * (64 << 20)), encoding="bzip2")}, "f.nrrd"),
        Case("NRRD bzip2 corrupt", "read_volume", {"f.nrrd": nrrd("2 2 2", b"BZh9garbage", encoding="bzip2")},
             "f.nrrd"),
        Case("NRRD ascii too few numbers", "read_volume", {"f.nrrd": nrrd("2 2 2", b"1 2 3", encoding="ascii")},
             "f.nrrd"),
        Case("NRRD ascii not numbers", "read_volume", {"f.nrrd": nrrd("2 2 2", b"a " * 8, encoding="ascii")},
             "f.nrrd"),
        Case("NRRD unknown space", "read_volume", {"f.nrrd": nrrd("2 2 2", b"\0" * 8, "space: sideways")},
             "f.nrrd"),
        Case("NRRD sheared directions", "read_volume",
             {"f.nrrd": nrrd("2 2 2", b"\0" * 8, "space directions: (1,0,0) (1,1,0) (0,0,1)")}, "f.nrrd"),
        Case("seg.nrrd 0 layers", "read_volume", {"f.seg.nrrd": seg_nrrd("0")}, "f.seg.nrrd"),
        Case(f"seg.nrrd {BIG} layers", "read_volume", {"f.seg.nrrd": seg_nrrd(BIG)}, "f.seg.nrrd"),
        Case("seg.nrrd segment on a missing layer", "read_volume",
             {"f.seg.nrrd": seg_nrrd("1", b"\1" * 8, "Segment0_Name:=A\nSegment0_Layer:=5\nSegment0_LabelValue:=1")},
             "f.seg.nrrd"),
        # MetaImage geometry
        Case("mha TransformMatrix not orthonormal", "read_volume",
             {"f.mha": mha("2 2 2", b"\0" * 8).replace(b"NDims", b"TransformMatrix = 1 1 0 0 1 0 0 0 1\nNDims")},
             "f.mha"),
        Case("mha ElementSpacing nan", "read_volume",
             {"f.mha": mha("2 2 2", b"\0" * 8).replace(b"NDims", b"ElementSpacing = nan 1 1\nNDims")}, "f.mha"),
        # the text files' geometry line
        Case("mskel geometry spacing 0", "read_mskel",
             {"f.mskel": b"# geometry: spacing 0 1 1\n1 2 3 1.5 0.5\n"}, "f.mskel"),
        Case("mskel geometry of 10^400", "read_mskel",
             {"f.mskel": b"# geometry: spacing 1 1 1 origin 1" + b"0" * 400 + b" 0 0\n1 2 3 1.5 0.5\n"}, "f.mskel"),
        Case("tskel geometry direction sheared", "read_tskel",
             {"f.tskel": b"# geometry: spacing 1 1 1 direction 1 1 0 0 1 0 0 0 1\nRoot: 0 0 0 :: 1 0 0\n"
                         b"1 0 0 0\n0 1 0 0\n0 0 1 0\n0 0 0 1\n1 2 3 1.5\n"}, "f.tskel"),
    ]
