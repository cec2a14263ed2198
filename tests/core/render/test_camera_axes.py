"""Named views stand an object up by its shape (issue #18: the frog opened edge-on)."""

from __future__ import annotations

import numpy as np
import pytest

from volanim_core.render.views import named_view, natural_axes


def _look(cam) -> np.ndarray:
    d = np.subtract(cam.focal_point, cam.position)
    return d / np.linalg.norm(d)


def test_a_standing_figure_keeps_the_thesis_axes():
    assert np.array_equal(natural_axes([0, 0, 0], [160, 100, 300]), np.eye(3))  # the mannequin
    assert np.array_equal(natural_axes([0, 0, 0], [50, 50, 50]), np.eye(3))  # no shape to go by


def test_the_frog_lying_flat_is_seen_from_above_head_up():
    lo, hi = [0, 0, 0], [500, 470, 204]  # the frog in mm: thin along z, longest along x
    axes = natural_axes(lo, hi)
    assert np.isclose(np.linalg.det(axes), 1.0)  # a rotation: pictures are never mirrored
    front = named_view("front", lo, hi, axes=axes)
    assert np.allclose(np.abs(_look(front)), [0, 0, 1]) and np.allclose(front.view_up, [1, 0, 0])


@pytest.mark.parametrize("extent", [[300, 100, 160], [100, 300, 160], [90, 400, 200], [400, 200, 90]])
def test_the_line_of_sight_is_the_shortest_extent_and_up_the_longest(extent):
    axes = natural_axes([0, 0, 0], extent)
    cam = named_view("front", [0, 0, 0], extent, axes=axes)
    assert np.argmax(np.abs(_look(cam))) == np.argmin(extent)
    assert np.argmax(np.abs(cam.view_up)) == np.argmax(extent) and np.isclose(np.linalg.det(axes), 1.0)
