"""Names in the viewport, the joint or bone under the cursor, and the line of the bone being built.

    doc.events.bones / picked, settings.names_visible --> joint labels (white), named bones' labels
        (grey, italic), each laid out beside its place before every render (label_layout: every name
        shown, none over another), the picked joint ringed in cyan
    mouse move (no button held) --> the joint or bone under the cursor, drawn yellow, named in the
        status bar; in Bones mode with a chain started, a line from its last joint to the cursor

Owned by :class:`~volanim_studio.scene.view.SceneView`; its actors belong to the edit stage.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pyvista as pv
from vtkmodules.vtkRenderingCore import vtkTextActor

from volanim_core.render.bone_colours import bone_colour

from . import label_layout
from .pose_layer import bone_lines

HOVER = "#ffe14d"
PICKED_JOINT = "#00ffff"
ACTORS = ("hover", "chain_preview", "picked_joint")  # by name; the labels are kept in ``label_actors``


class NamesLayer:
    def __init__(self, view):
        self.view = view
        self.hovered: tuple[str, object] | None = None  # ("joint", name) or ("bone", index)
        self.shown_names: list[str] = []  # the joint and bone names drawn, in that order
        # pyvista files label actors under names of its own (not ``name=``): kept here to remove and hide
        self.label_actors: list = []  # one vtkTextActor a label, laid out by label_layout
        self.label_boxes = np.zeros((0, 4))  # where they were put at the last render (display pixels)
        self.joint_labels = 0
        self._labels = None  # (joint world points, names, bone middles, bone names) while names show
        #: where the chain being built continues from (voxels), or None; the window sets it to the
        #: Bones mode's ``pending_position``
        self.pending: Callable[[], np.ndarray | None] = lambda: None
        doc = view.doc
        doc.events.bones.connect(self.update_labels)
        doc.events.picked.connect(self._on_picked)
        view.settings.events.names_visible.connect(self.update_labels)
        view.plotter.iren.add_observer("MouseMoveEvent", self._on_move)
        view.plotter.renderer.AddObserver("StartEvent", self._lay_out)

    # ---------------------------------------------------------------- labels
    def update_labels(self, **_) -> None:
        view, plotter = self.view, self.view.plotter
        for actor in self.label_actors:
            plotter.remove_actor(actor, render=False)
        self.label_actors, self._labels = [], None
        bones = view.doc.bones
        self.shown_names = []
        if view.settings.names_visible and len(bones.joints):
            names = list(bones.joints)
            named = [i for i, b in enumerate(bones.bones) if b.name]
            self.shown_names = names + [bones.bones[i].name for i in named]
            joints = view.world(np.array([bones.joints[n] for n in names]))
            mids = view.world(bones.segments()[named].mean(1)) if named else np.zeros((0, 3))
            self._labels = (joints, names, mids, [bones.bones[i].name for i in named])
            # laid out (their actors made) as the next frame starts: by then a project being opened is in
            # its saved mode, and in Pose mode none are made (37 made twice: 50 ms of mannequin-large's open)
            view.render()
        self.hovered = None
        plotter.remove_actor("hover", render=False)
        self._on_picked()

    def _lay_out(self, *_) -> None:
        """Every name beside its joint (or its bone's middle), none over another (scene/label_layout.py):
        laid out again before each render, since a turn of the camera moves them all on screen."""
        if self._labels is None:
            return
        view, plotter = self.view, self.view.plotter
        if view.posing:  # hidden in Pose mode: no layout (20 ms a render on 30 bones), and none made (a project
            for actor in self.label_actors:  # opened in Pose mode made 37 twice: 50 ms of the GUI thread)
                actor.SetVisibility(False)
            return
        joints, names, mids, bone_names = self._labels
        xy, _ = view.project_world(joints)
        groups = label_layout.merge_coincident(xy, names)
        self.joint_labels = len(groups)  # label_actors[:joint_labels] name joints, the rest bones
        texts = [t for t, _ in groups] + bone_names
        anchors = np.vstack([xy[[m[0] for _, m in groups]], view.project_world(mids)[0] if len(mids) else
                             np.zeros((0, 2))])
        if [a.GetInput() for a in self.label_actors] != texts:  # new names: new actors
            for actor in self.label_actors:
                plotter.remove_actor(actor, render=False)
            self.label_actors = [self._text_actor(t, bone=k >= len(groups)) for k, t in enumerate(texts)]
        sizes = np.array([self._size(a) for a in self.label_actors], np.float64).reshape(-1, 2)
        self.label_boxes = label_layout.place(anchors, sizes)
        for actor, box in zip(self.label_actors, self.label_boxes):
            actor.SetPosition(float(box[0]), float(box[1]))
            actor.SetVisibility(not view.posing)

    def _text_actor(self, text: str, bone: bool):
        actor = vtkTextActor()
        actor.SetInput(text)
        prop = actor.GetTextProperty()
        prop.SetFontSize(11 if bone else 13)
        prop.SetItalic(bone)
        prop.SetColor(*((0.82, 0.82, 0.82) if bone else (1.0, 1.0, 1.0)))
        prop.SetShadow(True)
        actor.SetPickable(False)
        # the kind in the name: a bone named as a joint ("HEAD") replaced, and so hid, the joint's label
        self.view.plotter.add_actor(actor, reset_camera=False, name=f"label:{'bone' if bone else 'joint'}:{text}",
                                    pickable=False, render=False)
        return actor

    def _size(self, actor) -> tuple[float, float]:
        box = [0.0] * 4
        actor.GetBoundingBox(self.view.plotter.renderer, box)
        return box[1] - box[0], box[3] - box[2]

    def show(self, on: bool) -> None:
        """The labels' part of the stage switch (the named actors follow ``SceneView.EDIT_ACTORS``)."""
        for actor in self.label_actors:
            actor.SetVisibility(on)

    def _on_picked(self, **_) -> None:
        view, plotter = self.view, self.view.plotter
        plotter.remove_actor("picked_joint", render=False)
        name = view.doc.picked_joint
        if name is not None and name in view.doc.bones.joints:
            plotter.add_mesh(pv.PolyData(view.world(view.doc.bones.joints[name][None]).astype(np.float32)),
                             color=PICKED_JOINT, point_size=22, render_points_as_spheres=True, name="picked_joint",
                             render=False, reset_camera=False, pickable=False)
        view.apply_stage()
        view.render()

    # ----------------------------------------------------------------- hover
    def under_cursor(self, x: float, y: float) -> tuple[str, object] | None:
        """``("joint", name)`` or else ``("bone", index)`` under display ``(x, y)``, or None."""
        joint, bone = self.view.joint_and_bone_at(x, y)
        return ("joint", joint) if joint is not None else ("bone", bone) if bone is not None else None

    def _on_move(self, *_) -> None:
        view = self.view
        if view._press is not None or view.posing:
            return  # a button is held: the camera turns; the pose stage has no edit actors
        x, y = view.event_position()
        self._hover(self.under_cursor(x, y))
        self._chain_preview(x, y)

    def _hover(self, what) -> None:
        if what == self.hovered:
            return
        self.hovered = what
        view, plotter = self.view, self.view.plotter
        plotter.remove_actor("hover", render=False)
        bones = view.doc.bones
        if what is not None and what[0] == "joint":
            plotter.add_mesh(pv.PolyData(view.world(bones.joints[what[1]][None]).astype(np.float32)), color=HOVER,
                             point_size=20, render_points_as_spheres=True, name="hover", render=False,
                             reset_camera=False, pickable=False)
            view.doc.message(f"Joint {what[1]}: click to pick it, then F2 renames it and "
                             "Ctrl+F2 names its chain.")
        elif what is not None:
            b = bones.bones[what[1]]
            plotter.add_mesh(bone_lines(view.world(bones.segments()[[what[1]]])), color=HOVER, line_width=10,
                             render_lines_as_tubes=True, name="hover", render=False, reset_camera=False,
                             pickable=False)
            view.doc.message(f"Bone {b.label} ({b.proximal} → {b.distal}, root {what[1]}, "
                             f"colour {bone_colour(what[1])}): click to select it.")
        view.render()

    def _chain_preview(self, x: float, y: float) -> None:
        view, plotter = self.view, self.view.plotter
        start = self.pending()
        had = "chain_preview" in plotter.renderer.actors
        if start is None:
            if had:
                plotter.remove_actor("chain_preview", render=False)
                view.render()
            return
        a = view.world(start[None])[0]
        _, depth = view.project_world(a[None])
        r = plotter.renderer
        r.SetDisplayPoint(float(x), float(y), float(depth[0]))  # the cursor, at the chain end's depth
        r.DisplayToWorld()
        w = np.array(r.GetWorldPoint())
        b = w[:3] / w[3] if w[3] else w[:3]
        line = pv.Line(a, b)
        if had:
            plotter.renderer.actors["chain_preview"].mapper.SetInputData(line)
        else:
            plotter.add_mesh(line, color=HOVER, line_width=3, name="chain_preview", render=False,
                             reset_camera=False, pickable=False)
        view.render()

    def clear_chain_preview(self) -> None:
        if "chain_preview" in self.view.plotter.renderer.actors:
            self.view.plotter.remove_actor("chain_preview", render=False)
            self.view.render()
