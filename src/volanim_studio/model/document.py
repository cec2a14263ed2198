"""The studio document: everything a session edits, with undo and change events.

    volume, mask, spacing ......... what was loaded (or None)
    skeleton (Skeleton) ........... the cloud, sorted by decreasing thinness
    hull (vertices, faces) ........ isosurface, drawn translucent and not pickable
    hull_lod ...................... a coarser one, drawn while a slider is held
    thinness ...................... the slider: points with thinness >= it are shown
    bones (BoneSkeleton) .......... named joints, bones in root order  [undoable: bone_edits]
    attachments ................... the bone of every skeleton point  [undoable]
    pose .......................... rotations per bone, the posed frame  [undoable]
    timeline ...................... a clip (BVH, .trans frames) or pose keys  [keys undoable]
    selected_bones, picked_point .. view state (not undoable)
    symmetry_x .................... mirror plane for Symmetrize
    settings ...................... view and tool settings (colours, preview, lasso, cube, mode, ...)
    camera ........................ the view's camera: the scene lends ``view_camera``; ``set_camera`` puts one back

What a project and an autosave hold of it is defined once, in
:mod:`~volanim_studio.model.document_state`.

Every setter validates, stores, then emits ``events.<name>``; views never
write the model except through these methods. Sub-models are handed the
document: ``bone_edits`` changes the bones, ``attachments`` the connectivity,
``pose`` the pose; each pushes its own commands on ``undo``.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from volanim_core.rig.bones import BoneSkeleton
from volanim_core.skeleton.points import Skeleton

from .attachments import Attachments
from .bone_edits import BoneEdits
from .events import EventEmitter
from .ownership_state import OwnershipState
from .posing import PoseState
from .proposal import BoneProposal
from .settings import Settings
from .timeline import Timeline
from .transfer import TransferState
from .undo import UndoStack

if TYPE_CHECKING:
    from .project import SaveTaken

#: Changes that make the shown picture (and its verdict) old, with the words the verdict says them in.
#: (A clip or keys matter through the pose they set: the timeline's own event is not one of these. Nor is the
#: transfer function: the picture is drawn again in its colours at once, and no verdict depends on them.)
STALE_AFTER = (("attachments", "the attachments"), ("bones", "the bones"), ("pose", "the pose"),
               ("thinness", "the thinness"), ("skeleton", "the skeleton"), ("ownership", "the ownership"))
STALE_AFTER_SETTINGS = ("preview_mode", "preview_kernel", "preview_padding", "joints", "blend", "body")


class Document:
    """The Qt-free model of one studio session."""

    def __init__(self):
        self.events = EventEmitter("volume", "skeleton", "hull", "thinness", "bones", "selection", "picked",
                                   "symmetry", "message", "project", "attachments", "filter", "cube",
                                   "point_selection", "pose", "pose_settled", "preview", "timeline", "camera",
                                   "transfer", "stale", "ownership", "owners_shown")
        self.undo = UndoStack()
        self.generation = 0  # counts reset(): which document a save in flight was taken from
        self.volume: np.ndarray | None = None
        self.mask: np.ndarray | None = None
        self.spacing = (1.0, 1.0, 1.0)
        self.volume_path: str | None = None
        self.volume_dims: tuple | None = None
        self.segmentation: dict | None = None  # threshold lo/hi, fill, metric, min_thinness (saved in projects)
        self.skeleton: Skeleton | None = None
        self.mskel_path: str | None = None
        self.hull: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None  # vertices, faces, normals
        self.hull_lod: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None  # drawn while a slider is held
        self._thinness = 0.0
        self.bones = BoneSkeleton()
        self.bones_path: str | None = None
        self.selected_bones: tuple[int, ...] = ()
        self.picked_point: int | None = None
        self.picked_joint: str | None = None  # the last joint clicked (F2 renames it, chains are named from it)
        self._symmetry_x: float | None = None
        self.project_path: str | None = None
        self.demo_name: str | None = None  # a session opened on a demo dataset reopens it
        self.settings = Settings()
        self.bone_edits = BoneEdits(self)
        self.proposal = BoneProposal(self)
        self.attachments = Attachments(self)
        self.ownership = OwnershipState(self)
        self.pose = PoseState(self)
        self.timeline = Timeline(self)
        self.transfer = TransferState(self)
        self.preview = None  # the last preview.Preview shown
        self.only_unconnected = False
        self.only_working = False
        self.cube_centre: np.ndarray | None = None
        self.point_selection = np.zeros(0, np.int64)  # the last cube / lasso selection
        self.camera: dict | None = None  # the last camera set or saved (the view's own when it lends it)
        self.view_camera = None  # () -> dict: the scene's camera now (a project saves what is on screen)
        # what a picture is of (#83: after an auto-connect, a lasso or an undo the old picture and its green
        # "healthy" stayed): every change that makes the shown preview old counts here; a preview carries the
        # count it was made at, and the verdict and the scene say "old" until one of the count now is shown
        self.body_pieces: int | None = None  # the segmented volume's pieces (a rest pose in more lost thin parts)
        self.picture_basis = 0
        self.picture_change: str | None = None  # what changed last, in words ("the attachments")
        for event, what in STALE_AFTER:
            getattr(self.events, event).connect(lambda _what=what, **_: self._picture_changed(_what))
        for name in STALE_AFTER_SETTINGS:
            getattr(self.settings.events, name).connect(lambda **_: self._picture_changed("the preview settings"))

    # ------------------------------------------------------------------ data
    def set_volume(self, volume, mask=None, *, spacing=(1.0, 1.0, 1.0), path=None, segmentation=None, dims=None):
        self.volume = volume
        self.mask = mask if mask is not None or volume is None else volume > 0
        self.spacing = tuple(float(s) for s in spacing)
        self.volume_path = str(path) if path else None
        self.volume_dims = tuple(dims) if dims is not None else None
        self.segmentation = dict(segmentation) if segmentation is not None else None
        self.events.volume.emit()
        self.events.symmetry.emit()

    def set_skeleton(self, skeleton: Skeleton | None, path=None, keep_attachments=None) -> None:
        """Replace the cloud; attachments start empty unless ``keep_attachments`` (one per point)."""
        if skeleton is not None and not skeleton.is_sorted():
            if keep_attachments is not None:
                raise ValueError("pass a sorted skeleton with its attachments")
            skeleton = skeleton.sorted()
        self.skeleton = skeleton
        self.mskel_path = str(path) if path else None
        self.picked_point = None
        n = 0 if skeleton is None else len(skeleton)
        if keep_attachments is not None:
            self.attachments.bone = np.asarray(keep_attachments, np.int32).copy()
        else:
            self.attachments.bone = np.full(n, -1, np.int32)
        if skeleton is not None and len(skeleton):
            lo, hi = float(skeleton.thinness.min()), float(skeleton.thinness.max())
            self._thinness = float(np.clip(self._thinness, lo, hi))
        self.events.skeleton.emit()
        self.events.thinness.emit(value=self._thinness)
        self.events.attachments.emit(indices=None)

    def set_hull(self, vertices, faces, normals=None, *, lod=None) -> None:
        """The hull to draw, ``(vertices, faces, normals)``, and ``lod``: a coarser one of it for frames drawn
        while a slider is held (None: the hull is light enough as it is). Normals not given are made here
        (:func:`~volanim_core.skeleton.hull.vertex_normals`); the volume's worker gives them, so the GUI
        thread only hands arrays to VTK."""
        self.hull = None if vertices is None else _hull(vertices, faces, normals)
        self.hull_lod = None if vertices is None or lod is None else _hull(*lod)
        self.events.hull.emit()

    @property
    def shape(self) -> tuple[int, int, int] | None:
        if self.volume is not None:
            return tuple(self.volume.shape[:3])  # a colour volume has its channels last
        if self.skeleton is not None and len(self.skeleton):
            return tuple(int(v) + 1 for v in self.skeleton.points.max(0))
        return None

    # ------------------------------------------------------------- thinness
    @property
    def thinness(self) -> float:
        return self._thinness

    @thinness.setter
    def thinness(self, value: float) -> None:
        value = float(value) + 0.0  # -0.0 is 0.0: a project says the same number it was saved with
        if not np.isfinite(value):
            raise ValueError(f"thinness must be a finite number, got {value!r}")
        if value == self._thinness:
            return
        self._thinness = value
        self.events.thinness.emit(value=value)

    @property
    def thinness_range(self) -> tuple[float, float]:
        if self.skeleton is None or not len(self.skeleton):
            return (0.0, 1.0)
        return float(self.skeleton.thinness.min()), float(self.skeleton.thinness.max())

    @property
    def visible_count(self) -> int:
        """Points shown: the sorted prefix with thinness >= the slider."""
        return 0 if self.skeleton is None else self.skeleton.count_at(self._thinness)

    # ------------------------------------------------------------- symmetry
    @property
    def symmetry_x(self) -> float:
        if self._symmetry_x is not None:
            return self._symmetry_x
        shape = self.shape
        return (shape[0] - 1) / 2.0 if shape else 0.0

    @symmetry_x.setter
    def symmetry_x(self, value: float) -> None:
        self._symmetry_x = float(value)
        self.events.symmetry.emit()

    # ------------------------------------------------------ picks and status
    def pick_point(self, index: int | None) -> None:
        if index is not None and (self.skeleton is None or not 0 <= index < len(self.skeleton)):
            raise ValueError(f"no skeleton point {index}")
        self.picked_point = index
        self.events.picked.emit(index=index)

    def pick_joint(self, name: str | None) -> None:
        if name is not None and name not in self.bones.joints:
            raise ValueError(f"no joint named {name!r}")
        self.picked_joint = name
        self.events.picked.emit(index=self.picked_point)

    @property
    def grid(self):
        """Where the voxels of the skeleton, bones and attachments are (the identity before a skeleton)."""
        from volanim_core.geometry import IDENTITY

        return self.skeleton.geometry if self.skeleton is not None else IDENTITY

    def point_info(self, index: int) -> dict:
        """What the status bar shows for a point: position, DT, thinness, its bone."""
        s = self.skeleton
        p = s.points[index]
        mm = s.geometry.to_physical(p[None])[0]  # where it is in the scan (LPS millimetres)
        return {"x": int(p[0]), "y": int(p[1]), "z": int(p[2]), "dt": float(s.dt[index]),
                "thinness": float(s.thinness[index]), "bone": self.bone_of_point(index),
                "mm": tuple(float(v) for v in mm), "dt_mm": float(s.dt[index]) * s.geometry.spacing[0]}

    def bone_of_point(self, index: int) -> str | None:
        """The bone a point is attached to, or None."""
        return self.attachments.label_of(index)

    @property
    def working_bone(self) -> int | None:
        """The bone Connect and Remove act on: the first selected bone."""
        return self.selected_bones[0] if self.selected_bones else None

    def set_filter(self, *, only_unconnected=None, only_working=None) -> None:
        """Show only unconnected points, or only the working bone's (not both)."""
        if only_unconnected is not None:
            self.only_unconnected = bool(only_unconnected)
            if self.only_unconnected:
                self.only_working = False
        if only_working is not None:
            self.only_working = bool(only_working)
            if self.only_working:
                self.only_unconnected = False
        self.events.filter.emit()

    def set_cube(self, centre) -> None:
        """Place (or move) the selection cube; ``centre`` None hides it (its size is a setting)."""
        self.cube_centre = None if centre is None else np.asarray(centre, np.float64)
        self.events.cube.emit()

    def set_preview(self, preview) -> None:
        self.preview = preview
        self.events.preview.emit()

    def _picture_changed(self, what: str) -> None:
        self.picture_basis += 1
        self.picture_change = what
        self.events.stale.emit(what=what)

    @property
    def preview_is_current(self) -> bool:
        """A preview is shown and nothing it depends on changed since it was asked for."""
        p = self.preview
        return p is not None and getattr(p, "basis", None) == self.picture_basis

    def set_camera(self, camera: dict | None) -> None:
        """Look from ``camera`` (a saved view: position, focal_point, view_up); the scene follows."""
        self.camera = None if camera is None else dict(camera)
        self.events.camera.emit(camera=self.camera)

    def camera_now(self) -> dict | None:
        """The camera to save: the view's own when a scene lends it, else the last one set."""
        return self.view_camera() if self.view_camera is not None else self.camera

    def set_point_selection(self, indices) -> None:
        self.point_selection = np.asarray(indices, np.int64)
        self.events.point_selection.emit()

    def shown_indices(self) -> np.ndarray:
        """Skeleton points on screen: the thinness prefix, then the filters."""
        idx = np.arange(self.visible_count)
        if self.only_unconnected:
            idx = idx[self.attachments.bone[idx] < 0]
        elif self.only_working:
            w = self.working_bone
            idx = idx[self.attachments.bone[idx] == (-2 if w is None else w)]
        return idx

    def select_bones(self, indices) -> None:
        indices = tuple(sorted({int(i) for i in indices}))
        for i in indices:
            if not 0 <= i < len(self.bones):
                raise ValueError(f"no bone {i}")
        if indices != self.selected_bones:
            self.selected_bones = indices
            self.events.selection.emit(indices=indices)

    def message(self, text: str) -> None:
        self.events.message.emit(text=text)

    def loading(self, load):
        """Run ``load()``, which puts a file into the session, as what it is: not an edit (issue #37).

        Ctrl+Z right after opening a file undid the opening. The history starts clean after a
        load, and the document reads as modified until saved: what was loaded is not in the project
        yet. A load that fails (raises) leaves the document and its history as they were.
        """
        result = load()
        self.undo.clear()
        return result

    # ------------------------------------------------------ document state
    @property
    def modified(self) -> bool:
        """Edits since the project was last saved or opened (undoing back to that state clears it)."""
        return not self.undo.is_clean

    @property
    def is_empty(self) -> bool:
        return self.skeleton is None and self.volume is None and not len(self.bones)

    def reset(self) -> None:
        """A new, empty document in this object (views stay subscribed): nothing loaded, no history.

        Opening a volume, a demo or a project starts here, so nothing of the previous
        project (bones, connectivity, pose, keys, its path) leaks into the new one.
        """
        self.generation += 1  # a save of the old document finishing now is not adopted by the new one
        self.timeline.unload()
        self.timeline._set_keys({})
        self.pose._write({}, {})
        self.selected_bones = ()
        self.picked_joint = None
        self.set_preview(None)
        self.set_hull(None, None)
        self.set_skeleton(None)  # points (and their attachments) before the bones they name: views index
        self.bone_edits._set_bones(BoneSkeleton())  # the bone colours with the attachments
        self.only_unconnected = self.only_working = False
        self.cube_centre = None
        self.point_selection = np.zeros(0, np.int64)
        self.body_pieces = None
        self._symmetry_x = None
        self.camera = None
        self.transfer._write(None)
        self.set_volume(None)
        self.bones_path = self.project_path = self.demo_name = None
        self.undo.clear()
        self.undo.mark_clean()
        self.events.project.emit(path=None)

    def check_savable(self) -> None:
        """Raise ValueError (in words for the status bar) when there is no project to save yet."""
        if self.skeleton is None and not len(self.bones):
            raise ValueError("nothing to save yet: open a volume, a demo or a project first (File menu)")

    def save_project(self, path) -> Path:
        """Save the project as one unit: ``NAME.volanim`` and its data files in ``NAME.volanim.d/``.

        The bone skeleton, the attachments (all of them, whatever the slider)
        and the skeleton are stored under content names; the manifest is
        replaced last (see :mod:`volanim_studio.model.project`). The studio's
        Save does the same in three steps (:meth:`take_save`, the write on a
        thread, :meth:`adopt_save`) so the GUI thread never formats files.
        """
        from .project import write_save

        save = self.take_save(path)
        self.adopt_save(save, write_save(save))
        return save.path

    def take_save(self, path) -> SaveTaken:
        """What a save of the document to ``path`` (``.volanim`` added when missing) writes, taken now
        (cheap: :class:`~volanim_studio.model.project.Snapshot`). Raises ValueError when nothing can be saved."""
        from .project import SaveTaken, snapshot

        self.check_savable()
        path = Path(path)
        if path.suffix != ".volanim":
            path = path.with_suffix(".volanim")
        return SaveTaken(path, snapshot(self, path), self.undo.state, self.generation)

    def adopt_save(self, save: SaveTaken, written: dict) -> bool:
        """The document is now the project ``save`` wrote (``written``: :func:`write_save`'s paths), unmodified
        as of when it was taken (edits made while it was written stay unsaved). False, and nothing adopted,
        when the document was replaced meanwhile (another volume or project opened)."""
        if save.generation != self.generation:
            return False
        self.bones_path = written["bones"]
        self.mskel_path = written["mskel"]
        self.project_path = str(save.path)
        self.undo.mark_clean(save.state)
        self.events.project.emit(path=str(save.path))
        return True

    def write_project(self, path) -> dict:
        """Write the project files without adopting their paths (what the tests of saves drive)."""
        from .project import SaveTaken, snapshot, write_save

        return write_save(SaveTaken(Path(path), snapshot(self, path), self.undo.state, self.generation))


def _hull(vertices, faces, normals=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    from volanim_core.skeleton.hull import vertex_normals

    vertices, faces = np.asarray(vertices), np.asarray(faces)
    return vertices, faces, vertex_normals(vertices, faces) if normals is None else np.asarray(normals)
