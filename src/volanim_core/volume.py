"""Volume tools of the old pipeline as pure functions on ``vol[x, y, z]`` arrays.

=================  ==============================  ==========================
function           old tool                         note
=================  ==============================  ==========================
threshold          Convert2Binary                   band-pass lo <= v <= hi
fill_cavities      (segmentation)                   enclosed background -> object
box_fill           Fill                             set a box to a value
crop               CropVolume                       bounds may reach outside: pads
tight_bounds       TightBounds                      inclusive min/max of v > level
flip               (flip)                           along x, y or z
histogram          Count                            256 counts
super_diff         VolumeSuperDiff                  0/100/150/200 coding
reverse            ReverseData                      255 - v
remap              remapVolume                      256-entry lookup table
fit_pow2           FitVolume                        pad up to powers of two
float_to_uint8     float2uchar                      (in volanim_core.io)
segment            (segmentation)                   threshold + optional cavity fill
resample           (halving the Visible Human)      new voxel size, geometry kept
=================  ==============================  ==========================

Bounds are inclusive voxel index ranges ``(lo, hi)`` with ``lo, hi`` 3-tuples,
as the old tools printed them. The functions take and return arrays; where a
tool moves voxels (crop, flip, fit_pow2, resample) the caller updates the
volume's :class:`~volanim_core.geometry.Geometry` with the matching method
(``shifted``, ``flipped``, ``with_spacing``), so every voxel stays where it is
in physical space.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from scipy import ndimage

from .geometry import Geometry
from .limits import check_allocation
from .progress import Reporter

__all__ = [
    "Bounds", "box_fill", "crop", "fill_cavities", "fit_pow2", "flip", "float_to_uint8", "histogram",
    "isotropic_mask", "remap", "resample", "reverse", "segment", "super_diff", "threshold", "tight_bounds",
]


class Bounds(NamedTuple):
    """Inclusive voxel bounds: ``lo <= (x, y, z) <= hi``."""

    lo: tuple[int, int, int]
    hi: tuple[int, int, int]

    @property
    def shape(self) -> tuple[int, int, int]:
        return tuple(int(h - lo + 1) for lo, h in zip(self.lo, self.hi))

    def slices(self) -> tuple[slice, slice, slice]:
        return tuple(slice(lo, h + 1) for lo, h in zip(self.lo, self.hi))

    def __str__(self) -> str:
        return " ".join(str(int(v)) for v in (*self.lo, *self.hi))


# ------------------------------------------------------------------ values (io and every tool read them)
def finite_range(vol: np.ndarray) -> tuple[float, float] | None:
    """``(min, max)`` over the finite values (NaN and infinity are background); None if there are none."""
    vol = np.asarray(vol)
    if vol.dtype.kind != "f":
        return (float(vol.min()), float(vol.max())) if vol.size else None
    lo, hi = np.inf, -np.inf
    for z in range(vol.shape[-1] if vol.ndim else 0):  # a slice at a time: no volume-sized mask
        s = vol[..., z]
        s = s[np.isfinite(s)]
        if s.size:
            lo, hi = min(lo, float(s.min())), max(hi, float(s.max()))
    return (lo, hi) if lo <= hi else None


def non_finite_count(vol: np.ndarray) -> int:
    """How many voxels are NaN or infinite (0 for integer data)."""
    vol = np.asarray(vol)
    if vol.dtype.kind not in "fc":
        return 0
    return int(sum(int(np.count_nonzero(~np.isfinite(vol[..., z]))) for z in range(vol.shape[-1])))


def float_to_uint8(vol: np.ndarray, lo: float | None = None, hi: float | None = None) -> np.ndarray:
    """Map ``[lo, hi]`` linearly onto 0..255 and clip (float2uchar).

    ``lo``/``hi`` default to the data's finite minimum and maximum; NaN and infinite voxels are
    background (0), not part of the range.
    """
    vol = np.asarray(vol)
    if lo is None or hi is None:
        found = finite_range(vol) or (0.0, 0.0)
        lo = found[0] if lo is None else float(lo)
        hi = found[1] if hi is None else float(hi)
    lo, hi = float(lo), float(hi)
    if hi <= lo:
        if vol.size == 0 or hi < lo:
            return np.zeros(vol.shape, np.uint8)
        with np.errstate(invalid="ignore"):
            return ((vol > lo) & np.isfinite(vol)).astype(np.uint8) * 255
    with np.errstate(invalid="ignore", over="ignore"):
        out = (np.asarray(vol, np.float64) - lo) * (255.0 / (hi - lo))
        out[~np.isfinite(out)] = 0  # NaN, +-inf: background
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


def _check3d(vol, name="volume") -> np.ndarray:
    vol = np.asarray(vol)
    if vol.ndim != 3:
        raise ValueError(f"{name} must be a 3-D array indexed [x, y, z], got shape {vol.shape}")
    return vol


def threshold(vol: np.ndarray, lo: float, hi: float | None = None, *, value: int = 1) -> np.ndarray:
    """Band-pass threshold to a binary uint8 volume (Convert2Binary).

    Parameters
    ----------
    vol : (X, Y, Z) ndarray
    lo, hi : float
        Voxels with ``lo <= v <= hi`` become ``value``, others 0. ``hi``
        defaults to no upper limit.

    Examples
    --------
    >>> import numpy as np
    >>> threshold(np.array([[[0, 5, 10]]]), 5).ravel().tolist()
    [0, 1, 1]
    """
    vol = _check3d(vol)
    if not 0 <= value <= 255:
        raise ValueError(f"value must be 0..255, got {value}")
    inside = vol >= lo
    if hi is not None:
        if hi < lo:
            raise ValueError(f"threshold range is empty: hi {hi} < lo {lo}")
        inside &= vol <= hi
    return inside.astype(np.uint8) * np.uint8(value)


def fill_cavities(mask: np.ndarray) -> np.ndarray:
    """Fill background regions fully enclosed by the object.

    The object is taken as 26-connected, so background is 6-connected: a
    cavity is any background region with no 6-connected path to the border.
    Returns a mask of the input's dtype with enclosed voxels set to the
    object's value (the maximum of ``mask``).
    """
    mask = _check3d(mask, "mask")
    filled = ndimage.binary_fill_holes(mask != 0)
    out = mask.copy()
    out[filled & (mask == 0)] = mask.max() if mask.size else 1
    return out


def box_fill(vol: np.ndarray, bounds: Bounds, value: int) -> np.ndarray:
    """A copy of ``vol`` with the inclusive box ``bounds`` set to ``value`` (Fill)."""
    vol = _check3d(vol).copy()
    lo = np.maximum(bounds.lo, 0)
    hi = np.minimum(bounds.hi, np.array(vol.shape) - 1)
    if np.all(hi >= lo):
        vol[lo[0] : hi[0] + 1, lo[1] : hi[1] + 1, lo[2] : hi[2] + 1] = value
    return vol


def crop(vol: np.ndarray, bounds: Bounds, *, fill: int = 0) -> np.ndarray:
    """The part of ``vol`` inside ``bounds``; parts outside the volume read ``fill`` (CropVolume).

    So crop also pads: ``crop(v, Bounds((-2,)*3, np.array(v.shape) + 1))`` adds
    two voxels on every side.
    """
    vol = _check3d(vol)
    shape = Bounds(tuple(bounds.lo), tuple(bounds.hi)).shape
    if min(shape) < 1:
        raise ValueError(f"empty crop bounds {bounds}")
    out = np.full(shape, fill, dtype=vol.dtype, order="F")
    src_lo = np.maximum(bounds.lo, 0)
    src_hi = np.minimum(bounds.hi, np.array(vol.shape) - 1)
    if np.all(src_hi >= src_lo):
        dst_lo = src_lo - np.asarray(bounds.lo)
        dst_hi = dst_lo + (src_hi - src_lo)
        out[dst_lo[0] : dst_hi[0] + 1, dst_lo[1] : dst_hi[1] + 1, dst_lo[2] : dst_hi[2] + 1] = vol[
            src_lo[0] : src_hi[0] + 1, src_lo[1] : src_hi[1] + 1, src_lo[2] : src_hi[2] + 1
        ]
    return out


def tight_bounds(vol: np.ndarray, level: float = 0) -> Bounds | None:
    """Inclusive bounds of the voxels with value > ``level`` (TightBounds); None if there are none."""
    vol = _check3d(vol)
    # one pass for the (x, y) columns, then z only inside their box: a sequence records every frame's box,
    # and the mask three times over (once per axis) cost 3x as much
    def above(v):  # unsigned data above 0 is non-zero: no mask of the whole volume
        return v if level == 0 and v.dtype.kind in "ub" else v > level

    columns = np.any(above(vol), axis=2)
    xs, ys = np.flatnonzero(columns.any(axis=1)), np.flatnonzero(columns.any(axis=0))
    if not len(xs):
        return None
    zs = np.flatnonzero(np.any(above(vol[xs[0]:xs[-1] + 1, ys[0]:ys[-1] + 1]), axis=(0, 1)))
    return Bounds((int(xs[0]), int(ys[0]), int(zs[0])), (int(xs[-1]), int(ys[-1]), int(zs[-1])))


def brightest(vol: np.ndarray) -> np.ndarray:
    """One value a voxel: a colour volume's brightest channel (non-zero exactly where the voxel is not
    black), any other volume as it is -- what bounds and masks of a colour volume are taken on."""
    vol = np.asarray(vol)
    return vol.max(axis=3) if vol.ndim == 4 else vol


def each_channel(vol: np.ndarray, fn):
    """``fn(vol)`` for a 3-D volume; for a colour one ``(X, Y, Z, C)``, ``fn`` of each channel, stacked again
    along the last axis, so that a tool written for one value a voxel keeps colour (#66: resample, crop and
    flip made grey of it). ``fn`` returns a volume, or a tuple whose first item is one (the rest is the
    first channel's: an offset or a geometry, the same for every channel)."""
    vol = np.asarray(vol)
    if vol.ndim != 4:
        return fn(vol)
    results = [fn(vol[..., c]) for c in range(vol.shape[3])]
    if isinstance(results[0], tuple):
        return (np.stack([r[0] for r in results], axis=3), *results[0][1:])
    return np.stack(results, axis=3)


def flip(vol: np.ndarray, axis: str | int) -> np.ndarray:
    """Mirror the volume along ``axis`` ('x', 'y', 'z' or 0..2)."""
    vol = _check3d(vol)
    ax = {"x": 0, "y": 1, "z": 2}.get(axis, axis)
    if ax not in (0, 1, 2):
        raise ValueError(f"axis must be x, y or z, got {axis!r}")
    return np.flip(vol, ax).copy(order="F")


def histogram(vol: np.ndarray) -> np.ndarray:
    """Counts of each value 0..255 of a uint8 volume (Count)."""
    vol = _check3d(vol)
    if vol.dtype != np.uint8:
        raise ValueError(f"histogram expects uint8 data, got {vol.dtype}")
    return np.bincount(vol.ravel(order="K"), minlength=256)


# The thesis's VolumeSuperDiff codes: a changed value is a difference even where both are non-zero.
SUPER_DIFF_CODES = {"same value": 0, "only first": 100, "only second": 150, "both, changed": 200}


def super_diff(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Voxel-by-voxel comparison of two volumes (VolumeSuperDiff, the thesis's codes).

    Output: 0 where both hold the same value (empty or not), 100 where only ``a``
    is non-zero, 150 where only ``b`` is, 200 where both are non-zero with
    different values.
    """
    a, b = _check3d(a, "first volume"), _check3d(b, "second volume")
    if a.shape != b.shape:
        raise ValueError(f"volumes differ in size: {a.shape} vs {b.shape}")
    fa, fb = a != 0, b != 0
    out = np.zeros(a.shape, np.uint8, order="F")
    out[fa & ~fb] = 100
    out[~fa & fb] = 150
    out[fa & fb & (a != b)] = 200
    return out


def reverse(vol: np.ndarray) -> np.ndarray:
    """Invert intensities, ``255 - v`` (ReverseData)."""
    vol = _check3d(vol)
    if vol.dtype != np.uint8:
        raise ValueError(f"reverse expects uint8 data, got {vol.dtype}")
    return (255 - vol).astype(np.uint8)


def remap(vol: np.ndarray, table) -> np.ndarray:
    """Replace each value v by ``table[v]`` (remapVolume); ``table`` has 256 entries 0..255."""
    vol = _check3d(vol)
    table = np.asarray(table)
    if table.shape != (256,):
        raise ValueError(f"a remap table has 256 entries, got {table.shape}")
    if table.min() < 0 or table.max() > 255:
        raise ValueError("remap table values must be 0..255")
    if vol.dtype != np.uint8:
        raise ValueError(f"remap expects uint8 data, got {vol.dtype}")
    return table.astype(np.uint8)[vol]


def fit_pow2(vol: np.ndarray, *, center: bool = False) -> tuple[np.ndarray, tuple[int, int, int]]:
    """Pad every dimension up to a power of two (FitVolume).

    Returns the padded volume and the offset of the old voxel (0, 0, 0) in it
    (zero unless ``center``).
    """
    vol = _check3d(vol)
    target = [1 << int(np.ceil(np.log2(max(n, 1)))) for n in vol.shape]
    offset = tuple((t - n) // 2 if center else 0 for t, n in zip(target, vol.shape))
    lo = tuple(-o for o in offset)
    hi = tuple(lo_ + t - 1 for lo_, t in zip(lo, target))
    return crop(vol, Bounds(lo, hi)), offset


def segment(vol: np.ndarray, lo: float = 1, hi: float | None = None, *, fill: bool = False) -> np.ndarray:
    """The object mask (bool): ``lo <= v <= hi`` (default: every non-zero voxel), enclosed cavities
    filled when ``fill``. NaN voxels are background. The CLI's and the studio's one segmentation."""
    mask = threshold(vol, lo, hi).view(bool)
    return fill_cavities(mask) if fill else mask


def resampled_shape(shape, spacing, new_spacing) -> tuple[int, int, int]:
    """The grid covering the same extent (first to last voxel centre) at ``new_spacing``."""
    return tuple(int(np.floor((n - 1) * s / t + 1e-9)) + 1 for n, s, t in zip(shape, spacing, new_spacing))


def resample(vol: np.ndarray, geometry: Geometry, spacing, *, order: int = 1, threshold_at: float | None = None,
             progress=None, cancel=None) -> tuple[np.ndarray, Geometry]:
    """The volume on a grid of voxel size ``spacing`` (3 numbers, or one for cubes): ``(volume, geometry)``.

    Voxel ``[0, 0, 0]``'s centre and the axes stay where they are; the grid covers the same extent.
    ``order`` 0 is nearest (labels), 1 linear (intensities). ``threshold_at``: return the bool mask
    ``resampled > threshold_at`` instead, made a slab at a time (a mask resampled linearly and
    thresholded at 0.5 is smoother than nearest, without a float copy of the whole output).
    """
    from scipy import ndimage

    vol = _check3d(vol)
    new = np.broadcast_to(np.asarray(spacing, np.float64), (3,))
    if not np.all(np.isfinite(new)) or np.any(new <= 0):
        raise ValueError(f"the new voxel size must be positive, got {spacing!r}")
    if order not in (0, 1, 3):
        raise ValueError(f"order must be 0 (nearest), 1 (linear) or 3 (cubic), got {order}")
    shape = resampled_shape(vol.shape, geometry.spacing, new)
    check_allocation(shape, 1 if threshold_at is not None else vol.dtype.itemsize, "the resampled grid",
                     "choose a larger voxel size")
    step = new / np.asarray(geometry.spacing)
    src = vol.view(np.uint8) if vol.dtype == bool else vol  # ndimage takes no bool
    out = np.empty(shape, bool if threshold_at is not None else vol.dtype, order="F")
    report = Reporter(progress, cancel)
    slab = max(1, int(2**24 // max(1, shape[0] * shape[1])))
    for z0 in range(0, shape[2], slab):
        z1 = min(shape[2], z0 + slab)
        part = ndimage.affine_transform(src, step, offset=(0.0, 0.0, z0 * step[2]), output_shape=(*shape[:2], z1 - z0),
                                        order=order, mode="nearest", prefilter=order > 1,
                                        output=np.float32 if threshold_at is not None else src.dtype)
        out[:, :, z0:z1] = part > threshold_at if threshold_at is not None else part.view(out.dtype)
        report(z1, shape[2])
    return out, geometry.with_spacing(tuple(new))


def isotropic_mask(mask: np.ndarray, geometry: Geometry, voxel_size: float | None = None, *,
                   progress=None, cancel=None) -> tuple[np.ndarray, Geometry]:
    """A mask on cubic voxels of ``voxel_size`` (default: the smallest spacing), ``(mask, geometry)``;
    returned as it is when its voxels are cubes of that size already.

    Distances, thinness, sphere radii and bone rotations are all taken in voxels, so the skeleton
    is made on cubes: then a sphere is a sphere in the body and a rotation keeps its shape.
    """
    size = float(min(geometry.spacing) if voxel_size is None else voxel_size)
    if geometry.is_isotropic and abs(geometry.spacing[0] - size) <= 1e-6 * size:
        return mask, geometry
    return resample(mask, geometry, size, order=1, threshold_at=0.5, progress=progress, cancel=cancel)

