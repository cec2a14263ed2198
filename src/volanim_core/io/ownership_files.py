"""The rig's ownership on disk: ``NAME.owners.nrrd`` beside ``NAME.connect`` (docs/formats.md#ownership).

    Ownership --write_ownership--> NRRD label volume (the body's box, uint8/uint16: 1 + bone, 0 outside),
                                   its place on the rest grid and the bones, balls and tubes as key:=value pairs
    NAME.owners.nrrd --read_ownership(connect)--> Ownership, checked against the .connect's bones

Why NRRD: 3D Slicer and ITK open it as a label map, so an animator can look at and paint ownership
with the tools of the field too; the pairs keep what volanim needs beside the voxels in one file.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from volanim_core.errors import FormatError
from volanim_core.io.nrrd_files import read_nrrd, write_nrrd
from volanim_core.rig._ownership_kernels import TUBE_COLUMNS
from volanim_core.rig.connectivity import Connectivity
from volanim_core.rig.ownership import Ownership, label_dtype

SUFFIX = ".owners.nrrd"


def ownership_path(connect_path: str | Path) -> Path:
    """``NAME.owners.nrrd`` for ``NAME.connect`` (any suffix is replaced)."""
    p = Path(connect_path)
    return p.with_name(p.stem + SUFFIX) if p.suffix else p.with_name(p.name + SUFFIX)


def _floats(values) -> str:
    return " ".join(repr(float(v)) for v in np.ravel(values))


def write_ownership(path: str | Path, own: Ownership) -> None:
    """Write ``own`` atomically as a label NRRD (docs/formats.md#ownership)."""
    pairs = {
        "volanim_ownership": "1",
        "volanim_origin": " ".join(str(int(v)) for v in own.origin),
        "volanim_bones": str(len(own.bones)),
        "volanim_segments": _floats([np.concatenate([b.proximal, b.distal]) for b in own.bones]),
        "volanim_ball_radii": _floats(own.ball_radii),
        "volanim_tubes": _floats(own.tubes),
    }
    write_nrrd(path, own.labels, own.geometry.shifted(own.origin), pairs)


def _vector(path: Path, pairs: dict, key: str, n: int) -> np.ndarray:
    text = pairs.get(key)
    if text is None:
        raise FormatError(path, f"no '{key}:=' line: not an ownership file written by volanim connect")
    try:
        values = np.array([float(v) for v in text.split()], np.float64)
    except ValueError:
        raise FormatError(path, f"'{key}:=' holds something other than numbers") from None
    if len(values) != n or not np.isfinite(values).all():
        raise FormatError(path, f"'{key}:=' holds {len(values)} numbers, expected {n} finite ones")
    return values


def read_ownership(path: str | Path, conn: Connectivity) -> Ownership:
    """Read an ownership file and check it belongs to ``conn``: the same bones, labels within them."""
    path = Path(path)
    labels, geometry, _segments, pairs = read_nrrd(path, pairs=True)
    if pairs.get("volanim_ownership") != "1":
        raise FormatError(path, "not an ownership file (no 'volanim_ownership:=1' line)")
    n = len(conn.bones)
    count = _vector(path, pairs, "volanim_bones", 1)
    if int(count[0]) != n:
        raise FormatError(path, f"made for {int(count[0])} bones, but its .connect has {n}: make it again "
                                "with volanim connect")
    segments = _vector(path, pairs, "volanim_segments", 6 * n).reshape(n, 6)
    for k, b in enumerate(conn.bones):
        if not np.allclose(segments[k], np.concatenate([b.proximal, b.distal]), atol=1e-6):
            raise FormatError(path, f"bone {k} ({b.label}) has other joints than in its .connect: it was made "
                                    "for another rig; make it again with volanim connect")
    origin = _vector(path, pairs, "volanim_origin", 3).astype(int)
    if labels.dtype.kind != "u" or (labels.size and int(labels.max()) > n):
        raise FormatError(path, f"labels must be 0..{n} (unsigned): 1 + the bone owning each voxel")
    del geometry  # the connect's grid is the rig's: the labels' place on it is volanim_origin
    return Ownership(labels.astype(label_dtype(n), copy=False), tuple(origin), list(conn.bones),
                     _vector(path, pairs, "volanim_ball_radii", n), conn.geometry,
                     _vector(path, pairs, "volanim_tubes", TUBE_COLUMNS * n).reshape(n, TUBE_COLUMNS), path)


def attach_ownership(conn: Connectivity, connect_path: str | Path) -> Connectivity:
    """``conn`` with the ownership beside its file when there is one (else as it is)."""
    p = ownership_path(connect_path)
    if not p.exists():
        return conn
    return conn.with_ownership(read_ownership(p, conn))
