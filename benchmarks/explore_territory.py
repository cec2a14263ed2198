"""Where the posed body's shape goes wrong, and what would put it right (#60, item 4: a measured study).

    mannequin, its default connectivity (nearest) and its ground-truth one (each point to the part it lies in)
    for key joints and angles, against posed_sample (the capsules posed by the same matrices):
        spheres/nearest ....... today's rigid reconstruction
        spheres/true parts .... the same engine, every skeleton point attached to its true part
        territory/true parts .. every rest voxel moved by its true part's bone (an inverse warp),
                                plus a ball at each posed joint (radius: the rest body's depth there)
        territory/nearest ..... the same, each rest voxel owned by the bone of today's rest bone-mode voxel
    Dice, the largest extra (+) and missing (-) blob as % of the moved limb, surface p95

What it shows (README, #60's note): attachment alone cannot meet the goal (the true parts still leave
1-2 % blobs at shoulder and hip: a sphere centred beside a joint is wider than its limb and swings its
overhang with it). Moving voxels by territory, with the joints' balls filling the bend's wedge, meets it
at shoulder, elbow and knee -- given the true ownership. Which rest voxel a bone owns, without the truth,
is the open question: today's nearest owners keep the armpit with the arm.

Run: .venv/bin/python benchmarks/explore_territory.py   (about 3 minutes; numpy/scipy, not a product path)
"""

from __future__ import annotations

import numpy as np
from scipy import ndimage

ROWS = [("shoulder abduction", 45), ("shoulder abduction", 90), ("shoulder abduction", 150),
        ("shoulder flexion", 90), ("hip flexion", 45), ("hip flexion", 90), ("hip flexion", 120),
        ("elbow", 90), ("elbow", 150), ("knee", 150), ("neck", 45), ("spine twist", 60)]


def territory(owner: np.ndarray, matrices: np.ndarray, origin, shape, balls) -> np.ndarray:
    """Each bone's owned rest voxels moved by its matrix (nearest-voxel inverse warp), and the joints' balls."""
    q = np.stack(np.meshgrid(*[np.arange(shape[k], dtype=float) + origin[k] for k in range(3)], indexing="ij"), -1)
    out = np.zeros(shape, bool)
    for b in range(len(matrices)):
        inv = np.linalg.inv(matrices[b])
        rest = q @ inv[:3, :3] + inv[3, :3]
        out |= ndimage.map_coordinates((owner == b + 1).astype(np.uint8), np.moveaxis(rest, -1, 0), order=0) > 0
    for centre, radius in balls:
        out |= np.linalg.norm(q - centre, axis=-1) < radius
    return out


def main() -> None:
    from bench_shape import JOINTS, default_connectivity, moved_limb_voxels

    from volanim_core import samples
    from volanim_core.posed_truth import posed_sample
    from volanim_core.reconstruct.engine import reconstruct
    from volanim_core.reconstruct.shape import compare_shapes
    from volanim_core.rig.pose import pose_matrices, posed_joints
    from volanim_core.volume import Bounds

    s = samples.mannequin()
    bones = s.bones
    shape = s.volume.shape
    whole = Bounds((0, 0, 0), tuple(n - 1 for n in shape))
    identity = np.tile(np.eye(4), (len(bones), 1, 1))
    nearest, parts = default_connectivity(s), samples.part_connectivity(s)
    owners = {"nearest": reconstruct(nearest.posed(identity), mode="bone", bounds=whole).volume,
              "true parts": np.asarray(s.part)}
    depth = ndimage.distance_transform_edt(owners["nearest"] > 0)
    joint_depth = {n: float(ndimage.map_coordinates(depth, np.asarray(p, float)[:, None], order=1)[0])
                   for n, p in bones.joints.items()}
    methods = ["spheres/nearest", "spheres/true parts", "territory/true parts", "territory/nearest"]
    print("| joint | angle | " + " | ".join(f"{m}: Dice / +blob % / -blob % / p95" for m in methods) + " |")
    print("|---|---|" + "---|" * len(methods))
    for label, angle in ROWS:
        bone, _top, rotation = JOINTS[label]
        b = bones.bones[bones.index(bone)]
        u = np.asarray(bones.joints[b.distal], float) - bones.joints[b.proximal]
        m = pose_matrices(bones, {bone: rotation(angle, u / np.linalg.norm(u))})
        truth = posed_sample("mannequin", m)
        grid = Bounds(truth.origin, tuple(np.add(truth.origin, truth.volume.shape) - 1))
        at = posed_joints(bones, m)
        balls = [(np.asarray(at[n], float), r) for n, r in joint_depth.items()]
        limb = moved_limb_voxels(s, bone)
        cells = []
        for method in methods:
            how, who = method.split("/")
            if how == "spheres":
                ours = reconstruct((nearest if who == "nearest" else parts).posed(m), mode="bone", bounds=grid).volume
            else:
                ours = territory(owners[who], m, truth.origin, truth.volume.shape, balls)
            rep = compare_shapes((ours > 0).astype(np.uint8), truth.volume, ours_origin=truth.origin,
                                 truth_origin=truth.origin)
            extra = rep.largest_extra.voxels if rep.largest_extra else 0
            missing = rep.largest_missing.voxels if rep.largest_missing else 0
            cells.append(f"{rep.dice:.4f} / {100 * extra / limb:.1f} / {100 * missing / limb:.1f} / "
                         f"{rep.surface_p95:.1f}")
        print(f"| {label} | {angle} | " + " | ".join(cells) + " |", flush=True)


if __name__ == "__main__":
    main()
