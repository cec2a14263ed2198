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
    from volanim_core.io.mesh_files import write_mesh
    from volanim_core.render.run import encode, write_png
    from volanim_core.rig.bones import Bone, BoneSkeleton
    from volanim_core.rig.connectivity import Connectivity, RootBone
    from volanim_core.skeleton.points import Skeleton

    rng = np.random.default_rng(0)
    vol = rng.integers(0, 255, (80, 80, 80), dtype=np.uint8)  # 512 kB that compress poorly
    geo = Geometry((1.0, 1.0, 2.0), (5.0, 6.0, 7.0))
    verts = rng.random((20_000, 3)).astype(np.float32)
    faces = rng.integers(0, 20_000, (20_000, 3))
    pts = np.unique(rng.integers(0, 5000, (40_000, 3)), axis=0)
    skel = Skeleton(pts, rng.random(len(pts)) + 1, rng.random(len(pts))).sorted()
    bones = BoneSkeleton({f"J{i}": (i, i, i) for i in range(3)}, [Bone("J0", "J1"), Bone("J1", "J2")])
    roots = [RootBone(*bones.segment(i), "") for i in range(2)]
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
           for s in (".vti", ".nrrd", ".mha", ".nii", ".nii.gz", ".VOL")}
    out.update({f"mesh {s}": (f"m{s}", lambda p: write_mesh(p, verts, faces))
                for s in (".ply", ".vtp", ".stl", ".obj")})
    out.update({
        "skeleton .mskel": ("s.mskel", lambda p: io.write_mskel(p, skel)),
        "connectivity .connect": ("c.connect", lambda p: io.write_connect(p, conn)),
        "picture .png": ("o.png", lambda p: write_png(p, picture)),
        "movie .gif": ("o.gif", lambda p: encode(pngs * 4, p, 12.0)),
        "project .volanim": ("p.volanim", project),
    })
    return out


def main(full: Path, spare: Path) -> None:
    for name, (rel, write) in writers(spare).items():
        target = full / rel
        target.write_bytes(OLD)
        ballast = full / "ballast"
        free = os.statvfs(full).f_bavail * os.statvfs(full).f_frsize
        with open(ballast, "wb") as fh:  # leave 24 kB: more than the old file, less than any new one
            fh.write(b"\0" * max(0, free - 24 * 1024))
        result = {"writer": name}
        try:
            write(target)
            result["raised"] = None
        except Exception as exc:  # noqa: BLE001 - which type is part of the report
            result["raised"] = f"{type(exc).__name__}: {exc}"[:300]
            result["traceback"] = "Traceback" if not isinstance(exc, OSError | ValueError) else ""
            if result["traceback"]:
                result["traceback"] = traceback.format_exc()[-600:]
        result["old_intact"] = target.is_file() and target.read_bytes() == OLD
        ballast.unlink()
        result["litter"] = sorted(str(p.relative_to(full)) for p in full.rglob("*") if p.is_file() and p != target)
        for p in sorted(full.rglob("*"), reverse=True):  # the next writer starts on an empty disk
            p.unlink() if p.is_file() else p.rmdir()
        print(json.dumps(result), flush=True)


if __name__ == "__main__":
    main(Path(sys.argv[1]), Path(sys.argv[2]))
