"""Figs 5.1 and 5.2 as the thesis ran them, old algorithm beside ours, drawn from the voxels (no renderer).

Fig 5.1: the mannequin's left leg alone (L_THIGH, L_SHIN, L_FOOT's spheres, thinness >= 0.5), swung 45
degrees forward at the hip, reconstructed by the thesis's cube scan (every sphere's bounding cube scanned,
each voxel inverse-transformed: benchmarks/_old_reconstruct.py) and by ours, in bone mode; side views.
Fig 5.2: the aliasing cube's skeleton turned 45 degrees about z, sampled from the checkerboard: the cube
scan and ours with nearest sampling, and ours with the 3^3 kernel; the middle slice of each.

Fig 5.17: one skeleton at the caption's three thinness levels, 1.50, 1.35 and 1.10, read two ways: as the
thesis's 3-4-5 chamfer units (skeletonize --metric 345, the thesis's tools' units) and as Euclidean
thinness in those units (ours, a third of the value: 0.50, 0.45, 0.37). Taken at face value in Euclidean
voxels they give 0, 0 and 8 points on the mannequin: a Euclidean thinness can never exceed the mean length
of the 26 neighbour steps, (6 + 12*sqrt(2) + 8*sqrt(3)) / 26 = 1.416 (each neighbour's DT is at least
DT(p) minus its step), so the caption's 1.50 cannot be Euclidean voxels. Front views of the points
(nearer is brighter), drawn from the coordinates (no renderer).

Section 5.3, the colon uncoiled: the curved-tube sample (a tube bent through half a circle, 8 chained
bones) reconstructed at rest and with `volanim straighten`'s pose, in bone colours, seen from the side
the bend lies in; the tube's length along the axis against the arc length, its voxel count against the
rest pose's, and how far its cross-sections' centres stray from the axis.

Each figure also prints how many voxels the two reconstructions differ in (0 where both are exact: the
old algorithm and ours fill the same voxels; only the time differs, Fig 5.2's table in the README).

Run: .venv/bin/python docs/make_thesis_figures.py  (writes docs/thesis-fig-5-1.png, -5-2.png, -5-17.png,
docs/thesis-colon-straightened.png)
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from PIL import Image

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))

LEG = ("L_THIGH", "L_SHIN", "L_FOOT")


def _old(tskel, source, sampled):
    from _old_reconstruct import run_cube_scan

    from volanim_core.reconstruct.engine import grid_bounds

    bounds = grid_bounds(tskel)
    return run_cube_scan(tskel, bounds, source, sampled, 2), bounds


def side_view(labels: np.ndarray, table: np.ndarray) -> Image.Image:
    """The label volume seen from +x: the nearest non-zero label along x, coloured; z up."""
    filled = labels > 0
    first = np.where(filled.any(axis=0), filled.argmax(axis=0), -1)  # (y, z)
    y, z = np.nonzero(first >= 0)
    rgb = np.full(first.shape + (3,), 24, np.uint8)
    rgb[y, z] = table[labels[first[y, z], y, z]]
    return Image.fromarray(np.ascontiguousarray(rgb.transpose(1, 0, 2)[::-1]))


def fig_5_1(path: Path) -> int:
    from volanim_core import samples
    from volanim_core.reconstruct.engine import reconstruct
    from volanim_core.render.bone_colours import label_table
    from volanim_core.rig.attach import connect_nearest
    from volanim_core.rig.connectivity import Trans
    from volanim_core.rig.pose import pose_matrices, root_bones
    from volanim_core.rig.tskel_tools import connect_to_tskel
    from volanim_core.skeleton.skeletonize import skeletonize

    s = samples.load("mannequin")
    conn = connect_nearest(skeletonize(s.mask, min_thinness=0.5), s.bones)
    legs = [s.bones.index(b) for b in LEG]
    conn = conn.take(np.flatnonzero(np.isin(conn.bone, legs)))  # the leg's spheres alone
    tskel = connect_to_tskel(conn, Trans(root_bones(s.bones), pose_matrices(s.bones, {"L_THIGH": (-45, 0, 0)})))
    ours = reconstruct(tskel, mode="bone")
    old, bounds = _old(tskel, s.volume, False)  # binary: the source is not read
    old_labels = np.zeros(ours.volume.shape, ours.volume.dtype)
    at = tuple(slice(a - b, a - b + n) for a, b, n in zip(bounds.lo, ours.origin, old.shape))
    ours_in_old = ours.volume[at] > 0
    old_labels[at] = np.where(old > 0, ours.volume[at], 0)  # the cube scan's voxels, in ours' bone colours
    table = label_table(len(s.bones))
    differ = int(np.count_nonzero((old > 0) != ours_in_old)) + int(ours.volume.astype(bool).sum() - ours_in_old.sum())
    a, b = side_view(old_labels, table), side_view(ours.volume, table)
    _side_by_side(path, [a, b], scale=2)
    return differ


def fig_5_2(path: Path) -> int:
    from volanim_core import samples
    from volanim_core.reconstruct.engine import reconstruct
    from volanim_core.rig.attach import connect_nearest
    from volanim_core.rig.bones import Bone, BoneSkeleton
    from volanim_core.rig.connectivity import Trans
    from volanim_core.rig.pose import pose_matrices, root_bones
    from volanim_core.rig.tskel_tools import connect_to_tskel
    from volanim_core.skeleton.skeletonize import skeletonize

    s = samples.load("aliascube")
    bones = BoneSkeleton({"A": (64, 64, 0), "B": (64, 64, 127)}, [Bone("A", "B", "CUBE")])
    conn = connect_nearest(skeletonize(s.mask, min_thinness=0.5), bones)
    tskel = connect_to_tskel(conn, Trans(root_bones(bones), pose_matrices(bones, {"CUBE": (0, 0, 45)})))
    ours = reconstruct(tskel, mode="sampled", source=s.volume)
    smooth = reconstruct(tskel, mode="sampled", source=s.volume, kernel=3)
    old, bounds = _old(tskel, s.volume, True)
    assert tuple(bounds.lo) == tuple(ours.origin) and old.shape == ours.volume.shape
    differ = int(np.count_nonzero(old != ours.volume))
    z = ours.volume.shape[2] // 2
    pictures = [Image.fromarray(np.ascontiguousarray(v[:, :, z].T[::-1]).astype(np.uint8))
                for v in (old, ours.volume, smooth.volume)]
    _side_by_side(path, [p.convert("RGB") for p in pictures], scale=2)
    return differ


def colon(path: Path) -> dict:
    """The curved tube at rest and straightened (``volanim straighten``), side by side; measures."""
    from volanim_core import samples
    from volanim_core.reconstruct.engine import reconstruct
    from volanim_core.render.bone_colours import label_table
    from volanim_core.rig.attach import connect_nearest
    from volanim_core.rig.connectivity import Trans
    from volanim_core.rig.pose import root_bones
    from volanim_core.rig.straighten import straighten
    from volanim_core.rig.tskel_tools import connect_to_tskel
    from volanim_core.skeleton.skeletonize import skeletonize

    s = samples.load("curved-tube")
    conn = connect_nearest(skeletonize(s.mask), s.bones)  # the default skeleton, thinness >= 0.5
    mats, axis, ids = straighten(s.bones)
    rest = reconstruct(connect_to_tskel(conn, Trans(root_bones(s.bones), np.tile(np.eye(4), (len(s.bones), 1, 1)))),
                       mode="bone")
    straight = reconstruct(connect_to_tskel(conn, Trans(root_bones(s.bones), mats)), mode="bone")
    table = label_table(len(s.bones))
    views = [side_view(np.ascontiguousarray(r.volume.transpose(1, 0, 2)), table) for r in (rest, straight)]
    _side_by_side(path, views, scale=3)
    xyz = np.argwhere(straight.volume > 0) + straight.origin  # the straight tube's voxels
    along = (xyz - xyz.mean(axis=0)) @ axis
    off_axis = (xyz - xyz.mean(axis=0)) - np.outer(along, axis)
    centres = [off_axis[np.round(along) == t].mean(axis=0) for t in np.unique(np.round(along))[8:-8]]
    arc = sum(float(np.linalg.norm(np.subtract(*s.bones.segment(i)))) for i in ids)
    # the true uncoiled tube: its centre arc (pi x 40 voxels) laid along the axis from the first joint, the
    # same radius, round ends (as the sample's): a capsule, voxelised on the straight result's grid
    start = np.asarray(s.bones.joints[s.bones.bones[ids[0]].proximal], np.float64)
    centre_arc = np.pi * 40.0
    grid = np.argwhere(np.ones(straight.volume.shape, bool)) + straight.origin
    t = np.clip((grid - start) @ axis, 0.0, centre_arc)
    truth = np.linalg.norm(grid - start - np.outer(t, axis), axis=1) <= samples.TUBE_RADIUS
    ours = (straight.volume > 0).ravel()
    dice = 2.0 * np.count_nonzero(truth & ours) / (np.count_nonzero(truth) + np.count_nonzero(ours))
    return {"axis": axis, "length": float(along.max() - along.min() + 1), "chain length": arc, "dice": dice,
            "true voxels": int(truth.sum()),
            "rest voxels": int((rest.volume > 0).sum()), "straight voxels": int((straight.volume > 0).sum()),
            "centre stray max": float(np.max(np.linalg.norm(centres, axis=1)))}


FIG_5_17_LEVELS = (1.50, 1.35, 1.10)
NEIGHBOUR_STEP_MEAN = (6 + 12 * np.sqrt(2) + 8 * np.sqrt(3)) / 26  # the largest Euclidean thinness there is


def front_view(points: np.ndarray, shape: tuple[int, int, int], depth: tuple[int, int]) -> Image.Image:
    """Skeleton points seen from -y (x right, z up), each a 2x2 dot, brighter the nearer within ``depth``."""
    nx, _, nz = shape
    rgb = np.full((nz, nx, 3), 24, np.uint8)
    order = np.argsort(-points[:, 1])  # far first, so near points are drawn over them
    x, y, z = points[order].T
    near, far = depth
    shade = (255 - 190 * np.clip((y - near) / max(far - near, 1), 0, 1)).astype(np.uint8)
    for dx in (0, 1):
        for dz in (0, 1):
            xi, zi = np.minimum(x + dx, nx - 1), np.minimum(z + dz, nz - 1)
            rgb[nz - 1 - zi, xi] = np.stack([shade, shade, (shade * 0.8).astype(np.uint8)], axis=1)
    return Image.fromarray(rgb)


def fig_5_17(path: Path) -> list[tuple[str, float, int]]:
    """Returns (reading, level, points) for the three readings of the caption's levels."""
    from PIL import ImageDraw

    from volanim_core import samples
    from volanim_core.skeleton.skeletonize import skeletonize

    s = samples.load("mannequin")
    chamfer = skeletonize(s.mask, metric="345", min_thinness=1.0)
    euclid = skeletonize(s.mask, metric="euclid", min_thinness=0.0)
    rows = [("3-4-5 chamfer units (--metric 345)", chamfer, 1.0, "345"),
            ("Euclidean, in the thesis's units (ours x 3)", euclid, 1 / 3, "euclid")]
    ys = np.flatnonzero(s.mask.any(axis=(0, 2)))
    depth = (int(ys.min()), int(ys.max()))
    counts = [("euclid voxels, at face value", t, int((euclid.thinness >= t).sum())) for t in FIG_5_17_LEVELS]
    panels = []
    for label, sk, scale, metric in rows:
        for t in FIG_5_17_LEVELS:
            keep = sk.thinness >= t * scale
            counts.append((label, t, int(keep.sum())))
            pic = front_view(sk.points[keep], s.mask.shape, depth)
            ImageDraw.Draw(pic).text((4, 4), f"{metric} >= {t * scale:.2f}\n{int(keep.sum())} points",
                                     fill=(255, 220, 120))
            panels.append(pic)
    top, bottom = _row(panels[:3]), _row(panels[3:])
    out = Image.new("RGB", (top.width, top.height * 2 + 8), (60, 60, 60))
    out.paste(top, (0, 0))
    out.paste(bottom, (0, top.height + 8))
    out.resize((out.width * 2, out.height * 2), Image.NEAREST).save(path)
    return counts


def _row(pictures: list[Image.Image], gap: int = 8) -> Image.Image:
    w = sum(p.width for p in pictures) + gap * (len(pictures) - 1)
    h = max(p.height for p in pictures)
    out = Image.new("RGB", (w, h), (60, 60, 60))
    x = 0
    for p in pictures:
        out.paste(p, (x, h - p.height))
        x += p.width + gap
    return out


def _side_by_side(path: Path, pictures: list[Image.Image], scale: int) -> None:
    out = _row(pictures)
    out.resize((out.width * scale, out.height * scale), Image.NEAREST).save(path)


def main() -> None:
    d1 = fig_5_1(ROOT / "docs" / "thesis-fig-5-1.png")
    print(f"Fig 5.1: the left leg alone, cube scan | ours: {d1} voxels differ -> docs/thesis-fig-5-1.png")
    d2 = fig_5_2(ROOT / "docs" / "thesis-fig-5-2.png")
    print(f"Fig 5.2: the aliasing cube turned 45 degrees, cube scan | ours | ours 3^3: {d2} voxels differ between "
          f"the first two -> docs/thesis-fig-5-2.png")
    m = colon(ROOT / "docs" / "thesis-colon-straightened.png")
    print(f"Section 5.3: the curved tube straightened along {np.round(m['axis'], 3)}: {m['length']:.0f} voxels long "
          f"(its bones {m['chain length']:.1f} + the ends' radius), {m['straight voxels']} voxels against "
          f"{m['rest voxels']} at rest; cross-sections' centres within {m['centre stray max']:.2f} voxels of the "
          f"axis; Dice {m['dice']:.3f} against the true uncoiled tube ({m['true voxels']} voxels: its centre arc "
          f"laid straight) -> docs/thesis-colon-straightened.png")
    counts = fig_5_17(ROOT / "docs" / "thesis-fig-5-17.png")
    print(f"Fig 5.17: the mannequin's skeleton at thinness 1.50, 1.35, 1.10 -> docs/thesis-fig-5-17.png "
          f"(no Euclidean thinness exceeds {NEIGHBOUR_STEP_MEAN:.3f})")
    for reading, level, n in counts:
        print(f"  {reading:<45} {level:.2f}: {n} points")


if __name__ == "__main__":
    main()
