"""Shared fixtures: small real files on disk; the hypothesis profiles.

Hypothesis draws the same examples on every run unless asked not to: the ``repeatable`` profile
(``derandomize``: examples come from each test's own name, no example database) is the default, so
``make test``, ``make test-all`` and CI never pass or fail by luck. ``HYPOTHESIS_PROFILE=explore``
(``make explore``) draws new examples each run and keeps the failing ones in
``.hypothesis/`` to replay: for looking for bugs, not for proving.
"""

from __future__ import annotations

import os

import numpy as np
import pytest
from hypothesis import settings

from volanim_core.rig.bones import Bone, BoneSkeleton
from volanim_core.rig.connectivity import BoneSegment, Connectivity
from volanim_core.skeleton.points import Skeleton

settings.register_profile("repeatable", derandomize=True, database=None, print_blob=True)
settings.register_profile("explore", derandomize=False, print_blob=True)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "repeatable"))

# The default tier (make test) is the proof a contributor runs before every commit: a test in it that takes
# over LONG_SECONDS is named at the end of the run, with its `long` marker's reason or as one to move to
# `slow` (make test-all). Only named: a verdict on wall-clock time would itself pass or fail by luck.
LONG_SECONDS = 5.0
_long: list[tuple[float, str, str | None]] = []


def pytest_runtest_logreport(report):
    if report.when != "call" or report.duration <= LONG_SECONDS or "slow" in report.keywords:
        return
    _long.append((report.duration, report.nodeid, getattr(report, "long_reason", None)))


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    marker = item.get_closest_marker("long")
    if marker is not None:
        outcome.get_result().long_reason = marker.args[0] if marker.args else marker.kwargs.get("reason")


def pytest_terminal_summary(terminalreporter):
    if not _long:
        return
    terminalreporter.section(f"default-tier tests over {LONG_SECONDS:g} s")
    for seconds, nodeid, reason in sorted(_long, reverse=True):
        why = f"long: {reason}" if reason else "no `long` reason: mark it slow, or make it faster"
        terminalreporter.write_line(f"{seconds:6.1f} s  {nodeid}\n           {why}")



@pytest.fixture
def rng():
    return np.random.default_rng(1234)


@pytest.fixture
def small_bones() -> BoneSkeleton:
    joints = {"L_HIP": (212, 140, 401), "L_KNEE": (214, 152, 561), "L_ANKLE": (216.5, 160, 702)}
    return BoneSkeleton(joints, [Bone("L_HIP", "L_KNEE", "L_THIGH"), Bone("L_KNEE", "L_ANKLE")])


@pytest.fixture
def small_skeleton(rng) -> Skeleton:
    pts = rng.integers(0, 200, size=(50, 3))
    pts = np.unique(pts, axis=0)
    dt = np.sqrt(rng.integers(1, 30, size=len(pts)).astype(float))
    th = rng.normal(0.5, 1.0, size=len(pts))
    return Skeleton(pts, dt, th).sorted()


@pytest.fixture
def small_connect(small_skeleton, small_bones) -> Connectivity:
    roots = [BoneSegment(*small_bones.segment(i), small_bones.bones[i].name) for i in range(len(small_bones))]
    bone = np.arange(len(small_skeleton)) % 2
    s = small_skeleton
    return Connectivity(roots, s.points, s.dt, s.thinness, bone).grouped()
