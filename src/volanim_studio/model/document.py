"""The studio document: everything a session edits, with undo and change events.

    volume, mask, spacing ......... what was loaded (or None)
    skeleton (Skeleton) ........... the cloud, sorted by decreasing thinness
    hull (vertices, faces) ........ isosurface, drawn translucent and not pickable
    thinness ...................... the slider: points with thinness >= it are shown
    bones (BoneSkeleton) .......... named joints, bones in root order  [undoable]
    selected_bones, picked_point .. view state (not undoable)
    symmetry_x .................... mirror plane for Symmetrize

Every setter validates, stores, then emits ``events.<name>``; views never
write the model except through these methods. Bone edits are snapshot
commands on the UndoStack: a bone skeleton is small, so a copy per edit is
simpler and safer than hand-written inverse operations.
"""

from __future__ import annotations

import copy
from pathlib import Path

import numpy as np

from volanim_core import io
from volanim_core.bones import Bone, BoneSkeleton
from volanim_core.skeleton import Skeleton

from . import symmetry
from .attachments import Attachments
from .events import EventEmitter
from .posing import PoseState
from .project import read_project  # noqa: F401  (re-exported: the window opens projects through the document module)
from .undo import Command, UndoStack

SNAP_DISTANCE = 0.5  # voxels: a click this close to a joint reuses it


class Document:
    """The Qt-free model of one studio session."""

    def __init__(self):
        self.events = EventEmitter("volume", "skeleton", "hull", "thinness", "bones", "selection", "picked",
                                   "symmetry", "message", "project", "attachments", "filter", "cube",
                                   "point_selection", "pose", "preview")
        self.undo = UndoStack()
        self.volume: np.ndarray | None = None
        self.mask: np.ndarray | None = None
        self.spacing = (1.0, 1.0, 1.0)
        self.volume_path: str | None = None
        self.volume_dims: tuple | None = None
        self.threshold: tuple | None = None
        self.skeleton: Skeleton | None = None
        self.mskel_path: str | None = None
        self.hull: tuple[np.ndarray, np.ndarray] | None = None
        self._thinness = 0.0
        self.bones = BoneSkeleton()
        self.bones_path: str | None = None
        self.selected_bones: tuple[int, ...] = ()
        self.picked_point: int | None = None
        self._symmetry_x: float | None = None
        self.project_path: str | None = None
        self.demo_name: str | None = None  # a session opened on a demo dataset reopens it
        self._joint_counter = 0
        self.attachments = Attachments(self)
        self.pose = PoseState(self)
        self.preview = None  # the last preview.Preview shown
        self.only_unconnected = False
        self.only_working = False
        self.cube_centre: np.ndarray | None = None
        self.cube_size = 10.0
        self.point_selection = np.zeros(0, np.int64)  # the last cube / lasso selection

    # ------------------------------------------------------------------ data
    def set_volume(self, volume, mask=None, *, spacing=(1.0, 1.0, 1.0), path=None, threshold=None, dims=None):
        self.volume = volume
        self.mask = mask if mask is not None or volume is None else volume > 0
        self.spacing = tuple(float(s) for s in spacing)
        self.volume_path = str(path) if path else None
        self.volume_dims = tuple(dims) if dims is not None else None
        self.threshold = tuple(threshold) if threshold is not None else None
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

    def set_hull(self, vertices, faces) -> None:
        self.hull = None if vertices is None else (np.asarray(vertices), np.asarray(faces))
        self.events.hull.emit()

    @property
    def shape(self) -> tuple[int, int, int] | None:
        if self.volume is not None:
            return tuple(self.volume.shape)
        if self.skeleton is not None and len(self.skeleton):
            return tuple(int(v) + 1 for v in self.skeleton.points.max(0))
        return None

    # ------------------------------------------------------------- thinness
    @property
    def thinness(self) -> float:
        return self._thinness

    @thinness.setter
    def thinness(self, value: float) -> None:
        value = float(value)
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

    def point_info(self, index: int) -> dict:
        """What the status bar shows for a point: position, DT, thinness, its bone."""
        s = self.skeleton
        p = s.points[index]
        return {"x": int(p[0]), "y": int(p[1]), "z": int(p[2]), "dt": float(s.dt[index]),
                "thinness": float(s.thinness[index]), "bone": self.bone_of_point(index)}

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

    def set_cube(self, centre, size: float | None = None) -> None:
        """Place (or move) the selection cube; ``centre`` None hides it."""
        self.cube_centre = None if centre is None else np.asarray(centre, np.float64)
        if size is not None:
            if not size > 0:
                raise ValueError(f"cube size must be positive, got {size}")
            self.cube_size = float(size)
        self.events.cube.emit()

    def set_preview(self, preview) -> None:
        self.preview = preview
        self.events.preview.emit()

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

    # ------------------------------------------------------------ bone edits
    def _apply_bones(self, label: str, new: BoneSkeleton, remap: np.ndarray | None = None) -> None:
        """One undo step: the new bone skeleton and, when bones are renumbered
        (``remap[old index] = new index`` or -1), the attachments that follow."""
        old = copy.deepcopy(self.bones)
        new = copy.deepcopy(new)
        new.validate()
        changed = old_vals = new_vals = None
        if remap is not None and len(self.attachments.bone):
            after = self.attachments.remapped(np.asarray(remap, np.int32))
            changed = np.flatnonzero(after != self.attachments.bone)
            old_vals, new_vals = self.attachments.bone[changed].copy(), after[changed]

        def redo():
            self._set_bones(copy.deepcopy(new))
            if changed is not None and len(changed):
                self.attachments._write(changed, new_vals)

        def undo():
            self._set_bones(copy.deepcopy(old))
            if changed is not None and len(changed):
                self.attachments._write(changed, old_vals)

        self.undo.push(Command(label, redo, undo))

    def _set_bones(self, bones: BoneSkeleton) -> None:
        self.bones = bones
        self.selected_bones = tuple(i for i in self.selected_bones if i < len(bones))
        self.events.bones.emit()
        self.events.selection.emit(indices=self.selected_bones)

    def _edited(self) -> BoneSkeleton:
        return copy.deepcopy(self.bones)

    def joint_at(self, position, tolerance: float = SNAP_DISTANCE) -> str | None:
        """The joint within ``tolerance`` voxels of ``position``, if any."""
        best, name = tolerance, None
        for n, xyz in self.bones.joints.items():
            d = float(np.linalg.norm(xyz - np.asarray(position, float)))
            if d <= best:
                best, name = d, n
        return name

    def default_joint_name(self, position) -> str:
        """``L_J7`` / ``R_J7`` / ``J7`` by the side of the symmetry plane: the UI nudges towards L_/R_."""
        while True:
            self._joint_counter += 1
            x = float(position[0])
            prefix = "" if abs(x - self.symmetry_x) < 1.0 else ("L_" if x > self.symmetry_x else "R_")
            name = f"{prefix}J{self._joint_counter}"
            if name not in self.bones.joints:
                return name

    def add_bone(self, a, b, name: str = "") -> int:
        """A bone from joint/position ``a`` to joint/position ``b``; returns its index.

        ``a``/``b`` are joint names or positions; a position reuses a joint
        within :data:`SNAP_DISTANCE` or creates a new one. One undo step.
        """
        new = self._edited()
        names = []
        for end in (a, b):
            if isinstance(end, str):
                if end not in new.joints:
                    raise ValueError(f"no joint named {end!r}")
                names.append(end)
                continue
            found = self.joint_at(end)
            if found is None:
                found = next((n for n, xyz in new.joints.items() if np.allclose(xyz, end)), None)
            if found is None:
                found = self.default_joint_name(end)
                new.joints[found] = np.asarray(end, np.float64)
            names.append(found)
        if names[0] == names[1]:
            raise ValueError("a bone needs two different joints")
        if any({x.proximal, x.distal} == set(names) for x in new.bones):
            raise ValueError(f"there is already a bone between {names[0]} and {names[1]}")
        new.bones.append(Bone(names[0], names[1], name))
        self._apply_bones(f"Add bone {names[0]}-{names[1]}", new)
        return len(self.bones) - 1

    def remove_bones(self, indices) -> None:
        """Remove bones; joints no bone uses any more go too. One undo step."""
        indices = set(int(i) for i in indices)
        if not indices:
            return
        new = self._edited()
        new.bones = [b for i, b in enumerate(new.bones) if i not in indices]
        used = {j for b in new.bones for j in (b.proximal, b.distal)}
        new.joints = {k: v for k, v in new.joints.items() if k in used}
        remap = np.full(len(self.bones), -1, np.int32)
        kept = [i for i in range(len(self.bones)) if i not in indices]
        remap[kept] = np.arange(len(kept))
        self.selected_bones = ()
        self._apply_bones(f"Remove {len(indices)} bone(s)", new, remap)

    def rename_joint(self, old: str, new_name: str) -> None:
        new_name = new_name.strip()
        if not new_name or any(c.isspace() for c in new_name):
            raise ValueError(f"joint names cannot be empty or contain spaces: {new_name!r}")
        if old == new_name:
            return
        if new_name in self.bones.joints:
            raise ValueError(f"there is already a joint named {new_name!r}")
        new = self._edited()
        new.joints = {(new_name if k == old else k): v for k, v in new.joints.items()}
        new.bones = [Bone(new_name if b.proximal == old else b.proximal, new_name if b.distal == old else b.distal,
                          b.name) for b in new.bones]
        self._apply_bones(f"Rename joint {old} to {new_name}", new)

    def rename_bone(self, index: int, name: str) -> None:
        name = name.strip()
        if any(c.isspace() for c in name):
            raise ValueError(f"bone names cannot contain spaces: {name!r}")
        new = self._edited()
        b = new.bones[index]
        new.bones[index] = Bone(b.proximal, b.distal, name)
        self._apply_bones(f"Rename bone {b.label} to {name or '(none)'}", new)

    def move_joint(self, name: str, position) -> None:
        new = self._edited()
        new.joints[name] = np.asarray(position, np.float64)
        self._apply_bones(f"Move joint {name}", new)

    def set_root_order(self, order) -> None:
        """Reorder bones: ``order[k]`` is the old index of the new bone k."""
        order = [int(i) for i in order]
        if sorted(order) != list(range(len(self.bones))):
            raise ValueError(f"root order must be a permutation of 0..{len(self.bones) - 1}, got {order}")
        if order == list(range(len(self.bones))):
            return
        new = self._edited()
        new.bones = [new.bones[i] for i in order]
        remap = np.empty(len(order), np.int32)
        remap[order] = np.arange(len(order))
        self._apply_bones("Reorder bones", new, remap)

    def set_bones(self, bones: BoneSkeleton, label: str = "Load bones") -> None:
        """Replace the bone skeleton; attachments follow bones with the same joints, others are cleared."""
        keys = {(b.proximal, b.distal): i for i, b in enumerate(bones.bones)}
        remap = np.array([keys.get((b.proximal, b.distal), -1) for b in self.bones.bones], np.int32)
        self._apply_bones(label, bones, remap)

    def symmetrize(self, indices=None) -> list[str]:
        """Mirror bones (default: the selection) to the other side by their L_/R_ names.

        Each sided joint's twin (``L_X`` <-> ``R_X``) is created or moved to
        the mirror image across ``x = symmetry_x``, snapped to the nearest
        skeleton point; centre joints stay. Missing twin bones are added.
        Returns the names of the joints written. One undo step.
        """
        indices = self.selected_bones if indices is None else tuple(indices)
        if not indices:
            raise ValueError("select the bones to mirror first")
        new = self._edited()
        pts = self.skeleton.points if self.skeleton is not None else None
        written = []
        for i in indices:
            b = new.bones[i]
            if symmetry.side(b.proximal) is None and symmetry.side(b.distal) is None:
                raise ValueError(f"bone {b.label} has no L_/R_ joint to mirror; rename its joints first")
            twin_ends = []
            for j in (b.proximal, b.distal):
                t = symmetry.mirror_name(j)
                if t != j:
                    new.joints[t] = symmetry.snap(pts, symmetry.mirror_point(new.joints[j], self.symmetry_x))
                    written.append(t)
                twin_ends.append(t)
            twin = Bone(twin_ends[0], twin_ends[1], symmetry.mirror_name(b.name) if b.name else "")
            existing = [k for k, x in enumerate(new.bones) if (x.proximal, x.distal) == tuple(twin_ends)]
            if existing:
                new.bones[existing[0]] = twin
            else:
                new.bones.append(twin)
        self._apply_bones(f"Symmetrize {len(indices)} bone(s)", new)
        return written

    # ----------------------------------------------------------------- files
    def load_bones(self, path) -> None:
        bones = io.read_bones(path)
        self.set_bones(bones, f"Load {Path(path).name}")
        self.bones_path = str(path)

    def load_connections(self, path) -> None:
        """Take the bone list (root order) from a ``.connections`` file over the loaded joints.

        Bones that stay keep their names and attachments. One undo step.
        """
        pairs = io.read_connections(path)
        missing = sorted({j for pair in pairs for j in pair} - set(self.bones.joints))
        if missing:
            raise ValueError(f"{Path(path).name} names joints that are not loaded: {', '.join(missing)}; "
                             "open the .bones file with those joints first")
        names = {(b.proximal, b.distal): b.name for b in self.bones.bones}
        new = BoneSkeleton(copy.deepcopy(self.bones.joints), [Bone(a, b, names.get((a, b), "")) for a, b in pairs])
        self.set_bones(new, f"Load {Path(path).name}")

    def save_bones(self, path) -> None:
        io.write_bones(path, self.bones)
        self.bones_path = str(path)

    def save_connections(self, path) -> None:
        io.write_connections(path, self.bones)

    def save_project(self, path, camera: dict | None = None) -> Path:
        """Write ``NAME.volanim`` (JSON) plus the data it names that exists only in memory.

        The bone skeleton goes to ``NAME.bones``, the attachments (all of them,
        whatever the slider) to ``NAME.connect``, and a skeleton computed in
        this session (no ``.mskel`` on disk yet) to ``NAME.mskel``.
        """
        path = Path(path)
        if path.suffix != ".volanim":
            path = path.with_suffix(".volanim")
        written = self.write_project(path, camera)
        self.bones_path = written["bones"]
        self.mskel_path = written["mskel"]
        self.project_path = str(path)
        self.events.project.emit(path=str(path))
        return path

    def write_project(self, path, camera: dict | None = None, *, mskel: str | None = None) -> dict:
        """Write the project files without adopting their paths (autosave uses this)."""
        from .project import write_project

        return write_project(self, path, camera, mskel=mskel)

