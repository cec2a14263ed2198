"""Every volume format behind two calls: :func:`read_scan` (voxels and :class:`Geometry`) and
:func:`write_volume`; :func:`read_volume` when only the voxels matter.

    .vol/.VOL                      raw_volumes (ours; no geometry: the identity)
    .vti .vtk                      VTK readers through pyvista (lazy import)
    .nrrd .nhdr .seg.nrrd          nrrd_files (ours: guarded, every encoding, segment names)
    .mha .mhd                      metaimage_files (ours: VTK drops the direction)
    .nii .nii.gz .mgh .mgz         nibabel          } medical_files
    .tif/.tiff (one 3-D file)      tifffile         }
    DICOM folder or file           pydicom            dicom_files
    folder of 2-D images           scikit-image, stacked along z

Geometry is LPS millimetres (:mod:`volanim_core.geometry`); every writer but ``.vol``/``.VOL``
keeps it. Float data keep NaN and infinity as they are; :func:`float_to_uint8` (rescaling) and
every tool treat them as background.

Colour (RGB) volumes are ``vol[x, y, z, channel]`` uint8 arrays: RGB slice images,
3- or 4-component ``.vti``, an RGB NRRD and a raw ``.vol``/``.VOL`` of 3 bytes a voxel.
Readers return them only when asked (``colour=True``); otherwise colour becomes
grey (Rec. 709 luminance), so every grey tool works on a colour volume unchanged.

VTK stores x fastest, exactly like ``.vol``, so its flat scalars reshape with
``order="F"`` to ``vol[x, y, z]``.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from volanim_core.errors import FormatError
from volanim_core.geometry import IDENTITY, Geometry
from volanim_core.volume import float_to_uint8, is_colour, to_grey

from . import raw_volumes
from .atomic import atomic_vtk_save
from .metaimage_files import read_metaimage, write_metaimage
from .nrrd_files import read_nrrd, write_nrrd
from .vtk_headers import check_claims

VTK_SUFFIXES = (".vti", ".vtk")
NRRD_SUFFIXES = (".nrrd", ".nhdr")
META_SUFFIXES = (".mha", ".mhd")
NIBABEL_SUFFIXES = (".nii", ".nii.gz", ".mgh", ".mgz")
DICOM_SUFFIXES = (".dcm", ".dicom", ".ima")
TIFF_SUFFIXES = (".tif", ".tiff")
IMAGE_SUFFIXES = (".png", ".tif", ".tiff", ".jpg", ".jpeg", ".bmp", ".pgm", ".ppm")
READ_SUFFIXES = (".vol", ".VOL", *VTK_SUFFIXES, *NRRD_SUFFIXES, *META_SUFFIXES, *NIBABEL_SUFFIXES,
                 *DICOM_SUFFIXES, *TIFF_SUFFIXES)
WRITE_SUFFIXES = (".vol", ".VOL", ".vti", ".nrrd", ".nii", ".nii.gz", ".mha", ".tif", ".tiff")
SLICE_SUFFIXES = (".png", ".tif", ".tiff")  # NAME%04d.png: one image a slice


@dataclass(frozen=True)
class Scan:
    """A volume as read: its voxels ``data[x, y, z]`` (``[x, y, z, 3]`` colour), where they are
    (``geometry``) and, for a segmentation, the names of its labels (``segments``: value -> name).
    It unpacks as ``data, geometry, segments``; ``mode`` is the reconstruction mode a volanim result
    was made in (its colours), when the file records it."""

    data: np.ndarray
    geometry: Geometry
    segments: dict
    mode: str | None = None

    def __iter__(self):
        return iter((self.data, self.geometry, self.segments))


def _suffix(path: Path) -> str:
    name = path.name.lower()
    return ".nii.gz" if name.endswith(".nii.gz") else path.suffix.lower()


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
    try:
        geometry = Geometry(tuple(img.spacing), tuple(img.origin), tuple(np.asarray(img.direction_matrix).ravel()))
    except ValueError as exc:
        raise FormatError(path, f"bad geometry: {exc}") from None
    mode = _recorded_mode(img.field_data[MODE_KEY][0] if MODE_KEY in img.field_data else None)
    scalars = np.asarray(img.point_data.active_scalars)
    if scalars.ndim > 1 and scalars.shape[1] in (3, 4) and scalars.dtype == np.uint8:  # RGB(A)
        nx, ny, nz = img.dimensions
        rgb = _without_alpha(scalars, path) if scalars.shape[1] == 4 else scalars
        data = rgb.reshape(nz, ny, nx, 3).transpose(2, 1, 0, 3)
        return data, geometry, mode
    if scalars.ndim > 1:  # other vector data: take the first component
        scalars = scalars[:, 0]
    data = scalars.reshape(img.dimensions, order="F")
    return data, geometry, mode


MODE_KEY = "volanim_mode"  # .vti field data and a .nrrd key: the reconstruction mode of a result


def _recorded_mode(text) -> str | None:
    """A recorded mode when it is one we know (anything else is ignored: a hint, never an error)."""
    from volanim_core.modes import MODES

    text = str(text).strip() if text is not None else None
    return text if text in MODES else None


def _natural_key(name: str):
    return [int(t) if t.isdigit() else t for t in re.split(r"(\d+)", name)]


def natural_order(paths) -> list:
    """``paths`` in natural order (``frame.2`` before ``frame.10``): how a numbered series is taken."""
    return sorted(paths, key=lambda p: _natural_key(str(p)))


def slice_files(folder: str | Path) -> list[Path]:
    """The slice images of a folder in natural order (``s2`` before ``s10``)."""
    folder = Path(folder)
    files = sorted((f for f in folder.iterdir() if f.suffix.lower() in IMAGE_SUFFIXES),
                   key=lambda f: _natural_key(f.name))
    if not files:
        raise FormatError(folder, f"no slice images ({', '.join(IMAGE_SUFFIXES)}) in this folder")
    return files


def _without_alpha(img: np.ndarray, path: Path) -> np.ndarray:
    """Drop the alpha channel (the last of 2 or 4 on the last axis) when it is
    opaque everywhere; refuse it when it is not.

    Why refuse: a transparent pixel's RGB is whatever the painter left there
    (often white or the tissue colour), and whether it means "background" or
    "ignore the mask" is the user's to say. Reading the RGB as if opaque
    silently put masked-out pixels in the volume (docs/formats.md, slices).
    """
    alpha = img[..., -1]
    opaque = np.iinfo(img.dtype).max if np.issubdtype(img.dtype, np.integer) else 1.0
    seethrough = int(np.count_nonzero(alpha != opaque))
    if seethrough:
        raise FormatError(path, f"{seethrough} of {alpha.size} pixels are transparent (alpha below {opaque}); "
                                "volanim reads slices as opaque and will not guess what a transparent pixel "
                                "holds: flatten the images onto a background, or save them without alpha")
    return img[..., 0] if img.shape[-1] == 2 else img[..., :3]


_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
_PNG_COLOUR_TYPES = {0: "grey", 2: "RGB", 3: "palette", 4: "grey+alpha", 6: "RGBA"}


def _png_depth(path: Path) -> tuple[int, int] | None:
    """A PNG's ``(bit depth, colour type)`` from its header, or None for another kind of file."""
    try:
        with open(path, "rb") as f:
            head = f.read(26)
    except OSError:
        return None  # the reader below names the file and why
    if len(head) < 26 or not head.startswith(_PNG_SIGNATURE) or head[12:16] != b"IHDR":
        return None
    return head[24], head[25]


def _refuse_16_bit_colour_png(path: Path, depth: tuple[int, int] | None) -> None:
    """Refuse a 16-bit PNG with colour or alpha (``depth``: :func:`_png_depth`'s): Pillow, which reads the slices,
    keeps only the high byte of each of its channels (a CT of values 0..6000 came in as 0..23, silently). Grey
    16-bit PNGs and 16-bit TIFFs of any kind are read in full."""
    if depth is not None and depth[0] == 16 and depth[1] != 0:
        kind = _PNG_COLOUR_TYPES.get(depth[1], f"colour type {depth[1]}")
        raise FormatError(path, f"a 16-bit {kind} PNG: the image library volanim reads slices with (Pillow) keeps "
                                "only the high 8 bits of each channel, which would give wrong values; save the "
                                "slices as 16-bit grey PNG, or as TIFF (read in full at 16 bits)")


def _keyed_transparency(path: Path) -> bool:
    """Whether the image keys transparency in its palette or by a colour (PNG's tRNS, GIF's), not in an alpha
    channel of its own."""
    try:
        from PIL import Image

        with Image.open(path) as im:
            # not 16-bit grey ("I;16"): its conversion to RGBA clips the values to 255; _keyed_grey16 checks it
            return "transparency" in im.info and im.mode in ("P", "L", "RGB")
    except Exception:  # noqa: BLE001 - not an image PIL opens: the reader below says why
        return False


def _refuse_keyed_grey16(path: Path, depth: tuple[int, int] | None, img: np.ndarray) -> None:
    """A 16-bit grey PNG whose tRNS chunk keys one value as transparent: refused where a pixel has it (as an
    alpha channel with a transparent pixel is), read as it is where none has."""
    if depth != (16, 0):
        return
    from PIL import Image

    with Image.open(path) as im:
        key = im.info.get("transparency")
    seethrough = 0 if key is None else int(np.count_nonzero(img == key))
    if seethrough:
        raise FormatError(path, f"{seethrough} of {img.size} pixels are transparent (the PNG keys value {key} as "
                                "transparent); volanim reads slices as opaque and will not guess what a "
                                "transparent pixel holds: save the images without the transparency key")


def read_slice(path: Path, *, colour: bool | None = False, expect=None) -> np.ndarray:
    """One slice image as ``[x, y]``, or ``[x, y, 3]`` with ``colour`` (grey images then repeat in
    R, G, B). ``colour=None`` keeps the image as it is: ``[x, y, 3]`` for a colour image, else ``[x, y]``.

    ``expect`` is the first slice's ``(X, Y)``: every slice must have it.
    """
    import imageio.v3 as iio  # not skimage.io.imread: it moves the axes of a grey+alpha image 3 or 4 rows high

    depth = _png_depth(path)  # the PNG's header, read once for both checks
    _refuse_16_bit_colour_png(path, depth)
    try:
        # a palette (or grey, RGB) image with a tRNS chunk: its transparency is read as alpha, which PIL's
        # plain conversion drops (a mask's transparent background came in as opaque colour)
        img = np.asarray(iio.imread(path, mode="RGBA") if _keyed_transparency(path) else iio.imread(path))
    except Exception as exc:  # imageio/PIL raise many types
        raise FormatError(path, f"cannot read image: {exc}") from exc
    _refuse_keyed_grey16(path, depth, img)
    if img.ndim == 3 and img.shape[2] in (2, 4):  # grey+alpha or RGBA
        img = _without_alpha(img, path)
    is_rgb = img.ndim == 3 and img.shape[2] == 3
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


def read_scan(path: str | Path, *, dims=None, rescale: bool = False, colour: bool = False,
              series: str | None = None) -> Scan:
    """Read any supported volume with its geometry: a :class:`Scan` ``(data, geometry, segments)``.

    Parameters
    ----------
    path : str or Path
        A file, a folder of DICOM files, or a folder of slice images.
    dims : (3,) ints, optional
        Dimensions of a headerless ``.vol``.
    rescale : bool
        Map non-uint8 data onto 0..255 (finite min..max; NaN and infinity become 0). Off by
        default: data keep their type unless the user asks.
    colour : bool
        Return a colour volume as ``data[x, y, z, channel]`` (uint8 RGB); without it
        colour is read as grey (luminance).
    series : str, optional
        The DICOM series to read from a folder holding several (its UID or number).
    """
    path = Path(path)
    try:
        data, geometry, segments, *mode = _read_any(path, dims, colour, series)
    except OSError as exc:  # permissions, a file that vanished, disk errors: one error type, the file named
        raise FormatError(getattr(exc, "filename", None) or path, f"cannot read: {exc.strerror or exc}") from exc
    if is_colour(data) and not colour:
        data = np.asfortranarray(to_grey(data))
    if rescale and data.dtype != np.uint8:
        data = float_to_uint8(data)
    return Scan(data, geometry, segments, mode[0] if mode else None)


def _read_any(path: Path, dims, colour: bool, series):
    from . import dicom_files, medical_files

    if path.is_dir():
        if dicom_files.is_dicom_folder(path):
            return (*dicom_files.read_dicom(path, series=series), {})
        return read_image_folder(path, colour=colour), IDENTITY, {}
    if not path.exists():
        raise FormatError(path, "no such file or folder")
    suffix = _suffix(path)
    if suffix == ".vol":
        return raw_volumes.read_raw(path, dims), IDENTITY, {}
    if suffix in NRRD_SUFFIXES:
        data, geometry, segments, pairs = read_nrrd(path, pairs=True)
        return data, geometry, segments, _recorded_mode(pairs.get(MODE_KEY))
    if suffix in META_SUFFIXES:
        return (*read_metaimage(path), {})
    if suffix in NIBABEL_SUFFIXES:
        return (*medical_files.read_nibabel(path), {})
    if suffix in TIFF_SUFFIXES:
        return (*medical_files.read_tiff_stack(path), {})
    if suffix in VTK_SUFFIXES:
        data, geometry, mode = _read_vtk(path)
        return data, geometry, {}, mode
    if suffix in DICOM_SUFFIXES or dicom_files.is_dicom_file(path):
        return (*dicom_files.read_dicom(path, series=series), {})
    from .mesh_files import READ_MESH_SUFFIXES

    if suffix in READ_MESH_SUFFIXES:
        raise FormatError(path, f"is a surface mesh, not a volume: fill it first with `volanim voxelize {path.name} "
                                f"{path.stem}.nrrd` (the studio's File > Open volume fills a mesh itself)")
    raise FormatError(path, f"unknown volume format {path.suffix!r}; expected "
                      + ", ".join(READ_SUFFIXES) + ", a DICOM folder or a folder of slice images")


def read_volume(path: str | Path, *, dims=None, rescale: bool = False, colour: bool = False) -> np.ndarray:
    """Read any supported volume as an array indexed ``[x, y, z]`` (``[x, y, z, 3]`` for colour with ``colour``)."""
    return read_scan(path, dims=dims, rescale=rescale, colour=colour).data


def _write_vti(path: Path, vol: np.ndarray, geometry: Geometry, mode: str | None = None) -> None:
    import pyvista as pv

    img = pv.ImageData(dimensions=vol.shape[:3], origin=geometry.origin, spacing=geometry.spacing)
    img.direction_matrix = geometry.matrix
    if is_colour(vol):  # one RGB tuple per point, x fastest
        img.point_data["rgb"] = np.ascontiguousarray(vol.transpose(2, 1, 0, 3)).reshape(-1, 3)
    else:
        img.point_data["values"] = vol.ravel(order="F")
    if mode:
        img.field_data[MODE_KEY] = [mode]
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


def write_output(path: str | Path, vol: np.ndarray, geometry: Geometry = IDENTITY, mode: str | None = None
                 ) -> tuple[Path, str | None]:
    """Write a result where the user asked, with what raw formats need: counts above 255 saturate
    (:func:`saturate_for_raw`), a headerless ``.vol`` is named ``NAME.XxYxZ.vol``
    (:func:`raw_volumes.raw_name_for`), and a geometry ``.vol``/``.VOL`` cannot hold is said.
    Returns the path written and a note for the user, or None.

    Every command and the studio write their results through this, so none forgets these rules.
    """
    vol, note = saturate_for_raw(path, np.asarray(vol))
    path = raw_volumes.raw_name_for(path, vol.shape[:3])
    write_volume(path, vol, geometry, mode)
    if (path.suffix.lower() == ".vol" or "%" in path.name) and not geometry.is_identity:
        lost = f"{path.name} holds no geometry ({geometry.describe()}): write .nrrd, .nii, .mha or .vti to keep it"
        note = f"{note}; {lost}" if note else lost
    return path, note


def write_volume(path: str | Path, vol: np.ndarray, geometry: Geometry = IDENTITY, mode: str | None = None) -> None:
    """Write a volume as ``.vol``, ``.VOL``, ``.vti``, ``.nrrd``, ``.nii``/``.nii.gz``, ``.mha`` or a 3-D
    ``.tif``, atomically; a name with a number field (``slices/NAME%04d.png``) writes one image a slice.

    ``mode``: the reconstruction mode of a result, recorded in ``.vti`` and ``.nrrd`` so a viewer draws
    it in that mode's colours (a bone volume in bone colours, not a grey ramp).

    ``.vol``/``.VOL`` hold uint8 only and no geometry: :func:`~volanim_core.io.write_output` says so.
    """
    path = Path(path)
    vol = np.asarray(vol)
    if vol.ndim != 3 and not is_colour(vol):
        raise ValueError(f"a volume must be 3-D (or 3-D with 3 colour channels), got shape {vol.shape}")
    if not isinstance(geometry, Geometry):
        raise TypeError(f"geometry must be a Geometry, got {type(geometry).__name__}")
    from . import medical_files

    suffix = _suffix(path)
    if "%" in path.name and path.suffix.lower() in SLICE_SUFFIXES:
        medical_files.write_slices(str(path), vol)
    elif suffix == ".vol":
        raw_volumes.write_raw(path, vol)
    elif suffix == ".vti":
        _write_vti(path, vol, geometry, mode)
    elif suffix == ".nrrd":
        write_nrrd(path, vol, geometry, {MODE_KEY: mode} if mode else None)
    elif suffix == ".mha":
        write_metaimage(path, vol, geometry)
    elif suffix in (".nii", ".nii.gz"):
        _write_nifti(path, vol, geometry)
    elif suffix in TIFF_SUFFIXES:
        medical_files.write_tiff_stack(path, vol, geometry)
    else:
        raise ValueError(f"cannot write {path.name}: choose one of {', '.join(WRITE_SUFFIXES)}")


def _write_nifti(path: Path, vol: np.ndarray, geometry: Geometry) -> None:
    """NIfTI-1 through nibabel, qform and sform both set (scanner space), atomically."""
    import nibabel as nib

    from .atomic import atomic_open

    if is_colour(vol):
        raise ValueError(f"cannot write a colour volume to {path.name}: NIfTI colour is not supported; use .nrrd")
    affine = np.diag([-1.0, -1.0, 1.0, 1.0]) @ geometry.affine  # LPS -> RAS
    img = nib.Nifti1Image(np.asarray(vol), affine)
    img.set_qform(affine, code=1)
    img.set_sform(affine, code=1)
    data = img.to_bytes()
    if path.name.lower().endswith(".gz"):
        import gzip

        data = gzip.compress(data, compresslevel=6)
    with atomic_open(path, "wb", size=len(data)) as fh:
        fh.write(data)
