"""What a project *is*: the ``.volanim`` file, and how it is written, read and applied (Qt-free).

    NAME.volanim    {"format": "volanim project", "version": 3,
                     "demo" | "volume" + "volume_dims",   what to load (the volume is referenced, never copied)
                     "segmentation": {lo, hi, fill, metric, min_thinness},   how it was segmented
                     "bones", "connect", "mskel": "NAME.volanim.d/<kind>-<hash>.<kind>",
                     "sha256": {"bones": ..., ...},      what each data file must hash to
                     "settings", "thinness", "symmetry_x", "timeline", "pose", "selection", "camera"
                                                          the session's state: document_state.PARTS
    NAME.volanim.d/ the data files of the current and the previous save (``volanim_core.io.bundle``)

A save is one unit: the data files are written under content names first and
the manifest is renamed into place last, so a crash at any moment leaves the
previous save or the new one, never a mix. Reopening loads the saved
``.mskel`` rather than skeletonizing again, and segments the volume (the mask:
auto-connect and sampled previews need it) with the saved parameters, so the
skeleton that comes back is the one the user connected. Version 1 and 2 files
(data files beside the project, no hashes) still read; version 1 has no
``segmentation`` and gets the defaults of its time: fill off, Euclidean,
minimum thinness 0.5.
"""

from __future__ import annotations

import copy
import hashlib
import json
import math
import threading
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from volanim_core import io
from volanim_core.errors import FormatError
from volanim_core.io import bundle
from volanim_core.io.files import CHECKED_NUMBERS
from volanim_core.limits import checked_grid
from volanim_core.rig.bones import BoneSkeleton
from volanim_core.rig.skinning import Joints
from volanim_core.skeleton.skeletonize import DEFAULT_MIN_THINNESS

from . import document_state
from .attachments import connectivity
from .document_state import relative_path

PROJECT_FORMAT = "volanim project"
PROJECT_VERSION = 3
DEFAULT_SEGMENTATION = {"lo": 1, "hi": None, "fill": False, "metric": "euclid", "min_thinness": DEFAULT_MIN_THINNESS,
                        "spacing": None,  # spacing: the voxel size the user confirmed (None: the file's)
                        "series": None}  # series: the DICOM series chosen from a folder of several
DATA_FILES = ("mskel", "bones", "connect")
_stored: dict = {}  # (store folder, kind) -> (fingerprint, skeleton, relative path, sha256): written once
_stored_lock = threading.Lock()  # an autosave writes on its own thread while Save writes on the GUI's


@dataclass(frozen=True)
class Snapshot:
    """What one project save writes, taken from the document at one moment.

    Taking it is cheap (the bones deep-copied, the attachment array copied, the session's JSON parts;
    the skeleton by reference, since the document replaces it and never changes it in place), so an
    autosave takes one on the GUI thread and formats and writes the files on its own thread while the
    user goes on editing (#83: a held drag once held back the autosave of finished edits).
    """

    bones: BoneSkeleton
    grid: object
    skeleton: object  # volanim_core Skeleton or None
    attached: np.ndarray  # each skeleton point's bone (-1: none), a copy
    joints: Joints
    fields: dict  # the manifest's keys besides the data files: what to load, the segmentation, the state

    @property
    def is_empty(self) -> bool:
        """Nothing a user made: no volume, no skeleton, no bones."""
        return self.skeleton is None and not len(self.bones) and not (self.fields.get("volume")
                                                                     or self.fields.get("demo"))


def snapshot(doc, path, *, state: dict | None = None) -> Snapshot:
    """The document as :func:`write_snapshot` writes it to ``path`` (see :class:`Snapshot`); ``state``:
    ``document_state.save_all(doc, path)`` when the caller has it already."""
    path = Path(path)
    volume = relative_path(path, doc.volume_path) if doc.volume_path else None
    fields = {"format": PROJECT_FORMAT, "version": PROJECT_VERSION, "demo": doc.demo_name, "volume": volume,
              "volume_dims": list(doc.volume_dims) if doc.volume_dims else None,
              "segmentation": copy.deepcopy(doc.segmentation),
              **copy.deepcopy(document_state.save_all(doc, path) if state is None else state)}
    return Snapshot(copy.deepcopy(doc.bones), doc.grid, doc.skeleton, doc.attachments.bone.copy(),
                    Joints(doc.settings.joints, doc.settings.blend), fields)


@dataclass(frozen=True)
class SaveTaken:
    """A project save taken from the document (:meth:`Document.take_save`): where, what, and the undo
    history's :attr:`~volanim_studio.model.undo.UndoStack.state` and the document's ``generation`` then, so
    the document adopts it only as of that moment and only if it is still the same document."""

    path: Path
    snap: Snapshot
    state: object
    generation: int


def write_save(save: SaveTaken) -> dict:
    """Write ``save`` (any thread); a failure (a full disk) removes the data files it stored, which no
    manifest names. Returns the absolute paths written (:func:`write_snapshot`)."""
    try:
        return write_snapshot(save.snap, save.path)
    except BaseException:
        bundle.collect_garbage(save.path)
        raise


def _store_once(path: Path, kind: str, suffix: str, skeleton, fingerprint, write) -> tuple[str, str]:
    """The stored file of ``kind``; one already stored for this project from the same ``skeleton`` object and
    ``fingerprint`` is not formatted and written again (an autosave after a pose change wrote the frog's
    .connect anew: 1 s of number formatting for nothing, #65)."""
    key = (str(bundle.store_folder(path).resolve()), kind)
    with _stored_lock:
        hit = _stored.get(key)
    if hit is not None and hit[0] == fingerprint and hit[1] is skeleton and (path.parent / hit[2]).is_file():
        return hit[2], hit[3]
    rel, digest = bundle.store_file(path, kind, suffix, write)
    with _stored_lock:
        if len(_stored) > 16:
            _stored.clear()
        _stored[key] = (fingerprint, skeleton, rel, digest)
    return rel, digest


def _connect_fingerprint(snap: Snapshot) -> tuple:
    """What a .connect is made of besides the skeleton's own arrays: each point's bone, the bones, the joints."""
    digest = hashlib.sha256(snap.attached.tobytes())
    digest.update(np.ascontiguousarray(snap.bones.segments(), np.float64).tobytes())
    return (id(snap.skeleton), digest.hexdigest(), tuple(b.label for b in snap.bones.bones),
            snap.joints.kind, snap.joints.blend)


def write_snapshot(snap: Snapshot, path) -> dict:
    """Write one project save of ``snap`` (any thread: it reads nothing of the document); returns the
    absolute paths written."""
    path = Path(path)
    stored = {}
    if len(snap.bones):  # a .bones file with no bones is not a valid file: a project without bones has none
        stored["bones"] = bundle.store_file(path, "bones", ".bones", lambda p: io.write_bones(p, snap.bones, snap.grid))
    if snap.skeleton is not None:
        stored["mskel"] = _store_once(path, "skeleton", ".mskel", snap.skeleton, id(snap.skeleton),
                                      lambda p: io.write_mskel(p, snap.skeleton))
    if len(snap.attached) and (snap.attached >= 0).any():
        stored["connect"] = _store_once(
            path, "connect", ".connect", snap.skeleton, _connect_fingerprint(snap),
            lambda p: io.write_connect(p, connectivity(snap.skeleton, snap.bones, snap.attached, snap.joints)))
    data = {**snap.fields, **{key: rel for key, (rel, _) in stored.items()},
            "sha256": {key: digest for key, (_, digest) in stored.items()}}
    keys = ["format", "version", "demo", "volume", "volume_dims", "segmentation", *stored, "sha256"]
    data = {k: data[k] for k in keys} | {k: v for k, v in data.items() if k not in keys}  # the order it always had
    bundle.commit(path, numbers_as_values(data))
    written = {"project": str(path), "bones": None, "mskel": None, "connect": None}
    written.update({key: str((path.parent / rel).resolve()) for key, (rel, _) in stored.items()})
    return written


def numbers_as_values(data):
    """``data`` with every -0.0 made 0.0: a project's numbers mean their value, and JSON text that says
    ``-0.0`` for what a reopened document holds as ``0.0`` would read as a change (docs/formats.md#project)."""
    if isinstance(data, float):
        return data + 0.0
    if isinstance(data, dict):
        return {k: numbers_as_values(v) for k, v in data.items()}
    if isinstance(data, list | tuple):
        return [numbers_as_values(v) for v in data]
    return data


def _expect(path, data: dict, key: str, kinds, what: str):
    value = data.get(key)
    if value is not None and not isinstance(value, kinds):
        raise FormatError(path, f"\"{key}\" must be {what}, got {type(value).__name__} {value!r}")
    return value


def read_project(path) -> dict:
    """A ``.volanim`` file's content, checked, with paths made absolute and ``segmentation`` filled in.

    Its data files are checked against the saved hashes; when the last save is
    damaged the previous one is read and ``data["warnings"]`` says so. Raises
    FormatError (naming the file, and the line for JSON errors) when neither is usable.
    """
    path = Path(path)
    data, warnings = bundle.load(path, _parse)
    for key in ("volume", *DATA_FILES):
        if data.get(key):
            data[key] = str((path.parent / data[key]).resolve())
    data["warnings"] = warnings
    return data


def _parse(path: Path, text: str) -> dict:
    try:
        data = json.loads(text, **CHECKED_NUMBERS)  # one number parser: a 401-digit angle raised OverflowError
    except json.JSONDecodeError as exc:
        raise FormatError(path, f"not a volanim project (JSON error: {exc.msg})", exc.lineno) from exc
    except RecursionError:
        raise FormatError(path, "not a volanim project: nested too deeply") from None
    except ValueError as exc:  # the number hooks
        raise FormatError(path, f"holds {exc}") from None
    if not isinstance(data, dict) or data.get("format") != PROJECT_FORMAT:
        raise FormatError(path, f"not a volanim project: expected \"format\": \"{PROJECT_FORMAT}\"")
    version = _expect(path, data, "version", int, "a whole number")
    if version is not None and not isinstance(version, bool) and version > PROJECT_VERSION:
        raise FormatError(path, f"was saved by a newer volanim (project version {version}; "
                                f"this one reads up to {PROJECT_VERSION})")
    _expect(path, data, "demo", str, "a sample name")
    for key in ("volume", *DATA_FILES):
        _expect(path, data, key, str, "a file name")
    for key in ("segmentation", "sha256"):
        _expect(path, data, key, dict, "an object")
    data["state"] = document_state.parse_all(data, path)  # every part checked before anything is applied
    dims = _expect(path, data, "volume_dims", list, "a list of three sizes")
    if dims is not None:  # sizes of a headerless .vol: the same limits as any volume header
        checked_grid(path, dims, what="\"volume_dims\"")
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
        if (v is None and allow_none) or (isinstance(v, int | float) and not isinstance(v, bool)
                                          and (math.isfinite(v) or (key == "min_thinness" and v < 0))):
            return  # -inf is a valid minimum thinness (keep every point); NaN never is
        raise FormatError(path, f"\"segmentation\": \"{key}\" must be a number, got {v!r}")

    number("lo")
    number("hi", allow_none=True)
    number("min_thinness")
    if not isinstance(seg["fill"], bool):
        raise FormatError(path, f"\"segmentation\": \"fill\" must be true or false, got {seg['fill']!r}")
    sp = seg["spacing"]
    if sp is not None and not (isinstance(sp, list) and len(sp) == 3 and all(
            isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v) and v > 0 for v in sp)):
        raise FormatError(path, f"\"segmentation\": \"spacing\" must be three positive numbers, got {sp!r}")
    if seg["series"] is not None and not (isinstance(seg["series"], str) and 0 < len(seg["series"]) <= 128):
        raise FormatError(path, f"\"segmentation\": \"series\" must be a DICOM series UID, got {seg['series']!r}")
    if seg["metric"] not in ("euclid", "345"):
        raise FormatError(path, f"\"segmentation\": \"metric\" must be \"euclid\" or \"345\", got {seg['metric']!r}")
    return seg


@dataclass(frozen=True)
class ProjectFiles:
    """A project's data files, read (in a worker: a large skeleton or a clip of a thousand ``.trans``
    frames took seconds on the GUI thread, #83), ready for :func:`apply_project`."""
    skeleton: object = None  # the MultiSkeleton, when it is to be read (a document without one)
    bones: object = None
    connect: object = None
    clip: dict | None = None  # the timeline clip's content: {"motion": Motion} or {"frames": (mats, files)}
    # or {"error": text} (a clip that cannot be read is a warning when applied, never a failure)


def read_project_files(data: dict, path, *, skeleton: bool, grid=None) -> ProjectFiles:
    """Read the data files ``data`` (:func:`read_project`'s) names, and its timeline clip, without touching
    any document; ``skeleton``: the ``.mskel`` too (a document that has none yet); ``grid``: the Geometry
    the bones will be put on (the loaded skeleton's; else the ``.mskel``'s). A bad data file raises
    FormatError naming the project, then the file."""
    sk = _data_file(data, path, "mskel", io.read_mskel) if data.get("mskel") and skeleton else None
    bones = _data_file(data, path, "bones", io.read_bones) if data.get("bones") else None
    conn = _data_file(data, path, "connect", io.read_connect) if data.get("connect") else None
    clip = (data["state"].get("timeline") or {}).get("clip")
    grid = grid if grid is not None else (sk.geometry if sk is not None else None)
    content = None
    if clip and bones is not None:  # frames are read against the bones as the document will hold them
        content = _read_clip(clip, bones if grid is None else bones.on_grid(grid))
        content["grid"] = grid
    return ProjectFiles(sk, bones, conn, content)


def _data_file(data: dict, path, key: str, read):
    try:
        return read(data[key])
    except FormatError as exc:  # the project is what the user opened: name it, then the file
        raise FormatError(path, f"its {key} file: {exc}") from None


def _read_clip(clip: dict, bones) -> dict:
    """A timeline clip's file(s), read as :meth:`Timeline.restore` takes them."""
    from volanim_core.io.clip_files import read_clip
    from volanim_core.io.frame_files import read_frames

    from .timeline import retarget_clip

    try:
        if clip["kind"] == "bvh":
            motion = read_clip(clip["path"], clip.get("animation"))
            return {"motion": motion, "built": retarget_clip(clip["path"], bones, motion, clip.get("mapping"),
                                                              clip.get("up", "auto"), clip.get("forward", "auto"))}
        return {"frames": read_frames(clip["path"], bones)}
    except (OSError, ValueError) as exc:  # FormatError is a ValueError
        return {"error": str(exc)}


def apply_project(doc, data: dict, path, *, reset: bool = False, files: ProjectFiles | None = None) -> list[str]:
    """Load a read project's files and state into ``doc`` (after its volume, if any, is loaded).

    ``files``: :func:`read_project_files`' result, read in a worker (read here when None). Every
    data file is read before the document is touched, so a bad file (FormatError, naming it) leaves
    the document as it was; ``reset`` empties it first (a project without a volume or demo is a new
    document too). Returns warnings for the user (the previous save was used, settings refused,
    points added). The studio applies it in the two steps this is made of (:func:`apply_project_files`,
    then :func:`apply_project_state` at the next pass of its event loop): one pass of both took
    mannequin-large's GUI thread 110 ms.
    """
    warnings, state = apply_project_files(doc, data, path, reset=reset, files=files)
    return warnings + apply_project_state(doc, state, path)


def apply_project_files(doc, data: dict, path, *, reset: bool = False,
                        files: ProjectFiles | None = None) -> tuple[list[str], dict]:
    """The first step of :func:`apply_project`: the skeleton, bones and attachments. Returns its warnings
    and the session state for :func:`apply_project_state`."""
    warnings = list(data.get("warnings") or [])
    fresh = reset or doc.skeleton is None
    if files is None:
        files = read_project_files(data, path, skeleton=fresh)
    skeleton = files.skeleton if fresh else None
    if skeleton is None and fresh and data.get("mskel"):  # read without it: the document had one then
        skeleton = _data_file(data, path, "mskel", io.read_mskel)
    bones, conn = files.bones, files.connect
    state = data["state"]
    held = skeleton if skeleton is not None else None if reset else doc.skeleton  # load_bones puts bones on it
    grid = held.geometry if held is not None else None
    if (files.clip is not None and files.clip["grid"] == grid and state.get("timeline")
            and state["timeline"].get("clip")):  # else read again, on the grid the bones are put on
        state = {**state, "timeline": {**state["timeline"], "clip": {**state["timeline"]["clip"], "read": files.clip}}}
    if reset:  # a new document, once every file has been read
        doc.reset()
    if skeleton is not None:
        doc.set_skeleton(skeleton, data["mskel"])
    elif data.get("mskel"):
        doc.mskel_path = data["mskel"]
    if bones is not None:
        doc.bone_edits.load_bones(data["bones"], bones)
    if conn is not None:
        warnings += doc.attachments.apply_connectivity(conn, Path(data["connect"]).name)
    return warnings, state


def apply_project_state(doc, state: dict, path) -> list[str]:
    """The second step of :func:`apply_project`: the session's state (settings, pose, timeline, camera...);
    the document is then the project at ``path``, unmodified, with no history. Returns warnings."""
    warnings = document_state.apply_all(doc, state, path)
    doc.project_path = str(path)
    # opening is not an edit: Ctrl+Z right after it undid "Load connect", then the bones (issue #37)
    doc.undo.clear()
    doc.undo.mark_clean()
    doc.events.project.emit(path=str(path))
    return warnings
