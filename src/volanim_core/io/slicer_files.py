"""3D Slicer's files: joints as markups (``.mrk.json``), bone transforms as ITK transform files.

    .bones --write_markups--> one point list, a control point per joint (LPS mm),
                               each bone in its distal joint's description
    .mrk.json --read_markups--> .bones: our descriptions give the bones back exactly;
                               a list made in Slicer is a chain, one bone per pair of
                               neighbours; a label seen before is the same joint
                               (a list starting at NECK hangs the arm from the neck)
    4x4 physical matrix --write_transform--> .tfm (text, ITK's AffineTransform_double_3_3)
                                              or .h5 (through SimpleITK)

Markups hold physical points; a ``.bones`` file holds voxel indices of a grid it
records (``# geometry:``): reading needs that grid (the scan the bones are for).
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import numpy as np

from volanim_core.errors import FormatError
from volanim_core.geometry import Geometry
from volanim_core.rig.bones import Bone, BoneSkeleton

from .atomic import atomic_write_text
from .files import load_json

SCHEMA = ("https://raw.githubusercontent.com/slicer/slicer/master/Modules/Loadable/Markups/Resources/Schema/"
          "markups-schema-v1.0.3.json#")
POINT_LISTS = ("fiducial", "curve", "opencurve", "line")  # markup types whose control points can be a chain
_BONE = re.compile(r"^volanim bone (\d+) from (\S+)(?: named (\S+))?$")
SAME_JOINT_MM = 1e-3  # one label at two places further apart than this is an error, not one joint
MAX_MM = 1e6  # a kilometre: past it a "position" is no body's (1e308 became a joint at infinity in voxels)


def write_markups(path: str | Path, bones: BoneSkeleton, geometry: Geometry | None = None) -> None:
    """The joints as one Slicer point list (LPS millimetres) on ``geometry`` (default: the bones' own)."""
    geometry = bones.geometry if geometry is None else geometry
    names = list(bones.joints)
    where = geometry.to_physical(np.array([bones.joints[n] for n in names])) if names else np.zeros((0, 3))
    descriptions = {n: [] for n in names}
    for i, b in enumerate(bones.bones):
        descriptions[b.distal].append(f"volanim bone {i} from {b.proximal}" + (f" named {b.name}" if b.name else ""))
    points = [{"id": str(k + 1), "label": n, "description": "; ".join(descriptions[n]), "associatedNodeID": "",
               "position": [float(v) for v in p], "orientation": [-1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, 1.0],
               "selected": True, "locked": False, "visibility": True, "positionStatus": "defined"}
              for k, (n, p) in enumerate(zip(names, where))]
    doc = {"@schema": SCHEMA, "markups": [{"type": "Fiducial", "coordinateSystem": "LPS", "coordinateUnits": "mm",
                                           "locked": False, "labelFormat": "%N-%d", "controlPoints": points}]}
    atomic_write_text(path, json.dumps(doc, indent=1) + "\n")


def _lists(path: Path) -> list[list[tuple[str, str, np.ndarray]]]:
    """Each point list of the file as ``(label, description, LPS position)`` rows."""
    doc = load_json(path, what="markups file")
    markups = doc.get("markups") if isinstance(doc, dict) else None
    if not isinstance(markups, list) or not markups:
        raise FormatError(path, "not a Slicer markups file: expected {\"markups\": [...]}")
    out = []
    for m, markup in enumerate(markups):
        kind = str(markup.get("type", "")).lower() if isinstance(markup, dict) else ""
        if kind not in POINT_LISTS:
            raise FormatError(path, f"markup {m}: type {markup.get('type') if isinstance(markup, dict) else None!r}"
                              " is not a point list, curve or line")
        system = str(markup.get("coordinateSystem", "LPS")).upper()
        if system not in ("LPS", "RAS"):
            raise FormatError(path, f"markup {m}: coordinateSystem {system!r} (expected LPS or RAS)")
        if str(markup.get("coordinateUnits", "mm")).lower() != "mm":
            raise FormatError(path, f"markup {m}: coordinateUnits {markup.get('coordinateUnits')!r} (expected mm)")
        points = markup.get("controlPoints") or []
        if not isinstance(points, list):
            raise FormatError(path, f"markup {m}: \"controlPoints\" must be a list, got {type(points).__name__}")
        rows = []
        for k, cp in enumerate(points):
            if isinstance(cp, dict) and cp.get("positionStatus", "defined") != "defined":
                # a point Slicer was asked to place and never got ("undefined", its position written ""),
                # or is being placed ("preview"): not a joint yet, whatever its position says
                continue
            pos = cp.get("position") if isinstance(cp, dict) else None
            label = cp.get("label") if isinstance(cp, dict) else None
            ok = isinstance(pos, list) and len(pos) == 3 and all(
                isinstance(v, int | float) and not isinstance(v, bool) and abs(v) <= MAX_MM for v in pos)
            if not ok or not isinstance(label, str) or not label.strip() or len(label.split()) != 1:
                raise FormatError(path, f"markup {m}, control point {k}: expected a one-word \"label\" and a "
                                  f"\"position\" of three numbers within {MAX_MM:g} mm of the origin")
            p = np.asarray(pos, np.float64) * ((-1, -1, 1) if system == "RAS" else 1)
            rows.append((label, str(cp.get("description") or ""), p))
        out.append(rows)
    return out


def read_markups(paths, geometry: Geometry) -> BoneSkeleton:
    """Bones from one or more markups files, their joints on the grid ``geometry`` (FormatError)."""
    paths = [Path(p) for p in ([paths] if isinstance(paths, str | Path) else paths)]
    joints: dict[str, np.ndarray] = {}
    ours: list[tuple[int, Bone]] = []
    chains: list[Bone] = []
    for path in paths:
        for rows in _lists(path):
            for label, _, p in rows:
                if label in joints and np.abs(joints[label] - p).max() > SAME_JOINT_MM:
                    raise FormatError(path, f"joint {label!r} is at two places: {joints[label].round(3).tolist()} "
                                      f"and {p.round(3).tolist()} (mm); one label is one joint")
                joints.setdefault(label, p)
            tagged = [(label, d) for label, d, _ in rows if d.startswith("volanim bone")]
            if tagged:
                for label, d in tagged:
                    for part in d.split("; "):
                        m = _BONE.match(part)
                        if not m:
                            raise FormatError(path, f"joint {label}: cannot read the description {part!r}")
                        ours.append((int(m.group(1)), Bone(m.group(2), label, m.group(3) or "")))
            else:
                chains += [Bone(a[0], b[0]) for a, b in zip(rows, rows[1:]) if a[0] != b[0]]
    bones = [b for _, b in sorted(ours, key=lambda x: x[0])] + chains
    if not bones:
        raise FormatError(paths[0], "no bone: a point list of two or more joints makes a chain of bones")
    try:
        skeleton = BoneSkeleton({n: geometry.to_index(p[None])[0] for n, p in joints.items()}, bones, geometry)
    except ValueError as exc:
        raise FormatError(paths[0], str(exc)) from None
    return skeleton


def write_transform(path: str | Path, matrix: np.ndarray) -> None:
    """A 4x4 column-vector physical affine (LPS mm) as an ITK transform file: ``.tfm`` text, ``.h5`` HDF5."""
    m = np.asarray(matrix, np.float64)
    if str(path).lower().endswith(".h5"):
        try:
            import SimpleITK as sitk
        except ImportError:
            raise ValueError(f"cannot write {path}: .h5 transforms need SimpleITK (pip install SimpleITK); "
                             ".tfm needs nothing") from None
        import tempfile

        from .atomic import atomic_write_bytes

        tx = sitk.AffineTransform(3)
        tx.SetMatrix(m[:3, :3].ravel().tolist())
        tx.SetTranslation(m[:3, 3].tolist())
        with tempfile.TemporaryDirectory() as tmp:  # SimpleITK picks the format by the name: write, then move
            sitk.WriteTransform(tx, str(Path(tmp) / "t.h5"))
            atomic_write_bytes(path, (Path(tmp) / "t.h5").read_bytes())
        return
    if not str(path).lower().endswith((".tfm", ".txt")):
        raise ValueError(f"cannot write {path}: a transform file ends in .tfm or .h5")
    params = " ".join(repr(float(v)) for v in [*m[:3, :3].ravel(), *m[:3, 3]])
    atomic_write_text(path, "#Insight Transform File V1.0\n#Transform 0\nTransform: AffineTransform_double_3_3\n"
                            f"Parameters: {params}\nFixedParameters: 0 0 0\n")
