"""3D Slicer's files, checked with ITK's own reader (SimpleITK): markups, transform files, and the
displacement field that resamples any image of the scan into the pose.

The scan here has what real scans have: 0.8 mm voxels, an origin, and a flipped x axis, so a
mistake in any of spacing, origin, direction or the transforms' direction shows.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import SimpleITK as sitk

from volanim_core import io
from volanim_core.cli import main
from volanim_core.errors import FormatError
from volanim_core.geometry import Geometry
from volanim_core.io.slicer_files import read_markups, write_markups
from volanim_core.reconstruct.engine import reconstruct
from volanim_core.rig.pose import posed_joints
from volanim_core.rig.tskel_tools import connect_to_tskel
from volanim_core.samples import write_sample

GEOMETRY = Geometry((0.8, 0.8, 0.8), (-40.0, 20.0, 100.0), (-1, 0, 0, 0, 1, 0, 0, 0, 1))


@pytest.fixture(scope="module")
def scan(tmp_path_factory):
    """The mannequin as a scan in physical space, its skeleton, connectivity and a keyed frame."""
    d = tmp_path_factory.mktemp("slicer")
    write_sample("mannequin", d)
    io.write_volume(d / "ct.nrrd", io.read_volume(d / "mannequin.VOL"), GEOMETRY)
    for argv in (["skeletonize", d / "ct.nrrd", "-o", d / "ct.mskel"],
                 ["connect", d / "ct.mskel", d / "mannequin.bones", "--thinness", "0.5", "-o", d / "ct.connect"],
                 ["keys", d / "mannequin.keys", "--bones", d / "mannequin.bones", "-o", d / "wave"]):
        assert main([str(a) for a in argv]) == 0
    return d


# spec: docs/formats.md#slicer
def test_markups_round_trip_in_physical_space(scan, tmp_path):
    bones = io.read_bones(scan / "mannequin.bones").on_grid(GEOMETRY)
    bones = type(bones)(bones.joints, bones.bones, GEOMETRY)
    write_markups(tmp_path / "j.mrk.json", bones)
    doc = json.loads((tmp_path / "j.mrk.json").read_text())
    points = {p["label"]: p["position"] for p in doc["markups"][0]["controlPoints"]}
    assert doc["markups"][0]["coordinateSystem"] == "LPS"
    # the position is the joint's voxel through the scan's geometry, computed here by hand
    i, j, k = bones.joints["L_ELBOW"]
    assert np.allclose(points["L_ELBOW"], [-40 - 0.8 * i, 20 + 0.8 * j, 100 + 0.8 * k])
    back = read_markups(tmp_path / "j.mrk.json", GEOMETRY)
    assert back.bones == bones.bones and list(back.joints) == list(bones.joints)
    assert all(np.allclose(back.joints[n], bones.joints[n], atol=1e-9) for n in bones.joints)


def test_markups_as_slicer_writes_them_become_chains(tmp_path):
    # the example of Slicer's documentation (Docs/developer_guide/modules/markups.md), as a chain,
    # and a second list in RAS hanging a limb from its second point
    doc = {"@schema": "https://raw.githubusercontent.com/slicer/slicer/master/Modules/Loadable/Markups/Resources/"
                      "Schema/markups-schema-v1.0.0.json#",
           "markups": [{"type": "Fiducial", "coordinateSystem": "LPS", "controlPoints": [
               {"label": "F-1", "position": [-53.388409961685827, -73.33572796934868, 0.0]},
               {"label": "F-2", "position": [49.8682950191571, -88.58955938697324, 0.0]},
               {"label": "F-3", "position": [-25.22749042145594, 59.255268199233729, 0.0]}]},
                       {"type": "OpenCurve", "coordinateSystem": "RAS", "controlPoints": [
               {"label": "F-2", "position": [-49.8682950191571, 88.58955938697324, 0.0]},
               {"label": "TIP", "position": [-60.0, 90.0, 12.5]},
               {"label": "LATER", "position": [0, 0, 0], "positionStatus": "preview"}]}]}
    (tmp_path / "s.mrk.json").write_text(json.dumps(doc))
    g = Geometry((0.5, 0.5, 0.5), (-100.0, -100.0, -10.0))
    bones = read_markups(tmp_path / "s.mrk.json", g)
    assert [(b.proximal, b.distal) for b in bones.bones] == [("F-1", "F-2"), ("F-2", "F-3"), ("F-2", "TIP")]
    assert np.allclose(bones.joints["TIP"], [(60 + 100) / 0.5, (-90 + 100) / 0.5, (12.5 + 10) / 0.5])
    doc["markups"][1]["controlPoints"][0]["position"] = [49.0, 88.0, 0.0]  # F-2 somewhere else
    (tmp_path / "bad.mrk.json").write_text(json.dumps(doc))
    with pytest.raises(FormatError, match="bad.mrk.json.*F-2.*two places"):
        read_markups(tmp_path / "bad.mrk.json", g)


def test_an_unplaced_point_as_slicer_saves_it_is_skipped(tmp_path):
    """Slicer saves a control point it was asked to place and never got with ``"position": ""`` and
    ``"positionStatus": "undefined"`` (a user's file, as posted; the fields in Slicer's order): the file
    was refused whole ("a position of three finite numbers"). The point is no joint yet: skipped."""
    unplaced = {"id": "3", "label": "editing", "description": "", "associatedNodeID": "", "position": "",
                "orientation": [-1.0, -0.0, -0.0, -0.0, -1.0, -0.0, 0.0, 0.0, 1.0], "selected": True,
                "locked": False, "visibility": True, "positionStatus": "undefined"}
    placed = [{"id": str(k + 1), "label": label, "description": "", "associatedNodeID": "", "position": p,
               "orientation": [-1.0, -0.0, -0.0, -0.0, -1.0, -0.0, 0.0, 0.0, 1.0], "selected": True,
               "locked": False, "visibility": True, "positionStatus": "defined"}
              for k, (label, p) in enumerate([("HIP", [0.0, 0.0, 0.0]), ("KNEE", [0.0, 0.0, -40.0])])]
    doc = {"@schema": "https://raw.githubusercontent.com/slicer/slicer/master/Modules/Loadable/Markups/Resources/"
                      "Schema/markups-schema-v1.0.3.json#",
           "markups": [{"type": "Fiducial", "coordinateSystem": "LPS", "coordinateUnits": "mm",
                        "controlPoints": placed + [unplaced]}]}
    (tmp_path / "leg.mrk.json").write_text(json.dumps(doc, indent=4))
    bones = read_markups(tmp_path / "leg.mrk.json", Geometry((1.0, 1.0, 1.0), (-10.0, -10.0, -50.0)))
    assert [(b.proximal, b.distal) for b in bones.bones] == [("HIP", "KNEE")]
    assert "editing" not in bones.joints
    unplaced["positionStatus"] = "defined"  # a defined point without a position is still refused, by name
    (tmp_path / "bad.mrk.json").write_text(json.dumps(doc))
    with pytest.raises(FormatError, match="bad.mrk.json.*control point 2"):
        read_markups(tmp_path / "bad.mrk.json", Geometry((1.0, 1.0, 1.0), (-10.0, -10.0, -50.0)))


def test_markups_command_needs_the_scan_and_writes_nothing_without(scan, tmp_path):
    assert main(["markups", str(scan / "mannequin.bones"), "--like", str(scan / "ct.nrrd"),
                 "-o", str(tmp_path / "m.mrk.json")]) == 0
    assert main(["markups", str(tmp_path / "m.mrk.json"), "-o", str(tmp_path / "b.bones")]) == 2
    assert not (tmp_path / "b.bones").exists()
    assert main(["markups", str(tmp_path / "m.mrk.json"), "--like", str(scan / "ct.nrrd"),
                 "-o", str(tmp_path / "b.bones")]) == 0
    back = io.read_bones(tmp_path / "b.bones")
    ours = io.read_bones(scan / "mannequin.bones")
    assert back.geometry == GEOMETRY and back.bones == ours.bones
    assert all(np.allclose(back.joints[n], ours.joints[n], atol=1e-6) for n in ours.joints)


@pytest.mark.parametrize("fmt", ["tfm", "h5"])
def test_transform_files_move_the_joints_where_ours_go(scan, tmp_path, fmt):
    frame = scan / "wave" / "mannequin.0012.trans"
    assert main(["transforms", str(scan / "ct.connect"), str(frame), "--format", fmt, "-o", str(tmp_path)]) == 0
    bones = io.read_bones(scan / "mannequin.bones")
    ours = posed_joints(bones, io.read_trans(frame).matrices)  # voxels of the scan's grid
    for b in bones.bones:
        tx = sitk.ReadTransform(str(tmp_path / f"{b.label}.{fmt}"))
        for name in (b.proximal, b.distal):  # both ends of the bone move with it
            rest = GEOMETRY.to_physical(bones.joints[name][None])[0]
            posed = GEOMETRY.to_physical(ours[name][None])[0]
            # the file maps posed -> rest (ITK's resampling direction); its inverse carries rest -> posed
            assert np.allclose(tx.TransformPoint(tuple(posed)), rest, atol=1e-6)
            assert np.allclose(tx.GetInverse().TransformPoint(tuple(rest)), posed, atol=1e-6)


@pytest.mark.parametrize("writer", ["pynrrd", "SimpleITK"])
def test_a_scan_at_the_origin_in_1_mm_voxels_takes_a_displacement_field(tmp_path, writer):
    """#63: a scan written at origin 0 in 1 mm voxels (the identity grid) gives a .mskel and .connect with no
    `# geometry:` line; `displacement --like` the same scan was reported to refuse ("records no voxel grid").
    The identity grid is that scan's grid: the field is written on it (pynrrd's and SimpleITK's files)."""
    import nrrd

    v = np.zeros((40, 30, 60), np.uint8)
    v[10:30, 8:22, 5:55] = 1
    if writer == "pynrrd":
        nrrd.write(str(tmp_path / "s.nrrd"), v, {"space": "left-posterior-superior", "space directions": np.eye(3),
                                                 "space origin": np.zeros(3)})
    else:
        sitk.WriteImage(sitk.GetImageFromArray(v.transpose(2, 1, 0).copy()), str(tmp_path / "s.nrrd"))
    f = {k: str(tmp_path / f"s.{k}") for k in ("nrrd", "mskel", "bones", "connect", "trans")}
    assert main(["skeletonize", f["nrrd"], "-o", f["mskel"]]) == 0
    assert "# geometry:" not in (tmp_path / "s.mskel").read_text()[:200]
    assert main(["autorig", f["mskel"], "-o", f["bones"], "--connect", f["connect"]]) == 0
    assert main(["pose", f["bones"], "-o", f["trans"]]) == 0
    assert main(["displacement", f["connect"], f["trans"], "--like", f["nrrd"], "-o", str(tmp_path / "d.nrrd")]) == 0
    field = sitk.ReadImage(str(tmp_path / "d.nrrd"))
    assert field.GetSize() == (40, 30, 60) and field.GetOrigin() == (0.0, 0.0, 0.0)


@pytest.mark.long("3D Slicer's own resampling of our displacement field gives our sampled pose")
def test_displacement_field_resamples_the_scan_into_our_sampled_pose(scan, tmp_path):
    frame = scan / "wave" / "mannequin.0012.trans"
    field = tmp_path / "field.nrrd"
    assert main(["displacement", str(scan / "ct.connect"), str(frame), "--like", str(scan / "ct.nrrd"),
                 "-o", str(field)]) == 0
    image = sitk.ReadImage(str(scan / "ct.nrrd"))
    tx = sitk.DisplacementFieldTransform(sitk.ReadImage(str(field), sitk.sitkVectorFloat64))
    theirs = sitk.GetArrayFromImage(sitk.Resample(image, image, tx, sitk.sitkNearestNeighbor, 0)).transpose(2, 1, 0)
    source = io.read_scan(scan / "ct.nrrd")
    r = reconstruct(connect_to_tskel(io.read_connect(scan / "ct.connect"), io.read_trans(frame)), mode="sampled",
                    source=source.data, source_geometry=source.geometry)
    ours = np.zeros_like(theirs)
    lo = np.maximum(r.origin, 0)
    hi = np.minimum(np.add(r.origin, r.volume.shape), theirs.shape)
    ours[tuple(slice(a, b) for a, b in zip(lo, hi))] = \
        r.volume[tuple(slice(a - o, b - o) for a, b, o in zip(lo, hi, r.origin))]
    a, b = theirs > 0, ours > 0
    dice = 2 * (a & b).sum() / (a.sum() + b.sum())
    equal = (theirs[a | b] == ours[a | b]).mean()
    assert dice >= 0.95 and equal >= 0.95, (dice, equal)
    assert b.sum() > 200_000 and (b & ~(io.read_volume(scan / "ct.nrrd") > 0)).any()  # the arm moved out
