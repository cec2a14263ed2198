"""Per-frame .trans/.tskel files: written atomically with numbered names, read back in frame order."""

from __future__ import annotations

import numpy as np
import pytest

from small_rigs import arms_down
from volanim_core import io
from volanim_core.errors import Cancelled, FormatError
from volanim_core.io.frame_files import frame_number, read_frames, write_frames
from volanim_core.motion.keyframes import interpolate
from volanim_core.rig.connectivity import Connectivity
from volanim_core.rig.key_pose import KeyPose
from volanim_core.rig.pose import root_bones


def clip():
    bones = arms_down()
    keys = {0: KeyPose(), 12: KeyPose({("L_SHOULDER", "L_ELBOW"): np.array([0.0, 90.0, 0.0])})}
    return bones, interpolate(bones, keys, range(0, 13, 4))


def test_frames_round_trip_in_frame_order_with_tskels(tmp_path):
    bones, mats = clip()
    conn = Connectivity(root_bones(bones), np.array([[2.0, 0, 8], [2, 0, 2]]), np.array([1.0, 1.0]),
                        np.array([1.0, 1.0]), np.array([1, 2]))
    written = write_frames(tmp_path / "out", "wave", bones, mats, [0, 4, 8, 12], connect=conn)
    assert [p.name for p in written] == ["wave.0000.trans", "wave.0004.trans", "wave.0008.trans", "wave.0012.trans"]
    tskel = io.read_tskel(tmp_path / "out" / "wave.0012.tskel")
    assert np.allclose(tskel.matrices, mats[3], atol=1e-5)
    back, paths = read_frames(tmp_path / "out", bones)
    assert np.allclose(back, mats, atol=1e-5) and paths == written
    # numbers, not names, decide the order (frame 100 after frame 12)
    write_frames(tmp_path / "out", "wave", bones, mats[:1], [100])
    assert read_frames(tmp_path / "out", bones)[1][-1].name == "wave.0100.trans"
    assert frame_number("a.b.0012.trans") == 12 and frame_number("pose.trans") is None


def test_a_frame_of_another_skeleton_is_refused_by_name(tmp_path):
    bones, mats = clip()
    write_frames(tmp_path, "wave", bones, mats[:2], [0, 1])
    other = arms_down()
    other.joints["L_WRIST"] = np.array([2.0, 0.0, -3.0])
    with pytest.raises(FormatError, match=r"wave\.0000\.trans.*bone 2 differs: the \.bones has L_\w+ .*moved by up"):
        read_frames(tmp_path, other)
    (tmp_path / "empty").mkdir()
    with pytest.raises(FileNotFoundError, match="no .trans files"):
        read_frames(tmp_path / "empty", bones)


def test_cancel_stops_between_frames(tmp_path):
    bones, mats = clip()
    seen = []
    with pytest.raises(Cancelled):
        write_frames(tmp_path, "wave", bones, mats, range(4), progress=lambda d, t: seen.append(d),
                     cancel=lambda: len(seen) >= 2)
    assert len(list(tmp_path.glob("*.trans"))) == 2


def test_frames_a_run_did_not_finish_are_refused_until_it_is_run_again(tmp_path):
    """#64: a bvh2trans/keys/positions2trans run killed, cancelled or out of room left some frames and no way to
    tell; the marker write_frames keeps beside them until the last is written tells every reader."""
    bones, mats = clip()
    seen = []
    with pytest.raises(Cancelled):
        write_frames(tmp_path, "wave", bones, mats, range(4), progress=lambda d, t: seen.append(d),
                     cancel=lambda: len(seen) >= 2)
    assert (tmp_path / "wave.incomplete").is_file()
    with pytest.raises(FormatError, match=r"wave\.incomplete lies beside it"):
        read_frames(tmp_path, bones)
    from volanim_core.sequence.frames import frames_from_files

    conn = Connectivity(root_bones(bones), np.array([[2.0, 0, 8]]), np.array([1.0]), np.array([1.0]), np.array([1]))
    with pytest.raises(FormatError, match="stopped before the last"):
        frames_from_files(conn, sorted(tmp_path.glob("*.trans")))
    write_frames(tmp_path, "wave", bones, mats, range(4))  # run again: whole, the marker gone
    assert not (tmp_path / "wave.incomplete").exists() and len(read_frames(tmp_path, bones)[0]) == 4


def test_a_nan_frame_is_refused_before_any_file_is_written(tmp_path):
    bones, mats = clip()
    mats = mats.copy()
    mats[2, 1, 0, 0] = np.nan
    with pytest.raises(ValueError, match="NaN or infinite"):
        write_frames(tmp_path / "out", "wave", bones, mats, range(4))
    assert not list((tmp_path / "out").glob("*"))
