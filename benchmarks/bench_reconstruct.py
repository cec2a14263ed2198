"""Reconstruction benchmark on the frog (real data, default skeleton, thinness >= 0.5), or on
``--dataset mannequin-large`` (the thesis's half-size Visible Human scale: 25 k large spheres).

Two frames: identity, and the frog's LEGS bone (the mannequin's L_UPPERARM)
turned 45 degrees at its proximal joint. Each case runs in a fresh process (first call = numba cache
load; peak memory of a warm call beyond the loaded source). Ratios are
against baselines measured in the same run:

    ours (2 threads)  vs  thesis cube scan in numba (2 threads),
                          plain NumPy per sphere, ours on 1 thread,
                          the memory floor (one np.copyto over output + stencil bytes)

It ends with the speed issue's (#16) table: each measure, its target, met or not.

Run: .venv/bin/python benchmarks/bench_reconstruct.py [--dataset frog|mannequin|mannequin-large] [--repeats N]
"""

from __future__ import annotations

import sys
from functools import cache
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from _harness import child, measure, table  # noqa: E402


@cache
def load_connectivity(dataset: str):
    """The dataset's default skeleton (thinness >= 0.5) attached to its bones by nearest bone, and the bones."""
    from volanim_core import samples
    from volanim_core.rig.attach import connect_nearest
    from volanim_core.skeleton.skeletonize import skeletonize

    s = samples.load(dataset)
    return connect_nearest(skeletonize(s.mask), s.bones), s.bones


@cache
def load(dataset: str):
    from volanim_core import samples
    from volanim_core.reconstruct.engine import grid_bounds
    from volanim_core.reconstruct.neighbours import sphere_neighbours
    from volanim_core.rig.connectivity import Trans
    from volanim_core.rig.pose import pose_matrices, root_bones
    from volanim_core.rig.tskel_tools import connect_to_tskel, identity_tskel

    s = samples.load(dataset)
    conn, _ = load_connectivity(dataset)
    bone = "LEGS" if dataset == "frog" else "L_UPPERARM"
    posed = connect_to_tskel(conn, Trans(root_bones(s.bones), pose_matrices(s.bones, {bone: (0, -45, 45)})))
    ident = identity_tskel(conn)
    return {"source": s.volume, "posed": posed, "identity": ident, "neighbours": sphere_neighbours(posed),
            "bounds": {"posed": grid_bounds(posed), "identity": grid_bounds(ident)}}


def _ours(frame, mode, threads, cached=True, reuse_out=False):
    from volanim_core.reconstruct.engine import reconstruct

    def run(d):
        r = reconstruct(d[frame], mode=mode, source=d["source"], threads=threads,
                        neighbours=d["neighbours"] if cached else None, out=run.last if reuse_out else None)
        run.last = r.volume
    run.last = None
    return run


def _old(frame, sampled, threads):
    from _old_reconstruct import run_cube_scan

    return lambda d: run_cube_scan(d[frame], d["bounds"][frame], d["source"], sampled, threads)


def _numpy(frame, sampled):
    from _old_reconstruct import numpy_per_sphere

    return lambda d: numpy_per_sphere(d[frame], d["bounds"][frame], d["source"], sampled)


CASES = {
    "ours posed sampled 2T": _ours("posed", "sampled", 2),
    "ours posed sampled 2T, as a user calls it (no lists passed)": _ours("posed", "sampled", 2, cached=False),
    "ours posed sampled 1T": _ours("posed", "sampled", 1),
    "ours posed sampled 2T, out= reused (studio)": _ours("posed", "sampled", 2, reuse_out=True),
    "ours posed sampled 1T, out= reused (studio)": _ours("posed", "sampled", 1, reuse_out=True),
    "old cube scan posed sampled 2T": _old("posed", True, 2),
    "old cube scan posed sampled 1T": _old("posed", True, 1),
    "numpy posed sampled": _numpy("posed", True),
    "ours identity binary 2T": _ours("identity", "binary", 2),
    "numpy identity binary": _numpy("identity", False),
    "ours posed hotspot 2T": _ours("posed", "hotspot", 2),
    "ours posed bone 2T": _ours("posed", "bone", 2),
}


def floor_copy(d: dict, frame: str = "posed"):
    """The dense memory floor as a no-argument callable: one ``np.copyto`` over the bytes a dense
    reconstruction of ``frame``'s grid would touch (the output, 1 byte, and the stencil, 4, per voxel)."""
    n = int(np.prod(d["bounds"][frame].shape)) * 5
    a, b = np.ones(n, np.uint8), np.zeros(n, np.uint8)
    return lambda: np.copyto(b, a)


def floor_seconds(d: dict, frame: str = "posed") -> float:
    """Median seconds of :func:`floor_copy` over 7 calls (after one that touches the pages)."""
    import time

    copy = floor_copy(d, frame)
    copy()
    times = []
    for _ in range(7):
        t = time.perf_counter()
        copy()
        times.append(time.perf_counter() - t)
    return float(np.median(times))


def main() -> None:
    dataset = sys.argv[sys.argv.index("--dataset") + 1] if "--dataset" in sys.argv else "frog"
    repeats = int(sys.argv[sys.argv.index("--repeats") + 1]) if "--repeats" in sys.argv else 5
    from volanim_core.reconstruct.engine import reconstruct

    d = load(dataset)
    stats = {f: reconstruct(d[f], mode="sampled", source=d["source"], neighbours=d["neighbours"]).stats
             for f in ("posed", "identity")}
    results = {}
    for case in CASES:
        if case.startswith("numpy") and dataset == "mannequin-large":
            results[case] = {"error": "not run: minutes per call at this size"}
            continue
        reps = 0 if case.startswith("numpy") else repeats
        results[case] = measure(__file__, case, dataset, reps)
    base = results["ours posed sampled 2T"]["time"]
    rows = []
    for case, r in results.items():
        if "error" in r:
            rows.append([case, "-", "-", "-", r["error"][:50]])
            continue
        frame = "identity" if "identity" in case else "posed"
        voxels = int(np.prod(d["bounds"][frame].shape))
        rows.append([case, f"{r['time']:.4f}", f"{r['first']:.3f}", f"{r['peak'] / voxels:.2f}",
                     f"{r['time'] / base:.2f}"])
    floor = floor_seconds(d)
    rows.append(["memory floor: np.copyto of output+stencil", f"{floor:.4f}", "-", "-", f"{floor / base:.2f}"])
    posed_vox = int(np.prod(d["bounds"]["posed"].shape))
    print(f"\n{dataset}: {len(d['posed'])} spheres (mean radius {d['posed'].dt.mean():.2f}), "
          f"posed grid {d['bounds']['posed'].shape} = {posed_vox} voxels; "
          f"filled {stats['posed']['filled']} (identity {stats['identity']['filled']}); "
          f"overdraw posed {stats['posed']['overdraw']:.2f}, identity {stats['identity']['overdraw']:.2f}")
    # #85 item 3 asks for each voxel written once at <= 1.5x the floor: a kernel that still visits each sphere's rows
    # once (a per-row union or lower envelope of their runs) gets this long a row
    crossed = float(np.sum(np.pi * np.asarray(d["posed"].dt, np.float64) ** 2))
    print(f"sphere rows (sum of pi r^2) {crossed / stats['posed']['filled']:.2f} per filled voxel; 1.5x the floor "
          f"leaves {1e9 * 1.5 * floor / crossed:.1f} ns a sphere row; ours takes {1e9 * base / crossed:.1f} (all in)")
    print(table(rows, ["case", "time s", "first call s", "peak B/out voxel", "time / ours 2T"]))
    t = {k: v.get("time", float("nan")) for k, v in results.items()}
    print("\nratios (target):")
    print(f"  numpy posed sampled / ours 2T  = {t['numpy posed sampled'] / base:6.1f}  (>= 50)")
    ident = t["numpy identity binary"] / t["ours identity binary 2T"]
    print(f"  numpy identity binary / ours   = {ident:6.1f}  (>= 50)")
    reuse2, reuse1 = t["ours posed sampled 2T, out= reused (studio)"], t["ours posed sampled 1T, out= reused (studio)"]
    print(f"  ... with out= reused: 1T / 2T  = {reuse1 / reuse2:6.2f}")
    issue_table(dataset, d, results["ours posed sampled 2T"]["first"] - base)


def issue_table(dataset: str, d: dict, first_extra: float) -> None:
    """The speed issue's measures, as ratios from this one run: the cases the ratios compare are
    timed round by round in this process (:func:`_harness.interleaved`), not taken from the
    table above, whose cases ran in their own processes minutes apart."""
    from _harness import best_of, interleaved

    from volanim_core.reconstruct.engine import file_ordered
    from volanim_core.reconstruct.neighbours import cached_neighbours, sphere_neighbours

    cases = {"old": CASES["old cube scan posed sampled 2T"],
             "base": CASES["ours posed sampled 2T"],
             "user": CASES["ours posed sampled 2T, as a user calls it (no lists passed)"],
             "one": CASES["ours posed sampled 1T"]}
    m = interleaved({**{k: (lambda f=f: f(d)) for k, f in cases.items()}, "floor": floor_copy(d)})
    old, base, user, floor = m["old"], m["base"], m["user"], m["floor"]
    print(f"\ntimed round by round (medians of 15): cube scan {old:.4f} s, ours {base:.4f} s (lists passed), "
          f"{user:.4f} s (as a user calls it), ours on 1 thread {m['one']:.4f} s, floor {floor:.4f} s")
    print(f"  ours 1T / ours 2T, round by round = {m['one'] / base:.2f}  (>= 1.7)")
    frame = file_ordered(d["posed"])[0]
    made = best_of(lambda: sphere_neighbours(frame), 5)
    cached_neighbours(frame)
    looked_up = best_of(lambda: cached_neighbours(frame), 5)
    rows = [
        ["old cube scan / ours, called as a user calls it (2 threads)", f"{old / user:.2f}x", ">= 3x", old / user >= 3],
        ["old cube scan / ours, neighbour lists passed in", f"{old / base:.2f}x", ">= 3x", old / base >= 3],
        ["ours / dense memory floor (np.copyto of output + stencil)", f"{base / floor:.2f}x", "<= 4x",
         base / floor <= 4],
        ["neighbour lists made (a connectivity's first frame) / the call", f"{100 * made / base:.0f} %", "< 10 %",
         made / base < 0.10],
        ["neighbour lists looked up (every later frame) / the call", f"{100 * looked_up / base:.1f} %", "< 10 %",
         looked_up / base < 0.10],
        ["first call in a fresh process - a warm call (numba cache load)", f"{first_extra:.2f} s", "<= 3 s",
         first_extra <= 3],
    ]
    print(f"\nthe speed issue's table ({dataset}, posed sampled):")
    print(table([[m, v, g, "yes" if ok else "no"] for m, v, g, ok in rows], ["measure", "now", "target", "met"]))


if __name__ == "__main__":
    if "--child" in sys.argv:
        i = sys.argv.index("--child")
        child(CASES, load, sys.argv[i + 1], sys.argv[i + 2], int(sys.argv[i + 3]))
    else:
        main()
