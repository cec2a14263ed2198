"""Rigid against smooth joints (#42): the breakage measures at every angle, and what smooth costs.

    mannequin (or --large: mannequin-large), ground-truth attachments (samples.part_connectivity)
    for each joint and angle (15 degree steps), rigid and smooth:
        pieces, cracks, stump points, loss against the rest pose (breakage_report),
        far-limb Dice (reconstruct/bend.py: the limb beyond 3 limb radii, smooth against rigid),
        twist: the forearm's cross-section at the elbow against rest
    frog (LEGS turned as bench_reconstruct.py does), bone mode: smooth frame time / rigid, alternated
    mannequin: live previews (half resolution, bone mode) per second, smooth

Run: .venv/bin/python benchmarks/bench_joints.py [--large] [--step 15] [--rounds 5]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np
from scipy.spatial.transform import Rotation

#: joint -> (bent bone, the joint it turns about, the largest angle, rotation of the angle a in degrees)
JOINTS = {
    "shoulder raise": ("L_UPPERARM", "L_SHOULDER", 150, lambda a, u: (0, -a, 0)),
    "hip flexion": ("L_THIGH", "L_HIP", 120, lambda a, u: (-a, 0, 0)),
    "knee": ("L_SHIN", "L_KNEE", 150, lambda a, u: (a, 0, 0)),
    "elbow": ("L_FOREARM", "L_ELBOW", 150, lambda a, u: (-a, 0, 0)),
    "forearm twist": ("L_FOREARM", "L_ELBOW", 90, lambda a, u: Rotation.from_rotvec(u * np.radians(a)).as_matrix()),
}


def joint_table(sample, step: int) -> list[tuple]:
    """One row per joint, angle and kind: (joint, angle, kind, pieces, cracks, stump, loss %, dice, section %)."""
    from volanim_core import samples
    from volanim_core.reconstruct.bend import cross_section, far_limb_dice
    from volanim_core.reconstruct.breakage import RestParts, breakage_report
    from volanim_core.reconstruct.engine import reconstruct
    from volanim_core.rig.pose import pose_matrices, posed_joints
    from volanim_core.rig.skinning import Joints

    conn = samples.part_connectivity(sample)
    bones, joints = sample.bones, sample.bones.joints
    names = [b.name for b in conn.bones]
    rows = []
    rigid = {}  # (joint, angle) -> the rigid frame's bone volume, what smooth's far limb must match
    for kind in ("rigid", "smooth"):
        c = conn.with_joints(Joints(kind))
        rest = RestParts.of(c)
        rest_bone = reconstruct(c.posed(np.tile(np.eye(4), (len(names), 1, 1))), mode="bone")
        for label, (bone, joint, top, rotation) in JOINTS.items():
            b = names.index(bone)
            axis = bones.joints[bones.bones[b].distal] - joints[joint]
            u = axis / np.linalg.norm(axis)
            radius = float(c.dt[c.bone == b].max())
            at_rest = cross_section(rest_bone, joints[joint] + 2 * radius * u, u, 2 * radius)
            for angle in range(0, top + 1, step):
                m = pose_matrices(bones, {bone: rotation(angle, u)})
                t = c.posed(m)
                posed = reconstruct(t, mode="bone")
                rep = breakage_report(t, joints, posed_joints(bones, m), posed=posed, rest=rest)
                rigid.setdefault((label, angle), posed)
                dice = far_limb_dice(posed, rigid[(label, angle)], b, m[b], joints[joint], 3 * radius)
                section = 100.0 * cross_section(posed, joints[joint] + 2 * radius * u, u, 2 * radius) / at_rest \
                    if label == "forearm twist" else float("nan")
                rows.append((label, angle, kind, len(rep.components), rep.cracks, sum(s.points for s in rep.stumps),
                             rep.loss_percent, dice, section))
    return rows


def timing(rounds: int) -> tuple[list[float], list[float]]:
    """Seconds of a rigid and a smooth bone-mode frame of the frog (bench_reconstruct.py's pose), alternated."""
    from volanim_core import samples
    from volanim_core.reconstruct.engine import reconstruct
    from volanim_core.rig.attach import connect_nearest
    from volanim_core.rig.pose import pose_matrices
    from volanim_core.rig.skinning import Joints
    from volanim_core.skeleton.skeletonize import skeletonize

    frog = samples.load("frog")
    conn = connect_nearest(skeletonize(frog.mask), frog.bones)  # as bench_reconstruct.py
    m = pose_matrices(frog.bones, {"LEGS": (0, -45, 45)})
    conns = {k: conn.with_joints(Joints(k)) for k in ("rigid", "smooth")}
    for c in conns.values():  # compile; the weights are made once, kept with the connectivity as in a sequence
        reconstruct(c.posed(m), mode="bone")
    times = {"rigid": [], "smooth": []}
    for r in range(rounds):
        for k in (("rigid", "smooth") if r % 2 == 0 else ("smooth", "rigid")):
            t0 = time.perf_counter()
            reconstruct(conns[k].posed(m), mode="bone")  # a new frame: its blended motions are made again
            times[k].append(time.perf_counter() - t0)
    return times["rigid"], times["smooth"]


def live_rate(rounds: int) -> float:
    """Half-resolution smooth previews per second on the mannequin, the studio's live preview."""
    from volanim_core import samples
    from volanim_core.reconstruct.engine import reconstruct
    from volanim_core.rig.pose import pose_matrices
    from volanim_core.rig.skinning import Joints
    from volanim_core.rig.tskel_tools import coarse_tskel

    s = samples.mannequin()
    conn = samples.part_connectivity(s).with_joints(Joints("smooth"))
    reconstruct(coarse_tskel(conn.posed(pose_matrices(s.bones, {})), 2), mode="bone")
    t0 = time.perf_counter()
    for k in range(rounds * 4):
        t = conn.posed(pose_matrices(s.bones, {"L_UPPERARM": (0, -5.0 * k, 0)}))
        reconstruct(coarse_tskel(t, 2), mode="bone", padding=2)
    return rounds * 4 / (time.perf_counter() - t0)


def main(argv=None) -> int:
    from volanim_core import samples

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--large", action="store_true", help="mannequin-large instead of the mannequin")
    ap.add_argument("--step", type=int, default=15)
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--no-timing", action="store_true")
    args = ap.parse_args(argv)
    sample = samples.mannequin_large() if args.large else samples.mannequin()
    rows = joint_table(sample, args.step)
    print(f"{sample.name}: rigid | smooth (pieces / cracks / stump points / loss % / far-limb Dice"
          " [/ cross-section % of rest])")
    print("| joint | angle | rigid | smooth |\n|---|---|---|---|")
    by = {(r[0], r[1], r[2]): r for r in rows}
    for label, angle, kind, *_ in rows:
        if kind != "rigid":
            continue
        cells = []
        for k in ("rigid", "smooth"):
            _, _, _, pieces, cracks, stump, loss, dice, section = by[(label, angle, k)]
            cell = f"{pieces} / {cracks} / {stump} / {loss:+.1f} / {dice:.3f}"
            cells.append(cell + ("" if np.isnan(section) else f" / {section:.0f}"))
        print(f"| {label} | {angle} | {cells[0]} | {cells[1]} |")
    if args.no_timing:
        return 0
    rigid, smooth = timing(args.rounds)
    print("\nfrog, bone mode, LEGS turned (0, -45, 45) (seconds per frame, alternated)")
    print("| round | rigid | smooth | smooth / rigid |\n|---|---|---|---|")
    for k, (a, b) in enumerate(zip(rigid, smooth)):
        print(f"| {k} | {a:.3f} | {b:.3f} | {b / a:.2f} |")
    print(f"| median | {statistics.median(rigid):.3f} | {statistics.median(smooth):.3f} | "
          f"{statistics.median(b / a for a, b in zip(rigid, smooth)):.2f} (target <= 1.3) |")
    print(f"\nmannequin live preview, smooth joints: {live_rate(args.rounds):.1f} updates/s (target >= 10)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
