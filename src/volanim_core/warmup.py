"""Compile every numba kernel once, on tiny inputs, so the first real call is fast.

    compile_kernels()
        skeletonize (euclid, 345) --> auto_connect (path) --> reconstruct
        (every mode x metric, sampled with kernel 1 and 3, and a colour source) --> palette
        orderings --> breakage report (+ detached pieces; a clip's scan uses the same kernels, and its
        proof of one piece)
        --> a live picture's voxel faces --> a crumble's heap --> a proposed rig's balls --> the rig's ownership
        and a frame from it

Every kernel a user's command or the studio calls is in that list (a test holds it to that): a fresh
install that skipped this compiles on first use instead -- the walk's first `volanim scan` took 22 s
there against 8 s warm (#61 item 11), and three times as long on a busy machine.

The kernels are ``@njit(cache=True)``: the machine code lands in the package's
``__pycache__`` and later processes load it in well under a second. A fresh
install compiles them all in ~20 s the first time; doing it here, up front and
with a message (``volanim warmup``, run by ``make install``; ``make demo``; the test session), keeps
that cost out of anything a user -- or a test with a timeout -- is waiting on.
Types matter to numba, so the inputs use the dtypes real calls use (uint8
labels and sources, uint16 hotspot counts, float64 geometry).
"""

from __future__ import annotations

import time

import numpy as np


def _tiny_body() -> np.ndarray:
    """A 24x12x12 bar with a thinner bar on top: two bones' worth of shape."""
    mask = np.zeros((24, 12, 12), bool)
    mask[2:22, 3:9, 3:9] = True
    mask[10:14, 4:8, 8:11] = True
    return mask


def compile_kernels(progress=None) -> float:
    """Run every kernel variant the library uses once; returns the seconds it took.

    ``progress(done, total)`` is called after each step (for a message or a bar).
    """
    from volanim_core._run_kernels import run_values, runs
    from volanim_core.colour.sort import sort_palette
    from volanim_core.reconstruct._whole_kernels import touches_any
    from volanim_core.reconstruct.breakage import breakage_report, components
    from volanim_core.reconstruct.engine import MODES, reconstruct
    from volanim_core.rig.attach import auto_connect
    from volanim_core.rig.bones import Bone, BoneSkeleton
    from volanim_core.rig.connectivity import BoneSegment, Connectivity, Tskel
    from volanim_core.rig.curve_skeleton import balls
    from volanim_core.rig.pose import pose_matrices
    from volanim_core.rig.tskel_tools import coarse_tskel
    from volanim_core.sequence.effects import fall
    from volanim_core.skeleton.skeletonize import skeletonize
    from volanim_core.voxel_faces import face_arrays

    t0 = time.perf_counter()
    mask = _tiny_body()
    source = np.where(mask, 200, 0).astype(np.uint8)
    bones = BoneSkeleton({"A": (3.0, 6.0, 6.0), "B": (12.0, 6.0, 6.0), "C": (21.0, 6.0, 6.0)},
                         [Bone("A", "B"), Bone("B", "C")])
    roots = [BoneSegment(*bones.segment(i), bones.bones[i].label) for i in range(len(bones))]
    matrices = pose_matrices(bones, {1: np.array([0.0, 0.0, 30.0])})
    metrics = ("euclid", "345")
    total, done = len(metrics) * (len(MODES) + 1) + 1, 0
    tskel = None
    for metric in metrics:
        skel = skeletonize(mask, metric=metric, min_thinness=-np.inf)
        bone_of, _ = auto_connect(skel.points, bones, mask, method="path")
        auto_connect(skel.points, bones, mask, method="geodesic")  # the paths' many-pairs kernel
        conn = Connectivity(roots, skel.points, skel.dt, skel.thinness, np.maximum(bone_of, 0), metric).grouped()
        tskel = Tskel(conn.bones, matrices, conn.points, conn.dt, conn.thinness, conn.bone, metric)
        done += 1
        _report(progress, done, total)
        for mode in MODES:
            for kernel in ((1, 3) if mode == "sampled" else (1,)):
                reconstruct(tskel, mode=mode, source=source if mode == "sampled" else None, kernel=kernel)
            done += 1
            _report(progress, done, total)
    rgb = np.repeat(source[..., None], 3, axis=3)
    reconstruct(tskel, mode="sampled", source=rgb, kernel=3)  # a colour source: float32 linear light
    for labels in (np.uint8, np.uint16):  # a live picture's faces: bone labels of up to 254 bones, and more
        face_arrays(np.asfortranarray(_tiny_body().astype(labels)), (0, 0, 0), (1, 1, 1), np.zeros((2, 3), np.uint8))
    sort_palette(rgb[10:13, 5, 5:8].reshape(-1, 3) + np.arange(9, dtype=np.uint8)[:, None], "path")  # all moves
    sort_palette(np.arange(12, dtype=np.uint8).repeat(3).reshape(-1, 3), "farthest-seeds")
    sort_palette(rgb[10:13, 5, 5:8].reshape(-1, 3) + np.arange(9, dtype=np.uint8)[:, None], "ramp")  # the default
    breakage_report(tskel, dict(bones.joints), dict(bones.joints))
    two = np.zeros((6, 6, 6), np.uint8)
    two[1, 1, 1] = two[4, 4, 4] = 1
    components(two)  # a report's detached pieces: where each is nearest the main body
    two16 = np.ascontiguousarray(two.astype(np.uint16))  # a smooth frame's report: its pieces and rest owners
    components(two16)
    first, x0, _ = runs(two16, True)
    run_values(two16, first, x0)
    # a clip scan's proof of one piece: its small spheres' voxel test, with a scan's own dtypes
    touches_any(np.zeros((2, 3)), np.array([4.0, 1.0]), np.array([1]), np.array([[0]]), np.array([True, False]),
                np.zeros(1, np.int8))
    fall(np.pad(source, ((8, 8), (8, 8), (0, 8))), 1.0)  # a crumble's heap (room for it around the bar)
    balls(skel)  # a proposed rig's body of balls (auto-rig)
    # the ownership default (#84): the rig's ownership, then a frame in every mode from it, uint8 labels
    from volanim_core.rig.ownership import ownership
    from volanim_core.rig.reach import out_of_reach
    from volanim_core.rig.specks import join_specks

    own = ownership(mask, conn)
    out_of_reach(own)  # flesh that hangs on only through another limb (volanim connect warns of it)
    owned = conn.with_ownership(own).posed(matrices)
    specks = np.ones((6, 4, 4), np.uint8, order="F")
    specks[5], specks[2, 1, 1] = 2, 2  # bone 2's flesh at one end, a speck of it in bone 1's
    join_specks(specks, 2)  # a speck of one bone inside another's flesh
    for mode in MODES:
        reconstruct(owned, mode=mode, source=source if mode == "sampled" else None)
    reconstruct(coarse_tskel(owned, 2), mode="bone")  # a live preview at half size: the ownership pooled (#85)
    _report(progress, total, total)
    return time.perf_counter() - t0


def _report(progress, done: int, total: int) -> None:
    if progress is not None:
        progress(done, total)
