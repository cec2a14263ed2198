"""Progress helpers: one bar over a job's stages."""

from __future__ import annotations

import pytest

from volanim_core.errors import Cancelled
from volanim_core.progress import Reporter, stage


def test_a_stage_draws_on_its_share_of_the_bar():
    seen = []
    first, second = stage(lambda d, t: seen.append((d, t)), 0, 20), stage(lambda d, t: seen.append((d, t)), 20, 100)
    for done in range(0, 5):
        first(done, 4)
    for done in range(0, 11):
        second(done, 10)
    assert seen[0] == (0, 100) and seen[4] == (20, 100) and seen[-1] == (100, 100)
    assert [d for d, _ in seen] == sorted(d for d, _ in seen)  # only forward
    stage(None, 0, 50)(3, 4)  # no bar: nothing to draw, no error
    second(1, 0)  # a stage with no steps does not divide by zero


def test_a_stage_of_a_reporter_keeps_its_cancel_check():
    cancelled = []
    report = stage(Reporter(lambda d, t: None, lambda: bool(cancelled)), 10, 80)
    report(1, 2)
    cancelled.append(True)
    with pytest.raises(Cancelled):
        report(2, 2)
