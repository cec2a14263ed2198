"""Reproduce the thesis's Tables 2.1 and 2.2 on the mannequin and the frog.

Table 2.1: thinness -> skeleton points -> voxels in the identity (rest)
reconstruction -> % voxel loss from the densest skeleton (every object voxel,
which reconstructs the object exactly).
Table 2.2: one posed frame (the mannequin's left upper arm / the frog's LEGS
bone turned 45 degrees at its proximal joint): time, voxels, % loss against
the same skeleton's identity frame, hotspot maximum redundancy.

mannequin-large (the thesis's half-size Visible Human scale, 290 x 169 x 940)
prints Table 2.2 with the thesis's own row at that scale beside ours.

Run: .venv/bin/python benchmarks/thesis_tables.py [mannequin] [mannequin-large] [frog]
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from _harness import table  # noqa: E402

from volanim_core import samples  # noqa: E402
from volanim_core.reconstruct.engine import reconstruct  # noqa: E402
from volanim_core.reconstruct.neighbours import sphere_neighbours  # noqa: E402
from volanim_core.rig.attach import connect_nearest  # noqa: E402
from volanim_core.rig.connectivity import Trans  # noqa: E402
from volanim_core.rig.pose import pose_matrices, root_bones  # noqa: E402
from volanim_core.rig.tskel import connect_to_tskel, identity_tskel  # noqa: E402
from volanim_core.skeleton.skeletonize import skeletonize  # noqa: E402

THINNESS = (1.0, 0.75, 0.5, 0.25, 0.0, -np.inf)
POSE = {"mannequin": ("L_UPPERARM", (0, -45, 0)), "mannequin-large": ("L_UPPERARM", (0, -45, 0)),
        "frog": ("LEGS", (0, 0, 45))}
#: The thesis's own Table 2.2 row at this scale: the half-size Visible Human (290 x 169 x 940) on 2001 hardware.
THESIS_ROW = ["thesis, Visible Human 1/2", 29777, f"{48 * 60 + 51} (48 min 51 s)", "-", "-", "-", "-"]


def tables(name: str) -> tuple[str, str]:
    s = samples.load(name)
    full = skeletonize(s.mask, min_thinness=-np.inf)
    densest = int(s.mask.sum())
    bone, angles = POSE[name]
    mats = pose_matrices(s.bones, {bone: angles})
    rows1, rows2 = [], []
    for th in THINNESS:
        skel = full.at(th)
        if not len(skel):  # no point is that thin: nothing to reconstruct
            rows1.append([f"{th:g}", 0, 0, "100.00"])
            rows2.append([f"{th:g}", 0, "-", 0, "-", "-", "-"])
            continue
        conn = connect_nearest(skel, s.bones)
        rest = reconstruct(identity_tskel(conn), mode="binary")
        loss = 100.0 * (densest - rest.stats["filled"]) / densest
        rows1.append([f"{th:g}", len(skel), rest.stats["filled"], f"{loss:.2f}"])
        posed = connect_to_tskel(conn, Trans(root_bones(s.bones), mats))
        nbrs = sphere_neighbours(posed)
        reconstruct(posed, mode="sampled", source=s.volume, neighbours=nbrs)  # warm
        t0 = time.perf_counter()
        r = reconstruct(posed, mode="sampled", source=s.volume, neighbours=nbrs)
        elapsed = time.perf_counter() - t0
        hot = reconstruct(posed, mode="hotspot")
        ploss = 100.0 * (rest.stats["filled"] - r.stats["filled"]) / rest.stats["filled"]
        rows2.append([f"{th:g}", len(skel), f"{elapsed:.3f}", r.stats["filled"], f"{ploss:.2f}",
                      hot.stats["hotspot_max"], f"{hot.stats['hotspot_mean']:.1f}"])
    if name == "mannequin-large":
        rows2.append(THESIS_ROW)
    t1 = table(rows1, ["thinness >=", "points", "identity voxels", "% loss from densest"])
    t2 = table(rows2, ["thinness >=", "points", "time s (sampled, 2 threads)", "voxels", "% loss vs identity",
                       "hotspot max", "hotspot mean"])
    return t1, t2


def main() -> None:
    for name in sys.argv[1:] or ("mannequin", "mannequin-large", "frog"):
        t1, t2 = tables(name)
        bone, angles = POSE[name]
        print(f"\n{name}: Table 2.1 (object: {int(samples.load(name).mask.sum())} voxels)\n{t1}")
        print(f"\n{name}: Table 2.2 ({bone} turned {angles} degrees at its proximal joint)\n{t2}")


if __name__ == "__main__":
    main()
