"""NAME.owners.nrrd beside a .connect (io/ownership_files.py), read back by pynrrd as well as by us."""

# spec: docs/formats.md#ownership

from __future__ import annotations

import numpy as np
import pytest

from volanim_core.errors import FormatError
from volanim_core.io import read_connect, write_connect
from volanim_core.io.ownership_files import ownership_path, read_ownership, write_ownership
from volanim_core.rig.connectivity import BoneSegment, Connectivity
from volanim_core.rig.ownership import ownership


def _rig():
    mask = np.zeros((20, 12, 30), bool)
    mask[6:14, 3:9, 2:16] = True
    mask[8:12, 4:8, 16:28] = True
    bones = [BoneSegment((10, 6, 2), (10, 6, 16), "TRUNK"), BoneSegment((10, 6, 16), (10, 6, 28), "LIMB")]
    pts = np.array([[10, 6, z] for z in range(4, 27)])
    conn = Connectivity(bones, pts, np.full(len(pts), 2.0), None, (pts[:, 2] >= 16).astype(int))
    return mask, conn


def test_round_trip_and_the_connect_reader_attaches_it(tmp_path):
    mask, conn = _rig()
    own = ownership(mask, conn)
    assert np.array_equal(own.volume(mask.shape) != 0, mask)
    write_connect(tmp_path / "r.connect", conn)
    write_ownership(ownership_path(tmp_path / "r.connect"), own)
    back = read_connect(tmp_path / "r.connect").ownership
    assert np.array_equal(back.labels, own.labels) and back.origin == own.origin
    assert np.array_equal(back.ball_radii, own.ball_radii) and np.array_equal(back.tubes, own.tubes)
    # another project's reader sees the same label volume
    import nrrd

    data, header = nrrd.read(str(ownership_path(tmp_path / "r.connect")))
    assert np.array_equal(data, own.labels) and header["volanim_origin"] == " ".join(map(str, own.origin))


def test_an_ownership_of_other_bones_is_refused_naming_the_bone(tmp_path):
    mask, conn = _rig()
    write_ownership(tmp_path / "o.owners.nrrd", ownership(mask, conn))
    moved = Connectivity([conn.bones[0], BoneSegment((10, 6, 16), (10, 9, 28), "LIMB")], conn.points, conn.dt,
                         None, conn.bone)
    with pytest.raises(FormatError, match="bone 1 \\(LIMB\\) has other joints"):
        read_ownership(tmp_path / "o.owners.nrrd", moved)
