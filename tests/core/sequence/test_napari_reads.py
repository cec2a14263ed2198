"""napari opens a sequence: the OME-Zarr store through the napari-ome-zarr reader (the plugin napari
users install for OME-Zarr), as a 4-D image with axes t, z, y, x whose frames are the store's.

napari runs in its own process: its plugin registry and its dependencies' deprecation warnings stay
out of this test session (which turns warnings into errors)."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np

from paths import ASSETS, WALK
from volanim_core import io
from volanim_core.samples import mannequin_bones
from volanim_core.sequence import store
from volanim_core.sequence.frames import frames_from_files
from volanim_core.sequence.run import run_sequence

OPEN_IN_NAPARI = """
import json, sys
import numpy as np
from napari.components import ViewerModel
from napari.plugins import _initialize_plugins

_initialize_plugins()  # what napari's window does at start: find the installed readers
viewer = ViewerModel()
viewer.open(sys.argv[1], plugin="napari-ome-zarr")
out = []
for layer in viewer.layers:
    frame = np.asarray(layer.data[int(sys.argv[2])])
    out.append({"kind": type(layer).__name__, "shape": list(layer.data.shape), "dtype": str(layer.data.dtype),
                "axes": list(layer.axis_labels), "scale": [float(s) for s in layer.scale],
                "frame_sum": int(frame.astype(np.int64).sum()), "frame_nonzero": int(np.count_nonzero(frame))})
print(json.dumps(out))
"""


def test_napari_opens_a_sequence_as_a_4d_image_of_its_frames(tmp_path):
    conn = io.read_connect(ASSETS / "mannequin.0.50.connect")
    frames = frames_from_files(conn, [WALK], bones=mannequin_bones(), frames=slice(0, 40, 10))
    out = tmp_path / "walk.zarr"
    rep = run_sequence(conn, frames, out, mode="bone", fps=30)
    done = subprocess.run([sys.executable, "-W", "ignore", "-c", OPEN_IN_NAPARI, str(out), "2"],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-3000:]
    (layer,) = json.loads(done.stdout.strip().splitlines()[-1])
    frame = store.read_frame(out, 2)
    assert layer["kind"] == "Image" and layer["axes"] == ["t", "z", "y", "x"]
    assert layer["shape"] == [4, *rep.bounds.shape[::-1]] and layer["dtype"] == "uint8"
    assert np.allclose(layer["scale"], [1 / 30, 1, 1, 1])  # seconds per frame, then voxels
    assert layer["frame_sum"] == int(frame.astype(np.int64).sum()) > 0
    assert layer["frame_nonzero"] == int(np.count_nonzero(frame))
