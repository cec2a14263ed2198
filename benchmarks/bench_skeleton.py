"""Skeletonization and hull benchmark: frog (real) and mannequin.

Prints wall time (median of warm runs), the first call in a fresh process,
and peak memory above the loaded mask, with ratios against baselines measured
in the same run:

    ours (full: crop + EDT + thinness + sort)  vs  scikit-image skeletonize,
    edt package EDT alone, scipy EDT alone;  isosurface: VTK flying edges vs skimage.

Run: .venv/bin/python benchmarks/bench_skeleton.py [--repeats N]
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from _harness import child, measure, table  # noqa: E402


def load(dataset: str) -> np.ndarray:
    from volanim_core import samples

    return np.asfortranarray(samples.load(dataset).volume > 0)


def _ours(m):
    from volanim_core.skeleton.skeletonize import skeletonize

    skeletonize(m)


def _skimage(m):
    from skimage.morphology import skeletonize

    skeletonize(m)


def _edt(m):
    import edt

    edt.edt(np.ascontiguousarray(m.T), black_border=True, parallel=2)


def _scipy(m):
    from scipy import ndimage

    ndimage.distance_transform_edt(np.pad(m, 1))


def _iso_vtk(m):
    from volanim_core.skeleton.hull import isosurface

    isosurface(m, engine="vtk")


def _iso_skimage(m):
    from volanim_core.skeleton.hull import isosurface

    isosurface(m, engine="skimage")


def _kimimaro(m):
    import kimimaro

    kimimaro.skeletonize(m.astype(np.uint8), parallel=2, progress=False)


CASES = {"ours: skeletonize": _ours, "skimage skeletonize": _skimage, "edt EDT alone": _edt,
         "scipy EDT alone": _scipy, "isosurface vtk": _iso_vtk, "isosurface skimage": _iso_skimage,
         "kimimaro TEASAR": _kimimaro}


def main() -> None:
    repeats = int(sys.argv[sys.argv.index("--repeats") + 1]) if "--repeats" in sys.argv else 3
    for dataset in ("frog", "mannequin"):
        voxels = int(np.prod(load(dataset).shape))
        results = {c: measure(__file__, c, dataset, repeats) for c in CASES}
        base = results["ours: skeletonize"]
        rows = []
        for case, r in results.items():
            if "error" in r:
                rows.append([case, "-", "-", "-", "-", f"not run: {r['error'][:60]}"])
                continue
            ratio = r["time"] / base["time"] if "error" not in base else float("nan")
            rows.append([case, f"{r['time']:.3f}", f"{r['first']:.3f}", f"{r['peak'] / 2**20:.0f}",
                         f"{r['peak'] / voxels:.2f}", f"{ratio:.2f}x ours"])
        print(f"\n{dataset}: {voxels} voxels")
        print(table(rows, ["case", "time s", "first call s", "peak MiB", "peak B/voxel", "time ratio"]))
        if "error" not in base:
            for other in ("skimage skeletonize", "edt EDT alone"):
                r = results[other]
                if "error" not in r:
                    print(f"  {other} / ours = {r['time'] / base['time']:.2f}")


if __name__ == "__main__":
    if "--child" in sys.argv:
        i = sys.argv.index("--child")
        child(CASES, load, sys.argv[i + 1], sys.argv[i + 2], int(sys.argv[i + 3]))
    else:
        main()
