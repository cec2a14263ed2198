"""The rest pose's bones (tubes in bone colours), their joints (white dots) and the selected bones' halo."""

from __future__ import annotations

import numpy as np
import pyvista as pv

from volanim_core.render.bone_colours import label_table

from .pose_layer import bone_lines


class BonesLayer:
    """Follows ``doc.events.bones`` and ``selection``: the edit stage's actors ``bones``, ``joints`` and
    ``selected`` (the posed bones are :class:`~.pose_layer.PoseLayer`'s)."""

    def __init__(self, view):
        self.view = view
        self.bones_actor = self.joints_actor = self.selected_actor = None
        view.doc.events.bones.connect(self._on_bones_changed)
        view.doc.events.selection.connect(self._on_selection_changed)

    def _on_bones_changed(self, **_) -> None:
        view = self.view
        for name in ("bones", "joints", "selected"):
            view.plotter.remove_actor(name, render=False)
        self.bones_actor = self.joints_actor = self.selected_actor = None
        bones = view.doc.bones
        if len(bones.joints):
            jpos = view.world(np.array(list(bones.joints.values())))
            self.joints_actor = view.plotter.add_mesh(
                pv.PolyData(jpos.astype(np.float32)), color="white", point_size=14,
                render_points_as_spheres=True, name="joints", render=False, reset_camera=False)
        if len(bones):
            poly = bone_lines(view.world(bones.segments()))
            poly.cell_data["rgb"] = label_table(len(bones))[1:]
            self.bones_actor = view.plotter.add_mesh(
                poly, scalars="rgb", rgb=True, line_width=6, render_lines_as_tubes=True, name="bones",
                render=False, reset_camera=False)
        self._on_selection_changed()

    def _on_selection_changed(self, **_) -> None:
        view = self.view
        view.plotter.remove_actor("selected", render=False)
        self.selected_actor = None
        sel = [i for i in view.doc.selected_bones if i < len(view.doc.bones)]
        if sel:
            self.selected_actor = view.plotter.add_mesh(
                bone_lines(view.world(view.doc.bones.segments()[sel])), color="white", line_width=12,
                render_lines_as_tubes=True, opacity=0.5, name="selected", render=False, reset_camera=False)
        view.apply_stage()
        view.render()
