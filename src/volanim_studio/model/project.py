"""The ``.volanim`` project file: small JSON naming the data files and view state.

    NAME.volanim   {"format": "volanim project", "version": 1, "demo", "volume", "volume_dims",
                    "threshold", "mskel", "bones", "connect", "thinness", "symmetry_x", "camera"}
    NAME.bones, NAME.connect (every attachment), NAME.mskel (when computed in the session)

Paths are stored relative to the project file when they are below it.
"""

from __future__ import annotations

import json
from pathlib import Path

from volanim_core import io
from volanim_core.io._atomic import atomic_write_text

PROJECT_FORMAT = "volanim project"


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
        "format": PROJECT_FORMAT, "version": 1, "demo": doc.demo_name,
        "volume": rel(doc.volume_path), "volume_dims": list(doc.volume_dims) if doc.volume_dims else None,
        "threshold": list(doc.threshold) if doc.threshold else None,
        "mskel": rel(mskel_path), "bones": rel(bones_path), "connect": rel(connect),
        "thinness": doc._thinness, "symmetry_x": doc._symmetry_x, "camera": camera,
    }
    atomic_write_text(path, json.dumps(data, indent=2) + "\n")
    return {"project": str(path), "bones": bones_path, "mskel": mskel_path, "connect": connect}




def read_project(path) -> dict:
    """A ``.volanim`` file's content with paths made absolute; FormatError when it is not one."""
    from volanim_core.errors import FormatError

    path = Path(path)
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError) as exc:
        raise FormatError(path, f"cannot read project: {exc}") from exc
    except json.JSONDecodeError as exc:
        raise FormatError(path, f"not a volanim project (JSON error: {exc.msg})", exc.lineno) from exc
    if not isinstance(data, dict) or data.get("format") != PROJECT_FORMAT:
        raise FormatError(path, f"not a volanim project: expected \"format\": \"{PROJECT_FORMAT}\"")
    for key in ("volume", "mskel", "bones", "connect"):
        if data.get(key):
            data[key] = str((path.parent / data[key]).resolve())
    return data
