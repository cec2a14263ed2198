"""napari opens a sequence: the OME-Zarr store through the napari-ome-zarr reader (the plugin napari
users install for OME-Zarr), as a 4-D image with axes t, z, y, x whose frames are the store's.

napari runs in its own process: its plugin registry and its dependencies' deprecation warnings stay
out of this test session (which turns warnings into errors)."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from paths import ASSETS, WALK
from volanim_core import io
from volanim_core.samples import mannequin_bones
from volanim_core.sequence.checked import read_store
from volanim_core.sequence.frames import frames_from_files
from volanim_core.sequence.run import SequenceSettings, run_sequence

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
    rep = run_sequence(conn, frames, out, SequenceSettings(mode="bone", fps=30))
    done = subprocess.run([sys.executable, "-W", "ignore", "-c", OPEN_IN_NAPARI, str(out), "2"],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-3000:]
    (layer,) = json.loads(done.stdout.strip().splitlines()[-1])
    frame = read_store(out).read_frame(2)
    assert layer["kind"] == "Image" and layer["axes"] == ["t", "z", "y", "x"]
    assert layer["shape"] == [4, *rep.bounds.shape[::-1]] and layer["dtype"] == "uint8"
    assert np.allclose(layer["scale"], [1 / 30, 1, 1, 1])  # seconds per frame, then voxels
    assert layer["frame_sum"] == int(frame.astype(np.int64).sum()) > 0
    assert layer["frame_nonzero"] == int(np.count_nonzero(frame))


SCALE_IN_NAPARI = """
import json, sys
from napari.components import ViewerModel
from napari.plugins import _initialize_plugins

_initialize_plugins()
viewer = ViewerModel()
viewer.open(sys.argv[1], plugin="napari-ome-zarr")
(layer,) = viewer.layers
print(json.dumps({"scale": [float(v) for v in layer.scale]}))
"""


# full tier only, so that make test stays under 10 minutes: napari (in its own process) places a RAS scan's frame
@pytest.mark.slow
def test_a_frame_of_a_scan_stored_ras_lies_on_the_scan(tmp_path):
    """#63 item 7: a scan stored RAS (a NIfTI written by nibabel) is read into LPS with x and y reversed; the
    store's OME scale and translation ignored the reversal: its rest frame lay at x 94..229 mm, beside the
    scan at -47..88. Now a reversed axis is a negative scale. Placed as the OME-Zarr spec says (scale, then
    translation, read from the store's zarr.json), every voxel of the rest frame is where nibabel's affine
    puts the scan's (in LPS: x and y negated); napari (napari-ome-zarr) reads the reversed axes' scales.

    napari-ome-zarr 0.10 reads only a dataset's first transform, the scale, and draws every store at the
    origin whatever its translation (ours, or any other writer's): so napari is asked for the scale only."""
    import nibabel as nib

    from volanim_core.cli import main
    from volanim_core.samples import write_sample

    write_sample("mannequin", tmp_path)
    vol = io.read_volume(tmp_path / "mannequin.VOL")
    affine = np.diag([1.0, 1.0, 1.0, 1.0])
    affine[:3, 3] = (-100.0, 30.0, -150.0)  # RAS: voxel i is at x = i - 100 mm
    nib.save(nib.Nifti1Image(vol, affine), tmp_path / "ct.nii.gz")
    f = {k: str(tmp_path / f"ct.{k}") for k in ("nii.gz", "mskel", "connect")}
    for argv in (["skeletonize", f["nii.gz"], "-o", f["mskel"]],
                 ["connect", f["mskel"], str(tmp_path / "mannequin.bones"), "--thinness", "0.5", "-o", f["connect"]],
                 ["pose", str(tmp_path / "mannequin.bones"), "-o", str(tmp_path / "rest.trans")],
                 ["sequence", f["connect"], str(tmp_path / "rest.trans"), "--mode", "binary", "--fps", "25",
                  "-o", str(tmp_path / "rest.zarr")]):
        assert main(argv) == 0, argv[0]
    ome = json.loads((tmp_path / "rest.zarr" / "zarr.json").read_text())["attributes"]["ome"]
    scale, translation = (t[t["type"]] for t in ome["multiscales"][0]["datasets"][0]["coordinateTransformations"])
    import zarr

    stored = zarr.open_array(str(tmp_path / "rest.zarr" / "0"), mode="r")[0]
    assert np.array_equal(read_store(tmp_path / "rest.zarr").read_frame(0), stored.transpose(2, 1, 0))  # ours reads it
    index = np.argwhere(stored > 0)  # z, y, x as stored
    placed = index * scale[1:] + translation[1:]
    lps = nib.affines.apply_affine(affine, np.argwhere(vol > 0)) * (-1, -1, 1)
    scan_lo, scan_hi = lps.min(axis=0)[::-1], lps.max(axis=0)[::-1]  # z, y, x
    # the rest frame re-grows the scan's body from its skeleton's spheres: within a few voxels of it
    assert np.allclose(placed.min(axis=0), scan_lo, atol=3) and np.allclose(placed.max(axis=0), scan_hi, atol=3), \
        (placed.min(axis=0), placed.max(axis=0), scan_lo, scan_hi)
    done = subprocess.run([sys.executable, "-W", "ignore", "-c", SCALE_IN_NAPARI, str(tmp_path / "rest.zarr")],
                          capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-3000:]
    assert json.loads(done.stdout.strip().splitlines()[-1])["scale"] == [1 / 25, 1.0, -1.0, -1.0]
