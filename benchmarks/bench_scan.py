"""Scanning a clip for breakage (#61 item 11): this tree against an older one, the same frames, one run.

    the walk clip (src/volanim_core/sample_data/walk.bvh, 1064 frames) retargeted onto the mannequin's bones
    --> every --every'th frame's matrices, saved once (.npy)
    each tree (this one; --old REV, checked out with `git worktree` into a temporary folder), in a process of
    its own with that tree's src first on the path:
        scan_frames(mannequin.0.50.connect with rigid / smooth joints, the frames) --> ms a frame
        `volanim scan mannequin.0.50.connect` of all 1064 frames' .trans (written once by this tree) --> seconds
    printed as a table with each tree's ratio to the old one (the machine drifts: compare within a run)

Run: .venv/bin/python benchmarks/bench_scan.py [--old REV] [--every 4]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
WALK = REPO / "src" / "volanim_core" / "sample_data" / "walk.bvh"
CHILD = r"""
import json, sys, time
import numpy as np
from volanim_core import io
from volanim_core.reconstruct.scan import scan_frames
try:
    from volanim_core.rig.skinning import Joints
except ImportError:  # a tree from before smooth joints: rigid only
    Joints = None
mats = np.load(sys.argv[1])
conn = io.read_connect(sys.argv[2])
bones = io.read_bones(sys.argv[3])
out = {}
for kind in ("rigid", "smooth"):
    if Joints is None and kind == "smooth":
        continue
    c = conn if Joints is None else conn.with_joints(Joints(kind))
    scan_frames(c, mats[:2], range(2), joints=dict(bones.joints))  # compiled, rest parts made: not timed
    t0 = time.perf_counter()
    v = scan_frames(c, mats, range(len(mats)), joints=dict(bones.joints))
    ms = 1000 * (time.perf_counter() - t0) / len(mats)
    out[kind] = {"ms": ms, "broken": sum(x.pieces > getattr(x, "rest_pieces", 1) for x in v)}  # old: no field
print(json.dumps(out))
"""


def walk_matrices(every: int) -> np.ndarray:
    from volanim_core.io.bvh_files import read_bvh
    from volanim_core.motion.retarget import Retarget
    from volanim_core.samples import mannequin_bones

    r = Retarget.build(mannequin_bones(), read_bvh(WALK))
    return r.matrices()[::every]


def time_tree(root: Path, mats_path: Path, trans: list[Path]) -> dict:
    """Each tree scans with its own src and its own assets (a .connect as that tree wrote it): the library
    call on the matrices, then the whole ``volanim scan`` command on every frame's .trans (start-up, reading
    the files, the scan, the report: what a user waits for)."""
    env = dict(os.environ, PYTHONPATH=str(root / "src"))
    assets = root / "assets"
    out = subprocess.run([sys.executable, "-c", CHILD, str(mats_path), str(assets / "mannequin.0.50.connect"),
                          str(assets / "mannequin.bones")], env=env, capture_output=True, text=True, check=True)
    rows = json.loads(out.stdout.strip().splitlines()[-1])
    t0 = time.perf_counter()
    run = subprocess.run([sys.executable, "-m", "volanim_core", "scan", str(assets / "mannequin.0.50.connect"),
                          *map(str, trans), "--top", "1"], env=env, capture_output=True, text=True)
    rows["command"] = time.perf_counter() - t0
    # exit 1 is a verdict (frames broken); anything else is a failure, not a time (an old tree refusing
    # this tree's .trans files took 1.1 s and was printed as if it had scanned them)
    rows["failed"] = None if run.returncode in (0, 1) else (run.stderr.strip().splitlines() or ["?"])[-1][:80]
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--old", default="5277a0d", help="the tree to compare with (default: the commit whose "
                        "README said about 25 ms a frame)")
    parser.add_argument("--every", type=int, default=4, help="scan every N-th frame of the walk (default 4)")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        mats = walk_matrices(args.every)
        np.save(tmp / "walk.npy", mats)
        subprocess.run([sys.executable, "-m", "volanim_core", "bvh2trans", str(WALK), "--bones",
                        str(REPO / "assets" / "mannequin.bones"), "-o", str(tmp / "walk")], check=True,
                       capture_output=True)
        trans = sorted((tmp / "walk").glob("*.trans"))
        old = tmp / "old"
        subprocess.run(["git", "-C", str(REPO), "worktree", "add", "--detach", str(old), args.old], check=True,
                       capture_output=True)
        try:
            rows = {f"old ({args.old})": time_tree(old, tmp / "walk.npy", trans),
                    "this tree": time_tree(REPO, tmp / "walk.npy", trans)}
        finally:
            subprocess.run(["git", "-C", str(REPO), "worktree", "remove", "--force", str(old)], capture_output=True)
    base = next(iter(rows.values()))
    print(f"{len(mats)} frames of the walk (every {args.every}th), mannequin.0.50.connect, {os.cpu_count()} cores")
    print(f"| tree | rigid: ms a frame | ratio | smooth: ms a frame | ratio | frames torn (rigid) | "
          f"`volanim scan` of all {len(trans)} .trans: s | ratio |")
    print("|---|---|---|---|---|---|---|---|")
    for name, r in rows.items():
        smooth = r.get("smooth")
        print(f"| {name} | {r['rigid']['ms']:.1f} | {r['rigid']['ms'] / base['rigid']['ms']:.2f} | "
              + (f"{smooth['ms']:.1f} | " if smooth else "— | ")
              + (f"{smooth['ms'] / base['smooth']['ms']:.2f} | " if smooth and "smooth" in base else "— | ")
              + f"{r['rigid']['broken']} | "
              + (f"failed: {r['failed']} | — |" if r["failed"] else
                 f"{r['command']:.1f} | " + ("— |" if base["failed"] else f"{r['command'] / base['command']:.2f} |")))


if __name__ == "__main__":
    main()
