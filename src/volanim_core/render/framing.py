"""Where a render's camera goes: a named view of every frame's body, a given camera, or one that follows.

    RenderInputs (render/movie.py) + a view name or a Camera or "follow" --place_camera--> (Camera, inputs)

Apart from views.py (views and cameras from boxes: no frames, no files) so that views.py never reads the
movie's inputs; the movie, the quick look, the demo and ``volanim render`` call this.
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING

from .views import Camera, named_view

if TYPE_CHECKING:
    from .movie import RenderInputs


def place_camera(inputs: RenderInputs, view: str = "three-quarter", camera: Camera | str | None = None,
                 aspect: float = 4 / 3, axes=None) -> tuple[Camera, RenderInputs]:
    """The camera a render uses and the inputs to draw (``volanim render`` and ``view``, the demo; the
    studio's movie follows with its own view, :meth:`RenderInputs.follow`).

    ``camera``: None (the named ``view`` framing every frame's body: the union of their boxes), a
    :class:`Camera` in world units, or ``"follow"`` (each frame its own camera, :meth:`RenderInputs.follow`;
    the one returned is the middle frame's, for ``--save-camera``).
    """
    if camera == "follow":
        frames = inputs.follow(view, aspect, axes)
        return frames[len(frames) // 2].camera, replace(inputs, frames=frames)
    if isinstance(camera, Camera):
        return camera, inputs
    if camera is not None:
        raise ValueError(f"camera: a Camera or 'follow', got {camera!r}")
    lo, hi = inputs.world_box()
    return named_view(view, lo, hi, aspect=aspect, axes=axes, faces=0.0), inputs
