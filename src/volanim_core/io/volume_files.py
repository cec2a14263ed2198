"""Every volume format behind two calls: :func:`read_volume` and :func:`write_volume`.

    .vol/.VOL           raw_volumes (ours)
    .vti .mha .mhd .nii .nii.gz               VTK readers through pyvista (lazy import)
    .nrrd                                     nrrd_files (ours: VTK's reader mangles 3-D scalars)
    folder of 2-D images                      scikit-image, stacked along z

Colour (RGB) volumes are ``vol[x, y, z, channel]`` uint8 arrays: RGB slice images,
3- or 4-component ``.vti``, an RGB NRRD and a raw ``.vol``/``.VOL`` of 3 bytes a voxel.
Readers return them only when asked (``colour=True``); otherwise colour becomes
grey (Rec. 709 luminance), so every grey tool works on a colour volume unchanged.

VTK stores x fastest, exactly like ``.vol``, so its flat scalars reshape with
``order="F"`` to ``vol[x, y, z]``.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from volanim_core.errors import FormatError

from . import raw_volumes
from ._atomic import atomic_vtk_save
from .nrrd_files import read_nrrd, write_nrrd
from .vtk_headers import check_claims

VTK_SUFFIXES = (".vti", ".mha", ".mhd", ".nii", ".nii.gz", ".vtk")
NRRD_SUFFIXES = (".nrrd",)
IMAGE_SUFFIXES = (".png", ".tif", ".tiff", ".jpg", ".jpeg", ".bmp", ".pgm", ".ppm")
WRITE_SUFFIXES = (".vol", ".VOL", ".vti", ".nrrd")


def _suffix(path: Path) -> str:
    name = path.name.lower()
    return ".nii.gz" if name.endswith(".nii.gz") else path.suffix.lower()


def float_to_uint8(vol: np.ndarray, lo: float | None = None, hi: float | None = None) -> np.ndarray:
    """Map ``[lo, hi]`` linearly onto 0..255 and clip (float2uchar).

    ``lo``/``hi`` default to the data's minimum and maximum.
    """
    vol = np.asarray(vol)
    lo = float(np.min(vol)) if lo is None else float(lo)
    hi = float(np.max(vol)) if hi is None else float(hi)
    if hi <= lo:
        return np.zeros(vol.shape, np.uint8) if vol.size == 0 or hi < lo else (vol > lo).astype(np.uint8) * 255
    out = (np.asarray(vol, np.float64) - lo) * (255.0 / (hi - lo))
    return np.clip(np.rint(out), 0, 255).astype(np.uint8)


LUMA = np.array([0.2125, 0.7154, 0.0721])  # Rec. 709, as skimage.color.rgb2gray


def to_grey(rgb: np.ndarray) -> np.ndarray:
    """Luminance of ``[..., 3]`` colour data, rounded, in the input's dtype."""
    rgb = np.asarray(rgb)
    if rgb.ndim < 4:
        return np.rint(rgb[..., :3] @ LUMA).astype(rgb.dtype)
    out = np.empty(rgb.shape[:-1], rgb.dtype, order="F")
    for z in range(rgb.shape[2]):  # a slice at a time: float64 of a whole volume is 24 bytes a voxel
        out[:, :, z] = np.rint(rgb[:, :, z, :3] @ LUMA)
    return out


def is_colour(vol) -> bool:
    """Whether ``vol`` is a colour volume ``[x, y, z, 3]``."""
    return np.ndim(vol) == 4 and np.shape(vol)[3] == 3


def _read_vtk(path: Path):
    import pyvista as pv  # lazy: VTK only when a VTK format is used

    claimed = check_claims(path, _suffix(path))  # before VTK allocates what the header says
    try:
        with pv.VtkErrorCatcher(raise_errors=True, send_to_logging=False):
            img = pv.read(str(path))
    except Exception as exc:  # VTK raises many types; report them as one
        raise FormatError(path, f"VTK could not read it as {_suffix(path)}: {exc}") from exc
    if not isinstance(img, pv.ImageData) or img.n_points == 0 or img.point_data.active_scalars is None:
        raise FormatError(path, "expected a 3-D image with point scalars")
    if tuple(img.dimensions) != tuple(claimed):
        raise FormatError(path, f"VTK read a {img.dimensions} grid, the header says {claimed}")
    scalars = np.asarray(img.point_data.active_scalars)
    if scalars.ndim > 1 and scalars.shape[1] in (3, 4) and scalars.dtype == np.uint8:  # RGB(A): drop alpha
        nx, ny, nz = img.dimensions
        data = scalars[:, :3].reshape(nz, ny, nx, 3).transpose(2, 1, 0, 3)
        return data, tuple(img.origin), tuple(img.spacing)
    if scalars.ndim > 1:  # other vector data: take the first component
        scalars = scalars[:, 0]
    data = scalars.reshape(img.dimensions, order="F")
    return data, tuple(img.origin), tuple(img.spacing)


def _natural_key(name: str):
    return [int(t) if t.isdigit() else t for t in re.split(r"(\d+)", name)]


def slice_files(folder: str | Path) -> list[Path]:
    """The slice images of a folder in natural order (``s2`` before ``s10``)."""
    folder = Path(folder)
    files = sorted((f for f in folder.iterdir() if f.suffix.lower() in IMAGE_SUFFIXES),
                   key=lambda f: _natural_key(f.name))
    if not files:
        raise FormatError(folder, f"no slice images ({', '.join(IMAGE_SUFFIXES)}) in this folder")
    return files


def read_slice(path: Path, *, colour: bool | None = False, expect=None) -> np.ndarray:
    """One slice image as ``[x, y]``, or ``[x, y, 3]`` with ``colour`` (grey images then repeat in
    R, G, B). ``colour=None`` keeps the image as it is: ``[x, y, 3]`` for a colour image, else ``[x, y]``.

    ``expect`` is the first slice's ``(X, Y)``: every slice must have it.
    """
    from skimage import io as skio

    try:
        img = np.asarray(skio.imread(path))
    except Exception as exc:  # imageio/PIL raise many types
        raise FormatError(path, f"cannot read image: {exc}") from exc
    is_rgb = img.ndim == 3 and img.shape[2] in (3, 4)
    if colour is None:
        colour = is_rgb
    if is_rgb:
        img = img[..., :3] if colour else to_grey(img)
    elif img.ndim == 2 and colour:
        img = np.repeat(img[..., None], 3, axis=2)
    if img.ndim != (3 if colour else 2):
        raise FormatError(path, f"expected a 2-D image, got shape {img.shape}")
    img = img.swapaxes(0, 1)  # image rows are y, columns x
    if expect is not None and img.shape[:2] != tuple(expect):
        raise FormatError(path, f"slice is {img.shape[1]}x{img.shape[0]} (rows x columns), expected "
                                f"{expect[1]}x{expect[0]} like the first slice")
    return img


def read_image_folder(folder: str | Path, *, colour: bool = False) -> np.ndarray:
    """Stack a folder of 2-D slice images along z (combineToGrayVolume).

    Files are taken in natural order (``s2`` before ``s10``). Image rows are y,
    columns x. Colour images become grey (luminance) unless ``colour``, which keeps
    them as ``[x, y, z, 3]`` (a folder whose first slice is grey stays ``[x, y, z]``).
    """
    files = slice_files(folder)
    first = read_slice(files[0], colour=None if colour else False)  # the first slice says what the scan is
    colour = first.ndim == 3
    slices = [first] + [read_slice(f, colour=colour, expect=first.shape[:2]) for f in files[1:]]
    return np.stack(slices, axis=2)


def read_volume_grid(path: str | Path, *, dims=None, rescale: bool = False, colour: bool = False):
    """Read any supported volume: ``(data[x, y, z], origin, spacing)``.

    Parameters
    ----------
    path : str or Path
        A file, or a folder of slice images.
    dims : (3,) ints, optional
        Dimensions of a headerless ``.vol``.
    rescale : bool
        Map non-uint8 data onto 0..255 (min..max). Off by default: data keep
        their type unless the user asks.
    colour : bool
        Return a colour volume as ``data[x, y, z, channel]`` (uint8 RGB); without it
        colour is read as grey (luminance).
    """
    path = Path(path)
    try:
        data, origin, spacing = _read_any(path, dims, colour)
    except OSError as exc:  # permissions, a file that vanished, disk errors: one error type, the file named
        raise FormatError(getattr(exc, "filename", None) or path, f"cannot read: {exc.strerror or exc}") from exc
    if is_colour(data) and not colour:
        data = np.asfortranarray(to_grey(data))
    if rescale and data.dtype != np.uint8:
        data = float_to_uint8(data)
    return data, origin, spacing


def _read_any(path: Path, dims, colour: bool):
    if path.is_dir():
        data, origin, spacing = read_image_folder(path, colour=colour), (0.0, 0.0, 0.0), (1.0, 1.0, 1.0)
    elif not path.exists():
        raise FormatError(path, "no such file or folder")
    elif path.suffix.lower() == ".vol":
        data, origin, spacing = raw_volumes.read_raw(path, dims), (0.0, 0.0, 0.0), (1.0, 1.0, 1.0)
    elif _suffix(path) in NRRD_SUFFIXES:
        data, origin, spacing = read_nrrd(path)
    elif _suffix(path) in VTK_SUFFIXES:
        data, origin, spacing = _read_vtk(path)
    else:
        raise FormatError(path, f"unknown volume format {path.suffix!r}; expected .vol, .VOL, "
                          + ", ".join(VTK_SUFFIXES + NRRD_SUFFIXES) + " or a folder of slice images")
    return data, origin, spacing


def read_volume(path: str | Path, *, dims=None, rescale: bool = False, colour: bool = False) -> np.ndarray:
    """Read any supported volume as an array indexed ``[x, y, z]`` (``[x, y, z, 3]`` for colour with ``colour``)."""
    return read_volume_grid(path, dims=dims, rescale=rescale, colour=colour)[0]


def _write_vti(path: Path, vol: np.ndarray, origin, spacing) -> None:
    import pyvista as pv

    img = pv.ImageData(dimensions=vol.shape[:3], origin=origin, spacing=spacing)
    if is_colour(vol):  # one RGB tuple per point, x fastest
        img.point_data["rgb"] = np.ascontiguousarray(vol.transpose(2, 1, 0, 3)).reshape(-1, 3)
    else:
        img.point_data["values"] = vol.ravel(order="F")
    atomic_vtk_save(path, img)


def saturate_for_raw(path: str | Path, vol: np.ndarray) -> tuple[np.ndarray, str | None]:
    """``.vol``/``.VOL`` hold bytes: integer counts above 255 (hotspot, >255 bones) saturate at 255.

    Returns the volume to write and, when values were clipped, a note for the user.
    Other formats keep their type and get the volume unchanged.
    """
    if Path(path).suffix.lower() != ".vol" or vol.dtype == np.uint8 or vol.dtype.kind not in "ui":
        return vol, None
    top = int(vol.max()) if vol.size else 0
    note = None if top <= 255 else (f"values above 255 (max {top}) are clipped to 255 in {Path(path).name}; "
                                    "write .vti or .nrrd to keep them")
    return np.minimum(vol, 255).astype(np.uint8), note


def write_output(path: str | Path, vol: np.ndarray, *, origin=(0.0, 0.0, 0.0),
                 spacing=(1.0, 1.0, 1.0)) -> tuple[Path, str | None]:
    """Write a result where the user asked, with what raw formats need: counts above 255 saturate
    (:func:`saturate_for_raw`) and a headerless ``.vol`` is named ``NAME.XxYxZ.vol``
    (:func:`raw_volumes.raw_name_for`). Returns the path written and a note for the user, or None.

    Every command and the studio write their results through this, so none forgets either rule.
    """
    vol, note = saturate_for_raw(path, np.asarray(vol))
    path = raw_volumes.raw_name_for(path, vol.shape[:3])
    write_volume(path, vol, origin=origin, spacing=spacing)
    return path, note


def write_volume(path: str | Path, vol: np.ndarray, *, origin=(0.0, 0.0, 0.0), spacing=(1.0, 1.0, 1.0)) -> None:
    """Write a volume as ``.vol``, ``.VOL``, ``.vti`` or ``.nrrd``, atomically.

    ``.vol``/``.VOL`` hold uint8 only and no origin: callers print the origin.
    """
    path = Path(path)
    vol = np.asarray(vol)
    if vol.ndim != 3 and not is_colour(vol):
        raise ValueError(f"a volume must be 3-D (or 3-D with 3 colour channels), got shape {vol.shape}")
    suffix = _suffix(path)
    if suffix == ".vol":
        raw_volumes.write_raw(path, vol)
    elif suffix == ".vti":
        _write_vti(path, vol, origin, spacing)
    elif suffix == ".nrrd":
        write_nrrd(path, vol, origin, spacing)
    else:
        raise ValueError(f"cannot write {path.name}: choose one of {', '.join(WRITE_SUFFIXES)}")
