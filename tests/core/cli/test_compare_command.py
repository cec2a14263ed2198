"""volanim samples NAME --pose and volanim compare: the true posed shape, and a reconstruction measured on it."""

from __future__ import annotations

import json

import numpy as np
import pytest

from paths import ASSETS
from runnable import volanim
from volanim_core import io
from volanim_core.cli import main
from volanim_core.posed_truth import posed_sample


def test_the_raised_arm_s_lump_is_measured_against_the_truth(tmp_path, capsys):
    """The README's default pipeline, the left upper arm raised 90 degrees: the flesh under the armpit is
    attached to the upper arm and hangs under it (#60). compare finds that lump near the shoulder, in the
    file the truth was written to and in the truth made in place alike."""
    d = tmp_path
    bones = ASSETS / "mannequin.bones"
    assert main(["pose", str(bones), "--rotate", "L_UPPERARM=0,-90,0", "-o", str(d / "arm.trans")]) == 0
    assert main(["connect2tskel", str(ASSETS / "mannequin.0.50.connect"), str(d / "arm.trans"),
                 "-o", str(d / "arm.tskel")]) == 0
    assert main(["reconstruct", str(d / "arm.tskel"), "--mode", "bone", "-o", str(d / "arm.vti")]) == 0
    assert main(["samples", "mannequin", "--pose", str(d / "arm.trans"), "-o", str(d / "truth.vti")]) == 0
    truth, geometry, _ = io.read_scan(d / "truth.vti")
    made = posed_sample("mannequin", io.read_trans(d / "arm.trans").matrices)
    assert np.array_equal(truth, made.volume) and np.allclose(geometry.origin, made.origin)
    capsys.readouterr()
    assert main(["compare", str(d / "arm.vti"), "--sample", "mannequin", "--pose", str(d / "arm.trans"), "--json"]) == 0
    here = json.loads(capsys.readouterr().out)
    assert main(["compare", str(d / "arm.vti"), str(d / "truth.vti"), "--pose", str(d / "arm.trans"),
                 "--bones", str(bones), "--json"]) == 0
    assert json.loads(capsys.readouterr().out) == here
    lump = here["largest_extra"]
    assert lump["near"] == "L_SHOULDER" and lump["bone"] == "L_UPPERARM" and lump["voxels"] > 500
    assert here["dice"] > 0.99 and here["largest_missing"] is None


def test_compare_refuses_what_it_cannot_measure(tmp_path):
    io.write_output(tmp_path / "a.vti", np.ones((4, 4, 4), np.uint8))
    r = volanim("compare", tmp_path / "a.vti", cwd=tmp_path)  # neither a truth nor a sample
    assert r.returncode == 2 and "TRUTH" in r.stderr
    r = volanim("compare", tmp_path / "a.vti", "--sample", "mannequin", cwd=tmp_path)
    assert r.returncode == 2 and "--pose" in r.stderr
    r = volanim("samples", "frog", "--pose", ASSETS / "mannequin.bones", "-o", tmp_path / "t.vti", cwd=tmp_path)
    assert r.returncode == 2 and "only the mannequins" in r.stderr


@pytest.mark.parametrize("output", [".", ""])
def test_a_posed_truth_needs_a_file_to_write(tmp_path, capsys, output):
    assert main(["pose", str(ASSETS / "mannequin.bones"), "-o", str(tmp_path / "rest.trans")]) == 0
    assert main(["samples", "mannequin", "--pose", str(tmp_path / "rest.trans"), "-o", output]) == 2
    assert "-o names it" in capsys.readouterr().err
