"""The headless demo run behind ``make demo`` and ``volanim demo``.

    sample volume --> NAME.VOL + NAME.bones
      --skeletonize--> NAME.mskel, --isosurface--> NAME-hull.ply
      connectivity (assets/, else nearest bone) --> NAME.0.50.connect
      --identity--> rest.tskel --reconstruct--> rest-sampled.vti
      --pose (left upper arm 45 deg)--> arm.trans --> arm.tskel --> arm-sampled.vti, arm-bone.vti
      walk.bvh (package data, real motion capture) --retarget--> walk/walk.NNNN.trans + .tskel
        --> walk/walk.NNNN-sampled.vti for a few frames across the clip     (mannequin only)
      --sequence--> walk.zarr: one walk cycle, then a crumble; one grid, every core (mannequin only)
      --render--> walk.gif: the sequence from the side, off-screen                  (mannequin only)
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from volanim_core.io import (
    connect_filename,
    read_connect,
    write_bones,
    write_connect,
    write_connections,
    write_mskel,
    write_raw,
    write_trans,
    write_tskel,
    write_volume,
)
from volanim_core.io.mesh_files import write_mesh
from volanim_core.progress import TextProgress
from volanim_core.reconstruct.engine import reconstruct
from volanim_core.rig.attach import connect_nearest
from volanim_core.rig.connectivity import Trans
from volanim_core.rig.pose import pose_matrices, root_bones
from volanim_core.rig.tskel_tools import check_root_order, connect_to_tskel, identity_tskel
from volanim_core.skeleton.hull import isosurface
from volanim_core.skeleton.skeletonize import DEFAULT_MIN_THINNESS, skeletonize

from . import samples, volume
from .warmup import compile_kernels

POSES = {"mannequin": ("L_UPPERARM", (0.0, -45.0, 0.0)), "frog": ("LEGS", (0.0, 0.0, 45.0))}


def _say(msg: str) -> None:
    print(msg, flush=True)


def bundled_connect(sample: str) -> Path | None:
    """The connectivity shipped in ``assets/`` for ``sample``, when running from the repository."""
    path = Path(__file__).resolve().parents[2] / "assets" / connect_filename(sample, DEFAULT_MIN_THINNESS)
    return path if path.is_file() else None


def run_demo(folder: Path, sample: str = "mannequin") -> dict:
    """Run every stage on ``sample`` and write the files into ``folder``; returns their paths."""
    folder.mkdir(parents=True, exist_ok=True)
    _say("compiling the numba kernels (about 25 s after a fresh install, under a second after that)...")
    _say(f"  kernels ready in {compile_kernels():.1f} s")
    t0 = time.perf_counter()
    out: dict = {}
    s = samples.load(sample)
    out["volume"] = folder / f"{sample}.VOL"
    write_raw(out["volume"], s.volume)
    b = volume.tight_bounds(s.volume)
    counts = volume.histogram(s.volume)
    _say(f"[1] sample {sample}: {s.volume.shape} voxels, {int(np.count_nonzero(s.volume))} in the object, "
         f"tight bounds {b}, {int((counts[1:] > 0).sum())} distinct values -> {out['volume'].name}")
    out["bones"] = folder / f"{sample}.bones"
    write_bones(out["bones"], s.bones)
    write_connections(folder / f"{sample}.connections", s.bones)
    _say(f"    bone skeleton: {len(s.bones.joints)} joints, {len(s.bones)} bones -> {out['bones'].name}")

    t = time.perf_counter()
    skel = skeletonize(s.mask, progress=TextProgress("    skeletonize"))
    out["mskel"] = folder / f"{sample}.mskel"
    write_mskel(out["mskel"], skel)
    _say(f"[2] skeleton: {len(skel)} points, thinness {skel.thinness.min():.2f}..{skel.thinness.max():.2f}, "
         f"dt up to {skel.dt.max():.1f}, {time.perf_counter() - t:.2f} s -> {out['mskel'].name}")
    t = time.perf_counter()
    verts, faces = isosurface(s.mask)
    out["hull"] = folder / f"{sample}-hull.ply"
    write_mesh(out["hull"], verts, faces)
    _say(f"    hull: {len(faces)} triangles, {time.perf_counter() - t:.2f} s -> {out['hull'].name}")

    shipped = bundled_connect(sample)
    if shipped is not None:
        conn = read_connect(shipped)
        check_root_order(conn.bones, root_bones(s.bones), ".bones")
        how = f"bundled {shipped.name}"
    else:
        conn = connect_nearest(skel.at(DEFAULT_MIN_THINNESS), s.bones)
        how = "each point on its nearest bone"
    out["connect"] = folder / connect_filename(sample, DEFAULT_MIN_THINNESS)
    write_connect(out["connect"], conn, thinness=DEFAULT_MIN_THINNESS)
    per_bone = np.bincount(conn.bone, minlength=len(conn.bones))
    _say(f"[3] connectivity ({how}): {len(conn)} points on {len(conn.bones)} bones "
         f"({per_bone.min()}..{per_bone.max()} per bone) -> {out['connect'].name}")

    rest = identity_tskel(conn)
    write_tskel(folder / "rest.tskel", rest)
    r = reconstruct(rest, mode="sampled", source=s.volume, progress=TextProgress("    reconstruct"))
    out["rest"] = folder / "rest-sampled.vti"
    write_volume(out["rest"], r.volume, r.geometry)
    loss = 100.0 * (int(s.mask.sum()) - r.stats["filled"]) / s.mask.sum()
    _say(f"[4] identity reconstruction: {r.stats['filled']} voxels ({loss:.2f} % loss from the object), "
         f"{r.stats['seconds']:.3f} s -> {out['rest'].name}")

    bone, angles = POSES[sample]
    trans = Trans(root_bones(s.bones), pose_matrices(s.bones, {bone: angles}))
    write_trans(folder / "arm.trans", trans)
    posed = connect_to_tskel(conn, trans)
    write_tskel(folder / "arm.tskel", posed)
    r = reconstruct(posed, mode="sampled", source=s.volume, progress=TextProgress("    reconstruct"))
    out["posed"] = folder / "arm-sampled.vti"
    write_volume(out["posed"], r.volume, r.geometry)
    hot = reconstruct(posed, mode="hotspot")
    boned = reconstruct(posed, mode="bone")
    write_volume(folder / "arm-bone.vti", boned.volume, boned.geometry)
    _say(f"[5] {bone} turned {angles} deg: sampled reconstruction {r.stats['filled']} voxels in "
         f"{r.stats['seconds']:.3f} s (overdraw {r.stats['overdraw']:.1f}), hotspot max {hot.stats['hotspot_max']}, "
         f"origin {r.origin} -> {out['posed'].name}, arm-bone.vti")
    if sample == "mannequin":  # the walk clip is package data: always there
        out["walk"], retarget = _walk(folder / "walk", samples.walk_clip(), s, conn)
        out["sequence"] = _sequence(folder / "walk.zarr", retarget, conn, s.volume)
        out["movie"] = _movie(out["sequence"], folder / "walk.gif")
    out["skeleton"], out["sample"], out["connectivity"] = skel, s, conn
    _say(f"done in {time.perf_counter() - t0:.1f} s; files in {folder}/")
    return out


def _walk(folder: Path, clip: Path, s, conn, frames=slice(0, None, 133)):
    """Motion capture onto the mannequin: a few frames across the clip written and reconstructed."""
    from volanim_core.io.bvh_files import read_bvh
    from volanim_core.io.frame_files import frame_path, write_frames
    from volanim_core.motion.retarget import Retarget

    t = time.perf_counter()
    motion = read_bvh(clip)
    r = Retarget.build(s.bones, motion)
    numbers = list(range(motion.frames))[frames]
    mats = r.matrices(frames)
    written = write_frames(folder, "walk", s.bones, mats, numbers, connect=conn)
    _say(f"[6] {clip.name}: {motion.frames} frames at {motion.fps:.4g} fps retargeted onto {len(r.mapping)} bones "
         f"(up {r.up}, facing {r.forward}) in {time.perf_counter() - t:.2f} s; {len(numbers)} frames -> "
         f"{folder.name}/walk.NNNN.trans, .tskel")
    for n, m in zip(numbers, mats):
        tskel = connect_to_tskel(conn, Trans(root_bones(s.bones), m))
        rec = reconstruct(tskel, mode="sampled", source=s.volume)  # neighbour lists made once, then remembered
        path = frame_path(folder, "walk", n, "-sampled.vti")
        write_volume(path, rec.volume, rec.geometry)
        _say(f"    frame {n:4d}: {rec.stats['filled']} voxels, origin {rec.origin}, {rec.stats['seconds']:.3f} s "
             f"-> {folder.name}/{path.name}")
    return written, r


def _sequence(out: Path, retarget, conn, source, frames=slice(0, 144, 6)) -> Path:
    """One walk cycle (about 1.2 s of the clip), then the body crumbles into a heap: a sequence,
    every frame in one grid, all cores."""
    from volanim_core.parallel import RunOn, default_workers
    from volanim_core.sequence.effects import crumble
    from volanim_core.sequence.frames import FrameSpec
    from volanim_core.sequence.run import SequenceSettings, run_sequence

    numbers = range(retarget.motion.frames)[frames]
    specs = [FrameSpec(n, m) for n, m in zip(numbers, retarget.matrices(frames))]
    specs += crumble(specs, 10)
    rep = run_sequence(conn, specs, out, SequenceSettings(mode="sampled", source=source, fps=20.0),
                       on=RunOn(workers=min(default_workers(), 4)))
    grid = "x".join(map(str, rep.bounds.shape))
    _say(f"[7] sequence: {len(specs) - 10} frames of one walk cycle and 10 of crumbling, one {grid} grid "
         f"at origin {rep.bounds.lo}, {rep.workers}, {rep.seconds:.1f} s ({rep.computed} made, {rep.skipped} "
         f"already there) -> {out.name} (OME-Zarr: t, z, y, x)")
    return out


def _movie(sequence: Path, out: Path) -> Path:
    """The sequence as a small looping GIF, seen from the side (where a walk reads best), off-screen."""
    from volanim_core.parallel import RunOn, default_workers
    from volanim_core.render.framing import place_camera
    from volanim_core.render.movie import open_inputs, render
    from volanim_core.render.scene import RenderSettings

    camera, inputs = place_camera(open_inputs([sequence]), "side", aspect=320 / 240)  # every frame's body in view
    settings = RenderSettings(camera, preset=inputs.mode, vmax=inputs.vmax, size=(320, 240), background="#1e1e24")
    rep = render(inputs, settings, out, on=RunOn(workers=min(default_workers(), 4)))
    _say(f"[8] render: {rep.frames} frames, 320x240, surface style from the side, {rep.workers}, "
         f"{rep.seconds:.1f} s -> {out.name}")
    return out
