"""What a project *is*: the ``.volanim`` file, and how it is written, read and applied (Qt-free).

    NAME.volanim  {"format": "volanim project", "version": 2,
                   "demo" | "volume" + "volume_dims",   what to load
                   "segmentation": {lo, hi, fill, metric, min_thinness},   how it was segmented
                   "mskel", "bones", "connect",           the data files (relative when below the project)
                   "thinness", "symmetry_x", "settings", "camera"}
    NAME.bones, NAME.connect (every attachment), NAME.mskel (when computed in the session)

Reopening loads the saved ``.mskel`` rather than skeletonizing again, and
segments the volume (the mask: auto-connect and sampled previews need it)
with the saved parameters, so the skeleton that comes back is the one the user
connected. Version 1 files (no ``segmentation``) read with the defaults of
their time: fill off, Euclidean, minimum thinness 0.5.
"""

from __future__ import annotations

import json
from pathlib import Path

from volanim_core import io
from volanim_core.errors import FormatError
from volanim_core.io._atomic import atomic_write_text
from volanim_core.skeleton.skeletonize import DEFAULT_MIN_THINNESS

PROJECT_FORMAT = "volanim project"
DEFAULT_SEGMENTATION = {"lo": 1, "hi": None, "fill": False, "metric": "euclid", "min_thinness": DEFAULT_MIN_THINNESS}


def write_project(doc, path, camera: dict | None = None, *, mskel: str | None = None) -> dict:
    """Write ``doc``'s project files; ``mskel`` names a skeleton file instead of writing one."""
    path = Path(path)
    stem = path.with_suffix("")
    bones_path = f"{stem}.bones"
    io.write_bones(bones_path, doc.bones)
    mskel_path = mskel or doc.mskel_path
    if doc.skeleton is not None and not mskel_path:
        mskel_path = f"{stem}.mskel"
        io.write_mskel(mskel_path, doc.skeleton)
    connect = None
    if len(doc.attachments.bone) and (doc.attachments.bone >= 0).any():
        connect = f"{stem}.connect"
        io.write_connect(connect, doc.attachments.to_connectivity())

    def rel(p):
        if not p:
            return None
        try:
            return str(Path(p).resolve().relative_to(path.parent.resolve()))
        except ValueError:
            return str(Path(p).resolve())

    data = {
        "format": PROJECT_FORMAT, "version": 2, "demo": doc.demo_name,
        "volume": rel(doc.volume_path), "volume_dims": list(doc.volume_dims) if doc.volume_dims else None,
        "segmentation": doc.segmentation, "mskel": rel(mskel_path), "bones": rel(bones_path), "connect": rel(connect),
        "thinness": doc.thinness, "symmetry_x": doc._symmetry_x, "settings": doc.settings.as_dict(),
        "camera": camera,
    }
    atomic_write_text(path, json.dumps(data, indent=2) + "\n")
    return {"project": str(path), "bones": bones_path, "mskel": mskel_path, "connect": connect}


def _expect(path, data: dict, key: str, kinds, what: str):
    value = data.get(key)
    if value is not None and not isinstance(value, kinds):
        raise FormatError(path, f"\"{key}\" must be {what}, got {type(value).__name__} {value!r}")
    return value


def read_project(path) -> dict:
    """A ``.volanim`` file's content, checked, with paths made absolute and ``segmentation`` filled in.

    Raises FormatError (naming the file, and the line for JSON errors) when it is not a project.
    """
    path = Path(path)
    try:
        data = json.loads(path.read_text(encoding="utf-8-sig"))
    except (OSError, UnicodeDecodeError) as exc:
        raise FormatError(path, f"cannot read project: {exc}") from exc
    except json.JSONDecodeError as exc:
        raise FormatError(path, f"not a volanim project (JSON error: {exc.msg})", exc.lineno) from exc
    except RecursionError:
        raise FormatError(path, "not a volanim project: nested too deeply") from None
    if not isinstance(data, dict) or data.get("format") != PROJECT_FORMAT:
        raise FormatError(path, f"not a volanim project: expected \"format\": \"{PROJECT_FORMAT}\"")
    _expect(path, data, "demo", str, "a sample name")
    for key in ("volume", "mskel", "bones", "connect"):
        if _expect(path, data, key, str, "a file name"):
            data[key] = str((path.parent / data[key]).resolve())
    for key in ("thinness", "symmetry_x"):
        _expect(path, data, key, int | float, "a number")
    for key in ("settings", "camera", "segmentation"):
        _expect(path, data, key, dict, "an object")
    _expect(path, data, "volume_dims", list, "a list of three sizes")
    seg = dict(DEFAULT_SEGMENTATION)
    seg.update({k: v for k, v in (data.get("segmentation") or {}).items() if k in seg})
    threshold = _expect(path, data, "threshold", list, "a list [lo, hi]")
    if threshold is not None and not data.get("segmentation"):  # version 1
        if len(threshold) != 2:
            raise FormatError(path, f"\"threshold\" must be a list [lo, hi], got {threshold!r}")
        seg["lo"], seg["hi"] = threshold
    data["segmentation"] = _checked_segmentation(path, seg)
    return data


def _checked_segmentation(path, seg: dict) -> dict:
    """The segmentation parameters, refused with the file's name when a value is not usable."""
    def number(key, allow_none=False):
        v = seg[key]
        if (v is None and allow_none) or (isinstance(v, int | float) and not isinstance(v, bool)):
            return
        raise FormatError(path, f"\"segmentation\": \"{key}\" must be a number, got {v!r}")

    number("lo")
    number("hi", allow_none=True)
    number("min_thinness")
    if not isinstance(seg["fill"], bool):
        raise FormatError(path, f"\"segmentation\": \"fill\" must be true or false, got {seg['fill']!r}")
    if seg["metric"] not in ("euclid", "345"):
        raise FormatError(path, f"\"segmentation\": \"metric\" must be \"euclid\" or \"345\", got {seg['metric']!r}")
    return seg


def apply_project(doc, data: dict, path) -> list[str]:
    """Load a read project's files and state into ``doc`` (after its volume, if any, is loaded).

    Returns warnings for the user (settings that were refused, points added).
    Raises FormatError for a data file that cannot be read; the document keeps
    what was applied before it.
    """
    warnings = []
    if data.get("mskel") and doc.skeleton is None:
        doc.set_skeleton(io.read_mskel(data["mskel"]), data["mskel"])
    elif data.get("mskel"):
        doc.mskel_path = data["mskel"]
    if data.get("bones"):
        doc.bone_edits.load_bones(data["bones"])
    if data.get("connect"):
        warnings += doc.attachments.load(data["connect"])
    if data.get("symmetry_x") is not None:
        doc.symmetry_x = data["symmetry_x"]
    if data.get("thinness") is not None:
        doc.thinness = data["thinness"]
    warnings += [f"{Path(path).name}: {w}" for w in doc.settings.update(data.get("settings") or {})]
    doc.project_path = str(path)
    doc.events.project.emit(path=str(path))
    return warnings
