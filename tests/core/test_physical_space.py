"""A scan placed in physical space goes through the whole pipeline and comes out where it was.

The bug this guards: the mannequin written as NRRD with origin (-40, -25, -900) and spacing 0.5
went through skeletonize, connect and connect2identitytskel, then ``reconstruct --source scan.nrrd
--mode sampled`` printed "243790 voxels filled" and wrote a volume whose every voxel was 0 (the
source's origin, in millimetres, was rounded and used as a voxel offset).
"""

from __future__ import annotations

import numpy as np
import pytest

from volanim_core import io, samples, volume
from volanim_core.cli import main
from volanim_core.geometry import Geometry
from volanim_core.reconstruct.engine import reconstruct
from volanim_core.rig.attach import connect_nearest
from volanim_core.rig.bones import BoneSkeleton
from volanim_core.rig.connectivity import Trans
from volanim_core.rig.pose import pose_matrices, root_bones
from volanim_core.rig.tskel_tools import connect_to_tskel
from volanim_core.skeleton.skeletonize import skeletonize


@pytest.fixture(scope="module")
def man():
    return samples.mannequin()


def physical_voxels(vol: np.ndarray, geometry: Geometry) -> dict:
    """Non-zero voxels keyed by their physical centre (rounded to 1e-3 mm)."""
    idx = np.argwhere(vol != 0)
    where = np.round(geometry.to_physical(idx), 3)
    return {tuple(p): v for p, v in zip(where.tolist(), vol[tuple(idx.T)].tolist())}


def scaled_bones(bones: BoneSkeleton, factor) -> BoneSkeleton:
    return BoneSkeleton({n: np.asarray(p) * factor for n, p in bones.joints.items()}, list(bones.bones))


def run(args):
    assert main([str(a) for a in args]) == 0


# spec: docs/formats.md#physical-space
def test_a_scan_with_an_origin_reconstructs_in_place(man, tmp_path, capsys):
    g = Geometry(spacing=(0.5, 0.5, 0.5), origin=(-40, -25, -900))
    scan = tmp_path / "scan.nrrd"
    io.write_volume(scan, man.volume, g)
    io.write_bones(tmp_path / "man.bones", man.bones)
    run(["skeletonize", scan, "-o", tmp_path / "man.mskel"])
    assert io.read_mskel(tmp_path / "man.mskel").geometry == g  # recorded in the file
    run(["connect", tmp_path / "man.mskel", tmp_path / "man.bones", "-o", tmp_path / "man.connect"])
    run(["connect2identitytskel", tmp_path / "man.connect", "-o", tmp_path / "rest.tskel"])
    assert io.read_tskel(tmp_path / "rest.tskel").geometry == g
    run(["reconstruct", tmp_path / "rest.tskel", "--source", scan, "--mode", "sampled", "-o", tmp_path / "rest.nrrd"])
    out = io.read_scan(tmp_path / "rest.nrrd")
    assert out.geometry.spacing == g.spacing
    source = physical_voxels(man.volume, g)
    rest = physical_voxels(out.data, out.geometry)
    assert len(rest) > 0.98 * len(source)  # was 0: every voxel empty
    common = source.keys() & rest.keys()
    assert len(common) == len(rest)  # every filled voxel lies on the scan, in physical space
    assert all(source[p] == rest[p] for p in common)  # with the scan's own value there


def test_an_anisotropic_scan_is_skeletonized_on_cubes_and_keeps_its_shape(man, tmp_path, capsys):
    """0.5 x 0.5 x 1 mm voxels: the skeleton is made on 0.5 mm cubes (the body's true shape), and the
    identity frame, sampled from the anisotropic scan, reproduces it on that grid."""
    thick = man.volume[:, :, ::2]  # every other slice: the same body at 1 mm slices
    g = Geometry(spacing=(0.5, 0.5, 1.0), origin=(10, 20, 30))
    scan = tmp_path / "thick.nii.gz"
    io.write_volume(scan, thick, g)
    io.write_bones(tmp_path / "man.bones", scaled_bones(man.bones, (1, 1, 1)))
    run(["skeletonize", scan, "-o", tmp_path / "thick.mskel"])
    assert "to 0.5 mm cubes" in capsys.readouterr().out
    skel = io.read_mskel(tmp_path / "thick.mskel")
    assert skel.geometry.is_isotropic and np.allclose(skel.geometry.spacing, 0.5)
    run(["connect", tmp_path / "thick.mskel", tmp_path / "man.bones", "-o", tmp_path / "thick.connect"])
    run(["connect2identitytskel", tmp_path / "thick.connect", "-o", tmp_path / "rest.tskel"])
    run(["reconstruct", tmp_path / "rest.tskel", "--source", scan, "--mode", "sampled", "-o", tmp_path / "rest.mha"])
    out = io.read_scan(tmp_path / "rest.mha")
    cubes, cubic = volume.resample(thick, g, 0.5, order=0)  # the scan on the same cubes, nearest
    expected = physical_voxels(cubes, cubic)
    got = physical_voxels(out.data, out.geometry)
    assert abs(len(got) - len(expected)) < 0.03 * len(expected)
    common = expected.keys() & got.keys()
    assert len(common) > 0.97 * len(expected)
    assert np.mean([expected[p] == got[p] for p in common]) > 0.99


def test_an_elbow_bent_on_an_anisotropic_scan_matches_its_isotropic_resampling(man):
    """The issue's proof: a 90-degree elbow bend of the anisotropic scan against the same bend of its
    isotropic resampling, Dice >= 0.95 on the body."""
    thick, g = man.mask[:, :, ::2], Geometry(spacing=(1.0, 1.0, 2.0))
    bones_cubes = man.bones  # the 1 mm cube grid is the original mannequin's own grid
    frames = []
    for mask, geometry in (volume.isotropic_mask(thick, g), (man.mask, Geometry())):
        skel = skeletonize(mask, geometry=geometry)
        conn = connect_nearest(skel, bones_cubes)
        trans = Trans(root_bones(bones_cubes), pose_matrices(bones_cubes, {"L_FOREARM": (0, -90, 0)}))
        r = reconstruct(connect_to_tskel(conn, trans), mode="binary")
        frames.append(set(physical_voxels(r.volume, r.geometry)))
    a, b = frames
    dice = 2 * len(a & b) / (len(a) + len(b))
    assert dice >= 0.95, dice


def test_a_frame_that_misses_its_source_is_refused_not_written_empty(man, tmp_path):
    """A frame placed in one place sampling a source placed elsewhere: a clear refusal."""
    io.write_volume(tmp_path / "scan.nrrd", man.volume, Geometry(spacing=(0.5, 0.5, 0.5), origin=(-40, -25, -900)))
    io.write_volume(tmp_path / "moved.nrrd", man.volume, Geometry(spacing=(0.5, 0.5, 0.5), origin=(400, 0, 0)))
    io.write_bones(tmp_path / "man.bones", man.bones)
    run(["skeletonize", tmp_path / "scan.nrrd", "-o", tmp_path / "man.mskel"])
    run(["connect", tmp_path / "man.mskel", tmp_path / "man.bones", "-o", tmp_path / "man.connect"])
    run(["connect2identitytskel", tmp_path / "man.connect", "-o", tmp_path / "rest.tskel"])
    assert main(["reconstruct", str(tmp_path / "rest.tskel"), "--source", str(tmp_path / "moved.nrrd"),
                 "--mode", "sampled", "-o", str(tmp_path / "x.nrrd")]) == 2
    assert not (tmp_path / "x.nrrd").exists()


def test_old_files_without_geometry_keep_working_on_an_anisotropic_source(man, tmp_path, capsys):
    """A .tskel from before geometry was recorded is on its source's voxel grid, as it always was."""
    thick = man.volume[:, :, ::2]
    io.write_volume(tmp_path / "thick.nrrd", thick, Geometry(spacing=(1, 1, 2)))
    skel = skeletonize(thick > 0)  # index space, no geometry: what the old tools wrote
    conn = connect_nearest(skel, scaled_bones(man.bones, (1, 1, 0.5)))
    still = Trans(conn.bones, np.tile(np.eye(4), (len(conn.bones), 1, 1)))
    io.write_tskel(tmp_path / "old.tskel", connect_to_tskel(conn, still))
    run(["reconstruct", tmp_path / "old.tskel", "--source", tmp_path / "thick.nrrd", "--mode", "sampled",
         "-o", tmp_path / "old.nrrd"])
    assert "records no geometry" in capsys.readouterr().out
    out = io.read_scan(tmp_path / "old.nrrd")
    assert out.geometry.spacing == (1, 1, 2)
    source, got = physical_voxels(thick, Geometry(spacing=(1, 1, 2))), physical_voxels(out.data, out.geometry)
    assert len(got) > 0.95 * len(source)  # an index-space skeleton of flat voxels: the old tools' own loss
    assert got.keys() <= source.keys() and all(source[p] == v for p, v in got.items())


def test_tools_keep_the_geometry(tmp_path, capsys):
    vol = np.zeros((10, 12, 14), np.uint8)
    vol[2:8, 3:9, 4:10] = 200
    g = Geometry((0.7, 0.7, 2.5), (-40, -25, -900), (0, 1, 0, -1, 0, 0, 0, 0, 1))
    src = tmp_path / "ct.nrrd"
    io.write_volume(src, vol, g)
    run(["convert", src, tmp_path / "c.nii.gz"])
    assert np.allclose(io.read_scan(tmp_path / "c.nii.gz").geometry.affine, g.affine, atol=1e-5)
    for tool, extra in (("threshold", ["--range", "100"]), ("reverse", []), ("remap", ["--pairs", "200:1"]),
                        ("fill", ["--cavities"])):
        run([tool, src, tmp_path / f"{tool}.nrrd", *extra])
        assert io.read_scan(tmp_path / f"{tool}.nrrd").geometry == g, tool
    run(["crop", src, tmp_path / "crop.nrrd"])  # to the tight bounds: voxel (2, 3, 4) becomes (0, 0, 0)
    cropped = io.read_scan(tmp_path / "crop.nrrd")
    assert np.allclose(cropped.geometry.origin, g.to_physical([[2, 3, 4]])[0])
    assert physical_voxels(cropped.data, cropped.geometry) == physical_voxels(vol, g)
    run(["flip", src, tmp_path / "flip.nrrd", "--axis", "y"])
    flipped = io.read_scan(tmp_path / "flip.nrrd")
    assert physical_voxels(flipped.data, flipped.geometry) == physical_voxels(vol, g)  # still in place
    run(["fitpow2", src, tmp_path / "pow2.nrrd", "--center"])
    padded = io.read_scan(tmp_path / "pow2.nrrd")
    assert padded.data.shape == (16, 16, 16)
    assert physical_voxels(padded.data, padded.geometry) == physical_voxels(vol, g)
    run(["info", src])
    text = capsys.readouterr().out
    assert "spacing 0.7 x 0.7 x 2.5 mm, origin (-40, -25, -900) mm" in text


def test_resample_keeps_voxels_in_place(tmp_path):
    vol = np.zeros((20, 20, 8), np.uint8)
    vol[5:15, 5:15, 2:6] = 9
    g = Geometry((0.5, 0.5, 2.0), (1, 2, 3))
    io.write_volume(tmp_path / "in.nrrd", vol, g)
    run(["resample", tmp_path / "in.nrrd", tmp_path / "out.nrrd", "--labels"])
    out = io.read_scan(tmp_path / "out.nrrd")
    assert out.geometry.spacing == (0.5, 0.5, 0.5) and out.data.shape == (20, 20, 29)
    assert set(np.unique(out.data)) == {0, 9}
    idx = np.argwhere(out.data)
    centre = out.geometry.to_physical(idx).mean(axis=0)
    assert np.allclose(centre, g.to_physical(np.argwhere(vol)).mean(axis=0), atol=0.3)


def test_palette_apply_keeps_the_geometry(tmp_path):
    rgb = np.zeros((6, 5, 4, 3), np.uint8)
    rgb[1:4, 1:4, 1:3] = (200, 40, 30)
    g = Geometry((0.5, 0.5, 1.5), (10, 20, 30))
    io.write_volume(tmp_path / "c.nrrd", rgb, g)
    run(["palette", "build", tmp_path / "c.nrrd", "-o", tmp_path / "c.palette"])
    run(["palette", "apply", tmp_path / "c.nrrd", tmp_path / "c.palette", "-o", tmp_path / "i.nrrd"])
    assert io.read_scan(tmp_path / "i.nrrd").geometry == g


def test_pyvistas_frog_keeps_its_slices_1_5_mm_apart(tmp_path):
    """`convert frog_tissues.vti frog.nrrd` wrote spacing (1, 1, 1) for the (1, 1, 1.5) scan."""
    from pathlib import Path

    from pyvista import examples

    frog = Path(examples.__file__).parent / "frog_tissues.vti"  # the wheel's copy: offline
    run(["convert", frog, tmp_path / "frog.nrrd"])
    assert io.read_scan(tmp_path / "frog.nrrd").geometry.spacing == (1.0, 1.0, 1.5)


# spec: docs/formats.md#physical-space
def test_bones_drawn_on_another_grid_land_where_they_were_drawn(man, tmp_path):
    """Bones placed on the scan at 1 mm voxels, a skeleton made on 0.5 mm cubes: connect maps the joints
    through millimetres, so the attachments are those of bones drawn on the skeleton's own grid."""
    place = Geometry(spacing=(1, 1, 1), origin=(-40, -25, -900))
    fine = place.with_spacing((0.5, 0.5, 0.5))
    io.write_bones(tmp_path / "coarse.bones", man.bones, place)  # recorded: joints in 1 mm voxels
    assert io.read_bones(tmp_path / "coarse.bones").geometry == place
    io.write_bones(tmp_path / "fine.bones", scaled_bones(man.bones, 2.0), fine)  # the same joints, 0.5 mm voxels
    cubes, _ = volume.resample(man.mask, place, 0.5, order=0)
    skel = skeletonize(cubes, geometry=fine)
    io.write_mskel(tmp_path / "man.mskel", skel)
    for name in ("coarse", "fine"):
        run(["connect", tmp_path / "man.mskel", tmp_path / f"{name}.bones", "-o", tmp_path / f"{name}.connect"])
    a, b = io.read_connect(tmp_path / "coarse.connect"), io.read_connect(tmp_path / "fine.connect")
    assert np.array_equal(a.bone, b.bone) and a.bones == b.bones and a.geometry == fine
