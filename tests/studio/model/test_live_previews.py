"""#65: the studio's live previews redo only the slices the moved spheres reach, and each is the very
preview make_preview makes of the frame: the same voxels on the same grid."""

from __future__ import annotations

import numpy as np
import pytest

from paths import ASSETS
from volanim_core import io, samples
from volanim_core.rig.pose import pose_matrices
from volanim_studio.model.preview import LivePreviews, make_preview

# a drag of the left forearm in 10-degree steps, then the right thigh, then the whole body walked off
DRAG = [{"L_FOREARM": (0, 0, a)} for a in range(0, 70, 10)] + [{"R_THIGH": (-30, 0, 0)}]


@pytest.mark.parametrize("mode", ["bone", "binary"])
def test_a_drag_is_the_previews_make_preview_makes_and_redoes_a_part(mode):
    conn = io.read_connect(ASSETS / "mannequin.0.50.connect")
    bones = samples.mannequin_bones()
    live = LivePreviews()
    roots = [i for i, parent in enumerate(bones.parents()) if parent is None]
    frames = [conn.posed(pose_matrices(bones, pose)) for pose in DRAG]
    frames.append(conn.posed(pose_matrices(bones, DRAG[-1], {i: (200.0, 0.0, 0.0) for i in roots})))
    redone = []
    for t in frames:
        got = live.make(t, mode=mode, factor=2, padding=2)
        want = make_preview(t, mode=mode, factor=2, padding=2)
        assert got.reconstruction.origin == want.reconstruction.origin
        assert np.array_equal(got.reconstruction.volume, want.reconstruction.volume)
        assert np.allclose(got.reconstruction.geometry.origin, want.reconstruction.geometry.origin)
        assert np.array_equal(got.origin_voxels, want.origin_voxels) and got.factor == 2 and got.mode == mode
        redone.append(live.redone)
    nz = live.bounds.shape[2]
    assert all(0 < n < nz // 2 for n in redone[1:7])  # each step of the forearm: its slices only
    assert redone[-1] == live.bounds.shape[2]  # walked off the grid: a new one, every slice


def test_a_small_body_is_previewed_live_at_full_resolution_a_large_one_at_half():
    """#65: the mannequin's posed grid (about 4 M voxels) live at full resolution, mannequin-large's (97 M) at
    half; the choice is made on a mode's first frame and kept while the drag goes on."""
    from volanim_core.rig.connectivity import Tskel
    from volanim_core.rig.tskel_tools import identity_tskel
    from volanim_studio.model.preview import LIVE_FULL_VOXELS, live_factor

    conn = io.read_connect(ASSETS / "mannequin.0.50.connect")
    small = identity_tskel(conn)
    # the same body at twice the size each way: 8x the voxels, past the limit
    large = Tskel(small.bones, small.matrices, small.points * 2, small.dt * 2, small.thinness, small.bone)
    assert live_factor(small) == 1 and live_factor(large) == 2
    live = LivePreviews()
    first = live.make(small, mode="bone")
    assert first.factor == 1 and first.live
    assert np.array_equal(first.reconstruction.volume, make_preview(small, mode="bone").reconstruction.volume)
    assert live.make(small, mode="bone").factor == 1  # kept
    assert np.prod(live.bounds.shape) < 2 * LIVE_FULL_VOXELS


@pytest.mark.parametrize("factor", [1, 2])
def test_a_drag_of_an_owned_body_is_the_full_preview_s_body_and_redoes_the_moved_bones_box(factor):
    """#85: with the rig's ownership (the default body) the live pictures were still the thesis's spheres, so a
    raised arm swung its armpit lump while dragged and lost it on release. Now each live picture is the owned body
    make_preview makes (half size: the ownership pooled), redoing only the box the moved bones reach."""
    from volanim_core.rig.ownership import ownership

    s = samples.mannequin()
    conn = io.read_connect(ASSETS / "mannequin.0.50.connect")
    conn = conn.with_ownership(ownership(s.mask, conn))
    live = LivePreviews()
    redone = []
    for pose in DRAG:
        t = conn.posed(pose_matrices(s.bones, pose))
        got = live.make(t, mode="bone", factor=factor, padding=2)
        want = make_preview(t, mode="bone", factor=factor, padding=2)
        assert want.reconstruction.stats["method"] == "owned"
        assert got.reconstruction.origin == want.reconstruction.origin
        assert np.array_equal(got.reconstruction.volume, want.reconstruction.volume)
        assert np.array_equal(got.origin_voxels, want.origin_voxels)
        redone.append(live.redone)
    whole = int(np.prod(live.bounds.shape))
    assert all(0 < n < whole // 10 for n in redone[1:7])  # each step of the forearm: its own box


@pytest.mark.parametrize("owned", [True, False])
def test_a_factor_taken_again_redoes_what_moved_since_its_last_picture_not_its_whole_grid(owned):
    """#85: the live resolution went half, quarter, half... and every change made a whole new grid (the frog's
    half-size one: 100 ms a picture). Each factor's grid is kept while the mode lasts: back at half size only
    what moved since its last half-size picture is redone, and the picture is still make_preview's."""
    from volanim_core.rig.ownership import ownership

    s = samples.mannequin()
    conn = io.read_connect(ASSETS / "mannequin.0.50.connect")
    if owned:
        conn = conn.with_ownership(ownership(s.mask, conn))
    live = LivePreviews()
    factors = [2, 4, 2, 4, 2]
    for i, (f, pose) in enumerate(zip(factors, DRAG[1:6])):
        t = conn.posed(pose_matrices(s.bones, pose))
        got = live.make(t, mode="bone", factor=f, padding=2)
        want = make_preview(t, mode="bone", factor=f, padding=2)
        assert got.factor == f and np.array_equal(got.reconstruction.volume, want.reconstruction.volume)
        whole = int(np.prod(live.bounds.shape)) if owned else live.bounds.shape[2]
        if i >= 2:  # the factor's grid made before: only what moved since
            assert 0 < live.redone < whole // 2
    live.make(conn.posed(pose_matrices(s.bones, DRAG[1])), mode="binary", factor=2, padding=2)
    assert live.redone == (int(np.prod(live.bounds.shape)) if owned else live.bounds.shape[2])  # another mode: anew


def clear_label_two(values: np.ndarray) -> np.ndarray:
    """A transfer function (RGBA a label) that makes label 2 clear and the others a colour of their own."""
    rgba = np.stack([values / 40.0 % 1, 0.5 + 0 * values, 1 - values / 40.0 % 1, 1 + 0 * values], axis=1)
    rgba[values == 2, 3] = 0
    return np.clip(rgba, 0, 1)


@pytest.mark.parametrize("owned", [True, False])
def test_a_drags_surfaces_are_the_pictures_surfaces_made_whole_with_only_the_changed_slices_made_again(owned):
    """#85: a live picture's surface was made from the whole body each time (the mannequin's full-size faces: more
    than half the live stages). Its faces are now kept from the last picture of the same grid and only the slices
    the moved bones reach are made again: every surface of a drag is the one made whole from the picture, face
    for face, across factors taken again, a picture made without its surface, and a transfer function changed."""
    from volanim_core.rig.ownership import ownership
    from volanim_studio.model.preview import live_surface

    s = samples.mannequin()
    conn = io.read_connect(ASSETS / "mannequin.0.50.connect")
    if owned:
        conn = conn.with_ownership(ownership(s.mask, conn))
    live = LivePreviews()
    n_bones, spacing = len(s.bones), (1.5, 1.5, 2.0)
    arm = [{"L_FOREARM": (0, 0, a)} for a in range(0, 80, 10)]
    # (factor, transfer function, surface made, pose): the undrawn picture also turns the head, which the
    # next one keeps: only the kept slices' record of that picture's changes tells the next surface about it
    steps = [(2, None, True, arm[0]), (2, None, True, arm[1]), (4, None, True, arm[2]),
             (2, None, False, {**arm[2], "HEAD": (0, 0, 20)}), (2, None, True, {**arm[3], "HEAD": (0, 0, 20)}),
             (2, clear_label_two, True, arm[4]), (2, clear_label_two, True, arm[5]), (1, None, True, arm[6]),
             (1, None, True, arm[7])]
    redone = []
    for factor, function, drawn, pose in steps:
        p = live.make(conn.posed(pose_matrices(s.bones, pose)), mode="bone", factor=factor, padding=2)
        if not drawn:
            continue  # its surface never made: the next one's redoes its slices as well
        got, want = live.surface(p, function, n_bones, spacing), live_surface(p, function, n_bones, spacing)
        assert got.n_cells == want.n_cells > 1000
        assert np.array_equal(np.asarray(got.point_data["rgb"]), np.asarray(want.point_data["rgb"]))
        assert np.allclose(np.asarray(got.points), np.asarray(want.points), atol=1e-4)
        redone.append(live.faces_redone)
    grid = live.bounds.shape[2]
    assert redone[-1] < grid // 2 and redone[1] < redone[0]  # a step of the forearm: its own slices, not the grid's
