"""Auto-rig time against skeletonize, measured side by side (#41: <= 2 s on the frog's skeleton).

    frog (500 x 470 x 136, 137 k skeleton points)        skeletonize the mask / autorig the skeleton
    mannequin-large (290 x 169 x 940)                    the same
    mannequin (160 x 100 x 300)                          the same

Each pair runs back to back, alternating which goes first, for several rounds in one process; the
table shows every round, the median ratio (the machine drifts by 2x: only ratios measured side by
side mean anything) and autorig's median seconds against the issue's 2 s on the frog.

Run: .venv/bin/python benchmarks/bench_autorig.py [--rounds N]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time


def timed(fn) -> tuple[float, object]:
    t0 = time.perf_counter()
    out = fn()
    return time.perf_counter() - t0, out


def main(argv=None) -> int:
    from volanim_core import samples
    from volanim_core.rig.autorig import autorig
    from volanim_core.skeleton.skeletonize import skeletonize

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--rounds", type=int, default=3)
    args = p.parse_args(argv)
    print("| body | round | skeletonize s | autorig s | autorig / skeletonize | proposal |")
    print("|---|---|---|---|---|---|")
    frog_seconds = None
    for name, load in (("frog", samples.frog), ("mannequin-large", samples.mannequin_large),
                       ("mannequin", samples.mannequin)):
        mask = load().mask
        skel = skeletonize(mask)
        autorig(skel)  # warm: numba, imports
        ratios, seconds = [], []
        for k in range(args.rounds):
            def skeleton(m=mask):
                return skeletonize(m)

            def rig(s=skel):
                return autorig(s)

            if k % 2 == 0:
                a, _ = timed(skeleton)
                b, prop = timed(rig)
            else:
                b, prop = timed(rig)
                a, _ = timed(skeleton)
            ratios.append(b / a)
            seconds.append(b)
            print(f"| {name} | {k + 1} | {a:.2f} | {b:.2f} | {b / a:.2f} | "
                  f"{len(prop.bones)} bones ({prop.template}) |")
        sec, ratio = statistics.median(seconds), statistics.median(ratios)
        print(f"| **{name}** | median | | **{sec:.2f}** | **{ratio:.2f}** | |")
        if name == "frog":
            frog_seconds = statistics.median(seconds)
    print(f"\nfrog: autorig {frog_seconds:.2f} s (target 2 s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
