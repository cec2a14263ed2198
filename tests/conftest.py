"""Shared fixtures: small real files on disk."""

from __future__ import annotations

import numpy as np
import pytest

from volanim_core.rig.bones import Bone, BoneSkeleton
from volanim_core.rig.connectivity import BoneSegment, Connectivity
from volanim_core.skeleton.points import Skeleton


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
