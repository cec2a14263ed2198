"""Image geometry: where each voxel of a volume is in the patient's (or the world's) space.

    voxel index (i, j, k) --spacing, direction, origin--> physical point (mm, LPS)

        p = origin + direction @ (spacing * [i, j, k])

This is ITK's convention (and so 3D Slicer's, DICOM's and NRRD's ``space:
left-posterior-superior``): the origin is the *centre* of voxel ``[0, 0, 0]``,
``direction``'s columns are the unit vectors of the x, y and z index axes, and
coordinates are in millimetres, x to the patient's left, y to the back, z up.
NIfTI and MGH store RAS; their readers flip x and y into LPS.

Every volume in memory travels with one :class:`Geometry`; the text files of
the pipeline (``.mskel``, ``.connect``, ``.tskel``) record the geometry of the
grid their voxel indices refer to in a ``# geometry:`` header line
(docs/formats.md, "Physical space"). A file without it has the identity
geometry: unit spacing, origin 0, axes as they are.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

__all__ = ["Geometry", "IDENTITY", "axis_codes", "mm"]

_ORTHO_TOLERANCE = 1e-4
_ASCII_NUMBER = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")  # as io._text.NUMBER


def mm(values, sep: str = " x ") -> str:
    """Numbers as people read them (``0.7 x 0.7 x 2.5``): spacings, origins, in messages."""
    return sep.join(f"{float(v):g}" for v in values)


def _triple(values, what: str) -> tuple[float, float, float]:
    try:
        out = tuple(float(v) for v in values)
    except (TypeError, ValueError):
        raise ValueError(f"{what} must be three numbers, got {values!r}") from None
    if len(out) != 3 or not all(math.isfinite(v) for v in out):
        raise ValueError(f"{what} must be three finite numbers, got {values!r}")
    return out


@dataclass(frozen=True)
class Geometry:
    """Spacing, origin and direction of a voxel grid (ITK's convention, LPS millimetres).

    Attributes
    ----------
    spacing : 3 floats > 0
        Voxel size along the x, y and z index axes.
    origin : 3 floats
        Physical position of the centre of voxel ``[0, 0, 0]``.
    direction : 9 floats
        The 3x3 direction matrix, row by row; its columns are the index axes'
        unit vectors in physical space (orthonormal).

    Examples
    --------
    >>> g = Geometry(spacing=(0.5, 0.5, 2.0), origin=(-40, -25, -900))
    >>> g.to_physical([[2, 0, 1]]).tolist()
    [[-39.0, -25.0, -898.0]]
    >>> g.to_index([[-39.0, -25.0, -898.0]]).tolist()
    [[2.0, 0.0, 1.0]]
    """

    spacing: tuple[float, float, float] = (1.0, 1.0, 1.0)
    origin: tuple[float, float, float] = (0.0, 0.0, 0.0)
    direction: tuple[float, ...] = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)

    def __post_init__(self):
        spacing = _triple(self.spacing, "spacing")
        if min(spacing) <= 0:
            raise ValueError(f"spacing must be positive, got {spacing}")
        object.__setattr__(self, "spacing", spacing)
        object.__setattr__(self, "origin", _triple(self.origin, "origin"))
        d = np.asarray(self.direction, np.float64).reshape(-1)
        if d.shape != (9,) or not np.isfinite(d).all():
            raise ValueError(f"direction must be nine finite numbers (a 3x3 matrix), got {self.direction!r}")
        m = d.reshape(3, 3)
        # the axes' own directions need no test: np.allclose was 5 % of a scan's frame (#65)
        if d.tolist() != [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0] and \
                not np.allclose(m.T @ m, np.eye(3), atol=_ORTHO_TOLERANCE):
            raise ValueError(f"direction must be orthonormal (rotations and axis flips only), got {m.tolist()}")
        object.__setattr__(self, "direction", tuple(float(v) for v in d))

    # -- matrices -------------------------------------------------------------------------------

    @property
    def matrix(self) -> np.ndarray:
        """The 3x3 direction matrix (columns: the index axes in physical space)."""
        return np.asarray(self.direction, np.float64).reshape(3, 3)

    @property
    def affine(self) -> np.ndarray:
        """4x4 column-vector affine, index -> physical (``p = A @ [i, j, k, 1]``), as nibabel writes."""
        a = np.eye(4)
        a[:3, :3] = self.matrix * np.asarray(self.spacing)
        a[:3, 3] = self.origin
        return a

    @classmethod
    def from_affine(cls, affine) -> Geometry:
        """The geometry of a 4x4 column-vector index -> physical affine (no shear)."""
        a = np.asarray(affine, np.float64)
        if a.shape != (4, 4) or not np.isfinite(a).all():
            raise ValueError(f"an affine must be a finite 4x4 matrix, got shape {a.shape}")
        columns = a[:3, :3]
        spacing = np.linalg.norm(columns, axis=0)
        if np.any(spacing <= 0):
            raise ValueError(f"the affine has a zero-length axis: {a[:3, :3].tolist()}")
        return cls(tuple(spacing), tuple(a[:3, 3]), tuple((columns / spacing).reshape(-1)))

    # -- points ---------------------------------------------------------------------------------

    def to_physical(self, index) -> np.ndarray:
        """``(N, 3)`` voxel indices (fractional allowed) -> ``(N, 3)`` physical points."""
        idx = np.asarray(index, np.float64)
        return (idx * np.asarray(self.spacing)) @ self.matrix.T + np.asarray(self.origin)

    def to_index(self, points) -> np.ndarray:
        """``(N, 3)`` physical points -> ``(N, 3)`` fractional voxel indices."""
        p = np.asarray(points, np.float64) - np.asarray(self.origin)
        return (p @ self.matrix) / np.asarray(self.spacing)

    # -- derived grids --------------------------------------------------------------------------

    @property
    def is_identity(self) -> bool:
        return self == IDENTITY

    @property
    def is_isotropic(self) -> bool:
        s = self.spacing
        return max(s) - min(s) <= 1e-6 * max(s)

    def shifted(self, index_offset) -> Geometry:
        """The geometry of a sub-grid whose voxel ``[0, 0, 0]`` is this grid's voxel ``index_offset``
        (crop, a reconstruction's box)."""
        origin = self.to_physical(np.asarray(index_offset, np.float64)[None])[0]
        return Geometry(self.spacing, tuple(origin), self.direction)

    def flipped(self, axis: int, size: int) -> Geometry:
        """The geometry of the grid mirrored along ``axis`` (``size`` voxels): the same physical
        points, the axis reversed (so the voxels stay where they were in space)."""
        last = np.zeros(3)
        last[axis] = size - 1
        m = self.matrix.copy()
        m[:, axis] *= -1
        return Geometry(self.spacing, tuple(self.to_physical(last[None])[0]), tuple(m.reshape(-1)))

    def with_spacing(self, spacing) -> Geometry:
        """The same origin and axes, another voxel size (resampling keeps voxel 0's centre)."""
        return Geometry(spacing, self.origin, self.direction)

    def index_map(self, other: Geometry) -> np.ndarray:
        """4x4 *row-vector* matrix taking this grid's indices to ``other``'s (``[i j k 1] @ M``), the
        convention of our bone matrices, so it composes with them."""
        column = np.linalg.inv(other.affine) @ self.affine
        return np.ascontiguousarray(column.T)

    # -- text -----------------------------------------------------------------------------------

    def header_value(self) -> str:
        """The value of a ``# geometry:`` header line (docs/formats.md)."""
        def fmt(values):  # the shortest text that reads back as the same float: files keep exact geometry
            return " ".join(np.format_float_positional(float(v) + 0.0, unique=True, trim="-") for v in values)

        return f"spacing {fmt(self.spacing)} origin {fmt(self.origin)} direction {fmt(self.direction)}"

    @classmethod
    def parse(cls, text: str) -> Geometry:
        """Read :meth:`header_value`'s text: ``spacing S S S origin O O O direction D x 9``; a
        ValueError says what is wrong."""
        words = text.split()
        want = {"spacing": 3, "origin": 3, "direction": 9}
        found: dict[str, list[float]] = {}
        i = 0
        while i < len(words):
            key = words[i].lower()
            if key not in want or key in found:
                raise ValueError(f"expected 'spacing', 'origin' or 'direction' (each once), got {words[i]!r}")
            values = words[i + 1:i + 1 + want[key]]
            numbers = [float(v) for v in values if _ASCII_NUMBER.fullmatch(v)]  # no "nan", "1_0", "１"
            if len(numbers) != want[key]:
                raise ValueError(f"'{key}' takes {want[key]} numbers, got {' '.join(values)!r}")
            found[key] = numbers
            i += 1 + want[key]
        if "spacing" not in found:
            raise ValueError("a geometry needs at least 'spacing' with three numbers")
        return cls(found["spacing"], found.get("origin", (0, 0, 0)),
                   found.get("direction", IDENTITY.direction))

    def describe(self) -> str:
        """One line for people: ``spacing 0.5 x 0.5 x 2 mm, origin (-40, -25, -900) mm[, axes ...]``."""
        text = f"spacing {mm(self.spacing)} mm, origin ({mm(self.origin, ', ')}) mm"
        if self.direction != IDENTITY.direction:
            text += f", axes {axis_codes(self.matrix)}"
        return text


def axis_codes(direction) -> str:
    """Where each index axis points, as ITK's orientation letters of LPS space (``LPS`` for the identity,
    ``RAS`` for x and y reversed); an oblique axis takes its largest component."""
    letters = (("L", "R"), ("P", "A"), ("S", "I"))
    m = np.asarray(direction, np.float64).reshape(3, 3)
    out = []
    for col in m.T:
        k = int(np.argmax(np.abs(col)))
        out.append(letters[k][0 if col[k] > 0 else 1])
    return "".join(out)


IDENTITY = Geometry()
