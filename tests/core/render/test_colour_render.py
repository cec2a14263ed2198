"""A colour volume is drawn in its own colours (RGB straight to the screen, black transparent)."""

from __future__ import annotations

import numpy as np
import pytest
from test_render import H, W, ball, lit

from volanim_core.render.scene import Renderer, RenderSettings
from volanim_core.render.views import Camera


@pytest.mark.parametrize(("style", "mapper"), [("volume", "gpu"), ("volume", "cpu"), ("surface", "gpu")])
def test_a_red_and_a_blue_half_ball_show_red_and_blue(style, mapper):
    body = ball() > 0
    rgb = np.zeros((*body.shape, 3), np.uint8)
    rgb[:40, ..., 0] = 220  # x < 40 red, the rest blue
    rgb[40:, ..., 2] = 220
    rgb[~body] = 0
    cam = Camera((40.0, -260.0, 40.0), (40.0, 40.0, 40.0), (0.0, 0.0, 1.0), 30.0)
    r = Renderer(RenderSettings(cam, style=style, mapper=mapper, size=(W, H), background="black"))
    try:
        image = r.render(rgb, (0, 0, 0)).astype(int)
    finally:
        r.close()
    on = lit(image)
    left, right = on[:, : W // 2 - 4], on[:, W // 2 + 4:]
    assert left.sum() > 500 and right.sum() > 500
    # seen from -y with z up, +x is to the right: red on the left half, blue on the right
    red, blue = image[:, : W // 2 - 4][left], image[:, W // 2 + 4:][right]
    assert (red[:, 0] > 2 * red[:, 2]).mean() > 0.95 and (blue[:, 2] > 2 * blue[:, 0]).mean() > 0.95
    assert not on[:5].any() and not on[:, :5].any()  # black around the ball stays background
