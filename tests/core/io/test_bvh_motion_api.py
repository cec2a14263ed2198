"""The Motion API holds a clip made in code to what a file is (#38): it took NaN values, a joint cycle
(forward kinematics returned uninitialised numbers), and raised KeyError or IndexError."""

from __future__ import annotations

import numpy as np
import pytest

from volanim_core.io.bvh_files import Motion


def motion(**change) -> Motion:
    args = dict(names=["Hips", "Arm"], parents=[-1, 0], offsets=[[0, 0, 0], [0, 10, 0]],
                channels=[["xposition", "yposition", "zposition", "zrotation", "xrotation", "yrotation"],
                          ["zrotation", "xrotation", "yrotation"]], frame_time=0.04, values=np.zeros((2, 9)))
    args.update(change)
    return Motion(**args)


def test_a_valid_motion_moves_its_joints():
    m = motion(values=np.array([[0, 0, 0, 0, 0, 0, 90, 0, 0]] * 2, float))
    _, pos = m.forward_kinematics()
    assert np.allclose(pos[0, 1], [0, 10, 0])


@pytest.mark.parametrize("change, message", [
    ({"values": np.full((2, 9), np.nan)}, "finite"),
    ({"values": np.full((2, 9), 1e308)}, "finite"),
    ({"values": np.zeros((2, 7))}, r"\(frames, 9\)"),
    ({"parents": [1, 0]}, "parents must come before"),  # a cycle: each the other's parent
    ({"parents": [-1, 1]}, "parents must come before"),  # its own parent
    ({"names": ["Hips", "Hips"]}, "distinct names"),
    ({"channels": [["xposition"], ["twist"]], "values": np.zeros((2, 2))}, "unknown channel"),
    ({"frame_time": float("nan")}, "frame time"),
])
def test_a_motion_made_in_code_is_refused_with_a_message(change, message):
    with pytest.raises(ValueError, match=message):
        motion(**change)


def test_an_unknown_joint_is_a_value_error_naming_the_joints():
    with pytest.raises(ValueError, match="no joint named 'Leg'.*Hips, Arm"):
        motion().index("Leg")
