"""``volanim autorig`` as a process: the mannequin's names and an auto-connect posable without breakage;
the ant (a mesh of separate parts nobody here rigged) gets one chain per leg; refusals exit 2."""

from __future__ import annotations

import json

import numpy as np
import pytest

from runnable import volanim
from volanim_core import io
from volanim_core.cli import main
from volanim_core.samples import mannequin_bones


@pytest.fixture
def made(skeletonized_mannequin):
    return skeletonized_mannequin


@pytest.mark.slow
def test_autorig_writes_the_humanoids_bones_and_a_posable_connect(made):
    out = volanim("autorig", made / "m.mskel", "--template", "humanoid", "-o", made / "p.bones",
                  "--connect", made / "p.connect", "--volume", made / "mannequin.VOL")
    assert out.returncode == 0, out.stderr
    assert "18 bones, 19 joints (humanoid)" in out.stdout and "attached 4380 points" in out.stdout
    bones = io.read_bones(made / "p.bones")
    assert [b.name for b in bones.bones] == [b.name for b in mannequin_bones().bones]
    conn = io.read_connect(made / "p.connect")
    assert conn.bones[0].label == "SPINE" and len(conn.points) == 4380
    # the left upper arm and the right thigh bent 60 degrees: volanim report says one piece (exit 0)
    for bone in ("L_UPPERARM", "R_THIGH"):
        posed = volanim("pose", made / "p.bones", "--rotate", f"{bone}=0,60,0", "-o", made / f"{bone}.trans")
        assert posed.returncode == 0, posed.stderr
        rep = volanim("report", made / "p.connect", made / f"{bone}.trans", "--bones", made / "p.bones", "--json")
        assert rep.returncode == 0, rep.stdout + rep.stderr
        assert json.loads(rep.stdout)["pieces"] == []  # no piece torn off (a lump may hang: #60's open work)


def test_template_none_with_a_bone_count(made):
    out = volanim("autorig", made / "m.mskel", "--template", "none", "--bones", "12", "-o", made / "c.bones")
    assert out.returncode == 0, out.stderr
    bones = io.read_bones(made / "c.bones")
    assert len(bones.bones) == 12 and "ROOT" in bones.joints


def test_refusals_exit_2_and_write_nothing(made):
    out = volanim("autorig", made / "m.mskel", "--thinness", "5", "-o", made / "none.bones")
    assert out.returncode == 2 and "no points at this thinness" in out.stderr
    out = volanim("autorig", made / "m.mskel", "--template", "humanoid", "--bones", "4", "-o", made / "x.bones")
    assert out.returncode == 2 and "--template none" in out.stderr
    assert not (made / "none.bones").exists() and not (made / "x.bones").exists()


def test_the_ant_gets_one_chain_per_leg(tmp_path):
    """pyvista's ant: legs are separate parts of the mesh, so its voxels are in 13 pieces; autorig bridges
    the gaps and proposes each leg as one chain from the thorax, ending at the leg's tip."""
    assert main(["samples", "ant", "-o", str(tmp_path)]) == 0
    assert main(["voxelize", str(tmp_path / "ant.ply"), str(tmp_path / "ant.nrrd"), "--size", "160"]) == 0
    assert main(["skeletonize", str(tmp_path / "ant.nrrd"), "--min-thinness", "0",
                 "-o", str(tmp_path / "a.mskel")]) == 0
    assert main(["markups", str(tmp_path / "ant.mrk.json"), "--like", str(tmp_path / "ant.nrrd"),
                 "-o", str(tmp_path / "hand.bones")]) == 0
    out = volanim("autorig", tmp_path / "a.mskel", "-o", tmp_path / "auto.bones")
    assert out.returncode == 0, out.stderr
    auto = io.read_bones(tmp_path / "auto.bones")
    hand = io.read_bones(tmp_path / "hand.bones").on_grid(auto.geometry)
    children = {}
    for b in auto.bones:
        children.setdefault(b.proximal, []).append(b.distal)
    tips = [j for j in auto.joints if j not in children]
    # each hand-placed foot (L_FOOT1 ... R_FOOT3, where a leg's chain ends) has a proposed chain end near it,
    # and no two feet share one: one chain per leg
    leg_tips = [j for j in hand.joints if "FOOT" in j]
    assert len(leg_tips) == 6, leg_tips
    tip_pos = np.array([auto.joints[t] for t in tips])
    nearest = [int(np.argmin(np.linalg.norm(tip_pos - hand.joints[t], axis=1))) for t in leg_tips]
    assert len(set(nearest)) == 6
    # the proposal ends a chain at the surface, the markups at the cross-section's centre: within 10 voxels
    assert all(np.linalg.norm(tip_pos[n] - hand.joints[t]) < 10 for n, t in zip(nearest, leg_tips))


@pytest.fixture(scope="module")
def ant(tmp_path_factory):
    """pyvista's ant voxelized and skeletonized as the README does (default thinness)."""
    folder = tmp_path_factory.mktemp("ant")
    assert main(["samples", "ant", "-o", str(folder)]) == 0
    assert main(["voxelize", str(folder / "ant.ply"), str(folder / "ant.nrrd"), "--size", "160"]) == 0
    assert main(["skeletonize", str(folder / "ant.nrrd"), "-o", str(folder / "ant.mskel")]) == 0
    return folder


def _leaves(bones) -> list[str]:
    return [bones.bones[i].label for i in bones.leaves()]


# full tier only, so that make test stays under 10 minutes: 18 poses of a real model through the commands a user
# runs, each judged with both joints
@pytest.mark.slow
def test_every_leaf_bone_of_the_ant_poses_healthy(ant, capsys):
    """#62: the ant's proposal connected by autorig itself, each leaf bone turned 45 and 90 degrees: `volanim
    report` exits 0 for every one. Its legs are separate shells; the path method (the old default) left a
    tenth of the points unattached and gave a shell's first points to the bone of the shell next to it, and
    6 of the 9 leaf poses tore a piece off. Now each piece's points go to the bones lying in that piece.
    With smooth joints the abdomen's tip bent 90 degrees tore a one-voxel speck off the waist: it took the
    weights of a thorax sphere it lay deepest in by power distance but did not touch; now the sphere whose
    surface is nearest."""
    assert main(["autorig", str(ant / "ant.mskel"), "-o", str(ant / "owned.bones"),
                 "--connect", str(ant / "owned.connect")]) == 0
    said, warned = capsys.readouterr()
    # the ownership beside it, as volanim connect writes it (the owned default), and no flesh out of reach
    assert (ant / "owned.owners.nrrd").exists() and "ownership of" in said and "warning" not in warned, warned
    # the spheres' rigid and smooth joints are what this test judges: no ownership beside the .connect
    assert main(["autorig", str(ant / "ant.mskel"), "-o", str(ant / "auto.bones"),
                 "--connect", str(ant / "auto.connect"), "--no-ownership"]) == 0
    said = capsys.readouterr().out
    assert not (ant / "auto.owners.nrrd").exists() and "ownership of" not in said
    bones = io.read_bones(ant / "auto.bones")
    assert len(io.read_connect(ant / "auto.connect").points) == len(io.read_skeleton(ant / "ant.mskel").points)
    leaves = _leaves(bones)
    assert len(leaves) >= 6  # a chain a leg at least
    broken = []
    for leaf in leaves:
        for angle in (45, 90):
            trans = ant / f"{leaf}.{angle}.trans"
            assert main(["pose", str(ant / "auto.bones"), "--rotate", f"{leaf}=0,{angle},0", "-o", str(trans)]) == 0
            capsys.readouterr()
            for joints in ("rigid", "smooth"):
                if main(["report", str(ant / "auto.connect"), str(trans), "--bones", str(ant / "auto.bones"),
                         "--joints", joints]) != 0:
                    broken.append(f"{leaf} {angle} {joints}: {capsys.readouterr().out.splitlines()[0]}")
    assert broken == []
    assert "(pieces)" in said


@pytest.mark.slow
def test_autorig_connect_hangs_the_frogs_stray_flesh_on_and_its_leaf_bends_whole(tmp_path, capsys):
    """#86: `volanim autorig --connect` gives the rig the ownership `volanim connect` gives it (without it
    every frame re-grew the thesis's spheres, whatever the tutorial's table said). The frog's proposed
    R_POST_3 owns 27,000 voxels that touch the body only through another limb's flesh: bent 45 degrees they
    tore off. By default they now go to the flesh they hang from, said by bone, and the bent leaf stays
    whole; --no-hang-on keeps them, warns by bone (tests/core/rig/test_reach.py), and the leaf tears."""
    from volanim_core import samples
    from volanim_core.skeleton.skeletonize import skeletonize

    s = samples.load("frog")
    io.write_skeleton(tmp_path / "frog.mskel", skeletonize(s.mask))
    io.write_volume(tmp_path / "frog.nrrd", s.mask.astype(np.uint8))
    verdicts = {}
    for flag in ("--hang-on", "--no-hang-on"):
        name = tmp_path / flag.strip("-")
        assert main(["autorig", str(tmp_path / "frog.mskel"), "-o", f"{name}.bones", "--connect",
                     f"{name}.connect", "--volume", str(tmp_path / "frog.nrrd"), flag]) == 0
        said, warned = capsys.readouterr()
        assert "ownership of" in said and "the scan's object" in said
        conn = io.read_connect(f"{name}.connect")
        assert conn.ownership is not None and int(conn.ownership.mask.sum()) == int(s.mask.sum())
        lines = [line for line in warned.splitlines() if line.startswith("warning: ")]
        hung = [line.split(":")[0].strip() for line in said.splitlines() if "the flesh they hang from" in line]
        if flag == "--hang-on":
            assert lines == [] and hung == ["R_POST_3"], (said, warned)
        else:
            assert [line.split(":")[1].strip() for line in lines[:-1]] == ["R_POST_3"], warned
            assert "--hang-on" in lines[-1] and hung == []
        assert main(["pose", f"{name}.bones", "--rotate", "R_POST_3=0,45,0", "-o", f"{name}.trans"]) == 0
        verdicts[flag] = main(["report", f"{name}.connect", f"{name}.trans", "--bones", f"{name}.bones"])
        capsys.readouterr()
    assert verdicts == {"--hang-on": 0, "--no-hang-on": 1}
    # and every leaf of the rig as `autorig --connect` writes it bends 45 and 90 degrees whole: the snout's tip
    # took the lower jaw, which only its parent's yielding end held, and tore the head at 90 (#86)
    from leaf_bends import broken_bends

    bones, conn = io.read_bones(tmp_path / "hang-on.bones"), io.read_connect(tmp_path / "hang-on.connect")
    assert len(bones.leaves()) == 6 and broken_bends(conn, bones) == []

