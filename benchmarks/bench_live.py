"""Only what moved (#65): a drag's frames through a LiveFrame against the full reconstruction of each.

A drag turns one limb (the mannequins' L_FOREARM, the frog's LEGS) in 16 steps of 3 degrees, bone mode,
at full resolution and at the studio's half. Each frame is reconstructed both ways in the same round,
alternately (the machine drifts); each update is checked equal to the full reconstruction.

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


def main() -> None:
    datasets = sys.argv[sys.argv.index("--datasets") + 1].split(",") if "--datasets" in sys.argv else \
        ["mannequin", "frog", "mannequin-large"]
    rows = [drag(d, f) for d in datasets for f in (1, 2)]
    print("\na drag of one limb, 15 steps of 3 degrees, bone mode; each update equal to the full reconstruction")
    print(table(rows, ["body, resolution", "grid M voxels", "slices redone (median)", "full ms", "live ms",
                       "full / live", "live updates/s (kernel)"]))


if __name__ == "__main__":
    main()
