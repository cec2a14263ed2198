"""DICOM, as CT and MRI leave the scanner, through pydicom (imported lazily).

    a folder --one deferred read a file--> series by SeriesInstanceUID (several: listed, one chosen)
        --ImagePositionPatient along the slice normal (never the file names)--> slices in order
        --even steps checked (a missing or duplicate slice named)--> pixels (plain slices straight
        from their bytes, the rest through pydicom's decoders) --rescale--> vol[x, y, z] + Geometry
    one multi-frame file --per-frame positions or GridFrameOffsetVector (RT dose)--> the same

Geometry is LPS millimetres, as DICOM stores it: ImageOrientationPatient's row and column cosines
are the x and y index axes, their cross product z. :func:`write_dicom_series` writes a series
(the ``mannequin-ct`` sample, the tests); SimpleITK's GDCM reader and pydicom are the oracles.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from volanim_core.errors import FormatError
from volanim_core.geometry import Geometry
from volanim_core.limits import checked_grid


def _read_deferred(f: Path):
    """A file's dataset with its large elements (the pixels) left on disk until they are used, or None
    for a file that is not DICOM: one read of each file serves grouping, sorting and the pixels."""
    import pydicom
    from pydicom.errors import InvalidDicomError

    try:
        return pydicom.dcmread(str(f), defer_size=4096)
    except (InvalidDicomError, OSError, EOFError, ValueError, TypeError, AttributeError, KeyError):
        return None


def _series_datasets(folder: Path) -> dict[str, list[tuple[Path, object]]]:
    series: dict[str, list[tuple[Path, object]]] = {}
    for f in sorted(p for p in folder.iterdir() if p.is_file()):
        ds = _read_deferred(f)
        if ds is None or "Rows" not in ds:  # not DICOM, or no image (a report, a DICOMDIR)
            continue
        series.setdefault(str(ds.get("SeriesInstanceUID", "")), []).append((f, ds))
    return series


def list_series(folder: str | Path) -> list[tuple[str, str]]:
    """``(SeriesInstanceUID, a line for people)`` for each DICOM series in a folder, for a choice."""
    found = _series_datasets(Path(folder))
    return list(zip(found, describe_series(found)))


def describe_series(series: dict[str, list]) -> list[str]:
    """One line a series: ``N. UID  modality description  (files)``, for the choice the user makes."""
    lines = []
    for k, (uid, found) in enumerate(series.items(), start=1):
        ds = found[0][1]
        text = " ".join(str(ds.get(t, "")) for t in ("Modality", "SeriesDescription")).strip()
        lines.append(f"{k}. {uid or '(no UID)'}  {text or '(no description)'}  ({len(found)} files)")
    return lines


def is_dicom_file(path: Path) -> bool:
    """Whether a file is DICOM Part 10: the 'DICM' mark after its 128-byte preamble."""
    try:
        with path.open("rb") as fh:
            return fh.read(132)[128:132] == b"DICM"
    except OSError:
        return False


def is_dicom_folder(folder: Path) -> bool:
    """Whether a folder holds DICOM files (a look at its first few files)."""
    return any(is_dicom_file(f) for f in sorted(p for p in folder.iterdir() if p.is_file())[:8])


def read_dicom(path: str | Path, *, series: str | None = None):
    """A DICOM series (a folder) or one multi-frame DICOM file: ``(data[x, y, z], Geometry)``.

    ``series`` picks one series of a folder that holds several, by its SeriesInstanceUID or its
    number in the list the refusal prints (1, 2, ...).
    """
    path = Path(path)
    if path.is_file():
        return _read_multiframe(path)
    found = _series_datasets(path)
    if not found:
        raise FormatError(path, "holds no DICOM image files")
    if series is None and len(found) > 1:
        raise FormatError(path, f"holds {len(found)} DICOM series; choose one with --series UID or its number:\n  "
                          + "\n  ".join(describe_series(found)))
    if series is None:
        headers = next(iter(found.values()))
    elif series in found:
        headers = found[series]
    elif series.isdigit() and 1 <= int(series) <= len(found):
        headers = list(found.values())[int(series) - 1]
    else:
        raise FormatError(path, f"has no series {series!r}; it has:\n  " + "\n  ".join(describe_series(found)))
    if len(headers) == 1 and _whole(*headers[0], "NumberOfFrames", 1) > 1:
        return _read_multiframe(headers[0][0])
    return _read_slices(path, headers)


def _orientation(path: Path, iop) -> tuple[np.ndarray, np.ndarray]:
    """The row and column direction cosines (unit vectors in LPS) of ImageOrientationPatient."""
    if iop is None or len(iop) != 6:
        raise FormatError(path, "lacks ImageOrientationPatient: its slices cannot be placed in space")
    row, col = np.asarray(iop[:3], np.float64), np.asarray(iop[3:], np.float64)
    if not (np.isfinite(row).all() and np.isfinite(col).all()) or abs(row @ col) > 1e-3 \
            or abs(np.linalg.norm(row) - 1) > 1e-3 or abs(np.linalg.norm(col) - 1) > 1e-3:
        raise FormatError(path, f"its ImageOrientationPatient {list(iop)} is not two orthogonal unit vectors")
    return row / np.linalg.norm(row), col / np.linalg.norm(col)


def _pixel_spacing(path: Path, ps) -> tuple[float, float]:
    """(x spacing, y spacing): PixelSpacing is (between rows, between columns); none given: 1."""
    ps = ps or [1.0, 1.0]
    if len(ps) != 2:
        raise FormatError(path, f"its PixelSpacing {list(ps)} is not two numbers")
    dy, dx = (float(v) for v in ps)
    if not (dx > 0 and dy > 0 and math.isfinite(dx) and math.isfinite(dy)):
        raise FormatError(path, f"its PixelSpacing {list(ps)} is not two positive numbers")
    return dx, dy


def rescale(slices: np.ndarray, slopes, intercepts) -> np.ndarray:
    """Apply a slope and intercept per slice (DICOM's RescaleSlope/RescaleIntercept, NIfTI's scl_*):
    integers stay integers where they fit (a CT in int16 Hounsfield units), else float32 (float64
    data stay float64)."""
    slopes, intercepts = np.asarray(slopes, np.float64), np.asarray(intercepts, np.float64)
    if np.all(slopes == 1) and np.all(intercepts == 0):
        return slices
    if np.all(slopes == 1) and np.all(intercepts == np.round(intercepts)) and slices.dtype.kind in "ui":
        lo = int(slices.min()) + int(intercepts.min()) if slices.size else 0
        hi = int(slices.max()) + int(intercepts.max()) if slices.size else 0
        for dtype in (np.int16, np.int32):
            if np.iinfo(dtype).min <= lo and hi <= np.iinfo(dtype).max:
                out = slices.astype(dtype, order="F")
                out += intercepts.astype(dtype)[None, None, :]
                return out
    dtype = np.result_type(slices.dtype, np.float32) if slices.dtype.kind == "f" else np.float32
    out = slices.astype(dtype, order="F")
    out *= slopes.astype(dtype)[None, None, :]
    out += intercepts.astype(dtype)[None, None, :]
    return out


def _uneven_step(steps: np.ndarray) -> int | None:
    """The index of the step that breaks an even stack of slices (a missing, duplicate or stray
    slice), or None when every step is the median within 1 % (0.01 mm at least)."""
    if not len(steps):
        return None
    if np.any(steps <= 1e-6):
        return int(np.argmin(steps))
    median = float(np.median(steps))
    if np.ptp(steps) > max(0.01, 0.01 * median):
        return int(np.argmax(np.abs(steps - median)))
    return None


_PLAIN_SYNTAXES = ("1.2.840.10008.1.2", "1.2.840.10008.1.2.1")  # implicit / explicit VR little endian


def _pixels(f: Path, ds) -> np.ndarray:
    """One frame's pixels ``[rows, columns]``. Uncompressed little-endian grey slices, what most series
    are, are viewed straight from their bytes (pydicom's general decoder spent half of a CT series'
    read deciding that); everything else goes through pydicom."""
    if "PixelData" not in ds:
        raise FormatError(f, "has no PixelData: a slice of the series without its image")
    syntax = str(getattr(getattr(ds, "file_meta", None), "TransferSyntaxUID", ""))
    alloc, stored = _whole(f, ds, "BitsAllocated", 0), _whole(f, ds, "BitsStored", 0)
    if syntax in _PLAIN_SYNTAXES and _whole(f, ds, "SamplesPerPixel", 1) == 1 and alloc in (8, 16, 32) \
            and 0 < stored <= alloc and _whole(f, ds, "NumberOfFrames", 1) == 1:
        rows, cols = _whole(f, ds, "Rows"), _whole(f, ds, "Columns")
        data = ds.PixelData
        need = rows * cols * alloc // 8
        if len(data) not in (need, need + 1):  # DICOM pads an odd length with one byte
            raise FormatError(f, f"its PixelData holds {len(data):,} bytes where {cols} x {rows} pixels of "
                                 f"BitsAllocated {alloc} need {need:,}: the header does not describe the pixels")
        if len(data) >= need:
            signed = _whole(f, ds, "PixelRepresentation", 0) == 1
            img = np.frombuffer(data, f"<{'i' if signed else 'u'}{alloc // 8}", count=rows * cols).reshape(rows, cols)
            if stored < alloc:  # the bits above BitsStored are not the pixel's: sign-extend or clear them
                shift = alloc - stored
                img = (img << shift) >> shift
            return img
    try:
        return ds.pixel_array
    except Exception as exc:  # missing decoder plugins, bad data: name the file and the syntax
        syntax = getattr(getattr(ds, "file_meta", None), "TransferSyntaxUID", None)
        name = getattr(syntax, "name", syntax)
        raise FormatError(f, f"its pixel data cannot be decoded ({name}): {exc}") from None


def _attr(f: Path, ds, attr: str, default=None):
    """A header value; one pydicom cannot convert (``NumberOfFrames`` "two") is refused naming the file and the
    attribute, where it raised a bare ValueError naming neither (#89)."""
    try:
        return ds.get(attr, default)
    except (TypeError, ValueError) as exc:
        raise FormatError(f, f"its {attr} cannot be read ({exc}): the header is damaged; fix the attribute or "
                             "leave this file out") from None


def _whole(f: Path, ds, attr: str, default: int | None = None) -> int:
    """A whole-number header value (absent or empty is ``default``), refused naming the file and the attribute."""
    raw = _attr(f, ds, attr, default)
    try:
        value = default if raw is None or raw == "" else int(raw)
        if value is None:
            raise ValueError
    except (TypeError, ValueError):
        raise FormatError(f, f"its {attr} is {raw!r}, not a whole number: the header is damaged; fix the "
                             "attribute or leave this file out") from None
    return value


def _position(f: Path, ds, attr: str = "ImagePositionPatient") -> np.ndarray:
    """Where a slice sits: three finite numbers, or refused naming the file (a NaN came out as "spacing must be
    three finite numbers" naming the folder)."""
    raw = _attr(f, ds, attr)
    if raw is None:
        raise FormatError(f, f"lacks {attr}: the slice cannot be placed in the series")
    try:
        at = np.asarray(raw, np.float64)
    except (TypeError, ValueError):
        at = np.full(1, np.nan)
    if at.shape != (3,) or not np.isfinite(at).all():
        raise FormatError(f, f"its {attr} is {list(raw) if at.ndim else raw!r}, not three finite numbers: the "
                             "slice cannot be placed in the series; fix the attribute or leave this file out")
    return at


def _finite(f: Path, ds, attr: str, default: float) -> float:
    """A rescale value of a slice: absent is ``default``; NaN, infinite or not a number is refused (a slope of
    NaN made an all-NaN volume)."""
    raw = ds.get(attr, None)
    try:
        value = default if raw is None or raw == "" else float(raw)
    except (TypeError, ValueError):
        raise FormatError(f, f"{attr} {raw!r} is not a number") from None
    if not np.isfinite(value) or abs(value) > 1e30:
        raise FormatError(f, f"{attr} {raw!r} is not a finite number")
    return value


def _read_slices(folder: Path, headers):
    f0, ds0 = headers[0]
    row, col = _orientation(f0, ds0.get("ImageOrientationPatient"))
    normal = np.cross(row, col)
    rows, cols = _whole(f0, ds0, "Rows"), _whole(f0, ds0, "Columns")
    places = []
    for f, ds in headers:
        if _whole(f, ds, "Rows") != rows or _whole(f, ds, "Columns") != cols:
            raise FormatError(f, f"is {ds.Columns}x{ds.Rows} pixels, the series' first slice {cols}x{rows}")
        ipp = _position(f, ds)
        r, c = _orientation(f, ds.get("ImageOrientationPatient"))
        if not (np.allclose(r, row, atol=1e-3) and np.allclose(c, col, atol=1e-3)):
            raise FormatError(f, "is oriented differently from the series' other slices")
        places.append(float(ipp @ normal))
    order = np.argsort(places, kind="stable")
    positions = np.asarray(places)[order]
    steps = np.diff(positions)
    where = _uneven_step(steps)
    if where is not None:
        a, b = headers[order[where]][0].name, headers[order[where + 1]][0].name
        raise FormatError(folder, f"its slices are not evenly spaced along the slice normal (step {steps[where]:.4g} "
                                  f"mm between {a} and {b}, median {np.median(steps):.4g} mm): a missing or "
                                  "duplicate slice?")
    dz = float(np.median(steps)) if len(steps) else float(ds0.get("SliceThickness", 1.0) or 1.0)
    bits = _whole(f0, ds0, "BitsAllocated", 16)
    checked_grid(folder, (cols, rows, len(headers)), max(bits // 8, 1) * _whole(f0, ds0, "SamplesPerPixel", 1),
                 what="the series' size")
    first = None
    slopes, intercepts = [], []
    for z, k in enumerate(order):
        f, ds = headers[k]
        img = _pixels(f, ds)  # its deferred pixels are read now
        if img.ndim != 2:
            raise FormatError(f, f"holds {img.shape} pixels; a series of grey slices was expected")
        if first is None:
            first = np.empty((cols, rows, len(headers)), img.dtype, order="F")
        first[:, :, z] = img.T
        slopes.append(_finite(f, ds, "RescaleSlope", 1.0))
        intercepts.append(_finite(f, ds, "RescaleIntercept", 0.0))
    dx, dy = _pixel_spacing(f0, ds0.get("PixelSpacing") or ds0.get("ImagerPixelSpacing"))
    origin = _position(*headers[order[0]])
    direction = np.column_stack([row, col, normal])
    return rescale(first, slopes, intercepts), Geometry((dx, dy, dz), tuple(origin),
                                                                 tuple(direction.reshape(-1)))


def _read_multiframe(path: Path):
    """One file of several frames: enhanced CT/MR (per-frame positions) or RT dose (GridFrameOffsetVector)."""
    import pydicom

    try:
        ds = pydicom.dcmread(str(path))
    except Exception as exc:
        raise FormatError(path, f"is not a DICOM file pydicom can read: {exc}") from None
    if "PixelData" not in ds:
        raise FormatError(path, "is a DICOM file without image data")
    frames = _whole(path, ds, "NumberOfFrames", 1)
    checked_grid(path, (_whole(path, ds, "Columns"), _whole(path, ds, "Rows"), frames),
                 max(_whole(path, ds, "BitsAllocated", 16) // 8, 1),
                 what="its frames")
    shared = ds.get("SharedFunctionalGroupsSequence", [None])[0]
    per_frame = ds.get("PerFrameFunctionalGroupsSequence")

    def item(group, seq, attr):
        if group is None or seq not in group or not len(group[seq].value):
            return None
        return group[seq][0].get(attr)

    iop = ds.get("ImageOrientationPatient") or item(shared, "PlaneOrientationSequence", "ImageOrientationPatient")
    if iop is None and per_frame:
        iop = item(per_frame[0], "PlaneOrientationSequence", "ImageOrientationPatient")
    ps = ds.get("PixelSpacing") or item(shared, "PixelMeasuresSequence", "PixelSpacing")
    if _whole(path, ds, "SamplesPerPixel", 1) != 1:
        raise FormatError(path, f"holds colour pixels ({ds.get('PhotometricInterpretation')}); volanim reads grey "
                                "DICOM images and series")
    alone = frames == 1 and iop is None and "ImagePositionPatient" not in ds
    if alone:  # one image placed nowhere (a secondary capture): ITK's default, the identity at 0
        iop, ds.ImagePositionPatient = [1, 0, 0, 0, 1, 0], [0, 0, 0]
    row, col = _orientation(path, iop)
    normal = np.cross(row, col)
    dx, dy = _pixel_spacing(path, ps)
    if per_frame and item(per_frame[0], "PlanePositionSequence", "ImagePositionPatient") is not None:
        positions = np.array([item(g, "PlanePositionSequence", "ImagePositionPatient") for g in per_frame], float)
    elif "GridFrameOffsetVector" in ds and "ImagePositionPatient" in ds:
        offsets = np.asarray(ds.GridFrameOffsetVector, np.float64)
        positions = np.asarray(ds.ImagePositionPatient, np.float64) + offsets[:, None] * normal
    elif frames == 1 and "ImagePositionPatient" in ds:
        positions = np.asarray(ds.ImagePositionPatient, np.float64)[None]
    else:
        raise FormatError(path, "its frames have no positions (no per-frame ImagePositionPatient or "
                                "GridFrameOffsetVector): they cannot be placed in space")
    if len(positions) != frames:
        raise FormatError(path, f"lists {len(positions)} frame positions for {frames} frames")
    if positions.shape[1:] != (3,) or not np.isfinite(positions).all():
        bad = int(np.flatnonzero(~np.isfinite(positions).all(axis=1))[0]) if positions.shape[1:] == (3,) else 0
        raise FormatError(path, f"frame {bad}'s position is {positions[bad].tolist()}, not three finite numbers: "
                                "the frames cannot be placed in space; fix the file's positions")
    pixels = _pixels(path, ds).reshape(frames, _whole(path, ds, "Rows"), _whole(path, ds, "Columns"))
    along = positions @ normal
    order = np.argsort(along, kind="stable")
    steps = np.diff(along[order])
    where = _uneven_step(steps)
    if where is not None:
        raise FormatError(path, f"its frames are not evenly spaced along the frame normal (step {steps[where]:.4g} "
                                f"mm after frame {int(order[where])}, median {np.median(steps):.4g} mm)")
    dz = float(np.median(steps)) if len(steps) else float(ds.get("SliceThickness", 1.0) or 1.0)
    vol = np.asfortranarray(pixels[order].transpose(2, 1, 0))
    # enhanced CT/MR keep the rescale in a functional group: a frame's own, else the shared one (pydicom-data's
    # eCT_Supplemental.dcm: intercept -1024 there and nowhere else), else the classic top-level attributes
    def frame_value(g, attr, default):
        v = item(g, "PixelValueTransformationSequence", attr)
        if v is None:
            v = item(shared, "PixelValueTransformationSequence", attr)
        if v is None:
            v = ds.get(attr)
        return float(v) if v not in (None, "") else default

    groups = list(per_frame) if per_frame and len(per_frame) == frames else [None] * frames
    scale = float(ds.get("DoseGridScaling", 1) or 1)
    slopes = [frame_value(groups[k], "RescaleSlope", 1.0) * scale for k in order]
    intercepts = [frame_value(groups[k], "RescaleIntercept", 0.0) for k in order]
    if not np.all(np.isfinite(slopes + intercepts)) or max(map(abs, slopes + intercepts)) > 1e30:
        raise FormatError(path, "its rescale slope, intercept or DoseGridScaling is not a finite number")
    vol = rescale(vol, slopes, intercepts)
    direction = np.column_stack([row, col, normal])
    return vol, Geometry((dx, dy, dz), tuple(positions[order[0]]), tuple(direction.reshape(-1)))


def write_dicom_series(folder: str | Path, volume: np.ndarray, geometry: Geometry, *, intercept: float = -1024.0,
                       modality: str = "CT", description: str = "volanim", series_uid: str | None = None,
                       names=None) -> list[Path]:
    """Write ``volume[x, y, z]`` (integers, e.g. Hounsfield units) as a DICOM series with pydicom, one
    file a slice, stored as ``value - intercept`` in unsigned 16 bits (``RescaleIntercept``), placed
    by ``geometry`` (ImagePositionPatient, ImageOrientationPatient, PixelSpacing). ``names``: the
    slices' file names (default ``IM0000.dcm``...), e.g. shuffled to show that order comes from the
    positions. Returns the files written."""
    from pydicom.dataset import FileDataset, FileMetaDataset
    from pydicom.uid import CTImageStorage, ExplicitVRLittleEndian, MRImageStorage, generate_uid

    from .atomic import atomic_open

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    stored = np.asarray(volume, np.float64) - intercept
    if stored.min() < 0 or stored.max() > 65535 or not np.all(stored == np.round(stored)):
        raise ValueError(f"values minus the intercept ({intercept:g}) must be whole numbers 0..65535")
    sop_class = CTImageStorage if modality == "CT" else MRImageStorage
    series_uid, study_uid, frame_uid = series_uid or generate_uid(), generate_uid(), generate_uid()
    m = geometry.matrix
    names = list(names) if names is not None else [f"IM{z:04d}.dcm" for z in range(volume.shape[2])]
    written = []
    for z in range(volume.shape[2]):
        meta = FileMetaDataset()
        meta.MediaStorageSOPClassUID, meta.MediaStorageSOPInstanceUID = sop_class, generate_uid()
        meta.TransferSyntaxUID = ExplicitVRLittleEndian
        ds = FileDataset(names[z], {}, file_meta=meta, preamble=b"\0" * 128)
        ds.SOPClassUID, ds.SOPInstanceUID = sop_class, meta.MediaStorageSOPInstanceUID
        ds.Modality, ds.SeriesDescription = modality, description
        ds.StudyInstanceUID, ds.SeriesInstanceUID, ds.FrameOfReferenceUID = study_uid, series_uid, frame_uid
        ds.InstanceNumber = z + 1
        ds.Rows, ds.Columns = volume.shape[1], volume.shape[0]
        ds.PixelSpacing = [f"{geometry.spacing[1]:.10g}", f"{geometry.spacing[0]:.10g}"]
        ds.SliceThickness = f"{geometry.spacing[2]:.10g}"
        ds.ImageOrientationPatient = [f"{v:.10g}" for v in (*m[:, 0], *m[:, 1])]
        ds.ImagePositionPatient = [f"{v:.10g}" for v in geometry.to_physical([[0, 0, z]])[0]]
        ds.RescaleIntercept, ds.RescaleSlope = f"{intercept:g}", "1"
        ds.SamplesPerPixel, ds.PhotometricInterpretation = 1, "MONOCHROME2"
        ds.BitsAllocated, ds.BitsStored, ds.HighBit, ds.PixelRepresentation = 16, 16, 15, 0
        ds.PixelData = np.ascontiguousarray(stored[:, :, z].T.astype("<u2")).tobytes()
        path = folder / names[z]
        with atomic_open(path, "wb") as fh:
            ds.save_as(fh, enforce_file_format=True)
        written.append(path)
    return written
