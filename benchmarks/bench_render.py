"""Render benchmark: seconds per frame at 640x480 per style on the frog and the mannequin, the CPU
ray caster against VTK's default volume mapper, and frames per second with 1 and 2 workers.

Both datasets are real sequences made here first (bench_sequence's cases: the mannequin walking, the
frog's legs swinging), rendered off-screen from the three-quarter view with their mode's preset.
Ratios are against a baseline in the same run: the surface style for the two volume mappers, 1 worker
for 2 (with this machine's own 2-vs-1 throughput on pure CPU work beside it).

    .venv/bin/python benchmarks/bench_render.py [FRAMES]
"""

from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from _harness import table  # noqa: E402
from bench_sequence import frog_case, machine_scaling, mannequin_case  # noqa: E402


def make_sequence(case, folder: Path, mode: str) -> Path:
    from volanim_core.parallel import RunOn
    from volanim_core.sequence.run import SequenceSettings, run_sequence

    name, conn, frames, source = case
    out = folder / f"{name.split()[0]}.zarr"
    run_sequence(conn, frames, out, SequenceSettings(mode=mode, source=source), on=RunOn(workers=2))
    return out


def per_frame(seq: Path, style: str, mapper: str = "gpu") -> float:
    """Median seconds per frame of one warm plotter (the first frame, which builds it, is not counted)."""
    from volanim_core.render.movie import open_inputs
    from volanim_core.render.scene import Renderer, RenderSettings
    from volanim_core.render.views import named_view
    from volanim_core.sequence.checked import read_store

    inputs = open_inputs([seq])
    settings = RenderSettings(named_view("three-quarter", inputs.lo, inputs.hi), style=style, mapper=mapper,
                              preset=inputs.mode, vmax=inputs.vmax, size=(640, 480))
    r = Renderer(settings)
    origin = read_store(seq).origin_xyz
    times = []
    try:
        for i, ref in enumerate(inputs.frames):
            vol = read_store(seq).read_frame(ref.index)
            t0 = time.perf_counter()
            r.render(vol, origin, ref.number)
            if i:
                times.append(time.perf_counter() - t0)
    finally:
        r.close()
    return float(np.median(times))


def whole_run(seq: Path, folder: Path, workers: int) -> tuple[float, float]:
    """(frames/s over the whole run, steady frames/s after each worker's first picture): worker start-up
    (a process, VTK, an OpenGL context) is paid once per run, not per frame."""
    from volanim_core.parallel import RunOn
    from volanim_core.render.movie import open_inputs, render
    from volanim_core.render.scene import RenderSettings
    from volanim_core.render.views import named_view

    inputs = open_inputs([seq])
    settings = RenderSettings(named_view("three-quarter", inputs.lo, inputs.hi), preset=inputs.mode,
                              vmax=inputs.vmax, size=(640, 480))
    stamps = []
    rep = render(inputs, settings, folder / f"pics-{workers}", on=RunOn(workers=workers), force=True,
                 on_frame=lambda *_: stamps.append(time.perf_counter()))
    steady = (len(stamps) - workers) / (stamps[-1] - stamps[workers - 1])
    return rep.frames / rep.seconds, steady


def main() -> None:
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 24
    rows, speed = [], []
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for make, mode in ((mannequin_case, "bone"), (frog_case, "sampled")):
            case = make(n)
            seq = make_sequence(case, folder, mode)
            surface = per_frame(seq, "surface")
            auto = per_frame(seq, "volume", "gpu")  # VTK smart mapper: its GPU ray caster, on Mesa here
            cpu = per_frame(seq, "volume", "cpu")
            rows.append([case[0], mode, f"{surface:.3f}", f"{auto:.3f}", f"{cpu:.3f}", f"{auto / surface:.1f}",
                         f"{cpu / auto:.2f}"])
            (one, one_s), (two, two_s) = whole_run(seq, folder, 1), whole_run(seq, folder, 2)
            speed.append([case[0], f"{n}", f"{one:.2f} / {one_s:.2f}", f"{two:.2f} / {two_s:.2f}",
                          f"{two_s / one_s:.2f}"])
    print(f"\nrender, 640x480, off-screen (software OpenGL), {n} frames per dataset; seconds per frame, warm plotter")
    print(table(rows, ["dataset", "preset", "surface s", "volume (VTK smart mapper) s", "volume (CPU ray caster) s",
                       "volume / surface", "CPU caster / default"]))
    print(f"\nwhole runs (read, draw, write PNG), surface style; this machine's own 2-vs-1 on pure CPU work: "
          f"{machine_scaling():.2f}x")
    print(table(speed, ["dataset", "frames", "1 worker f/s (run / steady)", "2 workers f/s (run / steady)",
                        "2 vs 1 steady"]))


if __name__ == "__main__":
    main()
