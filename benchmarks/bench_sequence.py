"""Sequence benchmark: frames per second on 1 and 2 local workers and on a Dask LocalCluster (loopback).

Datasets: the mannequin (the walk clip, every 10th frame), the frog (its legs swinging through 50
degrees) and mannequin-large, the largest sample (290x169x940, the thesis's half-size Visible Human:
the walk again). Reported: frames/s, the 2-worker speed-up over 1 worker (target >= 1.8x on 2
cores), Dask's overhead per frame against the local pool with the same workers (target <= 10 %),
peak memory per worker, the store's size on disk; then 100 frames at Visible-Human half scale on N
workers, from mannequin-large's measured cost per frame.

Frames/s are given for the whole run and for the steady state: while every worker runs, from the
moment the last worker finished its first frame (process start, imports and the numba cache load
are behind every worker) to the moment the first worker finished its last, each frame counted for
the part of its own time inside that window (``steady_rate``). A real sequence is 100-1000
frames, so the steady state is what it runs at.

The ratios (2 workers vs 1, Dask vs the pool) are medians of each round's own ratio: the two runs
of a round are seconds apart, in alternating order, while this shared VM's speed drifts by 2x
over minutes -- the ratio of each side's best round compares two unrelated lucky minutes. Dask's
overhead (the target) is estimated from all rounds of the three datasets together: one dataset's
7 rounds still move by +-5 points from run to run (a neighbour's burst in two of them).

    .venv/bin/python benchmarks/bench_sequence.py [FRAMES]    # FRAMES: the same count for every dataset
    .venv/bin/python benchmarks/bench_sequence.py --scale [FRAMES]   # the cost curve (#87), below

``--scale``: the walking mannequin on a quarter, half and the whole of the thesis's full Visible Human
grid (5.8 M, 46 M, 368 M voxels), the same walk frames at each, sampled mode, on a fresh Dask LocalCluster
of 1 and of 2 workers (fresh, so a worker's peak RSS is this run's). Reported per size: the voxels a frame
is made in (its own grid, not the walk's shared one), a worker's seconds per frame and per M voxels, the
2-worker throughput, peak RSS per worker and the store's bytes per frame. Linear in voxels is the goal:
seconds per M voxels within 1.3x of the quarter size's.
"""

from __future__ import annotations

import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from _harness import table  # noqa: E402

from volanim_core.sequence.store import bytes_on_disk  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]


def mannequin_case(n: int):
    from volanim_core import io, samples
    from volanim_core.sequence.frames import frames_from_files

    conn = io.read_connect(ROOT / "assets" / "mannequin.0.50.connect")
    frames = frames_from_files(conn, [samples.walk_clip()], bones=samples.mannequin_bones(),
                               frames=slice(0, 10 * n, 10))
    return "mannequin (walk)", conn, frames, samples.mannequin().volume


def frog_case(n: int):
    from volanim_core import samples
    from volanim_core.rig.attach import connect_nearest
    from volanim_core.rig.pose import pose_matrices
    from volanim_core.sequence.frames import FrameSpec
    from volanim_core.skeleton.skeletonize import skeletonize

    s = samples.frog()
    conn = connect_nearest(skeletonize(s.mask).at(0.5), s.bones)
    frames = [FrameSpec(k, pose_matrices(s.bones, {"LEGS": (0.0, 0.0, 50.0 * k / max(n - 1, 1))}))
              for k in range(n)]
    return "frog (legs swing)", conn, frames, s.volume


def large_case(n: int):
    from volanim_core import samples
    from volanim_core.sequence.frames import frames_from_files

    s = samples.mannequin_large()
    conn = samples.part_connectivity(s, 0.5)  # the thesis's Table 2.2 skeleton at this scale
    frames = frames_from_files(conn, [samples.walk_clip()], bones=s.bones, frames=slice(0, 10 * n, 10))
    return "mannequin-large (walk)", conn, frames, s.volume


# frames: 2-5 s of steady state a run on 2 workers -- with 1-1.7 s (48 mannequin or 24 frog frames) one
# neighbour's burst on this VM moved a round's Dask-vs-pool ratio by 15-25 points
CASES = ((mannequin_case, 96), (frog_case, 48), (large_case, 16))
ROUNDS = 7  # of the 2-worker pool and Dask, back to back (the 1-worker run: the first ONE_WORKER_ROUNDS)
ONE_WORKER_ROUNDS = 3


def steady_rate(records: list[dict]) -> float:
    """Frames/s while every worker runs: from the moment the last worker finished its first frame to
    the moment the first worker finished its last. Each frame counts for the part of its own time
    (``finished - seconds``, on its worker) inside that window, so frames reported several at a time
    (a Dask task of a few frames) or a worker's start count as they were made, and any gap between
    frames (scheduling, the driver) counts as lost time."""
    by_worker: dict[str, list[float]] = {}
    for r in records:
        by_worker.setdefault(r["worker"], []).append(r["finished"])
    lo, hi = max(min(t) for t in by_worker.values()), min(max(t) for t in by_worker.values())
    if hi <= lo:
        return float("nan")
    made = sum(max(0.0, min(hi, r["finished"]) - max(lo, r["finished"] - r["seconds"])) / r["seconds"]
               for r in records if r["seconds"] > 0)
    return made / (hi - lo)


def run(case, folder: Path, **where) -> dict:
    from volanim_core.parallel import RunOn
    from volanim_core.sequence.run import SequenceSettings, run_sequence

    name, conn, frames, source = case
    out = folder / "s.zarr"
    before = _helper_cpu()
    rep = run_sequence(conn, frames, out, SequenceSettings(mode="sampled", source=source), on=RunOn(**where),
                       existing="redo")
    helpers = _helper_cpu() - before
    size = bytes_on_disk(out)
    shutil.rmtree(out)
    return {"fps": len(frames) / rep.seconds, "steady": steady_rate(rep.records),
            "peak": max(r["peak_rss"] for r in rep.records), "size": size,
            "voxels": int(np.prod(rep.bounds.shape)), "seconds": rep.seconds, "helpers": helpers / rep.seconds}


def _helper_cpu() -> float:
    """CPU seconds of this process's threads other than the main one: with a LocalCluster, its
    scheduler, nannies and client (one event loop thread) -- Dask's own work on the workers' cores."""
    import threading

    import psutil

    main = threading.main_thread().native_id
    return sum(t.user_time + t.system_time for t in psutil.Process().threads() if t.id != main)


def _spin(n: int) -> float:
    """Pure CPU work with no memory traffic: what two cores can do at best."""
    t0 = time.perf_counter()
    x = 0
    for i in range(n):
        x += i * i
    return time.perf_counter() - t0


def machine_scaling(n: int = 8_000_000, rounds: int = 5) -> float:
    """The machine's own 2-vs-1 throughput on pure CPU work (a shared VM's 2 vCPUs may be one core):
    the best of ``rounds`` interleaved tries of each, like the sequences themselves."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    one = two = float("inf")
    with ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("spawn")) as pool:
        list(pool.map(_spin, [1000, 1000]))  # workers started
        for _ in range(rounds):
            t0 = time.perf_counter()
            list(pool.map(_spin, [n]))
            one = min(one, time.perf_counter() - t0)
            t0 = time.perf_counter()
            list(pool.map(_spin, [n, n]))
            two = min(two, time.perf_counter() - t0)
    return 2 * one / two


def _duration(seconds: float) -> str:
    return f"{seconds / 60:.1f} min" if seconds >= 60 else f"{seconds:.1f} s"


def main() -> None:
    from distributed import Client, LocalCluster

    count = int(sys.argv[1]) if len(sys.argv) > 1 else None
    rows, large, every_round = [], None, []
    with tempfile.TemporaryDirectory() as tmp, LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
            dashboard_address="127.0.0.1:0") as cluster, \
            Client(cluster) as client:
        folder = Path(tmp)
        for make, n in CASES:
            case = make(count or n)
            # This VM's neighbours take whole cores for seconds at a time, so the pool and Dask run back to
            # back, in alternating order, round after round: each ratio compares two runs a few seconds
            # apart, and the table gives the median ratio (best-of-N of each side compares two lucky
            # minutes instead). The frames/s columns are each side's best round.
            tries = []
            for k in range(ROUNDS):
                one = run(case, folder, workers=1) if k < ONE_WORKER_ROUNDS else None
                pair = [("two", {"workers": 2}), ("dask", {"scheduler": client})]
                got = {name: run(case, folder, **where) for name, where in (pair if k % 2 == 0 else pair[::-1])}
                tries.append({"one": one, **got})
            best = {k: max((t[k] for t in tries if t[k]), key=lambda r: r["steady"]) for k in ("one", "two", "dask")}
            one, two, dask = best["one"], best["two"], best["dask"]
            speedup = statistics.median(t["two"]["steady"] / t["one"]["steady"] for t in tries if t["one"])
            overheads = [t["two"]["steady"] / t["dask"]["steady"] - 1 for t in tries]  # extra time per frame
            every_round += overheads
            rows.append([case[0], f"{len(case[2])}", f"{one['voxels'] / 1e6:.0f}",
                         f"{one['fps']:.2f} / {one['steady']:.2f}",
                         f"{two['fps']:.2f} / {two['steady']:.2f}", f"{dask['fps']:.2f} / {dask['steady']:.2f}",
                         f"{speedup:.2f}", f"{100 * statistics.median(overheads):+.0f} %",
                         " ".join(f"{100 * o:+.0f}" for o in overheads),
                         f"{100 * statistics.median(t['dask']['helpers'] for t in tries):.0f} %",
                         f"{max(two['peak'], dask['peak']) / 2**20:.0f}", f"{two['size'] / 2**20:.1f}"])
            if make is large_case:
                large = (case, one, two, speedup)
    print("\nsequence, sampled mode, 2 cores; frames/s as whole run (with worker start-up) / steady state "
          "(while every worker runs, after its first frame)")
    print(f"f/s: each one's best of {ROUNDS} rounds ({ONE_WORKER_ROUNDS} for 1 worker); ratios: the median of the "
          f"rounds' own ratios (runs seconds apart); this machine's own 2-vs-1 throughput on pure CPU work "
          f"(same run, best of 5): {machine_scaling():.2f}x")
    print(table(rows, ["dataset", "frames", "grid M voxels", "1 worker f/s", "2 local workers f/s",
                       "Dask 2 workers f/s", "2 vs 1 steady (>= 1.8)", "Dask vs pool, median",
                       "Dask vs pool, each round %", "scheduler + nannies + client CPU", "peak MB/worker",
                       "store MB"]))
    q1, mid, q3 = statistics.quantiles(every_round, n=4)
    print(f"Dask vs pool, all {len(every_round)} rounds of the three datasets (the estimate of Dask's overhead per "
          f"frame, <= 10 %): median {100 * mid:+.1f} %, quartiles {100 * q1:+.1f} % / {100 * q3:+.1f} %")
    print("scheduler + nannies + client CPU: this process's threads but the main one (the LocalCluster's event loop) "
          "during the Dask run, "
          "in % of one core -- taken from the two cores the workers run on (on a cluster it is another machine's)")

    # 100 frames at Visible-Human half scale: mannequin-large is that scale, so its measured cost per
    # frame on one worker is the cost; N workers make ceil(100 / N) frames each, at the 2-worker efficiency
    # measured here (128 workers for 100 frames: one frame's time, not a 128th of a frame)
    case, one, two, speedup = large
    per = 1 / one["steady"]
    efficiency = min(1.0, speedup / 2)  # above 1 is this VM's noise, not a promise
    ext = [[str(w), f"{per:.2f}", _duration(-(-100 // w) * per / (efficiency if w > 1 else 1)),
            f"{two['peak'] / 2**30:.1f}"] for w in (1, 2, 8, 32, 128)]
    print(f"\n100 frames at Visible-Human half scale ({case[0]}: {len(case[1]):,} spheres, a "
          f"{one['voxels'] / 1e6:.0f} M-voxel shared grid): one worker's measured seconds per frame; N workers make "
          f"ceil(100 / N) frames each, at this run's 2-worker efficiency ({efficiency:.0%})")
    print(table(ext, ["workers", "s per frame", "100 frames take", "GB per worker"]))


def _scaled_case(fraction: float, n: int):
    """The walking mannequin on ``fraction`` of the full Visible Human grid (the sample's own body painted
    on that grid, its ground-truth skeleton), the walk's frames 0, 10, ... as at every size."""
    from volanim_core import samples
    from volanim_core.mannequin_body import FULL_SHAPE, MANNEQUIN_SHAPE
    from volanim_core.sequence.frames import frames_from_files

    s = samples._mannequin(np.array(FULL_SHAPE, float) * fraction / MANNEQUIN_SHAPE, f"mannequin x{fraction:g}")
    conn = samples.part_connectivity(s, 0.5)
    frames = frames_from_files(conn, [samples.walk_clip()], bones=s.bones, frames=slice(0, 10 * n, 10))
    return s, conn, frames


def _on_cluster(conn, frames, source, folder: Path, workers: int) -> dict:
    from distributed import Client, LocalCluster

    from volanim_core.parallel import RunOn
    from volanim_core.sequence.run import SequenceSettings, run_sequence

    out = folder / "scale.zarr"
    with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address="127.0.0.1:0", memory_limit=0) as cluster, Client(cluster) as client:
        rep = run_sequence(conn, frames, out, SequenceSettings(mode="sampled", source=source),
                           on=RunOn(scheduler=client), existing="redo")
    size = bytes_on_disk(out)
    shutil.rmtree(out)
    regions = [int(np.prod([b - a for a, b in r["region"]])) for r in rep.records]
    return {"seconds": float(np.median([r["seconds"] for r in rep.records])), "wall": rep.seconds,
            "steady": steady_rate(rep.records), "peak": max(r["peak_rss"] for r in rep.records),
            "size": size / len(frames), "voxels": float(np.mean(regions)),
            "filled": float(np.mean([r["filled"] for r in rep.records])),
            "overdraw": float(np.mean([r.get("overdraw", 0.0) for r in rep.records]))}


def scale_curve(n: int) -> None:
    import gc

    rows, per_voxel = [], {}
    with tempfile.TemporaryDirectory() as tmp:
        for fraction in (0.25, 0.5, 1.0):
            t0 = time.perf_counter()
            sample, conn, frames = _scaled_case(fraction, n)
            made = time.perf_counter() - t0
            got = {w: _on_cluster(conn, frames, sample.volume, Path(tmp), w) for w in (1, 2)}
            one, two = got[1], got[2]
            per_voxel[fraction] = one["seconds"] / (one["voxels"] / 1e6)
            rows.append([f"{fraction:g}", "x".join(map(str, sample.volume.shape)), f"{len(conn):,}", f"{n}",
                         f"{one['voxels'] / 1e6:.0f}", f"{one['filled'] / 1e6:.1f}", f"{one['seconds']:.2f}",
                         f"{1000 * per_voxel[fraction]:.1f}", f"{one['overdraw']:.1f}", f"{two['steady']:.3f}",
                         f"{two['seconds']:.2f}",
                         f"{one['peak'] / 2**30:.2f} / {two['peak'] / 2**30:.2f}", f"{one['size'] / 2**20:.2f}",
                         f"{made:.0f}"])
            del sample, conn, frames
            gc.collect()
    base = per_voxel[0.25]
    for row, fraction in zip(rows, per_voxel):
        row.insert(8, f"{per_voxel[fraction] / base:.2f}")
    print(f"\nsequence cost curve (#87): the walking mannequin, {n} walk frames a size, sampled mode, a fresh Dask "
          "LocalCluster of 1 and of 2 workers (1 thread each) per size; a frame's voxels: its own grid")
    print(table(rows, ["size (of full)", "body grid", "spheres", "frames", "M voxels a frame", "M filled",
                       "1 worker s/frame (median)", "ms per M voxels", "vs quarter (<= 1.3)", "overdraw",
                       "2 workers f/s (steady)", "2 workers s/frame a worker", "peak GB a worker (1 / 2)",
                       "store MB a frame", "body + skeleton s"]))


if __name__ == "__main__":
    if "--scale" in sys.argv:
        args = [a for a in sys.argv[1:] if a != "--scale"]
        scale_curve(int(args[0]) if args else 6)
    else:
        main()
