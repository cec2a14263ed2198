"""The pose stage of the scene: posed bones and preview reconstructions.

A mixin of :class:`~volanim_studio.scene.view.SceneView`. Full previews are
volumes with a transfer function per mode (``volanim_core.render``); live previews
are label-coloured surfaces, which software OpenGL draws far faster.
"""

from __future__ import annotations

import numpy as np
import pyvista as pv
from matplotlib.colors import ListedColormap

from volanim_core.render.colours import SKIN, label_table
from volanim_core.render.surfaces import label_surface
from volanim_core.render.transfer import apply_labels, binary_view, volume_style


class ScenePoseMixin:
    # ------------------------------------------------------------- posing
    def set_posing(self, on: bool) -> None:
        """Pose stage: the preview and the posed bones; edit stage: hull, cloud and rest bones."""
        self.posing = bool(on)
        self._apply_stage()
        if self.posing:
            self._on_pose_changed()
        self.render()

    EDIT_ACTORS = ("cloud", "bones", "joints", "selected", "picked", "cube")
    POSE_ACTORS = ("preview", "posed_bones", "slices")

    def _apply_stage(self) -> None:
        """Show the edit stage's actors or the pose stage's, whichever is current."""
        actors = self.plotter.renderer.actors
        for name in self.EDIT_ACTORS:
            if name in actors:
                actors[name].SetVisibility(not self.posing)
        if "hull" in actors:
            actors["hull"].SetVisibility(not self.posing and self.settings.hull_visible)
        for name in self.POSE_ACTORS:
            if name in actors:
                actors[name].SetVisibility(self.posing)

    def _on_pose_changed(self, **_) -> None:
        if not self.posing:
            return
        self.plotter.remove_actor("posed_bones", render=False)
        bones = self.doc.bones
        if len(bones):
            pj = self.doc.pose.posed_joints()
            segs = self.world(np.array([[pj[b.proximal], pj[b.distal]] for b in bones.bones]).reshape(-1, 3))
            lines = np.hstack([np.full((len(bones), 1), 2), np.arange(2 * len(bones)).reshape(-1, 2)]).ravel()
            poly = pv.PolyData(segs.astype(np.float32), lines=lines)
            poly.cell_data["rgb"] = label_table(len(bones))[1:]
            self.plotter.add_mesh(poly, scalars="rgb", rgb=True, line_width=5, render_lines_as_tubes=True,
                                  name="posed_bones", render=False, reset_camera=False)
        self.render()

    def show_volume(self, volume: np.ndarray, origin_voxels, spacing_voxels, mode: str) -> None:
        """Draw a reconstruction; a live update with the same grid and mode only swaps the data."""
        n_bones = len(self.doc.bones)
        if mode in ("binary",):
            volume = binary_view(volume)
        world_origin = self.world(origin_voxels)
        world_spacing = np.asarray(spacing_voxels, np.float64) * self.spacing
        img = pv.ImageData(dimensions=volume.shape, origin=world_origin, spacing=world_spacing)
        img.point_data["values"] = np.asarray(volume).ravel(order="F")
        key = (mode, volume.shape, tuple(world_origin), tuple(world_spacing), n_bones,
               float(volume.max()) if mode == "hotspot" else 0)
        if self._preview_actor is not None and key == self._preview_key:
            self._preview_actor.mapper.SetInputData(img)
        else:
            self.plotter.remove_actor("preview", render=False)
            if self.plotter.scalar_bars:
                self.plotter.remove_scalar_bar()
            style = volume_style(mode, volume, n_bones)
            labels = style.pop("categories", None)
            self._preview_actor = self.plotter.add_volume(img, scalars="values", name="preview", render=False,
                                                          reset_camera=False, **style)
            if labels is not None:
                apply_labels(self._preview_actor, labels)
            self._preview_key = key
        self._preview_actor.SetVisibility(self.posing)
        self.plotter.remove_actor("slices", render=False)
        if self.settings.slices:
            style = volume_style(mode, volume, n_bones)
            labels = style.get("categories")
            cmap = style["cmap"] if labels is None else ListedColormap(np.vstack([[0.1, 0.1, 0.1], labels]))
            clim = style["clim"] if labels is None else (0, len(labels))
            self.plotter.add_mesh(img.slice_orthogonal(), scalars="values", cmap=cmap, clim=clim,
                                  n_colors=256 if labels is None else len(labels) + 1, show_scalar_bar=False,
                                  name="slices", render=False, reset_camera=False)
        self.render()

    def show_surface(self, volume: np.ndarray, origin_voxels, spacing_voxels, mode: str) -> None:
        """A live preview: the reconstruction's surface coloured by label (software GL draws a
        surface far faster than it ray-casts a volume)."""
        world_origin = self.world(origin_voxels)
        world_spacing = np.asarray(spacing_voxels, np.float64) * self.spacing
        table = label_table(len(self.doc.bones)) if mode == "bone" else None
        surf = label_surface(volume, world_origin, world_spacing, table)
        self.plotter.remove_actor("preview", render=False)
        self.plotter.remove_actor("slices", render=False)
        self._preview_actor = self._preview_key = None
        if surf.n_points and table is not None:
            self.plotter.add_mesh(surf, scalars="rgb", rgb=True, name="preview", render=False, reset_camera=False)
        elif surf.n_points:
            self.plotter.add_mesh(surf, color=SKIN, name="preview", render=False, reset_camera=False)
        self._apply_stage()
        self.render()

    def clear_volume(self) -> None:
        self.plotter.remove_actor("preview", render=False)
        self.plotter.remove_actor("slices", render=False)
        self._preview_actor = self._preview_key = None
        self.render()

    def jump_to(self, voxel_xyz) -> None:
        """Centre the view on a point and move closer."""
        cam = self.plotter.renderer.GetActiveCamera()
        target = self.world(voxel_xyz)
        pos, focal = np.array(cam.GetPosition()), np.array(cam.GetFocalPoint())
        cam.SetFocalPoint(*target)
        cam.SetPosition(*(target + 0.5 * (pos - focal)))
        self.plotter.renderer.ResetCameraClippingRange()
        self.render()

