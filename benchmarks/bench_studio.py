"""Studio interaction benchmark: the thinness slider on a 200k-point cloud.

Times ``doc.thinness = t`` -> the cloud actor updated and the frame rendered
(the real SceneView in a real QtInteractor), on the frog's skeleton kept down
to thinness 0.25 (~400 k points) with the slider at values showing ~200 k.
Needs a display: ``xvfb-run -a .venv/bin/python benchmarks/bench_studio.py``
(``make bench`` does this).
"""

from __future__ import annotations

import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from _harness import table  # noqa: E402


def main() -> None:
    from PySide6.QtWidgets import QApplication

    from volanim_core import samples
    from volanim_core.skeletonize import skeletonize
    from volanim_studio.qt_main_window import MainWindow

    app = QApplication.instance() or QApplication([])
    w = MainWindow()
    w.resize(1200, 800)
    w.show()
    app.processEvents()
    skel = skeletonize(samples.frog().mask, min_thinness=0.25)
    w.doc.set_skeleton(skel)
    # slider values whose prefix is about 200 k points
    t200 = float(skel.thinness[200_000]) if len(skel) > 200_000 else float(skel.thinness[-1])
    values = np.linspace(t200 - 0.02, t200 + 0.02, 20)
    rows = []
    for spheres in (False, True):
        for dragging in (False, True):
            w.scene.set_cloud_style(spheres=spheres)
            w.scene.set_dragging(dragging)
            app.processEvents()
            update, frame, counts = [], [], []
            for v in values:
                t0 = time.perf_counter()
                w.doc.thinness = float(v)  # model -> SceneView: actor updated, frame requested
                t1 = time.perf_counter()
                app.processEvents()  # the coalesced frame is drawn here
                t2 = time.perf_counter()
                update.append(t1 - t0)
                frame.append(t2 - t1)
                counts.append(w.scene.shown_points)
            rows.append([("spheres" if spheres else "points") + (", slider held (LOD)" if dragging else ""),
                         f"{w.doc.visible_count}", f"{int(np.mean(counts))}",
                         f"{1000 * statistics.median(update):.1f}", f"{1000 * statistics.median(frame):.1f}"])
    print(f"\nthinness slider, frog skeleton ({len(skel)} points kept), window 1200x800")
    print(table(rows, ["style", "points shown", "points drawn", "update ms (median)", "frame ms (median)"]))
    print("target: the update under 50 ms for 200k points; frames are software GL (llvmpipe) here")
    w.close()


if __name__ == "__main__":
    main()
