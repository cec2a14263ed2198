"""``volanim view VOLUME --slices``: a pyvista window of one slice at a time, with a slider.

    volume --slice_picture(axis, k)--> (H, W, 3) --cells of a flat image, unlit--> parallel camera
    slider k --> the cells' colours refilled (the camera stays)

One picture pixel is one cell, drawn flat and unlit, so the window shows the
picture's colours exactly (``--screenshot`` writes what the window shows, the
slider left out). The studio's *File → View slices…* shows the same
``slice_picture`` in a Qt window.
"""

from __future__ import annotations

import numpy as np

from .slices import AXES, default_window, pixel_aspect, slice_picture

SLIDER_MARGIN = 90  # pixels under the picture for the slider in a window


def window_size(shape, axis: int, spacing, longest: int = 800) -> tuple[int, int]:
    """``(W, H)`` pixels that show a slice at a whole number of pixels a voxel across (or one, when large)."""
    u, v = [a for a in range(3) if a != axis]
    tall = shape[v] * pixel_aspect(spacing, axis)  # in voxel widths
    scale = max(1, int(longest // max(shape[u], tall)))
    return int(shape[u] * scale), int(round(tall * scale))


class SliceView:
    """A slice of ``volume`` in a pyvista plotter (made here; ``off_screen`` as for ``pyvista.Plotter``)."""

    def __init__(self, volume: np.ndarray, spacing=(1.0, 1.0, 1.0), axis: int = 2, index: int | None = None,
                 grey=None, off_screen: bool | None = True, slider: bool = False, title: str = ""):
        import pyvista as pv

        from .scene import prefer_egl_without_display

        prefer_egl_without_display()
        self.volume, self.axis = volume, axis
        self.grey = grey if grey is not None else default_window(volume) if volume.ndim == 3 else None
        self.index = volume.shape[axis] // 2 if index is None else int(index)
        w, h = window_size(volume.shape, axis, spacing)
        margin = SLIDER_MARGIN if slider else 0
        self.size = (w, h + margin)
        picture = self.picture()
        ph, pw = picture.shape[:2]
        tall = ph * pixel_aspect(spacing, axis)  # world units: a pixel is 1 wide
        self.grid = pv.ImageData(dimensions=(pw + 1, ph + 1, 1), spacing=(1.0, tall / ph, 1.0))
        self.grid.cell_data["rgb"] = self._cells(picture)
        self.plotter = pv.Plotter(off_screen=off_screen, window_size=self.size)
        self.plotter.set_background("black")
        self.plotter.add_mesh(self.grid, scalars="rgb", rgb=True, lighting=False, name="slice",
                              show_scalar_bar=False, reset_camera=False)
        per_pixel = tall / h  # world units a screen pixel
        cam = self.plotter.camera
        cam.parallel_projection = True
        centre_y = (tall - margin * per_pixel) / 2
        cam.focal_point = (pw / 2, centre_y, 0.0)
        cam.position = (pw / 2, centre_y, 10.0 * max(pw, tall))
        cam.up = (0.0, 1.0, 0.0)
        cam.parallel_scale = self.size[1] * per_pixel / 2
        self.plotter.renderer.ResetCameraClippingRange()
        self.plotter.camera_set = True
        if slider:
            y = 0.6 * margin / self.size[1]  # the bar in the margin, its title under it and still in the window
            self.plotter.add_slider_widget(lambda value: self.show(int(round(value))), [0, volume.shape[axis] - 1],
                                           value=self.index, title=f"{AXES[axis]} slice{title}", fmt="%.0f",
                                           pointa=(0.1, y), pointb=(0.9, y), style="modern")

    def picture(self) -> np.ndarray:
        return slice_picture(self.volume, self.axis, self.index, self.grey)

    def show(self, index: int) -> None:
        """Slice ``index`` in place of the one shown."""
        self.index = int(np.clip(index, 0, self.volume.shape[self.axis] - 1))
        self.grid.cell_data["rgb"] = self._cells(self.picture())
        self.plotter.render()

    def screenshot(self) -> np.ndarray:
        return np.asarray(self.plotter.screenshot(return_img=True), np.uint8)[..., :3].copy()

    def close(self) -> None:
        self.plotter.close()

    @staticmethod
    def _cells(picture: np.ndarray) -> np.ndarray:
        """VTK's cell order: x fastest, rows from the bottom up (the picture's row 0 is the top)."""
        return np.ascontiguousarray(picture[::-1].reshape(-1, 3))
