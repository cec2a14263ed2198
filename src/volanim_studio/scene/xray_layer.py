"""An x-ray layer: actors drawn over everything else, so the posed bones show through the preview.

    SceneView's renderer (layer 0: preview, hull, cloud)  +  XRayLayer's renderer (layer 1, same camera)

A second renderer on the window's layer 1 shares the main renderer's camera and
viewport and keeps no depth of layer 0, so what it holds is never hidden inside
the opaque preview: the user sees the bones they click (picking projects the
posed bones, ``SceneView.joint_and_bone_at``). It takes no mouse events: the
camera moves with layer 0.
"""

from __future__ import annotations


class XRayLayer:
    def __init__(self, plotter):
        import vtk

        self.plotter = plotter
        self.renderer = vtk.vtkRenderer()
        self.renderer.SetLayer(1)
        self.renderer.InteractiveOff()
        self.renderer.SetActiveCamera(plotter.renderer.GetActiveCamera())
        self.renderer.SetViewport(*plotter.renderer.GetViewport())
        ren_win = plotter.ren_win
        ren_win.SetNumberOfLayers(max(2, ren_win.GetNumberOfLayers()))
        ren_win.AddRenderer(self.renderer)
        self.actors: dict[str, object] = {}

    def put(self, name: str, actor) -> None:
        """Show ``actor`` (made by ``plotter.add_mesh``) in the x-ray layer under ``name``, replacing the old one."""
        self.remove(name)
        self.plotter.renderer.RemoveActor(actor)  # add_mesh put it in layer 0
        self.renderer.AddActor(actor)
        self.actors[name] = actor

    def remove(self, name: str) -> None:
        actor = self.actors.pop(name, None)
        if actor is not None:
            self.renderer.RemoveActor(actor)

    def show(self, on: bool) -> None:
        self.renderer.SetDraw(bool(on))

    def close(self) -> None:
        for name in list(self.actors):
            self.remove(name)
        ren_win = self.plotter.ren_win
        if ren_win is not None:
            ren_win.RemoveRenderer(self.renderer)
