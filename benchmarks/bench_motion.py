"""Motion benchmark: the whole walk clip parsed, forward-kinematicked and retargeted; keyframes; playback.

Part 1 (no display): ``read_bvh`` + ``Retarget.build`` + ``matrices()`` for all 1064 frames of
the bundled walk.bvh onto the mannequin, against a per-frame baseline measured in the same run (one
scipy ``Rotation`` per joint per frame, the loop a straightforward port would write), and against
the clip's own duration (how many times faster than real time). Keyframe interpolation of 1000
frames for the 18 mannequin bones, against calling ``pose_matrices`` once per frame.

Part 2 (needs a display: ``xvfb-run -a``): the studio playing the clip with live previews on the
mannequin: frames drawn per second, against the rate the live preview alone allows (its compute
time per frame, measured in the same window) and against the clip's 120 fps.

    xvfb-run -a .venv/bin/python benchmarks/bench_motion.py
"""

from __future__ import annotations

import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

sys.path.insert(0, str(Path(__file__).parent))
from _harness import best_of, table  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
from volanim_core.samples import walk_clip  # noqa: E402

WALK = walk_clip()


def per_frame_baseline(motion):
    """The loop a direct port would write: per frame, per joint, one Euler conversion and matrix product."""
    values = motion.values
    out = []
    for f in range(motion.frames):
        world = {}
        column = 0
        for j, chans in enumerate(motion.channels):
            axes = "".join(c[0].lower() for c in chans if c.endswith("rotation"))
            cols = [column + k for k, c in enumerate(chans) if c.endswith("rotation")]
            r = Rotation.from_euler(axes.upper(), values[f, cols], degrees=True).as_matrix() if axes else np.eye(3)
            p = motion.parents[j]
            world[j] = r if p < 0 else world[p] @ r
            column += len(chans)
        out.append(world)
    return out


def bench_clip() -> None:
    from volanim_core.io.bvh_files import read_bvh
    from volanim_core.motion.keyframes import interpolate
    from volanim_core.motion.retarget import Retarget
    from volanim_core.rig.key_pose import KeyPose
    from volanim_core.rig.pose import pose_matrices
    from volanim_core.samples import mannequin_bones

    bones = mannequin_bones()
    motion = read_bvh(WALK)

    def ours():
        m = read_bvh(WALK)
        return Retarget.build(bones, m).matrices()

    parse = best_of(lambda: read_bvh(WALK))
    whole = best_of(ours)
    baseline = best_of(lambda: per_frame_baseline(motion), repeats=2)
    duration = motion.frames / motion.fps
    rows = [["parse only", f"{1000 * parse:.0f}", "", ""],
            ["parse + FK + retarget, all frames", f"{1000 * whole:.0f}", f"{baseline / whole:.1f}",
             f"{duration / whole:.0f}"],
            ["baseline: per-frame, per-joint FK only", f"{1000 * baseline:.0f}", "1.0", f"{duration / baseline:.0f}"]]
    print(f"\n{WALK.name}: {motion.frames} frames, {len(motion.names)} joints, {motion.fps:.4g} fps "
          f"({duration:.1f} s of motion) onto the mannequin's {len(bones)} bones")
    print(table(rows, ["case", "ms (best of 5)", "speed-up vs baseline", "x real time"]))
    print("target: parse + FK + retarget of the whole clip well under 1 s")

    rng = np.random.default_rng(0)
    keys = {f: KeyPose({(b.proximal, b.distal): rng.uniform(-60, 60, 3) for b in bones.bones})
            for f in range(0, 1000, 50)}
    frames = np.arange(1000)
    ours_keys = best_of(lambda: interpolate(bones, keys, frames, ease=True))
    each = interpolate(bones, keys, frames[:50])

    def one_by_one():
        for m in each:  # FK alone, frame by frame, with the angles already interpolated
            pose_matrices(bones, {i: m[i, :3, :3].T for i in range(len(bones))})

    per_frame = best_of(one_by_one, repeats=3) * 1000 / 50
    print(table([["keyframes: slerp + batched FK, 1000 frames", f"{1000 * ours_keys:.0f}",
                  f"{per_frame / ours_keys:.1f}"],
                 ["baseline: pose_matrices per frame (FK only)", f"{1000 * per_frame:.0f}", "1.0"]],
                ["case", "ms", "speed-up vs baseline"]))


def bench_playback(seconds: float = 6.0) -> None:
    from PySide6.QtWidgets import QApplication

    from volanim_studio.qt.main_window import MainWindow

    app = QApplication.instance() or QApplication([])
    w = MainWindow()
    w.resize(1200, 800)
    w.show()
    w.files.load_demo("mannequin")
    while w.busy:
        app.processEvents()
        time.sleep(0.005)
    w.files.open_bones(ROOT / "assets" / "mannequin.bones")
    w.files.open_connect(ROOT / "assets" / "mannequin.0.50.connect")
    w.timeline.load_bvh(WALK)  # read in the reader thread, then retargeted
    while w.readers.busy:
        app.processEvents()
        time.sleep(0.005)
    rows = []
    for mode in ("bone", "binary"):
        w.doc.settings.preview_mode = mode
        w.previews.live_timings.clear()
        w.timeline.play()
        t0 = time.perf_counter()
        while time.perf_counter() - t0 < seconds:
            app.processEvents()
        elapsed = time.perf_counter() - t0
        shown = list(w.timeline.shown_frames)
        w.timeline.stop()
        while w.busy:
            app.processEvents()
            time.sleep(0.005)
        drawn = len(shown) / elapsed
        compute = statistics.median(w.previews.live_timings)
        span = (shown[-1] - shown[0]) % w.doc.timeline.frame_count if len(shown) > 1 else 0
        rows.append([mode, f"{drawn:.1f}", f"{1000 * compute:.0f}", f"{drawn * compute:.2f}",
                     f"{span / (elapsed * w.doc.timeline.frame_rate):.2f}", f"{w.doc.timeline.frame_rate / drawn:.1f}"])
    w.close()
    print(f"\nstudio playback of {WALK.name} on the mannequin, live half-resolution previews, 1200x800, "
          f"software GL, {seconds:.0f} s each")
    print(table(rows, ["preview", "frames drawn/s", "live preview ms (median)",
                       "drawn/s vs preview-only rate", "clip time kept (1 = real time)", "clip frames per drawn"]))
    print("targets: >= 10 drawn/s; clip time kept ~1 (frames dropped, never slowed down)")


def bench_real_clip() -> None:
    """#39: mapping and detection (names, shape, axes from the motion, plausibility) on LAFAN's
    7184-frame test.bvh, against parsing it, measured in the same run. Target: at most +20 %."""
    sys.path.insert(0, str(ROOT / "tests"))
    from real_clips import clip
    from volanim_core.io.bvh_files import read_bvh
    from volanim_core.motion.plausible import check_clip
    from volanim_core.motion.retarget import Retarget
    from volanim_core.samples import mannequin_bones

    path, bones = clip("lafan_test"), mannequin_bones()
    motion = read_bvh(path)
    parse = best_of(lambda: read_bvh(path))
    build = best_of(lambda: Retarget.build(bones, motion))
    retarget = Retarget.build(bones, motion)
    check = best_of(lambda: check_clip(retarget))
    frames = best_of(lambda: retarget.matrices(), repeats=3)
    rows = [["parse (read_bvh)", f"{1000 * parse:.0f}", "1.00"],
            ["map + detect axes, units, reference (Retarget.build)", f"{1000 * build:.1f}", f"{build / parse:.3f}"],
            ["plausibility check (64 sampled frames)", f"{1000 * check:.1f}", f"{check / parse:.3f}"],
            ["mapping and detection together", f"{1000 * (build + check):.1f}", f"{(build + check) / parse:.3f}"],
            ["retarget all 7184 frames (matrices)", f"{1000 * frames:.0f}", f"{frames / parse:.2f}"]]
    print(f"\nLAFAN test.bvh ({motion.frames} frames, {len(motion.names)} joints) onto the mannequin")
    print(table(rows, ["step", "ms (best of 5)", "ratio to parse"]))
    print("target: mapping and detection add at most 0.20 of the parse time")


if __name__ == "__main__":
    bench_clip()
    bench_real_clip()
    if os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"):
        bench_playback()
    else:
        print("\n(no display: playback skipped; run under xvfb-run -a)")
