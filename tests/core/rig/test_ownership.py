"""The rest body's owners (rig/ownership.py, rig/specks.py): no bone keeps a speck inside another bone's flesh."""

from __future__ import annotations

import cc3d
import numpy as np
import pytest
from scipy import ndimage

from volanim_core import samples
from volanim_core.cli import main
from volanim_core.io import read_connect
from volanim_core.rig.specks import join_specks


def specks(labels: np.ndarray) -> list[tuple[int, int]]:
    """(label, voxels) of every piece of a label's voxels, other than its largest, that touches another label:
    flesh that stays with its bone, alone, when the bone around it moves. Measured on its own (cc3d's pieces,
    scipy's rings), not with join_specks' bookkeeping."""
    pieces = cc3d.connected_components(labels, connectivity=26)
    stats = cc3d.statistics(pieces)
    sizes = np.asarray(stats["voxel_counts"])
    label_of = np.zeros(len(sizes), np.int64)
    label_of[pieces.ravel()] = labels.ravel()
    out = []
    for label in np.unique(labels[labels > 0]):
        mine_pieces = np.flatnonzero(label_of == label)
        mine_pieces = mine_pieces[mine_pieces > 0]
        for piece in mine_pieces[mine_pieces != mine_pieces[sizes[mine_pieces].argmax()]]:
            box = tuple(slice(max(0, b.start - 1), b.stop + 1) for b in stats["bounding_boxes"][piece])
            mine = pieces[box] == piece
            ring = ndimage.binary_dilation(mine, np.ones((3, 3, 3), bool)) & ~mine
            around = labels[box][ring]
            if ((around != 0) & (around != label)).any():
                out.append((int(label), int(sizes[piece])))
    return out


def test_two_specks_side_by_side_do_not_trade_labels_into_a_new_speck():
    """A speck of bone 2 whose neighbours are mostly a speck of bone 1 (inside bone 3's flesh): one pass that
    reads the neighbours as they were gave the first bone 1's label and bone 1's speck bone 3's, leaving a
    new speck of bone 1 (how the ant's abdomen kept two voxels in a leg, torn off when the leg stepped)."""
    lab = np.full((12, 12, 20), 3, np.uint8, order="F")
    lab[:, :, 14:] = 1  # bone 1's flesh
    lab[0:6, 0:6, 18:] = 2  # bone 2's
    for x, y, z in np.ndindex(3, 3, 3):
        if (z, y, x) > (1, 1, 1):  # after the middle voxel in the grid's order: bone 1's speck
            lab[4 + x, 4 + y, 4 + z] = 1
    lab[5, 5, 5] = 2  # bone 2's speck, met first
    assert specks(lab)
    assert join_specks(lab, 3) == 14
    assert specks(lab) == []
    assert (lab[3:8, 3:8, 3:8] == 3).all()  # both specks went to the flesh around them


@pytest.mark.parametrize("name", ["mannequin", "frog"])
def test_no_bone_keeps_a_speck_in_another_s_flesh(name):
    from volanim_core.rig.attach import connect
    from volanim_core.rig.ownership import ownership
    from volanim_core.skeleton.skeletonize import skeletonize

    s = samples.load(name)
    conn = connect(skeletonize(s.mask, **({} if name == "frog" else {"min_thinness": 0.5})), s.bones)[0]
    assert specks(ownership(s.mask, conn).labels) == []


def test_the_ant_rigged_from_slicer_markups_keeps_no_speck_and_steps_whole(tmp_path, capsys):
    """The slicer tutorial's ant (legs in separate pieces, 4 voxels thick): its abdomen kept two voxels of a
    leg, which stayed behind when the leg stepped (frame 12 of its walk: `volanim report` said BROKEN)."""
    a = str(tmp_path)
    for argv in (["samples", "ant", "-o", a], ["voxelize", f"{a}/ant.ply", f"{a}/ant.nrrd", "--size", "160"],
                 ["markups", f"{a}/ant.mrk.json", "--like", f"{a}/ant.nrrd", "-o", f"{a}/ant.bones"],
                 ["skeletonize", f"{a}/ant.nrrd", "--min-thinness", "0", "-o", f"{a}/ant.mskel"],
                 ["connect", f"{a}/ant.mskel", f"{a}/ant.bones", "-o", f"{a}/nearest.connect"],
                 ["keys", f"{a}/ant.keys", "--bones", f"{a}/ant.bones", "-o", f"{a}/walk/"]):
        assert main(argv) == 0, argv
    assert specks(read_connect(f"{a}/nearest.connect").ownership.labels) == []
    capsys.readouterr()
    assert main(["report", f"{a}/nearest.connect", f"{a}/walk/ant.0012.trans", "--bones", f"{a}/ant.bones"]) == 0, \
        capsys.readouterr().out


def test_each_bone_s_hull_points_are_its_voxels_and_hold_every_vertex_of_scipy_s_hull_of_all_of_them():
    """Ownership.hulls keeps only the corners of each z slice's and y plane's outline (rig/_hull_kernels): owned
    voxels, among them every vertex qhull finds over every voxel of the bone, so the hull is the same."""
    from scipy.spatial import ConvexHull

    from volanim_core.rig.attach import connect
    from volanim_core.rig.ownership import ownership
    from volanim_core.skeleton.skeletonize import skeletonize

    s = samples.mannequin()
    own = ownership(s.mask, connect(skeletonize(s.mask, min_thinness=0.5), s.bones)[0])
    hulls = own.hulls()
    assert len(hulls) == len(own.bones)
    assert sum(map(len, hulls)) < own.counts().sum() / 50  # a few of them: what every posed box is read from
    for b, hull in enumerate(hulls):
        voxels = np.argwhere(own.labels == b + 1) + np.asarray(own.origin)
        got = {tuple(p) for p in hull.astype(np.int64)}
        assert {tuple(p) for p in voxels[ConvexHull(voxels).vertices]} <= got, own.bones[b]
        assert got <= {tuple(p) for p in voxels}, own.bones[b]


def test_a_posed_bone_s_box_is_the_box_of_all_its_voxels_moved():
    """posed_boxes reads only the hull points: the box of every owned voxel moved, two voxels wider, exactly."""
    from scipy.spatial.transform import Rotation

    from volanim_core.reconstruct.owned import posed_boxes
    from volanim_core.rig.attach import connect
    from volanim_core.rig.ownership import ownership
    from volanim_core.skeleton.skeletonize import skeletonize

    s = samples.mannequin()
    own = ownership(s.mask, connect(skeletonize(s.mask, min_thinness=0.5), s.bones)[0])
    rng = np.random.default_rng(84)
    matrices = np.zeros((len(own.bones), 4, 4))
    matrices[:, :3, :3] = Rotation.random(len(own.bones), random_state=rng).as_matrix()
    matrices[:, 3, :3] = rng.uniform(-20, 20, (len(own.bones), 3))
    matrices[:, 3, 3] = 1
    boxes = posed_boxes(own, matrices)
    for b in range(len(own.bones)):
        moved = (np.argwhere(own.labels == b + 1) + np.asarray(own.origin)) @ matrices[b, :3, :3] + matrices[b, 3, :3]
        want = np.concatenate([np.floor(moved.min(0)) - 2, np.ceil(moved.max(0)) + 2])
        assert (boxes[b] == want).all(), (own.bones[b], boxes[b], want)


def test_a_bone_measured_only_in_its_tube_s_box_gives_the_owners_measuring_every_bone_everywhere_gives():
    """tube_boxes: each kernel measures a bone only in the box its tube can hold a voxel in (mannequin-large: 1.7
    bones a voxel, not 3.7). A tube holds nothing outside its box, so the owners and the cross-sections' moments
    are those of measuring every bone at every voxel, exactly."""
    from volanim_core.rig._ownership_kernels import own_by_tubes, section_moments
    from volanim_core.rig.attach import connect
    from volanim_core.rig.ownership import _yields, ownership, tube_boxes, tube_radii, tube_reaches, tube_rows
    from volanim_core.skeleton.skeletonize import skeletonize

    s = samples.mannequin()
    conn = connect(skeletonize(s.mask, min_thinness=0.5), s.bones)[0]
    own = ownership(s.mask, conn)
    lo = np.asarray(own.origin)
    box = np.asfortranarray(s.mask[tuple(slice(a, a + n) for a, n in zip(lo, own.labels.shape))] != 0)
    a = np.array([b.proximal for b in conn.bones], np.float64)
    ab = np.array([b.distal - b.proximal for b in conn.bones], np.float64)
    round_tubes = tube_rows(a, ab, tube_radii(conn, box, lo), [None] * len(a))
    everywhere = np.tile(np.array([-1, 10**6] * 3, np.int64), (len(a), 1))
    for tubes in (round_tubes, own.tubes):
        boxes = tube_boxes(tubes, lo)
        assert (boxes[:, 1::2] - boxes[:, ::2] < np.array(box.shape)).any()  # the boxes do leave voxels out
        moments = [np.zeros((len(a), 10)) for _ in range(2)]
        for reach, sums, threads in zip((boxes, everywhere), moments, (2, 1)):  # nor do the threads matter
            radius = tube_reaches(tubes) if reach is boxes else np.full(len(a), np.inf)
            section_moments(box, lo.astype(np.float64), tubes, reach, radius, 1, sums, threads)
        assert np.array_equal(*moments)
    labels = [np.zeros(box.shape, np.uint8, order="F") for _ in range(2)]
    for reach, radius, out, threads in zip((tube_boxes(own.tubes, lo), everywhere),
                                           (tube_reaches(own.tubes), np.full(len(a), np.inf)), labels, (2, 1)):
        own_by_tubes(box, lo.astype(np.float64), own.tubes, _yields(conn.bones), reach, radius, out, threads)
    assert np.array_equal(*labels) and (labels[0] > 0).sum() == box.sum()


@pytest.mark.parametrize("name", ["mannequin", "frog"])
def test_each_bone_s_thin_voxels_are_numpy_s_in_the_labels_order(name):
    """Ownership.thin (flagged_voxels, slices in parallel): bone by bone, every voxel of the bone whose flags have
    THIN, in z, y, x order, as numpy finds them."""
    from volanim_core.rig.attach import connect
    from volanim_core.rig.ownership import THIN, ownership
    from volanim_core.skeleton.skeletonize import skeletonize

    s = samples.load(name)
    own = ownership(s.mask, connect(skeletonize(s.mask, **({} if name == "frog" else {"min_thinness": 0.5})),
                                    s.bones)[0])
    starts, voxels = own.thin()
    thin = (own.flags() & THIN) != 0
    assert starts[0] == 0 and starts[-1] == thin.sum() > 0
    for b in range(len(own.bones)):
        want = np.argwhere(((own.labels == b + 1) & thin).T)[:, ::-1]  # [z, y, x] order, as (x, y, z)
        assert np.array_equal(voxels[starts[b]:starts[b + 1]], want), own.bones[b].label


def test_flesh_a_round_end_that_yields_holds_stays_with_it_not_with_a_thin_tube_far_away():
    """#86: the frog's snout-tip leaf (a tube one voxel wide) took the lower jaw, 47 voxels from it, because the
    jaw lay only in its parent's round end past the joint, which yields: no tube held it, and the nearest
    surface won. Its 90-degree turn tore the head. A yielding end that holds a voxel now comes before any tube
    FAR (30) of its sizes away, and after the ones nearer."""
    from volanim_core.rig._ownership_kernels import FAR, own_by_tubes, tube_distance
    from volanim_core.rig.connectivity import BoneSegment
    from volanim_core.rig.ownership import _yields, tube_boxes, tube_reaches, tube_rows

    # a head along x (radius 10) whose end yields to the snout going on up from it (radius 0.5), then its tip
    bones = [BoneSegment(np.array([0.0, 0, 0]), np.array([40.0, 0, 0]), "HEAD"),
             BoneSegment(np.array([40.0, 0, 0]), np.array([40.0, 10, 0]), "SNOUT"),
             BoneSegment(np.array([40.0, 10, 0]), np.array([44.0, 10, 0]), "TIP")]
    assert _yields(bones).tolist() == [[False, True], [True, True], [True, False]]
    a = np.array([b.proximal for b in bones])
    tubes = tube_rows(a, np.array([b.distal for b in bones]) - a, np.array([[10.0, 10], [0.5, 0.5], [0.5, 0.5]]),
                      [None] * 3)
    lo = np.array([-12.0, -12, -2])
    jaw, by_tip = np.array([45.0, -6, 0]), np.array([46.0, 10, 0])
    assert tube_distance(tubes[0], *jaw) < 1 and tube_distance(tubes[2], *jaw) > FAR  # only the head's end holds it
    assert tube_distance(tubes[0], *by_tip) > 1 and 1 < tube_distance(tubes[2], *by_tip) < FAR  # none holds it
    mask = np.zeros((70, 30, 5), bool, order="F")
    for p in (jaw, by_tip):
        mask[tuple((p - lo).astype(int))] = True
    out = np.zeros(mask.shape, np.uint8, order="F")
    own_by_tubes(mask, lo, tubes, _yields(bones), tube_boxes(tubes, lo), tube_reaches(tubes), out, 1)
    assert out[tuple((jaw - lo).astype(int))] == 1  # the head's yielding end, not the tip 32 of its sizes away
    assert out[tuple((by_tip - lo).astype(int))] == 3  # held by none: the nearest surface, the tip's


@pytest.mark.parametrize("ab", [(9.0, 4.0, -3.0), (12.0, 0.0, 0.0), (0.0, 0.0, 7.0), (0.0, 5.0, 5.0), (0.0, 0.0, 0.0)])
def test_a_rows_stretch_holds_every_voxel_within_a_tubes_reach_of_its_segment_and_a_voxel_more_at_most(ab):
    """_row_stretch (own_by_tubes and section_moments measure a tube only there): every voxel of the row within
    the reach of the segment (numpy's distance to it) lies in the stretch, which is at most one voxel wider each
    way; the segment along a row (ab along x), across it, and a point (no length)."""
    from volanim_core.rig._ownership_kernels import TUBE_COLUMNS, _row_stretch

    tube = np.zeros(TUBE_COLUMNS)
    tube[:3], tube[3:6] = (20.3, 18.7, 21.1), ab
    a, ab, r, lox = tube[:3], np.asarray(ab), 6.5, -3.0
    x = np.arange(60) + lox
    rows = 0
    for py in np.arange(5.0, 35.0):
        for pz in np.arange(5.0, 35.0):
            p = np.stack([x, np.full_like(x, py), np.full_like(x, pz)], axis=1)
            t = np.clip((p - a) @ ab / (ab @ ab), 0, 1) if ab @ ab > 0 else np.zeros(len(x))
            inside = np.flatnonzero(np.linalg.norm(p - a - t[:, None] * ab, axis=1) <= r)
            x0, x1 = _row_stretch(tube, r, py, pz, lox)
            if len(inside):
                rows += 1
                assert x0 <= inside[0] and inside[-1] <= x1, (py, pz)
                assert inside[0] - x0 <= 2 and x1 - inside[-1] <= 2, (py, pz)  # a voxel, and the rounding
            else:  # no whole voxel within: a stretch under one voxel long, a voxel more each way, at most
                assert x1 - x0 <= 3, (py, pz)
    assert rows > 50



@pytest.mark.parametrize("ab", [(9.0, 4.0, -3.0), (12.0, 0, 0), (0, 0, 7.0), (1e-14, 5.0, 5.0), (-4.0, 2.0, 0)])
def test_a_rows_middles_hold_every_voxel_in_some_tube_s_middle_merged_in_order(ab):
    """_middles (section_moments reads only there): every voxel of the row at which some tube's t -- as the kernel
    computes it -- lies in 0.3..0.7 is in one of the stretches; they are in order, apart, on the row, and at most
    a voxel and the rounding wider than the voxels they hold; a tube along the row, across it, and all but across."""
    from volanim_core.rig._ownership_kernels import TUBE_COLUMNS, _middles

    tubes = np.zeros((3, TUBE_COLUMNS))
    tubes[:, :3] = (20.3, 18.7, 21.1), (30.0, 25.0, 10.0), (12.0, 9.5, 30.0)
    tubes[:, 3:6] = ab, (3.0, -2.0, 8.0), (0.0, 6.0, 0.0)
    tubes[:, 6] = 1 / (tubes[:, 3:6] ** 2).sum(1)
    lo, nx = np.array([-3.0, 0.0, 0.0]), 60
    ia, ib = np.empty(3, np.int64), np.empty(3, np.int64)
    x = np.arange(nx) + lo[0]
    rows = 0
    for py in np.arange(0.0, 40.0):
        for pz in np.arange(0.0, 40.0):
            t = (((x[:, None] - tubes[:, 0]) * tubes[:, 3] + (py - tubes[:, 1]) * tubes[:, 4]
                  + (pz - tubes[:, 2]) * tubes[:, 5]) * tubes[:, 6])
            want = np.flatnonzero(((t > 0.3) & (t < 0.7)).any(1))
            n = _middles(tubes, lo, py, pz, nx, ia, ib)
            got = np.zeros(nx, bool)
            for j in range(n):
                assert 0 <= ia[j] <= ib[j] < nx and (j == 0 or ia[j] > ib[j - 1] + 1), (py, pz, ia[:n], ib[:n])
                got[ia[j]:ib[j] + 1] = True
                held = want[(want >= ia[j]) & (want <= ib[j])]
                assert not len(held) or (held[0] - ia[j] <= 3 and ib[j] - held[-1] <= 3), (py, pz)
            assert got[want].all(), (py, pz)
            rows += len(want) > 0
    assert rows > 100
