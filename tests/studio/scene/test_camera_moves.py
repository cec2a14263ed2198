"""The playing camera's easing (camera_moves.follow_blend with follow), on a real vtkRenderer."""

import numpy as np
import pytest

from volanim_studio.scene.camera_moves import FOLLOW_SECONDS, follow, follow_blend


@pytest.mark.parametrize("frames_between", [1, 4, 20, 60])
def test_a_playing_camera_trails_a_walk_by_the_same_bound_at_any_picture_rate(frames_between):
    """CI's loaded machine drew the walk at the view's edge: the camera moved a share (0.35) of the way
    per picture, so it trailed by the way the body went between pictures (60 frames apart: 1.86 x that).
    Eased in the clip's time it trails by at most speed x FOLLOW_SECONDS at 120 to 2 pictures a second."""
    import vtk

    renderer = vtk.vtkRenderer()
    fps, speed = 120.0, 1400.0  # a walk: 1.4 m/s in mm
    lags = []
    for k in range(0, 40 * frames_between + 1, frames_between):
        body = np.array([speed * k / fps, 0.0, 0.0])
        follow(renderer, body, 1.0 if k == 0 else follow_blend(frames_between / fps))
        lags.append(body[0] - renderer.GetActiveCamera().GetFocalPoint()[0])
    assert max(lags) <= speed * FOLLOW_SECONDS * 1.001
    assert lags[-1] >= 0  # behind the body, never ahead of it


def test_the_easing_is_gentle_for_a_picture_a_frame_and_lands_after_a_long_gap():
    assert follow_blend(1 / 120) < 0.05  # a swinging arm does not jerk the view
    assert follow_blend(2.0) > 0.99
    assert follow_blend(0.0) == 0.0
