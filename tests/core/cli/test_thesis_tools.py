"""The thesis's small tools as processes (#43): good input, bad input refused with the file named."""

from __future__ import annotations

import numpy as np

from runnable import volanim
from volanim_core import io


def _vol(path, v):
    io.write_volume(path, np.asarray(v, np.uint8, order="F"))
    return path


# spec: docs/formats.md#diff
def test_diff_reports_changed_values_and_a_summary(tmp_path):
    a = np.zeros((6, 5, 4), np.uint8)
    a[1:5, 1:4, 1:3] = 100
    b = a // 2  # every value changed, nothing added or removed
    b[0, 0, 0] = 9  # one voxel only in the second
    r = volanim("diff", _vol(tmp_path / "a.VOL", a), _vol(tmp_path / "b.VOL", b), tmp_path / "d.VOL")
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert "200 both, changed  24" in lines and "150 only second    1" in lines
    assert "25 of 120 voxels differ" in r.stdout
    d = io.read_volume(tmp_path / "d.VOL")
    assert np.array_equal(d, np.where(a > 0, 200, 0) + np.pad([[[150]]], ((0, 5), (0, 4), (0, 3))))
    same = volanim("diff", tmp_path / "a.VOL", tmp_path / "a.VOL")
    assert same.returncode == 0 and "identical: all 120 voxels" in same.stdout
    bad = volanim("diff", tmp_path / "a.VOL", _vol(tmp_path / "small.VOL", a[:3]))
    assert bad.returncode == 2 and "6x5x4 voxels but" in bad.stderr and "small.VOL is 3x5x4" in bad.stderr
