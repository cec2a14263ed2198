"""C3D motion capture drives a scan: real files from ezc3d's tests, read back by another project's reader
(py-c3d) and followed through positions2trans -> trans2positions."""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest

from paths import ASSETS, REPO
from runnable import volanim
from volanim_core import io
from volanim_core.io.marker_files import read_c3d
from volanim_core.io.positions_files import read_positions
from volanim_core.motion import markers

C3D = REPO / "tests" / "data" / "c3d"
QUALISYS, OPTOTRAK, MAP = C3D / "Qualisys.c3d", C3D / "Optotrak.c3d", C3D / "qualisys-mannequin.map"


def _read(path):
    """ezc3d's Optotrak.c3d claims 1149 frames (POINT:FRAMES) and holds 29, ending on a frame: read, and said."""
    if path != OPTOTRAK:
        return read_c3d(path)
    with pytest.warns(UserWarning, match="POINT:FRAMES says 1149 frames; it holds 29"):
        return read_c3d(path)


def _py_c3d(path):
    """Labels, (F, M, 3) with NaN where the residual says invalid, and the rate: by py-c3d, not ezc3d."""
    import c3d

    with open(path, "rb") as fh, warnings.catch_warnings():
        warnings.simplefilter("ignore")  # "no analog data": true and irrelevant
        reader = c3d.Reader(fh)
        frames = np.array([points.copy() for _, points, _ in reader.read_frames()])
        labels = [s.strip() for s in reader.point_labels]
        rate = reader.point_rate
    xyz = frames[:, :, :3].astype(float)
    xyz[frames[:, :, 3] < 0] = np.nan
    return labels, xyz, rate


@pytest.mark.parametrize("path", [QUALISYS, OPTOTRAK], ids=["qualisys", "optotrak"])
def test_our_c3d_markers_are_what_py_c3d_reads(path):
    labels, xyz, rate, unit = _read(path)
    their_labels, theirs, their_rate = _py_c3d(path)
    assert labels == their_labels and rate == their_rate and unit == "mm"
    assert np.array_equal(np.isnan(xyz), np.isnan(theirs))  # Optotrak: 3.8 % invalid, in the same places
    assert np.isnan(theirs).any() == (path == OPTOTRAK)
    np.testing.assert_allclose(xyz[~np.isnan(xyz)], theirs[~np.isnan(theirs)], atol=1e-3)


def test_a_joint_is_missing_where_any_of_its_markers_is():
    labels, xyz, _, _ = _read(OPTOTRAK)
    _, theirs, _ = _py_c3d(OPTOTRAK)
    bad = np.isnan(theirs[:, :, 0]).any(axis=0).nonzero()[0][0]  # a marker that goes missing
    good = np.isfinite(theirs[:, :, 0]).all(axis=0).nonzero()[0][0]
    joints = markers.joints_from_markers(labels, xyz, {"A": [labels[bad], labels[good]]}, ["A", "B"])
    missing = np.isnan(theirs[:, bad, 0])
    assert np.isnan(joints[:, 1]).all() and np.array_equal(np.isnan(joints[:, 0, 0]), missing)
    np.testing.assert_allclose(joints[~missing, 0], (theirs[~missing, bad] + theirs[~missing, good]) / 2, atol=1e-3)


# spec: docs/formats.md#positions
def test_a_real_qualisys_walk_drives_the_mannequin(tmp_path):
    """Each bone points where the markers say, after the fit the command prints; the body walks as far."""
    bones = io.read_bones(ASSETS / "mannequin.bones")
    r = volanim("positions2trans", QUALISYS, "--bones", ASSETS / "mannequin.bones", "--map", MAP,
                "--frames", "0:340:17", "-o", tmp_path / "t")
    assert r.returncode == 0, r.stderr
    assert "20 frames, 19 of 19 joints" in r.stdout and "55 markers at 200 Hz, in mm" in r.stdout
    # the lab's z is up (the markers span 1.5 m in z: a person's height) and the subject walks along x,
    # which is forward: ours faces -y, so data (x, y, z) -> ours (y, -x, z), written out by hand
    fitted = re.search(r"data up z, forward x, ([0-9.]+) voxels per unit", r.stdout)
    assert fitted, r.stdout
    scale = float(fitted.group(1))
    turn = np.array([[0.0, 1, 0], [-1, 0, 0], [0, 0, 1]])
    # our mannequin is 282 voxels from toe to head; the subject's markers span about 1.5 m
    assert 0.15 < scale < 0.2
    out = volanim("trans2positions", ASSETS / "mannequin.bones", *sorted((tmp_path / "t").glob("*.trans")),
                  "-o", tmp_path / "posed.csv")
    assert out.returncode == 0, out.stderr
    names = list(bones.joints)
    _, posed = read_positions(tmp_path / "posed.csv", names)
    labels, data, _ = _py_c3d(QUALISYS)
    wanted = {}
    for line in MAP.read_text().splitlines():
        if line.strip() and not line.startswith("#"):
            joint, *ms = line.split()
            wanted[joint] = data[0:340:17][:, [labels.index(m) for m in ms]].mean(axis=1) @ turn.T
    assert len(wanted) == 19
    worst = 0.0
    for b in bones.bones:
        ours = posed[:, names.index(b.distal)] - posed[:, names.index(b.proximal)]
        theirs = wanted[b.distal] - wanted[b.proximal]
        cos = np.einsum("ij,ij->i", ours, theirs) / np.linalg.norm(ours, axis=1) / np.linalg.norm(theirs, axis=1)
        worst = max(worst, float(np.degrees(np.arccos(np.clip(cos, -1, 1))).max()))
    assert worst < 0.1, worst  # every bone of every frame points along its markers
    pelvis = names.index("PELVIS")
    walked = posed[-1, pelvis] - posed[0, pelvis]
    # the scale is printed to 4 digits
    np.testing.assert_allclose(walked, scale * (wanted["PELVIS"][-1] - wanted["PELVIS"][0]), rtol=1e-3, atol=0.01)
    assert np.linalg.norm(walked[:2]) > 300  # two metres of walking, in voxels: it moved, along our floor


def test_c3d_input_that_cannot_work_is_refused_naming_the_file(tmp_path):
    bones = ASSETS / "mannequin.bones"
    (tmp_path / "text.c3d").write_text("frame,joint,x,y,z\n")
    r = volanim("positions2trans", tmp_path / "text.c3d", "--bones", bones, "-o", tmp_path / "a")
    assert r.returncode == 2 and "text.c3d: not a C3D file" in r.stderr and not (tmp_path / "a").exists()
    r = volanim("positions2trans", OPTOTRAK, "--bones", bones, "-o", tmp_path / "b")  # Marker_1 ...: no joint names
    assert r.returncode == 2 and "give --map" in r.stderr and "54 markers: Marker_1, Marker_2" in r.stderr
    (tmp_path / "typo.map").write_text(MAP.read_text().replace("L_FLE", "L_FLX"))
    r = volanim("positions2trans", QUALISYS, "--bones", bones, "--map", tmp_path / "typo.map", "-o", tmp_path / "c")
    assert r.returncode == 2 and "typo.map: no marker L_FLX" in r.stderr and "L_FLE" in r.stderr
    (tmp_path / "short.map").write_text("PELVIS L_IAS\nL_KNEE\n")
    r = volanim("positions2trans", QUALISYS, "--bones", bones, "--map", tmp_path / "short.map", "-o", tmp_path / "d")
    assert r.returncode == 2 and "short.map:2" in r.stderr
    r = volanim("positions2trans", tmp_path / "none.c3d", "--bones", bones, "-o", tmp_path / "e")
    assert r.returncode == 2 and "none.c3d" in r.stderr
    assert not any((tmp_path / d).exists() for d in "bcde")


@pytest.mark.parametrize("up, forward", [("y", "z"), ("z", "x"), ("-x", "y")])
def test_the_fit_finds_a_lab_turn_scale_and_place_it_was_given(up, forward):
    """Our rest joints put in a lab by hand (axes, millimetres, somewhere on the floor) come back exactly."""
    bones = io.read_bones(ASSETS / "mannequin.bones")
    names = list(bones.joints)
    rest = np.array([bones.joints[n] for n in names], float)
    u, f = (np.eye(3)[["xyz".index(a[-1])]][0] * (-1 if a.startswith("-") else 1) for a in (up, forward))
    lab_of_ours = np.column_stack([np.cross(-f, u), -f, u])  # our x = y cross z, y (we face -y), z in the lab
    lab = (rest @ lab_of_ours.T) / 0.17 + np.array([2500.0, -300.0, 40.0])  # 0.17 voxels per mm
    fitted = markers.fit(bones, lab[None], names)
    assert (fitted.up, fitted.forward) == (up, forward)
    assert fitted.scale == pytest.approx(0.17, rel=1e-9)
    np.testing.assert_allclose(fitted.apply(lab[None])[0], rest, atol=1e-9)


def test_axes_and_scale_given_are_kept_and_a_bad_axis_is_refused_where_typed(tmp_path):
    bones = ASSETS / "mannequin.bones"
    r = volanim("positions2trans", QUALISYS, "--bones", bones, "--map", MAP, "--frames", "0:1", "--up", "z",
                "--forward", "-y", "--scale", "0.25", "-o", tmp_path / "a")
    assert r.returncode == 0 and "data up z, forward -y, 0.25 voxels per unit (given)" in r.stdout
    r = volanim("positions2trans", QUALISYS, "--bones", bones, "--map", MAP, "--up", "w", "-o", tmp_path / "b")
    assert r.returncode == 2 and "--up" in r.stderr and "x, y or z" in r.stderr and not (tmp_path / "b").exists()
