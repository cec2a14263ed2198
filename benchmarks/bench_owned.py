"""What the ownership default costs (#84): a posed frame from ownership against the thesis's rigid sphere frame,
and the ownership (once per rig) against the skeletonize it follows, same run, as ratios.

    body (frog, mannequin, mannequin-large) --skeletonize (timed)--> skeleton --connect (nearest)--> connectivity
        --ownership and the tables every frame reads (flags, cells, thin, diagonals, spans, hulls), timed--> labels
    one pose, frames alternated: reconstruct(method='spheres') vs reconstruct(method='owned'), bone mode
    goals: frame owned / spheres <= 1.0; ownership / skeletonize <= 1.0

Run: .venv/bin/python benchmarks/bench_owned.py [--rounds 5] [--bodies frog,mannequin-large]
"""

from __future__ import annotations

import argparse
import statistics
import time

POSES = {"frog": {"LEGS": (0, -45, 45)}, "mannequin": {"L_UPPERARM": (0, -90, 0)},
         "mannequin-large": {"R_THIGH": (-90, 0, 0)}}


def timed(make, *args, rounds: int = 3, **kwargs):
    """(what ``make(*args, **kwargs)`` returns, the median seconds of ``rounds`` calls after a first one)."""
    out, times = make(*args, **kwargs), []
    for _ in range(rounds):
        t0 = time.perf_counter()
        out = make(*args, **kwargs)
        times.append(time.perf_counter() - t0)
    return out, statistics.median(times)


def with_tables(mask, conn):
    """The ownership of ``conn`` with the tables every frame reads made (once per rig, at the first frame)."""
    from volanim_core.rig.ownership import ownership

    own = ownership(mask, conn)
    for table in (own.flags, own.cells, own.thin, own.diagonals, own.spans, own.hulls):
        table()
    return own


def main() -> None:
    from volanim_core import samples
    from volanim_core.reconstruct.engine import reconstruct
    from volanim_core.rig.attach import connect
    from volanim_core.rig.pose import pose_matrices
    from volanim_core.skeleton.skeletonize import skeletonize

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--bodies", default="frog,mannequin,mannequin-large")
    args = parser.parse_args()
    print("| body | skeletonize, s | ownership + its tables, s | ownership / skeletonize | sphere frame, s | "
          "owned frame, s | owned / spheres (frame) | overdraw spheres / owned |\n|---|---|---|---|---|---|---|---|")
    for name in args.bodies.split(","):
        s = samples.load(name)
        # each the median of 3 after a first (compiled, caches warm): timed once, skeletonize's first run (0.45 s
        # on the frog, 0.26 s after) made ownership look 1.7 times cheaper than it is
        skel, t_skel = timed(skeletonize, s.mask, **({} if name == "frog" else {"min_thinness": 0.5}))
        conn = connect(skel, s.bones)[0]
        own, t_own = timed(with_tables, s.mask, conn)
        frame = conn.with_ownership(own).posed(pose_matrices(s.bones, POSES[name]))
        for method in ("spheres", "owned"):
            reconstruct(frame, mode="bone", method=method)  # compiled, neighbour lists made
        times, over = {"spheres": [], "owned": []}, {}
        for r in range(args.rounds):
            for method in (("spheres", "owned") if r % 2 == 0 else ("owned", "spheres")):
                t0 = time.perf_counter()
                out = reconstruct(frame, mode="bone", method=method)
                times[method].append(time.perf_counter() - t0)
                over[method] = out.stats["overdraw"]
        ratio = statistics.median(b / a for a, b in zip(times["spheres"], times["owned"]))
        print(f"| {name} | {t_skel:.2f} | {t_own:.2f} | {t_own / t_skel:.2f} (goal <= 1.0) | "
              f"{statistics.median(times['spheres']):.3f} | {statistics.median(times['owned']):.3f} | "
              f"{ratio:.2f} (goal <= 1.0) | {over['spheres']:.1f} / {over['owned']:.1f} |", flush=True)


if __name__ == "__main__":
    main()
