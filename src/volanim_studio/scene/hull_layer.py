"""The translucent, never-pickable hull of the segmented volume, with its clipping plane."""

from __future__ import annotations

import numpy as np
import pyvista as pv

from volanim_core.render.bone_colours import label_table
from volanim_core.render.surfaces import filled_voxel_values

HULL_COLOUR = "#d8c8b0"


class HullLayer:
    """Follows ``doc.events.volume``/``hull`` and the hull settings (visible, opacity, clip)."""

    def __init__(self, view):
        self.view = view
        self.actor = None
        self._meshes = None  # (full, coarse) once a hull exists; coarse is full when it has no LOD
        view.doc.events.volume.connect(self._on_hull_changed)
        view.doc.events.hull.connect(self._on_hull_changed)
        view.doc.events.owners_shown.connect(self._on_owners)
        view.settings.events.hull_owners.connect(self._on_owners)
        for name in ("hull_visible", "hull_opacity", "clip_axis", "clip_position"):
            getattr(view.settings.events, name).connect(self._on_state_changed)

    def _on_hull_changed(self, **_) -> None:
        view = self.view
        if self.actor is not None:
            view.plotter.remove_actor(self.actor, render=False)
            self.actor = None
        if view.doc.hull is None:
            view.render()
            return
        volume = view.doc.volume
        colour = volume is not None and volume.ndim == 4 and len(view.doc.hull[0])
        mesh = self._mesh(*view.doc.hull, colour)
        lod = mesh if view.doc.hull_lod is None else self._mesh(*view.doc.hull_lod, colour)
        self._meshes = (mesh, lod)
        # not pickable: a click must reach the skeleton points inside it
        self.actor = view.plotter.add_mesh(
            lod if view.dragging else mesh, color=None if colour else HULL_COLOUR,
            scalars="rgb" if colour else None, rgb=bool(colour),
            opacity=view.settings.hull_opacity, pickable=False, name="hull", render=False, reset_camera=False,
            interpolation="phong")  # smooth shading by the model's normals, what smooth_shading=True drew
        self._apply_state()
        self._on_owners()
        view.apply_stage()
        view.front_view()

    def _mesh(self, verts, faces, normals, colour: bool) -> pv.PolyData:
        view = self.view
        mesh = pv.PolyData.from_regular_faces(view.world(verts).astype(np.float32), faces)
        mesh.point_data.set_array(_scaled_normals(normals, view.spacing), "Normals")
        mesh.point_data.active_normals_name = "Normals"
        if colour:  # a colour scan's hull shows the colours of its surface voxels
            mesh.point_data["rgb"] = filled_voxel_values(view.doc.volume, np.asarray(verts, np.float64))
        return mesh

    def _on_owners(self, **_) -> None:
        """Colour the hull by the bone owning each surface voxel (``doc.ownership.shown``) while *Colour by owning
        bone* is on and an ownership for the rig as it is has been made; its own colours otherwise."""
        if self.actor is None:
            return
        doc = self.view.doc
        own = doc.ownership.shown if self.view.settings.hull_owners else None
        mapper = self.actor.GetMapper()
        if own is None:
            colour = doc.volume is not None and doc.volume.ndim == 4 and len(doc.hull[0])
            for mesh, verts in zip(self._meshes, (doc.hull[0], (doc.hull_lod or doc.hull)[0])):
                if colour:
                    mesh.point_data["rgb"] = filled_voxel_values(doc.volume, np.asarray(verts, np.float64))
            mapper.SetScalarVisibility(bool(colour))
        else:
            labels = own.volume(doc.mask.shape)
            table = label_table(len(own.bones))
            for mesh, verts in zip(self._meshes, (doc.hull[0], (doc.hull_lod or doc.hull)[0])):
                mesh.point_data["rgb"] = table[filled_voxel_values(labels, np.asarray(verts, np.float64))]
            mapper.SetScalarModeToUsePointFieldData()
            mapper.SelectColorArray("rgb")
            mapper.SetColorModeToDirectScalars()
            mapper.SetScalarVisibility(True)
        self.view.render()

    def set_dragging(self, on: bool) -> None:
        """The coarse hull while a slider is held, the full one after (same actor, clip and opacity)."""
        if self.actor is not None:
            self.actor.GetMapper().SetInputData(self._meshes[1] if on else self._meshes[0])

    @property
    def drawn_faces(self) -> int:
        return 0 if self.actor is None else int(self.actor.GetMapper().GetInput().GetNumberOfCells())

    def _apply_state(self) -> None:
        if self.actor is None:
            return
        settings, doc = self.view.settings, self.view.doc
        self.actor.SetVisibility(settings.hull_visible)
        self.actor.GetProperty().SetOpacity(settings.hull_opacity)
        mapper = self.actor.GetMapper()
        mapper.RemoveAllClippingPlanes()
        axis = settings.clip_axis
        if axis is not None and doc.shape is not None:
            import vtk

            origin, normal = [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]
            origin[axis] = settings.clip_position * (doc.shape[axis] - 1) * self.view.spacing[axis]
            normal[axis] = -1.0
            plane = vtk.vtkPlane()
            plane.SetOrigin(origin)
            plane.SetNormal(normal)
            mapper.AddClippingPlane(plane)

    def _on_state_changed(self, **_) -> None:
        self._apply_state()
        self.view.apply_stage()
        self.view.render()


def _scaled_normals(normals, spacing) -> np.ndarray:
    """Voxel-frame unit normals in a world of voxels ``spacing`` apart: scaled by 1 / spacing (normals go
    by the inverse transpose of the points' scaling), made unit again."""
    spacing = np.asarray(spacing, np.float64)
    if (spacing == spacing[0]).all():  # cubes: the same directions
        return np.asarray(normals, np.float32)
    n = np.asarray(normals, np.float64) / spacing
    length = np.linalg.norm(n, axis=1, keepdims=True)
    return (n / np.where(length > 0, length, 1.0)).astype(np.float32)
