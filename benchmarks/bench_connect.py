"""Connectivity benchmark: cube and lasso connect over ~200k shown points, auto-connect
on the frog's default skeleton, and each auto-connect method's error rate on the mannequin
(against its known limb membership).

Run: .venv/bin/python benchmarks/bench_connect.py
"""

from __future__ import annotations

import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from _harness import table  # noqa: E402

from volanim_core import samples  # noqa: E402
from volanim_core.rig.attach import auto_connect  # noqa: E402
from volanim_core.skeleton.skeletonize import skeletonize  # noqa: E402
from volanim_studio.model import Document  # noqa: E402
from volanim_studio.model.interaction import CubeMode, LassoMode  # noqa: E402
from volanim_studio.scene.projection import project  # noqa: E402


def timed(fn, repeats=5):
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def perspective(points: np.ndarray) -> tuple[np.ndarray, tuple]:
    """A camera 3 object-sizes in front (-y), looking +y: a composite projection matrix."""
    c = points.mean(0)
    size = np.ptp(points, axis=0).max()
    eye = c - [0, 3 * size, 0]
    f = (c - eye) / np.linalg.norm(c - eye)
    up = np.array([0.0, 0.0, 1.0])
    s = np.cross(f, up)
    s /= np.linalg.norm(s)
    u = np.cross(s, f)
    view = np.eye(4)
    view[0, :3], view[1, :3], view[2, :3] = s, u, -f
    view[:3, 3] = -view[:3, :3] @ eye
    near, far, fov = size, 5 * size, np.radians(30)
    t = 1 / np.tan(fov / 2)
    proj = np.array([[t, 0, 0, 0], [0, t, 0, 0], [0, 0, (far + near) / (near - far), 2 * far * near / (near - far)],
                     [0, 0, -1, 0]])
    return proj @ view, (0, 0, 1200, 800)


def main() -> None:
    frog = samples.frog()
    doc = Document()
    doc.set_volume(frog.volume, frog.mask)
    doc.set_skeleton(skeletonize(frog.mask, min_thinness=0.25))
    doc.bone_edits.set_bones(frog.bones)
    doc.thinness = float(doc.skeleton.thinness[200_000])
    doc.select_bones([1])
    shown = doc.shown_indices()
    pts = doc.skeleton.points[shown].astype(np.float64)
    rows = []

    cube = CubeMode(doc)
    doc.settings.cube_size = 120.0
    doc.set_cube(np.median(pts, axis=0))

    def cube_connect():
        cube.apply()
        doc.undo.undo()  # measure a full connect each time

    label = f"cube connect ({len(cube.inside())} of {len(shown)} shown inside)"
    rows.append([label, f"{1e3 * timed(cube_connect):.1f}"])
    matrix, viewport = perspective(pts)
    xy, depth = project(pts, matrix, viewport)
    view_depth = (pts - pts.mean(0)) @ [0, 1, 0]
    lo, hi = np.percentile(xy, 25, axis=0), np.percentile(xy, 75, axis=0)
    poly = [(lo[0], lo[1]), (hi[0], lo[1]), (hi[0], hi[1]), (lo[0], hi[1])]
    lasso = LassoMode(doc)
    rows.append(["projection of the shown points", f"{1e3 * timed(lambda: project(pts, matrix, viewport)):.1f}"])
    for mode in ("through", "visible", "slab"):
        doc.settings.lasso_depth = mode

        def lasso_connect():
            xy2, d2 = project(pts, matrix, viewport)
            lasso.finish(poly, xy2, d2, view_depth, shown)
            doc.undo.undo()

        rows.append([f"lasso connect, {mode} (incl. projection)", f"{1e3 * timed(lasso_connect):.1f}"])
    print(f"\nfrog skeleton at thinness >= {doc.thinness:.3f}: {len(shown)} points shown")
    print(table(rows, ["operation", "median ms"]))
    print("target: cube or lasso connect over 200k shown points under 50 ms")

    default = skeletonize(frog.mask)
    auto_connect(default.points[:100], frog.bones, frog.mask)  # compile / cache load
    for method in ("path", "path-or-nearest"):
        t0 = time.perf_counter()
        _, report = auto_connect(default.points, frog.bones, frog.mask, method=method)
        print(f"\nauto-connect ({method}) of the frog's default skeleton, {len(default)} points: "
              f"{time.perf_counter() - t0:.2f} s; {report}; target under 2 s")

    s = samples.mannequin()
    limb = np.array([samples.mannequin_limb(b.label) for b in s.bones.bones])
    rows = []
    for th in (0.5, 0.25):
        sk = skeletonize(s.mask, min_thinness=th)
        truth = s.part[tuple(sk.points.T)] - 1
        for method in ("nearest", "path", "geodesic", "fitted"):
            t0 = time.perf_counter()
            out, report = auto_connect(sk.points, s.bones, s.mask, method=method, radii=sk.dt)
            el = time.perf_counter() - t0
            ok = out >= 0
            wrong_limb = int((limb[out[ok]] != limb[truth[ok]]).sum())
            rows.append([f"{th:g}", len(sk), method, f"{100 * (out != truth).mean():.1f}",
                         f"{100 * (wrong_limb + (~ok).sum()) / len(sk):.2f}", int((~ok).sum()), f"{1e3 * el:.0f}"])
    print("\nauto-connect on the mannequin against its known membership")
    print(table(rows, ["thinness >=", "points", "method", "% wrong bone", "% wrong limb or unattached",
                       "unattached", "ms"]))


if __name__ == "__main__":
    main()
