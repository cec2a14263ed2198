"""The formats scans arrive in, through the libraries the field trusts (imported lazily).

    .nii .nii.gz .mgh .mgz   nibabel: qform/sform, scl_slope/scl_inter; RAS -> LPS
    DICOM                    pydicom: in dicom_files
    .tif .tiff (one file, many pages)
                             tifffile: pages are z; ImageJ's spacing when it is there

Each returns ``(data[x, y, z], Geometry)`` in LPS millimetres. Sizes are checked against the
memory limit before voxels are read. Why these and not SimpleITK (which the tests use as the
oracle, beside nibabel's and pydicom's own readers): the three are pure Python, 30 MB together,
where SimpleITK's wheel installs 260 MB, and on their own test files they agree with it voxel for
voxel and millimetre for millimetre (tests/core/io/test_real_scans.py).
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from volanim_core.errors import FormatError
from volanim_core.geometry import Geometry
from volanim_core.limits import checked_grid

from .dicom_files import rescale
from .vtk_headers import check_claims

_RAS_TO_LPS = np.diag([-1.0, -1.0, 1.0, 1.0])


def _squeeze3(path: Path, shape) -> tuple[int, int, int]:
    """A shape with trailing 1s dropped must be 3-D (or less): else a clear refusal."""
    shape = tuple(int(n) for n in shape)
    while len(shape) > 3 and shape[-1] == 1:
        shape = shape[:-1]
    if len(shape) > 3:
        raise FormatError(path, f"is {len(shape)}-D ({' x '.join(map(str, shape))}); volanim reads 3-D volumes: "
                                "take one volume out first (e.g. nibabel's or FSL's fslroi)")
    return (*shape, *(1,) * (3 - len(shape)))


def _geometry_from_ras(path: Path, affine) -> Geometry:
    try:
        return Geometry.from_affine(_RAS_TO_LPS @ np.asarray(affine, np.float64))
    except ValueError as exc:
        raise FormatError(path, f"its orientation cannot be used: {exc} (a sheared affine?)") from None


def read_nibabel(path: str | Path):
    """NIfTI-1/2 or MGH/MGZ through nibabel: ``(data[x, y, z], Geometry)``.

    The orientation is nibabel's ``affine`` (the sform when its code is set, else the qform);
    ``scl_slope``/``scl_inter`` are applied as DICOM's rescale is (:func:`_rescale`): a CT stored
    with intercept -1024 comes back as int16 Hounsfield units, whichever format it came in.
    """
    import nibabel as nib

    path = Path(path)
    name = path.name.lower()
    if name.endswith((".nii", ".nii.gz")):
        check_claims(path, ".nii.gz" if name.endswith(".gz") else ".nii")  # before nibabel reads a voxel
    try:
        if name.endswith((".mgh", ".mgz")):  # nibabel's MGH loader leaves its file open: hand it the bytes
            img = nib.MGHImage.from_bytes(_mgh_bytes(path))
        else:
            img = nib.load(str(path), mmap=False)  # read into memory: a memory map keeps the file open
    except FormatError:
        raise
    except Exception as exc:  # nibabel raises many types for a bad header
        raise FormatError(path, f"nibabel could not read it: {exc}") from None
    shape = _squeeze3(path, img.shape)
    checked_grid(path, shape, np.dtype(img.get_data_dtype()).itemsize, what="its dimensions")
    proxy = img.dataobj
    try:
        raw = np.asarray(proxy.get_unscaled())
    except Exception as exc:
        raise FormatError(path, f"its voxels cannot be read: {exc}") from None
    raw = np.asfortranarray(raw.reshape(shape, order="F"))
    slope, inter = float(proxy.slope), float(proxy.inter)  # nibabel gives 1 and 0 where the file sets none
    return rescale(raw, [slope] * shape[2], [inter] * shape[2]), _geometry_from_ras(path, img.affine)


_MGH_ITEMSIZE = {0: 1, 1: 4, 3: 4, 4: 2}  # MRI_UCHAR, MRI_INT, MRI_FLOAT, MRI_SHORT
_MGH_HEADER, _MGH_TAGS = 284, 1 << 16  # the fixed header; what may follow the data (TR, flip angle, tags)


def _mgh_bytes(path: Path) -> bytes:
    """An MGH file's bytes. A ``.mgz`` is inflated only as far as its header's sizes say (plus room for
    the optional tags after the data): a small bomb is refused instead of filling the memory."""
    import struct

    from ._inflate import inflate_capped

    with path.open("rb") as fh:
        if path.suffix.lower() != ".mgz":
            return fh.read()
        chunks = inflate_capped(path, fh, 1 << 62)
        body = bytearray()  # grown in place: bytes += would copy the whole body for each chunk
        for chunk in chunks:
            body += chunk
            if len(body) >= _MGH_HEADER:
                break
        if len(body) < _MGH_HEADER:
            raise FormatError(path, f"its inflated data hold {len(body)} bytes, less than an MGH header (284)")
        _, x, y, z, frames, kind = struct.unpack(">6i", body[:24])
        if kind not in _MGH_ITEMSIZE:
            raise FormatError(path, f"MGH data type {kind} is not one of uchar, short, int, float")
        checked_grid(path, (x, y, z), _MGH_ITEMSIZE[kind] * max(frames, 1), what="its MGH dimensions")
        most = _MGH_HEADER + x * y * z * max(frames, 1) * _MGH_ITEMSIZE[kind] + _MGH_TAGS
        for chunk in chunks:
            body += chunk
            if len(body) > most:
                raise FormatError(path, f"its compressed data inflate to more than the {most:,} bytes its header "
                                        "accounts for")
    return bytes(body)


# --- TIFF -------------------------------------------------------------------------------------

def read_tiff_stack(path: str | Path):
    """A multi-page (3-D) TIFF: pages are z, rows y, columns x; ``(data[x, y, z], Geometry)``.

    Spacing comes from ImageJ's metadata (``spacing`` for z, the resolution tags for x and y)
    when the file has it; otherwise it is 1.
    """
    import tifffile

    path = Path(path)
    try:
        with tifffile.TiffFile(str(path)) as tif:
            series = tif.series[0]
            shape = tuple(series.shape)
            axes = series.axes
            rgb = axes.endswith("S") and shape[-1] in (3, 4)
            spatial = shape[:-1] if rgb else shape
            if len(spatial) == 2:
                spatial = (1, *spatial)
            if len(spatial) != 3:
                raise FormatError(path, f"is a {len(spatial)}-D TIFF ({axes}); a 3-D stack (pages of 2-D images) "
                                        "was expected")
            checked_grid(path, spatial[::-1], series.dtype.itemsize * (shape[-1] if rgb else 1),
                         what="its pages")
            data = series.asarray()
            spacing = [1.0, 1.0, 1.0]
            ij = tif.imagej_metadata or {}
            page = tif.pages[0]
            for k, tag in ((0, "XResolution"), (1, "YResolution")):
                if ij and tag in page.tags:
                    num, den = page.tags[tag].value
                    if num > 0 and den > 0:
                        spacing[k] = den / num
            if ij.get("spacing"):
                spacing[2] = float(ij["spacing"])
    except FormatError:
        raise
    except Exception as exc:  # tifffile raises many types
        raise FormatError(path, f"cannot read it as a TIFF stack: {exc}") from None
    data = data.reshape(*spatial, *(shape[-1:] if rgb else ()))
    vol = data.transpose(2, 1, 0, 3) if rgb else data.T
    if rgb:
        vol = vol[..., :3]
    return np.asfortranarray(vol), Geometry(tuple(spacing))


def write_tiff_stack(path: str | Path, vol: np.ndarray, geometry) -> None:
    """One 3-D TIFF (pages z, rows y, columns x) with ImageJ's spacing metadata, atomically; what
    :func:`read_tiff_stack` and Fiji read back (the thesis's Toolbar wrote slice stacks)."""
    import tifffile

    from .atomic import atomic_open

    vol = _imagej_voxels(path, vol)
    zyx = np.ascontiguousarray(np.moveaxis(vol, (0, 1, 2), (2, 1, 0)))  # colour keeps its channels last
    sx, sy, sz = (float(v) for v in geometry.spacing)
    buffer = io.BytesIO()  # tifffile wants a named file; the atomic temporary has none
    tifffile.imwrite(buffer, zyx, imagej=True, resolution=(1 / sx, 1 / sy),
                     metadata={"spacing": sz, "unit": "mm", "axes": "ZYXS" if zyx.ndim == 4 else "ZYX"})
    with atomic_open(path, "wb", size=buffer.getbuffer().nbytes) as fh:
        fh.write(buffer.getvalue())


IMAGEJ_TYPES = (np.uint8, np.uint16, np.int16, np.float32)  # what an ImageJ TIFF stack holds


def _imagej_voxels(path, vol: np.ndarray) -> np.ndarray:
    """``vol`` in a type an ImageJ TIFF holds, exactly: itself, or the first of uint8, uint16, int16 that
    holds every value (a CT read as int32), or float32 when every value is one. Otherwise ValueError
    saying which types TIFF takes here and what to write instead (tifffile said only "the ImageJ format
    does not support data type 'i'")."""
    if vol.dtype.type in IMAGEJ_TYPES:
        return vol
    if vol.dtype.kind in "biu":
        lo, hi = (int(vol.min()), int(vol.max())) if vol.size else (0, 0)
        for t in IMAGEJ_TYPES[:3]:
            if np.iinfo(t).min <= lo and hi <= np.iinfo(t).max:
                return vol.astype(t)
        span = f"span {lo} .. {hi}"
    elif vol.dtype.kind == "f":
        as32 = vol.astype(np.float32)
        if np.array_equal(as32, vol, equal_nan=True):
            return as32
        span = "are not all float32 numbers"
    else:
        span = "are not numbers"
    raise ValueError(f"cannot write {path}: a TIFF stack (ImageJ, which Fiji reads with its spacing) holds uint8, "
                     f"uint16, int16 or float32 voxels, and these {vol.dtype} voxels {span}; write .nrrd, .nii.gz "
                     "or .mha instead, which keep them as they are")


def write_slices(pattern: str, vol: np.ndarray) -> list[Path]:
    """One 2-D image a z slice (rows y, columns x), named by ``pattern % z`` (``slices/frog%04d.png``); the
    folder reads back as a volume. Returns the paths.

    Whole or not at all (#64): the slices are made in a hidden folder beside them, then moved into place,
    and slices of an older, longer stack of the same name are removed, so the folder is never half one
    stack and half another (a full disk stops the making; the old stack stays as it was)."""
    import os
    import shutil

    import imageio.v3 as iio

    from .atomic import clean_stale, fsync_folder, naming_the_output, pending_name

    out = [Path(pattern % z) for z in range(vol.shape[2])]
    folder = out[0].parent
    folder.mkdir(parents=True, exist_ok=True)
    clean_stale(folder, "stack")
    stage = folder / pending_name("stack")
    stage.mkdir()
    try:
        with naming_the_output(pattern, "the slices (the folder's old slices are as they were)",
                               f"up to {vol.nbytes:,} bytes (the slices uncompressed)"):
            for z, path in enumerate(out):
                picture = np.ascontiguousarray(np.swapaxes(vol[:, :, z], 0, 1))
                data = iio.imwrite("<bytes>", picture, extension=path.suffix)
                with open(stage / path.name, "wb") as fh:
                    fh.write(data)
                    fh.flush()
                    os.fsync(fh.fileno())
            for path in out:
                os.replace(stage / path.name, path)
            k = len(out)
            while Path(pattern % k).is_file():  # an older stack's slices past the new one's end
                Path(pattern % k).unlink()
                k += 1
            fsync_folder(folder)
    finally:
        shutil.rmtree(stage, ignore_errors=True)
    return out
