"""`volanim warmup` compiles every numba kernel a command or the studio calls (#61 item 11: the walk's first
`volanim scan` on a fresh install spent 14 of its 22 s compiling; three times that on a busy machine)."""

from __future__ import annotations

import subprocess
import sys

import pytest

# numba functions only ever called from inside other kernels: compiled into their callers, never on their own
INLINED = {
    "volanim_core._face_kernels._empty_beside",
    "volanim_core._face_kernels._open_sides",
    "volanim_core.colour._tour_kernels.two_opt",
    "volanim_core.reconstruct._clip_kernels._last_inside",
    "volanim_core.reconstruct._clip_kernels._row_run",
    "volanim_core.reconstruct._kernels._distance",
    "volanim_core.reconstruct._kernels._inside",
    "volanim_core.reconstruct._kernels._rows_in_box",
    "volanim_core.reconstruct._plan_kernels._cuts",
    "volanim_core.rig._ownership_kernels._at",
    "volanim_core.rig._ownership_kernels._near",
    "volanim_core.rig._ownership_kernels._in_slice",
    "volanim_core.rig._ownership_kernels._row_stretch",
    "volanim_core.rig._ownership_kernels._middles",
    "volanim_core.rig._hull_kernels._side",
    "volanim_core.rig._table_kernels._counted_to_starts",
    "volanim_core.reconstruct._owned_kernels._take",
    "volanim_core.reconstruct._whole_kernels._inside",
    "volanim_core.reconstruct._whole_kernels._joins",
    "volanim_core.reconstruct._whole_kernels._next_to",
    "volanim_core.reconstruct._kernels._sample",
    "volanim_core.reconstruct._kernels.row_run",
    "volanim_core.reconstruct._kernels.slice_cuts",
    "volanim_core._run_kernels._root",
    "volanim_core.reconstruct._label_kernels.group_starts",
    "volanim_core.rig._attach_kernels._path_inside",
    "volanim_core.skeleton._kernels._relax",
    "volanim_core.reconstruct._owned_kernels._moved",
    "volanim_core.reconstruct._owned_kernels._label",
    "volanim_core.reconstruct._owned_kernels.claims_point",
    "volanim_core.rig._ownership_kernels.tube_depth",
    "volanim_core.rig._ownership_kernels.tube_distance",
}

CHILD = r"""
import importlib, pkgutil
import volanim_core
from numba.core.registry import CPUDispatcher
from volanim_core.cli import main
assert main(["warmup"]) == 0
for m in pkgutil.walk_packages(volanim_core.__path__, "volanim_core."):
    if m.name.endswith("__main__"):  # importing it runs the command line
        continue
    mod = importlib.import_module(m.name)
    for name, v in vars(mod).items():
        if isinstance(v, CPUDispatcher) and v.__module__ == m.name:
            print(("compiled " if v.signatures else "not compiled ") + f"{m.name}.{name}")
"""


@pytest.mark.long("a process of its own: only there does a dispatcher's compiled state come from the warm-up alone")
def test_the_warm_up_compiles_every_kernel_called_from_python():
    out = subprocess.run([sys.executable, "-c", CHILD], capture_output=True, text=True, check=True).stdout
    assert "kernels ready in" in out
    missing = {line.split()[-1] for line in out.splitlines() if line.startswith("not compiled ")}
    compiled = {line.split()[-1] for line in out.splitlines() if line.startswith("compiled ")}
    assert missing <= INLINED, f"kernels the warm-up leaves to a user's first call: {sorted(missing - INLINED)}"
    # three the warm-up missed before: auto-rig's balls, geodesic connect, the default palette sort (ramp)
    outside = sorted(k for k in missing | compiled if not k.rsplit(".", 1)[0].endswith("_kernels"))
    assert not outside, f"numba kernels outside a _kernels module (#68: arrays in, arrays out): {outside}"
    assert {"volanim_core.rig._curve_kernels.paint_balls", "volanim_core.rig._attach_kernels._path_inside_many",
            "volanim_core.colour._tour_kernels.or_opt"} <= compiled and len(compiled) >= 25


def test_numba_runs_on_a_thread_safe_layer():
    """The studio reconstructs on its GUI thread (live previews) while a cancelled job's thread ends its chunk,
    and viewers read in threads of their own: parallel kernels are entered from two threads at once. numba's
    fallback layer (workqueue) aborts the process on that; OpenMP (libgomp1, in the Makefile's packages) and TBB
    do not."""
    import numba
    import numpy as np

    @numba.njit(parallel=True)
    def total(a):
        s = 0.0
        for i in numba.prange(a.size):
            s += a[i]
        return s

    assert total(np.ones(64)) == 64.0  # a parallel kernel has run: numba has chosen its layer
    assert numba.threading_layer() in ("omp", "tbb")



def compiled_again(modules: list[str], body: str) -> str:
    """What ``body`` (Python, run in a process of its own after the warm-up) made numba compile or load anew: the
    kernels of ``modules`` that gained a signature, as the child prints them."""
    script = f"""
import importlib
from numba.core.registry import CPUDispatcher
from volanim_core.cli import main
assert main(["warmup"]) == 0
kernels = list({{id(v): v for name in {modules!r} for v in vars(importlib.import_module(name)).values()
                if isinstance(v, CPUDispatcher)}}.values())  # one entry each: a module may import another's
before = {{k: len(k.signatures) for k in kernels}}
{body}
print("compiled again:", sorted(f"{{k.py_func.__module__}}.{{k.__name__}}" for k in kernels
                                if len(k.signatures) > before[k]))
"""
    return subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True).stdout


C_ORDER_POSE = """
import numpy as np
from volanim_core.reconstruct.owned import reconstruct_owned
from volanim_core.rig.connectivity import BoneSegment
from volanim_core.rig.ownership import Ownership
labels = np.zeros((9, 8, 10), np.uint8)  # C order, as np.zeros makes it: a user's own labels
labels[1:8, 1:7, 1:5], labels[2:7, 2:6, 5:10] = 1, 2
own = Ownership(labels, (0, 0, 0), [BoneSegment((4, 4, 1), (4, 4, 5)), BoneSegment((4, 4, 5), (4, 4, 11))], [0, 2])
turn = np.eye(4)
turn[:2, :2] = [[0.6, 0.8], [-0.8, 0.6]]
reconstruct_owned(own, np.stack([np.eye(4), turn]), mode="bone")
"""


@pytest.mark.long("a process of its own: only there does a dispatcher's compiled state come from the warm-up alone")
def test_an_ownership_of_labels_in_c_order_uses_the_kernels_the_warm_up_compiled():
    """Labels given in C order (np.zeros's) were used as given, and the warp's kernels compiled again for that
    layout on first use: 20 s after the warm-up (the owned oracle test, in a clean clone)."""
    out = compiled_again(["volanim_core.reconstruct._owned_kernels", "volanim_core.rig._ownership_kernels",
                          "volanim_core.rig._table_kernels"], C_ORDER_POSE)
    assert "compiled again: []" in out, out


SMOOTH_REPORT = """
from volanim_core import samples
from volanim_core.reconstruct.breakage import breakage_report
from volanim_core.rig.pose import pose_matrices, posed_joints
from volanim_core.rig.skinning import Joints
s = samples.load("mannequin")
m = pose_matrices(s.bones, {"L_FOREARM": (0, 0, 60)})
breakage_report(samples.part_connectivity(s).with_joints(Joints("smooth")).posed(m), s.bones.joints,
                posed_joints(s.bones, m))
"""


@pytest.mark.long("a process of its own: only there does a dispatcher's compiled state come from the warm-up alone")
def test_a_smooth_frames_report_uses_the_kernels_the_warm_up_compiled():
    """A smooth frame's report reads uint16 labels (its claims), which the warm-up never gave the run and piece
    kernels: every user's first smooth report compiled four of them (2.5 s of the rabbit's leaf test)."""
    out = compiled_again(["volanim_core._run_kernels", "volanim_core.reconstruct._label_kernels"], SMOOTH_REPORT)
    assert "compiled again: []" in out, out


LIVE_SPHERES_AND_OWN_REST = """
import numpy as np
from volanim_core import samples
from volanim_core.reconstruct.breakage import rest_voxels
from volanim_core.reconstruct.engine import Reconstruction, grid_bounds
from volanim_core.reconstruct.live import LiveFrame
from volanim_core.rig.pose import pose_matrices
s = samples.load("mannequin")
conn = samples.part_connectivity(s)
frames = [conn.posed(pose_matrices(s.bones, {"L_FOREARM": (0, 0, a)})) for a in (0, 30)]
live = LiveFrame(grid_bounds(frames[0], 8))
for t in frames:
    live.update(t)  # the studio's live spheres: their neighbour lists are the LiveFrame's own
rest = np.zeros((12, 10, 8), np.uint8)  # a caller's own volume, in C order
rest[2:9, 2:8, 1:4], rest[3:8, 3:7, 4:7] = 1, 2
rest_voxels(Reconstruction(rest, (0, 0, 0)))
"""


@pytest.mark.long("a process of its own: only there does a dispatcher's compiled state come from the warm-up alone")
def test_live_spheres_and_a_callers_rest_volume_use_the_kernels_the_warm_up_compiled():
    """The sweep of the default tier (each test file in a process of its own after the warm-up, the dispatchers'
    signatures before and after) found two product paths compiling on first use: the studio's live spheres gave
    the overdraw cut their own, writeable neighbour lists (the warm-up's come read-only from the cache), and a
    report's rest voxels of a C-ordered volume ran the run kernels on its Fortran-ordered transpose."""
    out = compiled_again(["volanim_core.reconstruct._plan_kernels", "volanim_core._run_kernels"],
                         LIVE_SPHERES_AND_OWN_REST)
    assert "compiled again: []" in out, out
