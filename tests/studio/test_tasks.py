"""The studio's worker tasks (Qt-free): what they count, and that they leave the GIL to the window."""

from __future__ import annotations

from scipy import ndimage

from volanim_core import samples
from volanim_core.reconstruct.shape import PIECES
from volanim_core.rig._curve_kernels import paint_balls
from volanim_core.rig.curve_skeleton import balls
from volanim_core.skeleton.skeletonize import skeletonize
from volanim_studio import tasks


def test_regrown_pieces_counts_as_scipy_without_holding_the_gil(monkeypatch):
    """#83: opening a volume counted the pieces its skeleton's balls re-grow with scipy's label and a numba
    kernel that both held Python's GIL: 1.2 s of a frozen window on mannequin-large. The count is scipy's
    (the ant at a high thinness: its legs in dashes), made by nogil kernels and no scipy call."""
    s = samples.mannequin()
    skel = skeletonize(s.mask, min_thinness=1.0)  # 78 points: their balls leave the body in pieces
    want = (ndimage.label(balls(skel), PIECES)[1], ndimage.label(s.mask, PIECES)[1])
    assert want[0] > want[1]  # a case where the count matters

    def refused(*args, **kwargs):
        raise AssertionError("scipy's label holds the GIL")

    monkeypatch.setattr(ndimage, "label", refused)
    assert tasks.regrown_pieces(skel, s.mask) == want
    assert paint_balls.targetoptions.get("nogil")


def test_open_volume_fills_a_gltf_animal_as_volanim_voxelize_fills_it(tmp_path):
    """File > Open volume on Khronos' Fox (a skinned glTF): its surface at rest, filled, as the command fills it."""
    import numpy as np

    from paths import FOX
    from volanim_core.cli import main
    from volanim_core.io import read_volume

    loaded = tasks.load_volume_file(str(FOX))
    assert main(["voxelize", str(FOX), str(tmp_path / "fox.nrrd")]) == 0
    assert np.array_equal(loaded["volume"], read_volume(tmp_path / "fox.nrrd"))
    assert loaded["geometry"].spacing == loaded["spacing"] and np.count_nonzero(loaded["volume"]) > 20_000
