"""The reconstruction kernel, old tree against this one, in one run (#65's proof table).

For each body (the mannequin, the frog, mannequin-large) and each tree, one child process loads the
body's default skeleton attached by nearest bone, poses one limb 45 degrees (as bench_reconstruct does)
and times, warm, the median of ``--repeats`` calls:

    bone 2T, bone 1T, sampled 2T   reconstruct() as a user calls it
    overdraw                       stats["overdraw"]: sphere-voxel visits per filled voxel
    floor                          one np.copyto over the bytes a dense frame touches (output + stencil)

The old tree is checked out with ``git worktree`` (default: the commit before #65's first) and its
``src`` put first on the child's path; the measuring code is this file in both, so only the library
differs. Ratios are within one run: the machine is shared and drifts by 2x.

Run: .venv/bin/python benchmarks/bench_trees.py [--old REV] [--repeats N] [BODY ...]
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OLD = "44a8718~1"  # before #65: the power-plane cut, live frames, the whole-frame proof
BODIES = ["mannequin", "frog", "mannequin-large"]
sys.path.insert(0, str(Path(__file__).parent))
from _harness import table  # noqa: E402


def child(body: str, repeats: int) -> dict:
    import numpy as np

    from volanim_core import samples
    from volanim_core.reconstruct.engine import reconstruct
    from volanim_core.rig.attach import connect_nearest
    from volanim_core.rig.connectivity import Trans
    from volanim_core.rig.pose import pose_matrices, root_bones
    from volanim_core.rig.tskel_tools import connect_to_tskel
    from volanim_core.skeleton.skeletonize import skeletonize

    s = samples.load(body)
    conn = connect_nearest(skeletonize(s.mask), s.bones)
    bone = "LEGS" if body == "frog" else "L_UPPERARM"
    posed = connect_to_tskel(conn, Trans(root_bones(s.bones), pose_matrices(s.bones, {bone: (0, -45, 45)})))

    def timed(mode, threads):
        r = reconstruct(posed, mode=mode, source=s.volume, threads=threads)  # warm: compiled or cache-loaded
        times = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            reconstruct(posed, mode=mode, source=s.volume, threads=threads)
            times.append(time.perf_counter() - t0)
        return statistics.median(times), r

    bone2, r = timed("bone", 2)
    bone1, _ = timed("bone", 1)
    sampled2, _ = timed("sampled", 2)
    n = int(np.prod(r.volume.shape)) * 5
    a, b = np.ones(n, np.uint8), np.zeros(n, np.uint8)
    np.copyto(b, a)
    floor = []
    for _ in range(7):
        t0 = time.perf_counter()
        np.copyto(b, a)
        floor.append(time.perf_counter() - t0)
    return {"bone2": bone2, "bone1": bone1, "sampled2": sampled2, "overdraw": r.stats["overdraw"],
            "floor": statistics.median(floor), "grid": list(r.volume.shape)}


def run(tree: Path, body: str, repeats: int) -> dict:
    env = dict(os.environ, PYTHONPATH=str(tree / "src"))
    out = subprocess.run([sys.executable, __file__, "--child", body, str(repeats)], capture_output=True,
                         text=True, env=env, check=False, cwd=tree)
    if out.returncode:
        return {"error": (out.stderr.strip().splitlines() or ["failed"])[-1]}
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    args = sys.argv[1:]
    if args[:1] == ["--child"]:
        print(json.dumps(child(args[1], int(args[2]))))
        return
    old, repeats = OLD, 5
    if "--old" in args:
        i = args.index("--old")
        old = args[i + 1]
        del args[i:i + 2]
    if "--repeats" in args:
        i = args.index("--repeats")
        repeats = int(args[i + 1])
        del args[i:i + 2]
    bodies = args or BODIES
    load0 = os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as tmp:
        worktree = Path(tmp) / "old"
        subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "-q", "--detach", str(worktree), old], check=True)
        try:
            rows = []
            for body in bodies:
                for name, tree in (("old", worktree), ("new", ROOT)):
                    m = run(tree, body, repeats)
                    if "error" in m:
                        rows.append([body, name, m["error"], "", "", "", "", "", ""])
                        continue
                    ms = {k: 1000 * m[k] for k in ("bone2", "bone1", "sampled2", "floor")}
                    rows.append([body, name, "x".join(map(str, m["grid"])), f"{m['overdraw']:.1f}",
                                 f"{ms['bone2']:.1f}", f"{ms['bone1']:.1f}", f"{ms['bone1'] / ms['bone2']:.2f}",
                                 f"{ms['sampled2']:.1f}", f"{ms['floor']:.1f}",
                                 f"{ms['bone2'] / ms['floor']:.1f}"])
        finally:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(worktree)], check=False)
    print(f"\nthe posed frame, old tree {old} against this one (medians of {repeats}; "
          f"load average {load0:.2f} at the start, {os.getloadavg()[0]:.2f} at the end)")
    print(table(rows, ["body", "tree", "grid", "overdraw", "bone 2T ms", "bone 1T ms", "1T/2T", "sampled 2T ms",
                       "dense floor ms", "bone 2T / floor"]))


if __name__ == "__main__":
    main()
