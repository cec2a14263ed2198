"""A live picture's surface (#85): the voxels' own faces (``voxel_faces``, numba) against flying edges
(``label_surface``, VTK), on the three bodies' live pictures, and what each costs to draw.

Each body's L_UPPERARM (the frog's LEGS) turned 45 degrees, bone mode, at the studio's live factor (the mannequin
full size, the frog and mannequin-large half). Both surfaces are made in the same rounds, alternately (the machine
drifts; medians of 7), then each is drawn in a 1200 x 800 off-screen window (software GL here) turning 2 degrees a
frame. Ratios are voxel faces / flying edges, same run.

Run: xvfb-run -a .venv/bin/python benchmarks/bench_surfaces.py [--datasets mannequin,frog,mannequin-large]
"""

from __future__ import annotations

import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from _harness import table  # noqa: E402

FACTOR = {"mannequin": 1, "frog": 2, "mannequin-large": 2}


def picture(dataset: str) -> np.ndarray:
    """The live picture's labels ``[x, y, z]`` (a view of a ``[z, y, x]`` array, as the studio's are)."""
    from bench_reconstruct import load_connectivity

    from volanim_core.reconstruct.engine import reconstruct
    from volanim_core.rig.pose import pose_matrices
    from volanim_core.rig.tskel_tools import coarse_tskel

    conn, bones = load_connectivity(dataset)
    limb = "LEGS" if dataset == "frog" else "L_UPPERARM"
    frame = coarse_tskel(conn.posed(pose_matrices(bones, {limb: (0, -45, 45)})), FACTOR[dataset])
    return reconstruct(frame, mode="bone", padding=2).volume


def draw_seconds(mesh) -> float:
    import pyvista as pv

    pl = pv.Plotter(off_screen=True, window_size=(1200, 800))
    pl.add_mesh(mesh, scalars="rgb", rgb=True)
    pl.render()
    times = []
    for _ in range(7):
        pl.camera.Azimuth(2)
        t0 = time.perf_counter()
        pl.ren_win.Render()
        times.append(time.perf_counter() - t0)
    pl.close()
    return statistics.median(times)


def main() -> None:
    from volanim_core.render.bone_colours import label_table
    from volanim_core.render.surfaces import label_surface, voxel_faces

    names = sys.argv[sys.argv.index("--datasets") + 1].split(",") if "--datasets" in sys.argv else list(FACTOR)
    rows = []
    for name in names:
        vol = picture(name)
        table_ = label_table(int(vol.max()))
        made = {"edges": [], "faces": []}
        meshes = {}
        for _ in range(8):  # the first round loads each kernel: not counted
            for key, make in (("edges", label_surface), ("faces", voxel_faces)):
                t0 = time.perf_counter()
                meshes[key] = make(vol, (0, 0, 0), (1, 1, 1), table_)
                made[key].append(time.perf_counter() - t0)
        make_ms = {k: 1000 * statistics.median(v[1:]) for k, v in made.items()}
        draw_ms = {k: 1000 * draw_seconds(m) for k, m in meshes.items()}
        rows.append([name, f"1/{FACTOR[name]}", f"{vol.size / 1e6:.1f}", f"{make_ms['edges']:.1f}",
                     f"{make_ms['faces']:.1f}", f"{make_ms['faces'] / make_ms['edges']:.2f}",
                     f"{meshes['edges'].n_cells // 1000} / {meshes['faces'].n_cells // 1000}",
                     f"{draw_ms['edges']:.0f}", f"{draw_ms['faces']:.0f}",
                     f"{draw_ms['faces'] / draw_ms['edges']:.2f}"])
    print("\na live picture's surface: flying edges (VTK) against the voxels' faces (numba), same run")
    print(table(rows, ["body", "factor", "M voxels", "edges ms", "faces ms", "faces / edges", "k cells",
                       "draw edges ms", "draw faces ms", "draw faces / edges"]))


if __name__ == "__main__":
    main()
