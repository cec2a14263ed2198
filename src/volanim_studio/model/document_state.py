"""The session as one state: every part of the document a project and an autosave hold, defined once.

    PARTS (in the order they are applied)
        settings   every view and tool setting (Settings: display, preview, tools, current frame, mode)
        thinness   the slider
        symmetry_x the mirror plane (None: the volume's mid-plane)
        timeline   clip (referenced), mapping, axes, keys, ease, length, fps
        pose       the current pose (after the timeline: the user's pose wins over its frame's)
        selection  the selected bones (by joints), the clicked joint and point
        camera     the view's camera (the scene lends doc.view_camera; doc.set_camera puts one back)
        transfer   the user's transfer function (None: each mode's own look)
        ownership  the animator's repaints of which bone owns which voxels (None: none)

    write_project --> part.save(doc, path)          one JSON value per part
    read_project  --> part.parse(value, path)       checked before anything is applied (FormatError names the file)
    apply_project --> part.apply(doc, parsed, path) -> warnings, in PARTS order

The data files (skeleton, bones, connectivity) and the volume are stored by
:mod:`~volanim_studio.model.project`; this module is everything else. A new
setting is saved with no change here (``settings`` saves them all); a new
document attribute must be placed in :data:`ATTRIBUTES` (its part, or why it is not saved),
and ``tests/studio/model/test_document_state.py`` fails until it is.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from volanim_core.errors import FormatError

from . import transfer
from .ownership_state import OwnershipState
from .posing import PoseState
from .timeline import Timeline


@dataclass(frozen=True)
class Part:
    key: str  # the project's JSON key
    save: Callable[[Any, Path], Any]  # (doc, project path) -> JSON value (None: nothing to save)
    parse: Callable[[Any, Path], Any]  # (JSON value, project path) -> checked value; FormatError naming the file
    apply: Callable[[Any, Any, Path], list[str]]  # (doc, checked value, project path) -> warnings


def relative_path(path: Path, target: str) -> str:
    """``target`` relative to the project's folder when it is inside it (the pair can move together)."""
    try:
        return str(Path(target).resolve().relative_to(path.parent.resolve()))
    except ValueError:
        return str(Path(target).resolve())


def _number(key: str):
    def parse(value, path):
        if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
            raise FormatError(path, f"\"{key}\" must be a finite number, got {value!r}")
        return float(value)
    return parse


def _object(key: str, then=None):
    """A JSON object, then ``then(value, where)`` (raising ValueError naming ``where``) as a FormatError."""
    def parse(value, path):
        if not isinstance(value, dict):
            raise FormatError(path, f"\"{key}\" must be an object, got {type(value).__name__} {value!r}")
        if then is None:
            return value
        try:
            return then(value, path.name)
        except ValueError as exc:
            raise FormatError(path, str(exc).removeprefix(f"{path.name}: ")) from None
    return parse


# ------------------------------------------------------------------ settings
def _apply_settings(doc, values: dict, path: Path) -> list[str]:
    return [f"{path.name}: {w}" for w in doc.settings.update(values)]


# ------------------------------------------------------------------ timeline
def _save_timeline(doc, path: Path) -> dict:
    data = doc.timeline.to_json()
    if data["clip"]:
        data["clip"]["path"] = relative_path(path, data["clip"]["path"])
    return data


def _parse_timeline(value, path: Path) -> dict:
    parsed = _object("timeline", Timeline.parse)(value, path)
    if parsed["clip"]:
        parsed["clip"]["path"] = str((path.parent / parsed["clip"]["path"]).resolve())
    return parsed


# ------------------------------------------------------------------ pose
def _apply_pose(doc, parsed, path: Path) -> list[str]:
    return [f"{path.name}: {w}" for w in doc.pose.restore(*parsed)]


# ------------------------------------------------------------------ selection
def _save_selection(doc, _path) -> dict:
    bones = doc.bones.bones
    return {"bones": [[bones[i].proximal, bones[i].distal] for i in doc.selected_bones],
            "joint": doc.picked_joint, "point": doc.picked_point}


def _parse_selection(value, path: Path) -> dict:
    if not isinstance(value, dict):
        raise FormatError(path, f"\"selection\" must be an object, got {type(value).__name__}")
    bones = value.get("bones") or []
    joint, point = value.get("joint"), value.get("point")
    if (not isinstance(bones, list) or len(bones) > 100_000
            or not all(isinstance(b, list) and len(b) == 2 and all(isinstance(j, str) for j in b) for b in bones)
            or not (joint is None or isinstance(joint, str))
            or not (point is None or (isinstance(point, int) and not isinstance(point, bool) and point >= 0))):
        raise FormatError(path, "\"selection\" must be {\"bones\": [[PROXIMAL, DISTAL], ...], \"joint\": NAME or "
                                f"null, \"point\": INDEX or null}}, got {value!r}"[:300])
    return {"bones": [tuple(b) for b in bones], "joint": joint, "point": point}


def _apply_selection(doc, sel: dict, path: Path) -> list[str]:
    index = {(b.proximal, b.distal): i for i, b in enumerate(doc.bones.bones)}
    doc.select_bones([index[k] for k in sel["bones"] if k in index])
    doc.pick_joint(sel["joint"] if sel["joint"] in doc.bones.joints else None)
    point = sel["point"]
    doc.pick_point(point if point is not None and doc.skeleton is not None and point < len(doc.skeleton) else None)
    return []


# ------------------------------------------------------------------ camera
CAMERA_KEYS = ("position", "focal_point", "view_up")


def check_camera(value, where: str) -> dict:
    """A saved view: three points of three finite numbers, the camera off its focal point and a view-up
    that is not zero (VTK draws nothing, or NaNs, from such a camera). ValueError naming ``where``."""
    if not isinstance(value, dict) or not all(
            isinstance(value.get(k), list) and len(value[k]) == 3 and all(
                isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v) for v in value[k])
            for k in CAMERA_KEYS):
        raise ValueError(f"{where}: \"camera\" must be {{\"position\": [x, y, z], \"focal_point\": [x, y, z], "
                         f"\"view_up\": [x, y, z]}} with finite numbers, got {value!r}"[:300])
    pos, focal, up = (np.asarray(value[k], np.float64) for k in CAMERA_KEYS)
    if np.allclose(pos, focal) or not np.linalg.norm(up) > 0 or np.linalg.norm(np.cross(up, focal - pos)) == 0:
        raise ValueError(f"{where}: \"camera\" looks nowhere: its position is its focal point, or its view-up "
                         "is zero or along the view")
    return {k: [float(v) for v in value[k]] for k in CAMERA_KEYS}


def _apply_camera(doc, camera: dict, _path) -> list[str]:
    doc.set_camera(camera)
    return []


PARTS: tuple[Part, ...] = (
    # the settings first: the current frame and the mode are among them, and the pose comes after the frame
    Part("settings", lambda doc, _: doc.settings.as_dict(), _object("settings"), _apply_settings),
    Part("thinness", lambda doc, _: doc.thinness, _number("thinness"),
         lambda doc, v, _: setattr(doc, "thinness", v) or []),
    Part("symmetry_x", lambda doc, _: doc._symmetry_x, _number("symmetry_x"),
         lambda doc, v, _: setattr(doc, "symmetry_x", v) or []),
    Part("timeline", _save_timeline, _parse_timeline, lambda doc, v, path: doc.timeline.restore(v, path.name)),
    Part("pose", lambda doc, _: doc.pose.to_json(), _object("pose", PoseState.parse), _apply_pose),
    Part("selection", _save_selection, _parse_selection, _apply_selection),
    Part("camera", lambda doc, _: doc.camera_now(), _object("camera", check_camera), _apply_camera),
    Part("transfer", lambda doc, _: transfer.to_json(doc.transfer.function), transfer.parse,
         lambda doc, tf, _: doc.transfer._write(tf) or []),
    Part("ownership", lambda doc, _: doc.ownership.to_json(), OwnershipState.parse,
         lambda doc, paints, _: doc.ownership.restore(paints)),
)

#: Where each Document attribute is kept by a project (a part, a data file, a key of the manifest), or why
#: it is not (the test walks ``vars(Document())``: an attribute added without a place here fails it).
ATTRIBUTES = {
    "events": "wiring", "undo": "history: a reopened project starts a new one", "bone_edits": "an editor of bones",
    "proposal": "a preview being looked at: the bones it applied are saved, the preview itself is not",
    "attachments": "saved as the .connect data file", "bones": "saved as the .bones data file",
    "skeleton": "saved as the .mskel data file", "pose": "the pose part", "timeline": "the timeline part",
    "settings": "the settings part", "_thinness": "the thinness part", "_symmetry_x": "the symmetry_x part",
    "selected_bones": "the selection part", "picked_joint": "the selection part", "picked_point": "the selection part",
    "camera": "the camera part", "view_camera": "the scene lends it: the camera part",
    "volume": "read again from the volume file", "mask": "segmented again with the saved segmentation",
    "spacing": "the volume file's, or the segmentation's spacing", "volume_path": "saved as \"volume\"",
    "volume_dims": "saved as \"volume_dims\"", "segmentation": "saved as \"segmentation\"",
    "mskel_path": "the .mskel data file's place", "bones_path": "the .bones data file's place",
    "project_path": "where the project is", "demo_name": "saved as \"demo\"",
    "hull": "made again from the volume", "hull_lod": "made again from the volume",
    "generation": "counts documents in one window, for saves in flight: a session starts its own",
    "preview": "a reconstruction: made again with F5",
    "picture_basis": "counts changes since the preview: a new session has no preview",
    "body_pieces": "counted again when the volume is segmented",
    "picture_change": "counts changes since the preview: a new session has no preview",
    "only_unconnected": "a filter of the Connect tab, per visit",
    "only_working": "a filter of the Connect tab, per visit", "cube_centre": "placed again with a click in Cube mode",
    "point_selection": "the last cube or lasso, per visit", "transfer": "the transfer part",
    "ownership": "the ownership part (the repaints; the ownership itself is made again from the volume)",
}


def save_all(doc, path) -> dict:
    """``{key: JSON value}`` of every part."""
    return {part.key: part.save(doc, Path(path)) for part in PARTS}


def parse_all(data: dict, path) -> dict:
    """Every part present in a project's JSON, checked (FormatError naming the file); absent or null
    parts are left out."""
    return {part.key: part.parse(data[part.key], Path(path)) for part in PARTS if data.get(part.key) is not None}


def apply_all(doc, parsed: dict, path) -> list[str]:
    """Put the parsed parts into ``doc`` in PARTS order (no undo steps); returns warnings for the user."""
    warnings: list[str] = []
    for part in PARTS:
        if part.key in parsed:
            warnings += part.apply(doc, parsed[part.key], Path(path))
    return warnings
