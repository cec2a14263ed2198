"""Only what moved (#65): a drag's frames through a LiveFrame against the full reconstruction of each.

A drag turns one limb (the mannequins' L_FOREARM, the frog's LEGS) in 16 steps of 3 degrees, bone mode,
at full resolution and at the studio's half. Each frame is reconstructed both ways in the same round,
alternately (the machine drifts); each update is checked equal to the full reconstruction.

The owned body (#85, the default since #84) the same way: a LiveOwned redoing the moved bones' box against the
full owned frame on the same grid, and against the spheres' LiveFrame of the same drag, same run (ratios).

Run: .venv/bin/python benchmarks/bench_live.py [--datasets mannequin,frog,mannequin-large]
"""

from __future__ import annotations

import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from _harness import table  # noqa: E402

LIMB = {"mannequin": "L_FOREARM", "mannequin-large": "L_FOREARM", "frog": "LEGS"}


def drag(dataset: str, factor: int) -> list:
    from bench_reconstruct import load_connectivity

    from volanim_core.reconstruct.engine import reconstruct
    from volanim_core.reconstruct.live import LiveFrame
    from volanim_core.reconstruct.plan import grid_bounds
    from volanim_core.rig.pose import pose_matrices
    from volanim_core.rig.tskel_tools import coarse_tskel

    conn, bones = load_connectivity(dataset)
    frames = [coarse_tskel(conn.posed(pose_matrices(bones, {LIMB[dataset]: (0, -3 * k, 0)})), factor)
              for k in range(16)]
    bounds = grid_bounds(frames, padding=2)
    live = LiveFrame(bounds, mode="bone")
    live.update(frames[0])
    reconstruct(frames[0], mode="bone", bounds=bounds)  # both warm
    full, part, redone = [], [], []
    for t in frames[1:]:
        t0 = time.perf_counter()
        got = live.update(t, copy=False)
        t1 = time.perf_counter()
        want = reconstruct(t, mode="bone", bounds=bounds)
        t2 = time.perf_counter()
        assert np.array_equal(got.volume, want.volume)
        part.append(t1 - t0)
        full.append(t2 - t1)
        redone.append(live.redone / bounds.shape[2])
    full_s, part_s = statistics.median(full), statistics.median(part)
    return [f"{dataset}, 1/{factor}" if factor > 1 else dataset, f"{np.prod(bounds.shape) / 1e6:.1f}",
            f"{100 * statistics.median(redone):.0f} %", f"{1000 * full_s:.1f}", f"{1000 * part_s:.1f}",
            f"{full_s / part_s:.1f}x", f"{1 / part_s:.0f}"]


def drag_owned(dataset: str, factor: int) -> list:
    """The same drag of the owned body: LiveOwned's update, the full owned frame, the spheres' LiveFrame update."""
    from bench_reconstruct import load_connectivity

    from volanim_core import samples
    from volanim_core.reconstruct.live import LiveFrame
    from volanim_core.reconstruct.live_owned import LiveOwned
    from volanim_core.reconstruct.owned import posed_bounds, reconstruct_owned
    from volanim_core.reconstruct.plan import grid_bounds
    from volanim_core.rig.ownership import ownership
    from volanim_core.rig.pose import pose_matrices
    from volanim_core.rig.tskel_tools import coarse_tskel

    conn, bones = load_connectivity(dataset)
    conn = conn.with_ownership(ownership(samples.load(dataset).mask, conn))
    frames = [coarse_tskel(conn.posed(pose_matrices(bones, {LIMB[dataset]: (0, -3 * k, 0)})), factor)
              for k in range(16)]
    own = frames[0].ownership
    matrices = [own.rest_matrices(t.matrices) for t in frames]
    bounds = posed_bounds(own, matrices[0], 30)
    live, spheres = LiveOwned(own, bounds, mode="bone"), LiveFrame(grid_bounds(frames, padding=2), mode="bone")
    live.update(matrices[0])
    spheres.update(frames[0])
    full, part, sphere, redone = [], [], [], []
    for t, m in zip(frames[1:], matrices[1:]):
        t0 = time.perf_counter()
        got = live.update(m, copy=False)
        t1 = time.perf_counter()
        want = reconstruct_owned(own, m, mode="bone", bounds=bounds)
        t2 = time.perf_counter()
        spheres.update(t, copy=False)
        t3 = time.perf_counter()
        assert np.array_equal(got.volume, want.volume)
        part.append(t1 - t0)
        full.append(t2 - t1)
        sphere.append(t3 - t2)
        redone.append(live.redone / np.prod(bounds.shape))
    full_s, part_s, sphere_s = statistics.median(full), statistics.median(part), statistics.median(sphere)
    return [f"{dataset}, 1/{factor}" if factor > 1 else dataset, f"{np.prod(bounds.shape) / 1e6:.1f}",
            f"{100 * statistics.median(redone):.1f} %", f"{1000 * full_s:.1f}", f"{1000 * part_s:.1f}",
            f"{full_s / part_s:.1f}x", f"{1000 * sphere_s:.1f}", f"{part_s / sphere_s:.2f}"]


def main() -> None:
    datasets = sys.argv[sys.argv.index("--datasets") + 1].split(",") if "--datasets" in sys.argv else \
        ["mannequin", "frog", "mannequin-large"]
    rows = [drag(d, f) for d in datasets for f in (1, 2)]
    print("\na drag of one limb, 15 steps of 3 degrees, bone mode; each update equal to the full reconstruction")
    print(table(rows, ["body, resolution", "grid M voxels", "slices redone (median)", "full ms", "live ms",
                       "full / live", "live updates/s (kernel)"]))
    rows = [drag_owned(d, f) for d in datasets for f in (1, 2)]
    print("\nthe same drag of the owned body (#85): LiveOwned against the full owned frame and the spheres' LiveFrame")
    print(table(rows, ["body, resolution", "grid M voxels", "voxels redone (median)", "full owned ms",
                       "live owned ms", "full / live", "live spheres ms", "owned / spheres (live)"]))


if __name__ == "__main__":
    main()
