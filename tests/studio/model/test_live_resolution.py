"""The live preview's resolution (model/live_resolution.py): the one that keeps 10 pictures a second (#85 item 4)."""

from __future__ import annotations

import pytest

from volanim_studio.model.live_resolution import WINDOW, LiveResolution


def factors(res: LiveResolution, costs: list[float], size_factor: int = 1) -> list[int]:
    """The factor each picture is made at, each then costing the next of ``costs`` (seconds)."""
    out = []
    for cost in costs:
        f = res.factor_for(lambda: size_factor)
        out.append(f)
        res.took(f, cost)
    return out


def test_slow_pictures_go_coarser_one_step_per_window_and_no_coarser_than_a_quarter():
    got = factors(LiveResolution(), [0.15] * (4 * WINDOW))
    assert got == [1] * WINDOW + [2] * WINDOW + [4] * (2 * WINDOW)


def test_one_slow_picture_among_fast_ones_changes_nothing():
    """A first frame (every voxel of a new grid) is slow: the median of the window, not the worst, decides."""
    assert factors(LiveResolution(), [0.4, 0.05, 0.06, 0.05, 0.3, 0.05]) == [1] * 6


def test_fast_pictures_come_back_to_full_size_and_a_middling_one_stays():
    assert factors(LiveResolution(), [0.01] * (2 * WINDOW), size_factor=4) == [4] * WINDOW + [2] * WINDOW
    res = LiveResolution()
    assert factors(res, [0.01] * (3 * WINDOW), size_factor=4)[-1] == 1
    # at half size 40 ms a picture: full size would cost 200 ms, so it stays at half
    assert factors(LiveResolution(), [0.04] * (3 * WINDOW), size_factor=2) == [2] * (3 * WINDOW)


def test_a_step_found_too_slow_is_not_tried_again_on_a_guess():
    """The frog's quarter-size pictures cost 15 ms, its half-size ones 120 ms: x 5 guessed 75 ms for half size,
    and the factor went 2, 4, 2, 4, ... for the whole drag (each change a picture of a whole grid). After one
    round trip the step's ratio (8) is known, and quarter size stays."""
    res = LiveResolution()
    cost = {2: 0.12, 4: 0.015}
    got = []
    for _ in range(8 * WINDOW):
        f = res.factor_for(lambda: 2)
        got.append(f)
        res.took(f, cost[f])
    assert got == [2] * WINDOW + [4] * WINDOW + [2] * WINDOW + [4] * (5 * WINDOW)
    res.reset()  # another body: nothing is known of it
    assert factors(res, [0.01] * (2 * WINDOW), size_factor=4) == [4] * WINDOW + [2] * WINDOW


def test_a_fixed_choice_is_kept_whatever_the_cost_and_reset_starts_from_the_size_rule():
    assert factors(LiveResolution("full"), [1.0] * 6, size_factor=2) == [1] * 6
    assert factors(LiveResolution("quarter"), [0.001] * 6) == [4] * 6
    res = LiveResolution()
    factors(res, [0.2] * WINDOW)
    assert res.factor_for(lambda: 1) == 2
    res.reset()
    assert res.factor_for(lambda: 1) == 1
    res.took(2, 1.0)  # a picture of the old factor, arriving late, is not counted
    assert factors(res, [0.2] * (WINDOW - 1)) == [1] * (WINDOW - 1) and res.factor_for(lambda: 1) == 1


def test_an_unknown_choice_is_refused_by_name():
    with pytest.raises(ValueError, match="auto, full, half, quarter"):
        LiveResolution("eighth")
