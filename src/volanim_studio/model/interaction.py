"""Interaction modes as small Qt-free classes: plain pick events in, model calls out.

    scene click --PickEvent(point, joint, bone, button)--> mode.press(event) --> Document
    key press   --"Escape" / "Delete"-->                    mode.key(name)   --> Document

The Qt layer only turns mouse and keys into these events, so tests drive a
mode with plain objects and assert on the document.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import selection
from .document import Document
from .settings import Mode


@dataclass(frozen=True)
class PickEvent:
    """What is under the cursor: a skeleton point, a joint, a bone (each optional)."""

    point: int | None = None
    joint: str | None = None
    bone: int | None = None
    button: str = "left"
    shift: bool = False


class ModeHandler:
    """Base: a left click on a point shows its details; on a bone selects it."""

    name = Mode.VIEW
    help = "Click a point to see x y z, DT, thinness and bone; click a bone to select it."

    def __init__(self, doc: Document):
        self.doc = doc

    def enter(self) -> None:
        self.doc.message(self.help)

    def leave(self) -> None:
        pass

    def press(self, ev: PickEvent) -> None:
        if ev.button != "left":
            return
        if ev.point is not None:
            self.doc.pick_point(ev.point)
        if ev.joint is not None:
            self.doc.pick_joint(ev.joint)
        if ev.bone is not None:
            self.doc.select_bones([ev.bone])

    def key(self, name: str) -> None:
        pass


class ViewMode(ModeHandler):
    pass


class BonesMode(ModeHandler):
    """Build chains: click A, click B -> bone A-B; the next click continues from B.

    Esc or a right click ends the chain; clicking an existing joint starts from
    it. With ``remove`` on, clicking a bone deletes it; Delete removes the
    selected bones.
    """

    name = Mode.BONES
    help = ("Bones: click a point to start, click another to add a bone; keep clicking to continue the chain. "
            "Esc or right-click ends the chain. Delete removes the selected bone.")

    def __init__(self, doc: Document):
        super().__init__(doc)
        self.pending: str | np.ndarray | None = None  # joint name or position where the next bone starts
        self.remove = False

    def leave(self) -> None:
        self.pending = None

    def _target(self, ev: PickEvent):
        if ev.joint is not None:
            return ev.joint
        if ev.point is not None:
            return self.doc.skeleton.points[ev.point].astype(np.float64)
        return None

    def press(self, ev: PickEvent) -> None:
        if ev.button == "right":
            self.end_chain()
            return
        if ev.point is not None:
            self.doc.pick_point(ev.point)
        if ev.joint is not None:
            self.doc.pick_joint(ev.joint)
        if self.remove:
            if ev.bone is not None:
                self.doc.bone_edits.remove_bones([ev.bone])
            return
        target = self._target(ev)
        if target is None:
            self.doc.message("No skeleton point or joint under the cursor.")
            return
        if self.pending is None:
            self.pending = target
            where = target if isinstance(target, str) else " ".join(str(int(v)) for v in target)
            self.doc.message(f"Chain starts at {where}: click the next point.")
            return
        try:
            index = self.doc.bone_edits.add_bone(self.pending, target)
        except ValueError as exc:
            self.doc.message(str(exc))
            return
        self.pending = self.doc.bones.bones[index].distal
        self.doc.pick_joint(self.pending)
        self.doc.select_bones([index])
        self.doc.message(f"Added bone {self.doc.bones.bones[index].label}; click to continue, Esc to end.")

    def pending_position(self) -> np.ndarray | None:
        """Where the next bone starts (voxels), for the line drawn to the cursor; None between chains."""
        if self.pending is None:
            return None
        if isinstance(self.pending, str):
            j = self.doc.bones.joints.get(self.pending)
            return None if j is None else np.asarray(j, np.float64)
        return np.asarray(self.pending, np.float64)

    def end_chain(self) -> None:
        if self.pending is not None:
            self.pending = None
            self.doc.message("Chain ended.")

    def key(self, name: str) -> None:
        if name == "Escape":
            self.end_chain()
        elif name == "Delete" and self.doc.selected_bones:
            self.doc.bone_edits.remove_bones(self.doc.selected_bones)


class RootOrderMode(ModeHandler):
    """Click bones in sequence: the first becomes root 0, the next root 1, ...

    Bones not clicked yet keep their relative order after the clicked ones.
    Each click is one undo step; Esc starts the sequence again.
    """

    name = Mode.ROOT_ORDER
    help = "Root order: click bones in the order you want them (root 0, 1, ...). Esc starts again."

    def __init__(self, doc: Document):
        super().__init__(doc)
        self.assigned: list[tuple[str, str]] = []

    def enter(self) -> None:
        self.assigned = []
        super().enter()

    def press(self, ev: PickEvent) -> None:
        if ev.button != "left" or ev.bone is None:
            return
        bones = self.doc.bones.bones
        keys = [(b.proximal, b.distal) for b in bones]
        self.assigned = [k for k in self.assigned if k in keys]
        key = keys[ev.bone]
        if key in self.assigned:
            self.doc.message(f"{bones[ev.bone].label} is already root {self.assigned.index(key)}.")
            return
        self.assigned.append(key)
        order = [keys.index(k) for k in self.assigned] + [i for i, k in enumerate(keys) if k not in self.assigned]
        self.doc.bone_edits.set_root_order(order)
        n = len(self.assigned) - 1
        self.doc.select_bones([n])
        self.doc.message(f"{bones[ev.bone].label} is root {n}; click the next bone.")

    def key(self, name: str) -> None:
        if name == "Escape":
            self.assigned = []
            self.doc.message("Root order: start again from root 0.")


def choose_working_bone(doc: Document, ev: PickEvent) -> bool:
    """Shift+click in Cube and Lasso modes: the bone under the cursor, or else the bone of the point
    under it, becomes the working bone. Returns whether one was chosen."""
    bone = ev.bone
    if bone is None and ev.point is not None:
        b = int(doc.attachments.bone[ev.point])
        bone = b if b >= 0 else None
    if bone is None:
        doc.message("Shift+click a bone, or a connected point, to choose the working bone.")
        return False
    doc.select_bones([bone])
    doc.message(f"Working bone: {doc.bones.bones[bone].label}.")
    return True


def _working(doc: Document, remove: bool) -> int | None:
    """The bone to attach to (-1 to detach), or None with a message when no bone is chosen."""
    if remove:
        return -1
    if doc.working_bone is None:
        doc.message("Choose the working bone first: click a bone in the view or in the list.")
        return None
    return doc.working_bone


class CubeMode(ModeHandler):
    """Click a point to centre the cube on it; Connect / Remove act on the shown points inside.

    Arrow keys nudge it along x and z, Page Up / Page Down along y; + / - resize.
    """

    name = Mode.CUBE
    help = ("Cube: click a point to place the cube (arrows, PgUp/PgDn nudge; +/- size), then Connect (C) "
            "or Remove (X) the shown points inside it for the working bone (Shift+click a bone to choose it).")
    NUDGE = {"Left": (-1, 0, 0), "Right": (1, 0, 0), "Up": (0, 0, 1), "Down": (0, 0, -1),
             "PageUp": (0, 1, 0), "PageDown": (0, -1, 0)}

    def press(self, ev: PickEvent) -> None:
        if ev.button != "left":
            return
        if ev.shift:
            choose_working_bone(self.doc, ev)
        elif ev.point is not None:
            self.doc.pick_point(ev.point)
            self.doc.set_cube(self.doc.skeleton.points[ev.point])
        elif ev.bone is not None:
            self.doc.select_bones([ev.bone])

    def inside(self) -> np.ndarray:
        doc = self.doc
        if doc.cube_centre is None:
            return np.zeros(0, np.int64)
        shown = doc.shown_indices()
        return shown[selection.in_cube(doc.skeleton.points[shown], doc.cube_centre, doc.settings.cube_size)]

    def apply(self, remove: bool = False) -> int:
        if self.doc.cube_centre is None:
            self.doc.message("Place the cube first: click a point.")
            return 0
        bone = _working(self.doc, remove)
        if bone is None:
            return 0
        idx = self.inside()
        self.doc.set_point_selection(idx)
        n = self.doc.attachments.assign(idx, bone)
        self.doc.message(f"{'Removed' if remove else 'Connected'} {n} of {len(idx)} points in the cube.")
        return n

    def key(self, name: str) -> None:
        doc = self.doc
        if doc.cube_centre is None:
            return
        if name in self.NUDGE:
            doc.set_cube(np.asarray(doc.cube_centre) + self.NUDGE[name])
        elif name in ("Plus", "Equal"):
            doc.settings.cube_size = min(200.0, doc.settings.cube_size + 2)
        elif name == "Minus":
            doc.settings.cube_size = max(1.0, doc.settings.cube_size - 2)
        elif name == "C":
            self.apply()
        elif name == "X":
            self.apply(remove=True)


class LassoMode(ModeHandler):
    """Draw an outline over the view; the shown points under it are connected (or removed).

    The depth mode decides which of them: 'through', 'visible' or 'slab' (see
    ``selection``). Holding Ctrl while drawing, or the remove setting, removes.
    Depth, slab and remove are ``doc.settings.lasso_*``.
    """

    name = Mode.LASSO
    help = ("Lasso: drag an outline around points to connect them to the working bone (Ctrl: remove). "
            "Depth: through / visible / slab. A click (Shift+click) on a bone chooses the working bone.")

    def press(self, ev: PickEvent) -> None:
        """A click without dragging an outline: choose the working bone (a modifier is not needed here)."""
        if ev.button == "left":
            choose_working_bone(self.doc, ev)

    def finish(self, polygon, xy, depth, view_depth, shown, remove: bool | None = None) -> int:
        """Apply a closed outline: ``xy``/``depth``/``view_depth`` are the projections of ``shown`` points."""
        settings = self.doc.settings
        remove = settings.lasso_remove if remove is None else remove
        picked = selection.select_lasso(xy, depth, view_depth, polygon, mode=settings.lasso_depth,
                                        slab=settings.lasso_slab)
        idx = np.asarray(shown)[picked]
        self.doc.set_point_selection(idx)
        bone = _working(self.doc, remove)
        if bone is None:
            return 0
        doc = self.doc
        # in the owned body (the default) the flesh those points stand for goes with them: one undo step (#84)
        repaint = not remove and settings.body == "owned" and doc.ownership.available and len(idx)
        name = doc.bones.bones[bone].label if bone >= 0 else ""
        flesh = ()
        if repaint:
            with doc.undo.group(f"Connect {len(idx)} points and their flesh ({name})"):
                n = doc.attachments.assign(idx, bone)
                flesh = doc.ownership.flesh_of(idx)
                if len(flesh):
                    doc.ownership.paint_voxels(flesh, bone)
        else:
            n = doc.attachments.assign(idx, bone)
        also = f"; {len(flesh):,} voxels of their flesh now move with {name}" if len(flesh) else ""
        doc.message(f"{'Removed' if remove else 'Connected'} {n} of {len(idx)} points under the lasso "
                    f"({settings.lasso_depth}){also}.")
        return n


class PoseMode(ModeHandler):
    """Click a bone to pose it with the sliders of the Pose tab."""

    name = Mode.POSE
    help = ("Pose: click a bone, turn it with the sliders (children follow); the preview updates live. "
            "Then read the breakage report.")


HANDLERS = {Mode.VIEW: ViewMode, Mode.BONES: BonesMode, Mode.ROOT_ORDER: RootOrderMode, Mode.CUBE: CubeMode,
            Mode.LASSO: LassoMode, Mode.POSE: PoseMode}
