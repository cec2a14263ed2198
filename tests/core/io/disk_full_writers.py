"""Every writer onto a full disk (run by test_disk_full.py inside a small tmpfs of its own mount namespace).

    python disk_full_writers.py FULL_FOLDER SPARE_FOLDER

For each writer: a file "that was there" is put at the target, the disk is left with little room, then
the writer writes something larger. It must raise, leave the old file byte for byte, and leave no
temporary behind. One JSON line per writer on stdout.
"""

from __future__ import annotations

import json
import os
import sys
import traceback
from pathlib import Path

import numpy as np

OLD = b"the file that was there\n"


def writers(spare: Path):
    from volanim_core import io
    from volanim_core.geometry import Geometry
    from volanim_core.io.bvh_export import write_bvh
    from volanim_core.io.keys_files import Keys, write_keys
    from volanim_core.io.mesh_files import write_mesh
    from volanim_core.io.slicer_files import write_markups, write_transform
    from volanim_core.render.movie import encode, write_png
    from volanim_core.rig.bones import Bone, BoneSkeleton
    from volanim_core.rig.connectivity import BoneSegment, Connectivity, Tskel
    from volanim_core.rig.key_pose import KeyPose
    from volanim_core.skeleton.points import Skeleton

    rng = np.random.default_rng(0)
    vol = rng.integers(0, 255, (80, 80, 80), dtype=np.uint8)  # 512 kB that compress poorly
    geo = Geometry((1.0, 1.0, 2.0), (5.0, 6.0, 7.0))
    verts = rng.random((20_000, 3)).astype(np.float32)
    faces = rng.integers(0, 20_000, (20_000, 3))
    pts = np.unique(rng.integers(0, 5000, (40_000, 3)), axis=0)
    skel = Skeleton(pts, rng.random(len(pts)) + 1, rng.random(len(pts))).sorted()
    bones = BoneSkeleton({f"J{i}": (i, i, i) for i in range(3)}, [Bone("J0", "J1"), Bone("J1", "J2")])
    roots = [BoneSegment(*bones.segment(i), "") for i in range(2)]
    # a chain of 800 joints: markups, keys and a BVH larger than the room left
    many_joints = BoneSkeleton({f"J{i}": (0, 0, 10 * i) for i in range(801)},
                               [Bone(f"J{i}", f"J{i + 1}", f"B{i}") for i in range(800)])
    many_keys = {k: KeyPose({(f"J{i}", f"J{i + 1}"): np.array([0.0, k, 0.0]) for i in range(800)}) for k in range(3)}
    clip_matrices = np.tile(np.eye(4), (40, 800, 1, 1))
    conn = Connectivity(roots, skel.points, skel.dt, skel.thinness, np.arange(len(skel)) % 2).grouped()
    picture = rng.integers(0, 255, (600, 800, 3), dtype=np.uint8)
    pngs = []
    for k in range(3):
        pngs.append(spare / f"f{k}.png")
        write_png(pngs[-1], rng.integers(0, 255, (300, 400, 3), dtype=np.uint8))

    def project(path):
        from volanim_studio.model import Document

        doc = Document()
        doc.set_skeleton(skel)
        doc.bone_edits.set_bones(bones)
        doc.save_project(path)

    out = {f"volume {s}": (f"v{s}", lambda p: io.write_volume(p, vol, geo))
           for s in (".vti", ".nrrd", ".mha", ".nii", ".nii.gz", ".VOL", ".tif")}
    out.update({f"mesh {s}": (f"m{s}", lambda p: write_mesh(p, verts, faces))
                for s in (".ply", ".vtp", ".stl", ".obj")})
    out.update({
        "skeleton .mskel": ("s.mskel", lambda p: io.write_mskel(p, skel)),
        "connectivity .connect": ("c.connect", lambda p: io.write_connect(p, conn)),
        "posed .tskel": ("t.tskel", lambda p: io.write_tskel(p, Tskel(roots, np.stack([np.eye(4)] * 2), conn.points,
                                                                  conn.dt, conn.thinness, conn.bone))),
        "picture .png": ("o.png", lambda p: write_png(p, picture)),
        "movie .gif": ("o.gif", lambda p: encode(pngs * 4, p, 12.0)),
        "project .volanim": ("p.volanim", project),
        # the writers added since #38 (#64)
        "markups .mrk.json": ("b.mrk.json", lambda p: write_markups(p, many_joints, geo)),
        "keys .keys": ("k.keys", lambda p: write_keys(p, Keys(many_keys), many_joints)),
        "transform .tfm": ("t.tfm", lambda p: _big_text_file(p, lambda q: write_transform(q, np.eye(4)))),
        "transform .h5": ("t.h5", lambda p: _big_text_file(p, lambda q: write_transform(q, np.eye(4)))),
        "BVH export .bvh": ("w.bvh", lambda p: write_bvh(p, many_joints, clip_matrices, 30.0)),
        "slice stack .png": ("st%04d.png", lambda p: io.write_volume(p, vol)),
    })
    return out


def _big_text_file(path, write):
    """A transform file is a few hundred bytes: write it into a disk with no room at all."""
    ballast = path.parent / "ballast-all"
    room = os.statvfs(path.parent)
    with open(ballast, "wb") as fh:
        fh.write(b"\0" * (room.f_bavail * room.f_frsize))
    try:
        write(path)
    finally:
        ballast.unlink()


def fill(full: Path, leave: int) -> Path:
    """Fill the disk of ``full`` but ``leave`` bytes; the ballast file to delete for room."""
    ballast = full / "ballast"
    free = os.statvfs(full).f_bavail * os.statvfs(full).f_frsize
    with open(ballast, "wb") as fh:
        fh.write(b"\0" * max(0, free - leave))
    return ballast


def sequence_store(full: Path, spare: Path) -> dict:
    """A sequence store is a resumable cache, not a file replaced whole: on a full disk the run must
    raise, every frame it recorded complete must verify, and the same run must finish it after room is
    made, frame for frame equal to a run that had room."""
    sys.path.insert(0, str(Path(__file__).parents[2]))  # tests/: run as a script, not under pytest
    from paths import ASSETS, WALK
    from volanim_core import io
    from volanim_core.parallel import RunOn
    from volanim_core.samples import mannequin_bones
    from volanim_core.sequence import store
    from volanim_core.sequence.checked import read_store
    from volanim_core.sequence.frames import frames_from_files
    from volanim_core.sequence.run import SequenceSettings, run_sequence

    conn = io.read_connect(ASSETS / "mannequin.0.50.connect")
    walk = frames_from_files(conn, [WALK], bones=mannequin_bones(), frames=slice(0, 240, 10))
    run_sequence(conn, walk, spare / "roomy.zarr", SequenceSettings(mode="bone"), on=RunOn(workers=1))
    size = sum(f.stat().st_size for f in (spare / "roomy.zarr").rglob("*") if f.is_file())
    ballast = fill(full, size // 2)
    result = {"writer": "sequence .zarr", "store_bytes": size}
    try:
        run_sequence(conn, walk, full / "s.zarr", SequenceSettings(mode="bone"), on=RunOn(workers=1))
        result["raised"] = None
    except OSError as exc:
        result["raised"] = f"{type(exc).__name__}: {exc}"[:600]
    recorded = sorted(store.finished(full / "s.zarr"))
    result["recorded"] = len(recorded)
    result["frames"] = len(walk)
    want = store.open_frames(spare / "roomy.zarr")
    result["recorded_verify"] = all(np.array_equal(read_store(full / "s.zarr").read_frame(i),
                                                   read_store(spare / "roomy.zarr").read_frame(i)) for i in recorded)
    ballast.unlink()
    again = run_sequence(conn, walk, full / "s.zarr", SequenceSettings(mode="bone"), on=RunOn(workers=1))
    result["skipped_on_resume"] = again.skipped
    got = store.open_frames(full / "s.zarr")
    result["resumed_equal"] = bool(np.array_equal(got[:], want[:]))
    return result


def frame_folder(full: Path, spare: Path) -> dict:
    """A clip's frames (``bvh2trans``, ``keys``, ``positions2trans`` write them with ``write_frames``) on a
    disk with room for some: the run raises naming the frame that did not fit, the folder is marked
    incomplete and refused by every reader, and the same run after room is made completes it."""
    sys.path.insert(0, str(Path(__file__).parents[2]))
    from paths import WALK
    from volanim_core.errors import FormatError
    from volanim_core.io.bvh_files import read_bvh
    from volanim_core.io.frame_files import incomplete_marker, read_frames, write_frames
    from volanim_core.motion.retarget import Retarget
    from volanim_core.samples import mannequin_bones

    bones = mannequin_bones()
    mats = Retarget.build(bones, read_bvh(WALK)).matrices(slice(0, 200))
    write_frames(spare / "roomy", "walk", bones, mats, range(len(mats)))
    size = sum(f.stat().st_size for f in (spare / "roomy").iterdir())
    ballast = fill(full, size // 3)
    result = {"writer": "frame folder .trans", "frames": len(mats)}
    try:
        write_frames(full / "out", "walk", bones, mats, range(len(mats)))
        result["raised"] = None
    except OSError as exc:
        result["raised"] = f"{type(exc).__name__}: {exc}"[:600]
    result["written"] = len(list((full / "out").glob("*.trans")))
    result["marked"] = incomplete_marker(full / "out", "walk").is_file()
    try:
        read_frames(full / "out", bones)
        result["read_refused"] = None
    except FormatError as exc:
        result["read_refused"] = str(exc)[:300]
    ballast.unlink()
    write_frames(full / "out", "walk", bones, mats, range(len(mats)))
    result["marked_after_rerun"] = incomplete_marker(full / "out", "walk").is_file()
    result["rerun_equal"] = bool(np.array_equal(read_frames(full / "out", bones)[0],
                                                read_frames(spare / "roomy", bones)[0]))
    for f in (full / "out").iterdir():
        f.unlink()
    (full / "out").rmdir()
    return result


def main(full: Path, spare: Path) -> None:
    for name, (rel, write) in writers(spare).items():
        target = full / rel
        old = [full / (rel % k) for k in range(3)] if "%" in rel else [target]  # a stack: three old slices
        for f in old:
            f.write_bytes(OLD)
        ballast = fill(full, 24 * 1024)  # more than the old file, less than any new one
        result = {"writer": name, "target": rel}
        try:
            write(target)
            result["raised"] = None
        except Exception as exc:  # noqa: BLE001 - which type is part of the report
            result["raised"] = f"{type(exc).__name__}: {exc}"[:600]
            result["traceback"] = "Traceback" if not isinstance(exc, OSError | ValueError) else ""
            if result["traceback"]:
                result["traceback"] = traceback.format_exc()[-600:]
        result["old_intact"] = all(f.is_file() and f.read_bytes() == OLD for f in old)
        ballast.unlink()
        result["litter"] = sorted(str(p.relative_to(full)) for p in full.rglob("*") if p.is_file() and p not in old)
        for p in sorted(full.rglob("*"), reverse=True):  # the next writer starts on an empty disk
            p.unlink() if p.is_file() else p.rmdir()
        print(json.dumps(result), flush=True)
    print(json.dumps(frame_folder(full, spare)), flush=True)
    print(json.dumps(sequence_store(full, spare)), flush=True)


if __name__ == "__main__":
    main(Path(sys.argv[1]), Path(sys.argv[2]))
