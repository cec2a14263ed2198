"""Posed bodies against their true shape (#60): every joint and angle, every method, one run.

    mannequin (and mannequin-large with --large): the default pipeline's connectivity
        (skeletonize at thinness 0.5, connect to the nearest bone: what `volanim connect` gives)
    for each joint and angle and method (rigid: today's default; smooth: --joints smooth, blend 1; fitted:
    rigid over `connect --method fitted`, rig/limb_tubes.py):
        bone-mode reconstruction --compare_shapes--> posed_sample (the capsules posed by the same matrices)
        Dice, the largest extra and missing blob (opened by one voxel) as % of the moved limb's voxels,
        surface distance p95 (voxels)
    goals (#60): Dice >= 0.995, largest blob <= 0.5 % of the moved limb, p95 <= 1.5 voxels
    the report's lumps (reconstruct/lumps.py, no truth) against the truth's extra blobs: a row has a true
    lump when its largest extra blob is >= 0.5 % of the limb; recall and precision of the flags (rigid)

Run: .venv/bin/python benchmarks/bench_shape.py [--large] [--step 15] [--joints "shoulder abduction,hip flexion"]
     .venv/bin/python benchmarks/bench_shape.py --walk 10     (the real walk clip, every 10th frame)
     .venv/bin/python benchmarks/bench_shape.py --cost 7      (fitted's cost against nearest, frog and mannequin)
     .venv/bin/python benchmarks/bench_shape.py --floor [--joints ...] [--walk 1050]
                                      (what a read of the rest segmentation can reach: perfect owners and overlaps)
     .venv/bin/python benchmarks/bench_shape.py --true-owners [--joints ...]   (the truth's parts as owners)
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from scipy.spatial.transform import Rotation

#: joint -> (bone turned, largest angle, rotation of angle a in degrees given the bone's unit axis u)
JOINTS = {
    "shoulder abduction": ("L_UPPERARM", 150, lambda a, u: (0, -a, 0)),
    "shoulder flexion": ("L_UPPERARM", 150, lambda a, u: (-a, 0, 0)),
    "hip flexion": ("R_THIGH", 120, lambda a, u: (-a, 0, 0)),
    "elbow": ("L_FOREARM", 150, lambda a, u: (-a, 0, 0)),
    "knee": ("L_SHIN", 150, lambda a, u: (a, 0, 0)),
    "neck": ("HEAD", 60, lambda a, u: (-a, 0, 0)),
    "spine twist": ("SPINE", 60, lambda a, u: (0, 0, a)),
    "forearm twist": ("L_FOREARM", 90, lambda a, u: Rotation.from_rotvec(u * np.radians(a)).as_matrix()),
}
#: owned: the default since #84 (each rest voxel moved by its owner, balls at the joints; rig/ownership.py);
#: rigid and smooth joints over the default (nearest) connectivity; fitted: rigid joints over the fitted one;
#: the peers (benchmarks/_peers.py) over the default connectivity: linear-blend skinning, Bender's heat weights
METHODS = ("owned", "rigid", "smooth", "fitted", "lbs", "bender")
GOALS = {"dice": 0.995, "blob": 0.5, "p95": 1.5}


def joint_poses(bones, label: str, angles) -> list[tuple[int, np.ndarray]]:
    """``(angle, matrices)`` for each angle of joint ``label`` (:data:`JOINTS`): its bone turned, the rest at rest."""
    from volanim_core.rig.pose import pose_matrices

    bone, _top, rotation = JOINTS[label]
    b = bones.bones[bones.index(bone)]
    axis = np.asarray(bones.joints[b.distal], float) - bones.joints[b.proximal]
    u = axis / np.linalg.norm(axis)
    return [(a, pose_matrices(bones, {bone: rotation(a, u)})) for a in angles]


def default_connectivity(sample, method: str = "nearest"):
    """What a user's pipeline gives: skeletonize (thinness >= 0.5), then every point to its nearest bone
    (``method``: another rule of `volanim connect`, e.g. fitted)."""
    from volanim_core.rig.attach import connect
    from volanim_core.skeleton.skeletonize import skeletonize

    return connect(skeletonize(sample.mask, min_thinness=0.5), sample.bones, method=method)[0]


def moved_limb_voxels(sample, bone: str) -> int:
    """The rest voxels of the moved bone and every bone below it: the limb a pose moves."""
    bones = sample.bones
    moved, grew = {bone}, True
    while grew:
        below = {b.label for b in bones.bones if b.proximal in
                 {bones.bones[bones.index(m)].distal for m in moved}} - moved
        grew = bool(below)
        moved |= below
    labels = [bones.index(n) + 1 for n in moved]
    return int(np.isin(sample.part, labels).sum())


def rows_for(name: str, sample, step: int, joints: list[str]) -> list[dict]:
    from volanim_core.posed_truth import posed_sample
    from volanim_core.reconstruct.breakage import RestParts
    from volanim_core.reconstruct.engine import reconstruct
    from volanim_core.reconstruct.lumps import bone_reach, find_lumps, limb_voxels
    from volanim_core.reconstruct.shape import compare_shapes, extra_flesh
    from volanim_core.rig.pose import posed_joints

    conn = default_connectivity(sample)
    frame = frames_of(sample, conn)
    bones = sample.bones
    rest = RestParts.of(conn)
    rest_segments = [(b.proximal, b.distal) for b in conn.bones]
    reach = bone_reach(rest_segments, *rest.voxels)
    limbs = limb_voxels(rest_segments, rest.voxels[1])
    from volanim_core.reconstruct.lumps import frame_lumps
    from volanim_core.rig.skinning import Joints

    smooth_rest = RestParts.of(conn.with_joints(Joints("smooth")))  # smooth frames: followed back by their blends
    rows = []
    for label in joints:
        bone, top, _ = JOINTS[label]
        limb = moved_limb_voxels(sample, bone)
        for angle, m in joint_poses(bones, label, range(0, top + 1, step)):
            truth = posed_sample(name, m)
            at = posed_joints(bones, m)
            segments = {s.label: (at[s.proximal], at[s.distal]) for s in bones.bones}
            for method in METHODS:
                t0 = time.perf_counter()
                t = frame[method](m)
                r = reconstruct(t, mode="bone")
                seconds = time.perf_counter() - t0
                rep = compare_shapes(r.volume, truth.volume, ours_origin=r.origin, truth_origin=truth.origin,
                                     joints=at, segments=segments)
                lumps = find_lumps(r.volume, r.origin, m, rest_segments, reach, rest.rest_bone.volume,
                                   rest.rest_bone.origin, at, limbs) if method in ("rigid", "owned") else \
                    frame_lumps(t, r, smooth_rest, at) if method == "smooth" else []
                if lumps:  # once a frame, whatever the number of lumps
                    extra, lo = extra_flesh(r.volume, truth.volume, ours_origin=r.origin, truth_origin=truth.origin)
                real = [lump_is_real(lump, extra, lo) for lump in lumps]
                blobs = [b for b in (rep.largest_extra, rep.largest_missing) if b is not None]
                worst = max(blobs, key=lambda b: b.voxels) if blobs else None
                rows.append({"body": name, "joint": label, "angle": angle, "method": method, "dice": rep.dice,
                             "extra": rep.largest_extra.voxels if rep.largest_extra else 0,
                             "missing": rep.largest_missing.voxels if rep.largest_missing else 0,
                             "blob %": 100 * (worst.voxels if worst else 0) / limb,
                             "near": worst.near if worst else "", "p95": rep.surface_p95, "seconds": seconds,
                             "flagged": lumps[0].voxels if lumps else 0, "flagged near": lumps[0].near if lumps else "",
                             "flags": len(lumps), "real flags": sum(real),
                             "true lump": (rep.largest_extra.voxels if rep.largest_extra else 0) / limb >= 0.005})
    return rows


def frames_of(sample, conn) -> dict:
    """method -> (matrices -> the frame it reconstructs), every method over the same skeleton."""
    from _peers import bender_frame, bender_skin, lbs_frame

    from volanim_core.rig.ownership import ownership
    from volanim_core.rig.skinning import Joints

    smooth, fitted = conn.with_joints(Joints("smooth")), default_connectivity(sample, "fitted")
    bender = bender_skin(conn, sample.volume)
    owned = conn.with_ownership(ownership(sample.mask, conn))
    return {"owned": owned.posed, "rigid": conn.posed, "smooth": smooth.posed, "fitted": fitted.posed,
            "lbs": lambda m: lbs_frame(conn, m), "bender": lambda m: bender_frame(conn, m, bender)}


def lump_is_real(lump, extra: np.ndarray, lo: np.ndarray) -> bool:
    """Whether a flagged lump is flesh the true shape does not have: at least half its size of the extra
    voxels (``extra, lo``: :func:`~volanim_core.reconstruct.shape.extra_flesh`) lies in its box."""
    box = tuple(slice(int(x), int(y) + 1) for x, y in zip(np.asarray(lump.lo) - lo, np.asarray(lump.hi) - lo))
    return int(extra[box].sum()) >= lump.voxels / 2


def meets(row: dict) -> bool:
    return row["dice"] >= GOALS["dice"] and row["blob %"] <= GOALS["blob"] and row["p95"] <= GOALS["p95"]


def print_table(rows: list[dict]) -> None:
    print("| body | joint | angle | " + " | ".join(f"{m}: Dice / extra / missing / blob % limb / p95" for m in METHODS)
          + " |")
    print("|---|---|---|" + "---|" * len(METHODS))
    keyed = {(r["body"], r["joint"], r["angle"], r["method"]): r for r in rows}
    for body, joint, angle in dict.fromkeys((r["body"], r["joint"], r["angle"]) for r in rows):
        cells = []
        for m in METHODS:
            r = keyed[(body, joint, angle, m)]
            mark = "" if meets(r) else " ✗"
            cells.append(f"{r['dice']:.4f} / {r['extra']} / {r['missing']} / {r['blob %']:.2f} / {r['p95']:.1f}{mark}")
        print(f"| {body} | {joint} | {angle} | " + " | ".join(cells) + " |")
    print()
    for m in METHODS:
        mine = [r for r in rows if r["method"] == m]
        print(f"{m}: {sum(meets(r) for r in mine)} of {len(mine)} rows meet every goal "
              f"(Dice >= {GOALS['dice']}, blob <= {GOALS['blob']} % of the limb, p95 <= {GOALS['p95']}); "
              f"worst Dice {min(r['dice'] for r in mine):.4f}, largest blob {max(r['blob %'] for r in mine):.2f} %, "
              f"worst p95 {max(r['p95'] for r in mine):.1f}; {np.median([r['seconds'] for r in mine]):.2f} s a frame")


def print_lumps(rows: list[dict]) -> None:
    """The report's lumps (no truth) against the truth's, over the rigid rows: recall, the share of rows with a
    true lump (largest extra blob >= 0.5 % of the moved limb) that the report flags; precision, the share of
    flags that are real (mostly voxels the true shape does not have, :func:`lump_is_real`)."""
    for body, method in [(b, m) for b in dict.fromkeys(r["body"] for r in rows) for m in ("owned", "rigid", "smooth")]:
        mine = [r for r in rows if r["method"] == method and r["body"] == body]
        true = [r for r in mine if r["true lump"]]
        hit = [r for r in true if r["flagged"]]
        flags, real = sum(r["flags"] for r in mine), sum(r["real flags"] for r in mine)
        print(f"{body}, {method}: {len(true)} of {len(mine)} rows have a true lump (an extra blob >= 0.5 % of the "
              f"moved limb); the report flags {len(hit)} of them (recall {len(hit) / max(len(true), 1):.2f}); "
              f"of its {flags} flags {real} are real (precision {real / max(flags, 1):.2f})")
        for r in mine:
            if r["flags"] > r["real flags"] or r["true lump"] and not r["flagged"]:
                print(f"  {r['joint']} {r['angle']}: {r['flags']} flags ({r['real flags']} real), largest "
                      f"{r['flagged']} voxels near {r['flagged near'] or '-'}; true extra blob {r['extra']} voxels")


def walk_rows(sample, every: int) -> list[dict]:
    """The real walk clip (MIT, bundled) retargeted onto the mannequin, every ``every``-th frame, each method
    against the capsules posed by the same matrices (#60: Dice >= 0.97 in every frame)."""
    from volanim_core.io.bvh_files import read_bvh
    from volanim_core.motion.retarget import Retarget
    from volanim_core.posed_truth import posed_sample
    from volanim_core.reconstruct.engine import reconstruct
    from volanim_core.reconstruct.shape import compare_shapes
    from volanim_core.samples import walk_clip

    conn = default_connectivity(sample)
    frame = frames_of(sample, conn)
    mats = Retarget.build(sample.bones, read_bvh(walk_clip())).matrices()
    rows = []
    for i in range(0, len(mats), every):
        truth = posed_sample("mannequin", mats[i])
        for method in METHODS:
            r = reconstruct(frame[method](mats[i]), mode="bone")
            rep = compare_shapes(r.volume, truth.volume, ours_origin=r.origin, truth_origin=truth.origin)
            rows.append({"frame": i, "method": method, "dice": rep.dice,
                         "extra": rep.largest_extra.voxels if rep.largest_extra else 0})
    return rows


def print_walk(rows: list[dict]) -> None:
    frames = sorted({r["frame"] for r in rows})
    print(f"the walk clip, {len(frames)} frames (every {frames[1] - frames[0] if len(frames) > 1 else 1}th), "
          "against the capsules posed by the same matrices (goal: Dice >= 0.97 in every frame)")
    print("| method | worst Dice (frame) | median Dice | frames under 0.97 | largest extra blob, voxels |")
    print("|---|---|---|---|---|")
    for m in METHODS:
        mine = [r for r in rows if r["method"] == m]
        worst = min(mine, key=lambda r: r["dice"])
        print(f"| {m} | {worst['dice']:.4f} ({worst['frame']}) | {np.median([r['dice'] for r in mine]):.4f} | "
              f"{sum(r['dice'] < 0.97 for r in mine)} | {max(r['extra'] for r in mine)} |")


def cost(rounds: int) -> None:
    """What fitted costs against nearest (#60: frame time <= 1.3x, live preview >= 10 updates/s): the connect
    step once per rig, a bone-mode frame (alternated, same run) on the frog and the mannequin, and the studio's
    half-resolution live preview of the mannequin over the fitted connectivity."""
    import statistics

    from volanim_core import samples
    from volanim_core.reconstruct.engine import reconstruct
    from volanim_core.rig.attach import connect
    from volanim_core.rig.pose import pose_matrices
    from volanim_core.rig.tskel_tools import coarse_tskel
    from volanim_core.skeleton.skeletonize import skeletonize

    print("| body | points | connect nearest, s | connect fitted, s | frame nearest, s | frame fitted, s | "
          "fitted / nearest (frame) |\n|---|---|---|---|---|---|---|")
    for name, pose in (("frog", {"LEGS": (0, -45, 45)}), ("mannequin", {"L_UPPERARM": (0, -90, 0)})):
        sample = samples.load(name)
        skel = skeletonize(sample.mask, **({} if name == "frog" else {"min_thinness": 0.5}))
        conns, made = {}, {}
        for method in ("nearest", "fitted"):
            t0 = time.perf_counter()
            conns[method] = connect(skel, sample.bones, method=method)[0]
            made[method] = time.perf_counter() - t0
        m = pose_matrices(sample.bones, pose)
        for c in conns.values():
            reconstruct(c.posed(m), mode="bone")  # compiled
        times = {"nearest": [], "fitted": []}
        for r in range(rounds):
            for method in (("nearest", "fitted") if r % 2 == 0 else ("fitted", "nearest")):
                t0 = time.perf_counter()
                reconstruct(conns[method].posed(m), mode="bone")
                times[method].append(time.perf_counter() - t0)
        ratio = statistics.median(b / a for a, b in zip(times["nearest"], times["fitted"]))
        print(f"| {name} | {len(skel)} | {made['nearest']:.3f} | {made['fitted']:.3f} | "
              f"{statistics.median(times['nearest']):.3f} | {statistics.median(times['fitted']):.3f} | "
              f"{ratio:.2f} (goal <= 1.3) |")
    s = samples.mannequin()
    conn = default_connectivity(s, "fitted")
    reconstruct(coarse_tskel(conn.posed(pose_matrices(s.bones, {})), 2), mode="bone")
    t0 = time.perf_counter()
    for k in range(rounds * 4):
        reconstruct(coarse_tskel(conn.posed(pose_matrices(s.bones, {"L_UPPERARM": (0, -5.0 * k, 0)})), 2),
                    mode="bone", padding=2)
    print(f"\nmannequin live preview over the fitted connectivity, half resolution: "
          f"{rounds * 4 / (time.perf_counter() - t0):.1f} updates/s (goal >= 10)")


def rest_capsules() -> dict[int, np.ndarray]:
    """bone index -> its capsules at rest on the mannequin's grid (bool, ``[x, y, z]``), painted by the truth's own
    painter with every other bone moved off the grid: overlapping each other as the truth's capsules do."""
    from volanim_core.mannequin_body import MANNEQUIN_SHAPE, mannequin_bones, paint_mannequin

    bones = mannequin_bones()
    out = {}
    for b in range(len(bones.bones)):
        m = np.tile(np.eye(4), (len(bones.bones), 1, 1))
        m[np.arange(len(m)) != b, 3, 0] = 10.0 * max(MANNEQUIN_SHAPE)  # every other capsule misses the grid
        out[b] = paint_mannequin(bones, np.ones(3), MANNEQUIN_SHAPE, matrices=m)[0] > 0
    return out


def read_floor(capsules: dict, matrices: np.ndarray, fields: dict) -> dict:
    """Dice against ``posed_sample`` of each rest field in ``fields`` (name -> bone -> float32 occupancy) read
    trilinearly at the rest point each bone's inverse brings every posed voxel to, a voxel in where any bone's
    read is >= 1/2: the owners and the overlaps perfect, so only the read is measured."""
    from scipy.ndimage import map_coordinates

    from volanim_core.posed_truth import posed_sample

    truth = posed_sample("mannequin", matrices)
    want = truth.volume > 0
    q = np.indices(want.shape, np.float64).reshape(3, -1).T + np.asarray(truth.origin)
    out = {}
    for name, field in fields.items():
        got = np.zeros(len(q), bool)
        for b in capsules:
            inv = np.linalg.inv(matrices[b])
            rest = q @ inv[:3, :3] + inv[3, :3]
            got |= map_coordinates(field[b], rest.T, order=1, cval=0.0) >= 0.5
        got = got.reshape(want.shape)
        out[name] = 2.0 * (got & want).sum() / (got.sum() + want.sum())
    return out


def floor_rows(step: int, joints: list[str], walk_every: int | None) -> None:
    """#84: the Dice any owner rule reaches with a trilinear read of the rest segmentation (the mannequin), and
    with a smoother one: a Gaussian of one voxel clamped to the segmentation at voxel centres (>= 1/2 inside,
    < 1/2 outside), so the rest pose stays voxel for voxel. A row's goal above its floor is out of the read's reach."""
    from scipy.ndimage import gaussian_filter

    from volanim_core import samples
    from volanim_core.io.bvh_files import read_bvh
    from volanim_core.motion.retarget import Retarget

    capsules = rest_capsules()
    smooth = {}
    for b, mask in capsules.items():
        g = gaussian_filter(mask.astype(np.float32), 1.0)
        smooth[b] = np.where(mask, np.maximum(g, 0.5), np.minimum(g, np.float32(0.4999))).astype(np.float32)
    fields = {"trilinear": {b: m.astype(np.float32) for b, m in capsules.items()}, "smoothed": smooth}
    sample = samples.mannequin()
    bones = sample.bones
    poses = []
    for label in joints:
        poses += [(f"{label} {a}", m) for a, m in joint_poses(bones, label, range(step, JOINTS[label][1] + 1, step))]
    if walk_every:
        mats = Retarget.build(bones, read_bvh(samples.walk_clip())).matrices()
        poses += [(f"walk frame {i}", mats[i]) for i in range(0, len(mats), walk_every)]
    print("the floor of a read of the rest segmentation (the mannequin; true owners, overlapping capsules)")
    print("| row | trilinear | smoothed (Gaussian 1 voxel, clamped) |")
    print("|---|---|---|")
    for name, m in poses:
        d = read_floor(capsules, m, fields)
        print(f"| {name} | {d['trilinear']:.4f} | {d['smoothed']:.4f} |", flush=True)


def true_owner_rows(step: int, joints: list[str]) -> None:
    """#84: the owned default over its own owners (nearest) and over the truth's parts as owners (the mannequin's
    capsule each rest voxel lies deepest in; same balls): Dice / largest blob % of the moved limb. What perfect
    single owners would give, so what is left is the capsules' overlap."""
    from volanim_core import samples
    from volanim_core.posed_truth import posed_sample
    from volanim_core.reconstruct.engine import reconstruct
    from volanim_core.reconstruct.shape import compare_shapes
    from volanim_core.rig.ownership import ownership
    from volanim_core.rig.pose import posed_joints

    s = samples.mannequin()
    conn = default_connectivity(s)
    own = ownership(s.mask, conn)
    o, shape = np.asarray(own.origin), own.labels.shape
    parts = s.part[o[0]:o[0] + shape[0], o[1]:o[1] + shape[1], o[2]:o[2] + shape[2]].astype(own.labels.dtype)
    owners = {"nearest": own, "true parts": own.with_labels(np.where(own.labels > 0,
                                                                     np.where(parts > 0, parts, own.labels), 0))}
    bones = s.bones
    print("| row | " + " | ".join(f"{k}: Dice / blob % limb" for k in owners) + " |")
    print("|---|" + "---|" * len(owners))
    for label in joints:
        bone, top, _ = JOINTS[label]
        limb = moved_limb_voxels(s, bone)
        for angle, m in joint_poses(bones, label, range(step, top + 1, step)):
            truth = posed_sample("mannequin", m)
            at = posed_joints(bones, m)
            segments = {q.label: (at[q.proximal], at[q.distal]) for q in bones.bones}
            cells = []
            for ov in owners.values():
                r = reconstruct(conn.with_ownership(ov).posed(m), mode="bone")
                rep = compare_shapes(r.volume, truth.volume, ours_origin=r.origin, truth_origin=truth.origin,
                                     joints=at, segments=segments)
                blob = max((x.voxels for x in (rep.largest_extra, rep.largest_missing) if x is not None), default=0)
                cells.append(f"{rep.dice:.4f} / {100 * blob / limb:.2f}")
            print(f"| {label} {angle} | " + " | ".join(cells) + " |", flush=True)


def main() -> None:
    from volanim_core import samples

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--large", action="store_true", help="mannequin-large too")
    parser.add_argument("--step", type=int, default=15, help="degrees between angles (default 15)")
    parser.add_argument("--joints", default=",".join(JOINTS), help="comma-separated joints (default: all)")
    parser.add_argument("--walk", type=int, metavar="EVERY", help="only the walk clip, every EVERY-th frame")
    parser.add_argument("--cost", type=int, metavar="ROUNDS", help="only what fitted costs against nearest")
    parser.add_argument("--floor", action="store_true",
                        help="only the floor of a read of the rest segmentation per row (and walk frames with --walk)")
    parser.add_argument("--true-owners", action="store_true",
                        help="only the owned default over its owners and over the truth's parts as owners")
    args = parser.parse_args()
    joints = [j.strip() for j in args.joints.split(",") if j.strip()]
    if args.true_owners:
        true_owner_rows(args.step, joints)
        return
    if args.floor:
        floor_rows(args.step, joints, args.walk)
        return
    if args.cost:
        cost(args.cost)
        return
    if args.walk:
        print_walk(walk_rows(samples.mannequin(), args.walk))
        return
    rows = rows_for("mannequin", samples.mannequin(), args.step, joints)
    if args.large:
        rows += rows_for("mannequin-large", samples.mannequin_large(), args.step, joints)
    print_table(rows)
    print()
    print_lumps(rows)


if __name__ == "__main__":
    main()
