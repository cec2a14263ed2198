"""Demo datasets."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import ndimage

from volanim_core import io, samples


def test_aliascube_matches_thesis_table_5_2():
    v = samples.aliascube().volume
    counts = np.bincount(v.ravel(), minlength=256)
    assert v.shape == (128, 128, 128)
    assert (counts[0], counts[50], counts[250]) == (872109, 612521, 612522)
    assert counts.sum() == counts[0] + counts[50] + counts[250]


def test_mannequin_is_one_layered_body_with_bones():
    s = samples.mannequin()
    assert s.volume.shape == (160, 100, 300)
    _, n = ndimage.label(s.mask)
    assert n == 1
    values = set(np.unique(s.volume)) - {0}
    assert len(values) >= 6  # skin, fat, two muscle stripes, bone, skull, brain
    assert len(s.bones) == 18
    names = {j for j in s.bones.joints}
    for j in ("NECK", "HEAD", "SHOULDER", "ELBOW", "WRIST", "HIP", "KNEE", "ANKLE"):
        assert j in names or f"L_{j}" in names and f"R_{j}" in names
    # every object voxel has a ground-truth bone, and every bone owns voxels
    assert np.array_equal(s.part > 0, s.mask)
    assert set(np.unique(s.part)) == set(range(len(s.bones) + 1))
    # left is at +x: the left hand's voxels are right of centre
    assert np.argwhere(s.part == s.bones.index("L_HAND") + 1)[:, 0].min() > 80


def test_mannequin_is_mirror_symmetric_about_mid_plane():
    s = samples.mannequin()
    assert np.array_equal(s.mask, s.mask[::-1])
    for name, xyz in s.bones.joints.items():
        if name[:2] in ("L_", "R_"):
            twin = s.bones.joints[("R_" if name[0] == "L" else "L_") + name[2:]]
            assert np.allclose([159 - xyz[0], xyz[1], xyz[2]], twin)
        else:
            assert xyz[0] == 79.5


def test_frog_loads_offline():
    s = samples.frog()
    assert s.volume.shape == (500, 470, 136) and s.volume.dtype == np.uint8
    assert s.spacing == (1.0, 1.0, 1.5)


def test_frog_body_points_at_the_head_and_legs_at_the_legs():
    """BODY/LEGS were swapped: LEGS pointed at the brain and eyes (issue #18)."""
    s = samples.frog()
    head = np.argwhere(np.isin(s.volume, samples.FROG_HEAD_LABELS)).mean(0)
    body, legs = (s.bones.bones[s.bones.index(n)] for n in ("BODY", "LEGS"))
    j = s.bones.joints
    assert body.proximal == legs.proximal == "MID"
    assert np.linalg.norm(j[body.distal] - head) < 0.5 * np.linalg.norm(j[legs.distal] - head)


def test_write_sample_files(tmp_path):
    paths = samples.write_sample("mannequin", tmp_path)
    assert [p.name for p in paths] == ["mannequin.VOL", "mannequin.bones", "mannequin.connections", "mannequin.keys"]
    assert np.array_equal(io.read_volume(paths[0]), samples.mannequin().volume)
    assert io.read_bones(paths[1]) == samples.mannequin_bones()
    from volanim_core.io.keys_files import read_keys

    keys = read_keys(paths[3], samples.mannequin_bones())
    assert sorted(keys.keys) == [0, 12, 24] and (keys.fps, keys.length, keys.ease) == (24.0, 25, True)
    arm = ("L_SHOULDER", "L_ELBOW")
    assert np.array_equal(keys.keys[12].angles[arm], [0, -80, 0]) and not keys.keys[0].angles


def test_colour_mannequin_is_the_mannequin_in_colour():
    grey, colour = samples.mannequin(), samples.mannequin_colour()
    assert colour.volume.shape == (*grey.volume.shape, 3) and colour.volume.dtype == np.uint8
    assert np.array_equal(colour.mask, grey.mask)  # black exactly where the grey body is empty
    skin = colour.volume[grey.volume == samples.SKIN].astype(float).mean(axis=0)
    muscle = colour.volume[grey.volume == samples.MUSCLE_A].astype(float).mean(axis=0)
    assert skin[0] > skin[2] + 40 and muscle[0] > 2 * muscle[1]  # warm skin, red muscle
    from volanim_core.colour.palette import unique_colours

    assert len(unique_colours(colour.volume)[0]) > 10_000  # grain: a palette has to be built


@pytest.mark.long("the thesis-scale sample (46 M voxels) is the mannequin on a finer grid")
def test_large_mannequin_is_the_mannequin_on_a_finer_grid(tmp_path):
    """The thesis's half-size Visible Human scale; its .connect reconstructs the body."""
    from volanim_core.reconstruct.engine import reconstruct
    from volanim_core.rig.tskel_tools import identity_tskel

    small, large = samples.mannequin(), samples.mannequin_large()
    assert large.volume.shape == (290, 169, 940)
    _, n = ndimage.label(large.mask)
    assert n == 1
    assert set(np.unique(large.volume)) == set(np.unique(small.volume))  # the same tissues
    scale = np.array(large.volume.shape) / small.volume.shape
    ratio = large.mask.sum() / small.mask.sum()
    assert abs(ratio / scale.prod() - 1) < 0.03  # the same body, sampled finer
    for name, p in small.bones.joints.items():
        assert np.allclose(large.bones.joints[name], (p + 0.5) * scale - 0.5)
    calls = []
    files = samples.write_sample("mannequin-large", tmp_path, progress=lambda d, t: calls.append(d / t))
    assert calls == sorted(calls) and calls[-1] == 1.0 and len(set(calls)) > 10  # ~10 s: a bar that moves
    conn = io.read_connect(tmp_path / "mannequin-large.connect")
    assert [f.name for f in files][-1] == "mannequin-large.connect" and 20_000 < len(conn) < 40_000
    x, y, z = conn.points.astype(int).T
    assert np.array_equal(conn.bone + 1, large.part[x, y, z])  # each point on its body part's bone
    rest = reconstruct(identity_tskel(conn), mode="binary")
    assert rest.stats["filled"] > 0.98 * large.mask.sum()
