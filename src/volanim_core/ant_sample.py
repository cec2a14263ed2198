"""The ant: pyvista's ant mesh with joints placed on it as a 3D Slicer user would, and a tripod gait.

    ant.ply (pyvista's wheel) --volanim voxelize--> ant.nrrd (mm of the mesh)
    ant.mrk.json: one point list per chain, in LPS mm (body; each leg from the thorax)
        --volanim markups --like ant.nrrd--> ant.bones
    ant.keys: legs swinging about the vertical, three at a time (the insects' tripod gait)

The joints are the centres of the voxelized ant's cross-sections (legs across x, the body across z); the mesh is
symmetric about x = 0, so each right leg is its left twin with x negated.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

BODY = {"ABDOMEN": (0.0, -1.0, -14.5), "WAIST": (0.0, -0.59, -4.87), "THORAX": (0.0, 1.49, -0.32),
        "NECK": (0.0, 1.5, 7.04), "HEAD": (0.0, 1.56, 10.5)}
# x > 0 is the ant's left (LPS); legs 1 front, 2 middle, 3 hind: hip, knee (the top of the arch), ankle, foot,
# each the centre of the leg's cross-section there
LEFT_LEGS = {1: ((3.0, -0.8, 3.2), (7.81, 1.06, 4.11), (10.62, -1.48, 4.61), (15.17, -8.3, 5.4)),
             2: ((3.0, -0.9, -1.19), (7.81, 1.19, -1.18), (10.62, -1.53, -1.24), (15.17, -7.8, -1.23)),
             3: ((3.0, -0.5, -6.4), (7.81, 1.12, -6.06), (10.62, -1.66, -6.55), (15.17, -8.33, -7.32))}
PARTS = ("HIP", "KNEE", "ANKLE", "FOOT")
SWING = 20.0  # degrees each femur swings forward and back about the vertical (y)


def chains() -> dict[str, list[tuple[str, tuple]]]:
    """Point lists as a user would place them in Slicer: the body, then each leg from the thorax."""
    out = {"body": list(BODY.items())}
    for side, sign in (("L", 1.0), ("R", -1.0)):
        for n, joints in LEFT_LEGS.items():
            pts = [(f"{side}_{part}{n}", (sign * p[0], p[1], p[2])) for part, p in zip(PARTS, joints)]
            out[f"{side}_leg{n}"] = [("THORAX", BODY["THORAX"]), *pts]
    return out


def markups() -> dict:
    lists = [{"type": "Curve" if name != "body" else "Fiducial", "coordinateSystem": "LPS", "coordinateUnits": "mm",
              "controlPoints": [{"id": str(k + 1), "label": label, "position": list(p), "positionStatus": "defined"}
                                for k, (label, p) in enumerate(points)]}
             for name, points in chains().items()]
    return {"@schema": "https://raw.githubusercontent.com/slicer/slicer/master/Modules/Loadable/Markups/Resources/"
                       "Schema/markups-schema-v1.0.3.json#", "markups": lists}


def keys_text() -> str:
    """A tripod gait, one step each way in 24 frames: legs L1, R2, L3 swing against R1, L2, R3."""
    lines = ["# volanim keys 1", "# the ant's tripod gait: FRAME BONE RX RY RZ", "fps 24", "length 25", "ease on"]
    tripod = {("L", 1): 1, ("R", 2): 1, ("L", 3): 1, ("R", 1): -1, ("L", 2): -1, ("R", 3): -1}
    for frame, phase in ((0, 1.0), (12, -1.0), (24, 1.0)):
        for (side, n), sign in tripod.items():
            lines.append(f"{frame} {side}_HIP{n}-{side}_KNEE{n} 0 {np.round(SWING * sign * phase, 3):g} 0")
    return "\n".join(lines) + "\n"


def write_ant_rig(folder: str | Path) -> list[Path]:
    """``ant.mrk.json`` and ``ant.keys`` into ``folder``."""
    from volanim_core.io.atomic import atomic_write_text

    folder = Path(folder)
    written = [folder / "ant.mrk.json", folder / "ant.keys"]
    atomic_write_text(written[0], json.dumps(markups(), indent=1) + "\n")
    atomic_write_text(written[1], keys_text())
    return written
