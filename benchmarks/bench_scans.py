"""Reading scans: ours against SimpleITK's own readers, and what geometry costs a reconstruction.

    CT DICOM series 512 x 512 x 300 (int16 HU, written here with pydicom)   ours (pydicom) / SimpleITK (GDCM)
    NIfTI 256^3 int16 (.nii, written with nibabel)                          ours (nibabel) / SimpleITK
    frog, sampled rest frame: placed (anisotropic source) / unplaced        the geometry's cost

Each pair runs back to back, alternating which goes first, for several rounds in one process; the
table shows every round and the median of the per-round ratios (the machine drifts by 2x: only
ratios measured side by side mean anything). Targets (#35): readers within 1.5x of SimpleITK,
the placed reconstruction no slower than the unplaced one within noise.

Run: .venv/bin/python benchmarks/bench_scans.py [--rounds N]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np


def timed(fn) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def rounds(name: str, ours, theirs, n: int) -> list[str]:
    ours(), theirs()  # warm: imports, the page cache
    ratios, rows = [], []
    for k in range(n):
        a, b = (timed(ours), timed(theirs)) if k % 2 == 0 else tuple(reversed((timed(theirs), timed(ours))))
        ratios.append(a / b)
        rows.append(f"| {name} | {k + 1} | {a:.3f} | {b:.3f} | {a / b:.2f} |")
    rows.append(f"| **{name}** | median | | | **{statistics.median(ratios):.2f}** |")
    return rows


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--rounds", type=int, default=5)
    args = p.parse_args(argv)
    import nibabel as nib
    import SimpleITK as sitk

    from volanim_core import io, samples
    from volanim_core.geometry import Geometry
    from volanim_core.io.dicom_files import write_dicom_series
    from volanim_core.reconstruct.engine import reconstruct
    from volanim_core.rig.attach import connect_nearest
    from volanim_core.rig.tskel_tools import identity_tskel
    from volanim_core.skeleton.skeletonize import skeletonize

    rows = ["| case | round | ours s | baseline s | ours / baseline |", "|---|---|---|---|---|"]
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        rng = np.random.default_rng(0)
        ct = rng.integers(-1000, 1500, (512, 512, 300)).astype(np.int16)
        print("writing a 512 x 512 x 300 CT series ...", file=sys.stderr, flush=True)
        write_dicom_series(tmp / "ct", ct, Geometry((0.7, 0.7, 2.5), (-180, -180, -900)))
        files = sitk.ImageSeriesReader.GetGDCMSeriesFileNames(str(tmp / "ct"))

        def sitk_series():
            reader = sitk.ImageSeriesReader()
            reader.SetFileNames(files)
            sitk.GetArrayViewFromImage(reader.Execute())

        rows += rounds("DICOM CT 512x512x300", lambda: io.read_scan(tmp / "ct"), sitk_series, args.rounds)
        nib.save(nib.Nifti1Image(rng.integers(0, 4000, (256, 256, 256)).astype(np.int16), np.eye(4)),
                 tmp / "mri.nii")
        rows += rounds("NIfTI 256^3 int16", lambda: io.read_scan(tmp / "mri.nii"),
                       lambda: sitk.GetArrayViewFromImage(sitk.ReadImage(str(tmp / "mri.nii"))), args.rounds)

    frog = samples.load("frog")
    conn = connect_nearest(skeletonize(frog.mask), frog.bones)
    plain = identity_tskel(conn)
    placed = identity_tskel(conn)
    placed.geometry = Geometry((1.0, 1.0, 1.0), (-250, -235, -100))
    source_geometry = Geometry((1.0, 1.0, 1.5), (-250, -235, -100))  # the frog's own 1.5 mm slices
    rows += rounds("frog sampled rest: placed / unplaced",
                   lambda: reconstruct(placed, mode="sampled", source=frog.volume, source_geometry=source_geometry),
                   lambda: reconstruct(plain, mode="sampled", source=frog.volume), args.rounds)
    print("\n".join(rows))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
