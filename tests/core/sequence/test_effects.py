"""Effects after a clip: melt and teleport shrink the spheres, crumble drops the voxels into a heap.

``fall`` is checked against what falling means (every voxel and value kept, a shift
before anything lands, a settled 45-degree heap on the floor at the end); the
effects run through the real sequence machinery on 2 workers.
"""

from __future__ import annotations

import numpy as np
import pytest

from paths import ASSETS, WALK  # WALK: the real clip, bundled with its MIT licence
from volanim_core import io
from volanim_core.cli import main
from volanim_core.parallel import RunOn
from volanim_core.reconstruct.engine import posed_centres, reconstruct
from volanim_core.samples import mannequin_bones
from volanim_core.sequence import store
from volanim_core.sequence.checked import read_store
from volanim_core.sequence.effects import crumble, fall, melt, parse_axis, teleport
from volanim_core.sequence.frames import frames_from_files
from volanim_core.sequence.run import SequenceSettings, run_sequence, shared_bounds

CONNECT = ASSETS / "mannequin.0.50.connect"


@pytest.fixture(scope="module")
def conn():
    return io.read_connect(CONNECT)


def random_body(seed=1, shape=(9, 8, 30), density=0.3) -> np.ndarray:
    """Random voxels in the lower two thirds of the grid (room above for the heap), the lowest at z=3."""
    rng = np.random.default_rng(seed)
    vol = np.where(rng.random(shape) < density, rng.integers(1, 250, shape), 0).astype(np.uint8)
    vol[:, :, :3] = 0
    vol[:, :, shape[2] * 2 // 3:] = 0
    vol[2, 3, 3] = 7  # the lowest voxel: the floor
    return vol


def test_fall_keeps_every_voxel_and_value_and_ends_in_a_settled_heap_on_the_floor():
    for seed in range(12):
        vol = random_body(seed, density=0.2 + 0.05 * seed)
        assert np.array_equal(fall(vol, 0.0), vol)
        for fraction in np.linspace(0.1, 1.0, 10):
            out = fall(vol, fraction)
            assert out.dtype == vol.dtype and out.shape == vol.shape
            assert np.array_equal(np.sort(out[out != 0]), np.sort(vol[vol != 0])), (seed, fraction)
        heap = fall(vol, 1.0)
        height = np.count_nonzero(heap, axis=2)
        for x, y in np.ndindex(*height.shape):  # every column a solid stack standing on the floor
            assert np.all(heap[x, y, 3:3 + height[x, y]] != 0) and not heap[x, y, 3 + height[x, y]:].any()
        # settled: no slope steeper than 45 degrees between neighbouring columns
        assert np.abs(np.diff(height, axis=0)).max() <= 1 and np.abs(np.diff(height, axis=1)).max() <= 1
        assert height.max() <= np.count_nonzero(vol, axis=2).max()


def test_a_heap_that_cannot_fit_is_refused_not_cut():
    vol = np.zeros((3, 3, 12), np.uint8)
    vol[:, :, 1:11] = 5  # a 3x3 grid filled to its top: sand slumping into one hole lifts the rest
    vol[1, 1, 11] = 5
    vol[0, 0, 5] = 0
    with pytest.raises(ValueError, match="heap does not fit.*--padding"):
        fall(vol, 0.05)


def test_fall_before_anything_lands_is_a_shift_and_any_axis_can_be_down():
    vol = np.zeros((4, 5, 40), np.uint16)
    vol[1:3, 1:4, 20:30] = np.arange(1, 61, dtype=np.uint16).reshape(2, 3, 10)
    vol[0, 0, 2] = 9  # the floor, far below
    out = fall(vol, 0.5)  # 27 * 0.25 -> 6 voxels down
    assert np.array_equal(out[1:3, 1:4, 14:24], vol[1:3, 1:4, 20:30]) and out[0, 0, 2] == 9
    up_is_y = np.ascontiguousarray(np.flip(vol.transpose(0, 2, 1), axis=1))  # z -> -y
    assert np.array_equal(fall(up_is_y, 0.7, "+y"), np.flip(fall(vol, 0.7).transpose(0, 2, 1), axis=1))
    assert not fall(np.zeros((3, 3, 3), np.uint8), 1.0).any()
    with pytest.raises(ValueError, match="between 0 and 1"):
        fall(vol, 1.5)
    for bad in ("w", "--z", "", "zz"):
        with pytest.raises(ValueError, match="x, y or z"):
            parse_axis(bad)


def test_teleport_vanishes_from_the_head_down_and_ends_empty(conn):
    walk = frames_from_files(conn, [WALK], bones=mannequin_bones(), frames=slice(0, 1))
    frames = teleport(conn, walk, 8)
    assert [f.number for f in frames] == list(range(1, 9))
    height = posed_centres(walk[0].tskel(conn))[:, 2]
    high, low = height > np.percentile(height, 80), height < np.percentile(height, 20)
    mid = frames[3].dt_scale
    assert mid[high].mean() < 0.2 and mid[low].mean() > 0.8  # the beam is half-way down
    assert frames[0].dt_scale.min() < 1 and frames[-1].dt_scale.max() == 0
    scales = np.array([f.dt_scale for f in frames])
    assert np.all(np.diff(scales, axis=0) <= 0)  # nothing grows back
    assert np.array_equal(teleport(conn, walk, 8)[3].dt_scale, mid)  # reproducible


def test_a_walk_then_a_crumble_runs_on_two_workers_and_keeps_every_voxel(tmp_path, conn):
    walk = frames_from_files(conn, [WALK], bones=mannequin_bones(), frames=slice(0, 60, 30))
    frames = walk + crumble(walk, 3)
    rep = run_sequence(conn, frames, tmp_path / "c.zarr", SequenceSettings(mode="mottled"), on=RunOn(workers=2))
    last = rep.records[1]["filled"]
    assert [r["filled"] for r in rep.records[2:]] == [last] * 3  # falling loses nothing
    standing = read_store(tmp_path / "c.zarr").read_frame(1)
    for i in (2, 3, 4):
        assert np.array_equal(read_store(tmp_path / "c.zarr").read_frame(i), fall(standing, (i - 1) / 3)), i
    alone = reconstruct(walk[-1].tskel(conn), mode="mottled")
    assert np.count_nonzero(alone.volume) == last
    heap = read_store(tmp_path / "c.zarr").read_frame(4)
    z = np.nonzero(standing)[2]
    assert np.ptp(np.nonzero(heap)[2]) < np.ptp(z) / 3  # a heap, not a body
    assert np.nonzero(heap)[2].min() == z.min()  # on the floor the body stood on
    assert rep.bounds.shape[1] > shared_bounds(conn, walk).shape[1]  # the grid made room for the heap ...
    for axis in (0, 1):  # ... so it never leans on the grid's sides
        at = np.nonzero(heap)[axis]
        assert at.min() > 0 and at.max() < heap.shape[axis] - 1


def test_cli_effects_and_the_down_option(tmp_path, capsys):
    base = ["sequence", str(CONNECT), str(WALK), "--bones", str(ASSETS / "mannequin.bones"), "--frames", "0:1",
            "--mode", "bone", "--workers", "1"]
    assert main([*base, "--teleport", "2", "-o", str(tmp_path / "t.zarr")]) == 0
    assert "3 made" in capsys.readouterr().out
    assert not read_store(tmp_path / "t.zarr").read_frame(2).any()  # gone
    assert main([*base, "--crumble", "2", "--down", "-z", "-o", str(tmp_path / "c.zarr")]) == 0  # a dash value
    assert len(store.finished(tmp_path / "c.zarr")) == 3
    assert [f.number for f in melt(frames_from_files(io.read_connect(CONNECT), [WALK], bones=mannequin_bones(),
                                                     frames=slice(0, 1)), 2)] == [1, 2]
    with pytest.raises(ValueError, match="follows a pose"):
        crumble([], 3)


def test_dash_values_are_joined_only_where_an_option_takes_them():
    from volanim_core.cli._common import join_dash_values

    assert join_dash_values(["x", "--down", "-z", "--min-thinness", "-inf", "--up", "-Y", "-o", "f"]) == \
        ["x", "--down=-z", "--min-thinness=-inf", "--up=-Y", "-o", "f"]
    assert join_dash_values(["--force", "-x", "--down=-y"]) == ["--force", "-x", "--down=-y"]  # -x: not an axis here


def test_a_summed_heap_holds_what_rests_on_each_voxel_capped():
    for seed in range(6):
        vol = random_body(seed, density=0.4)
        keep, summed = fall(vol, 1.0), fall(vol, 1.0, heap="sum")
        assert np.array_equal(keep != 0, summed != 0)  # the same grains in the same places
        for x, y in np.ndindex(*keep.shape[:2]):  # the oracle: a column summed from its top down, by hand
            total = 0
            for z in range(keep.shape[2] - 1, -1, -1):
                total += int(keep[x, y, z])
                assert summed[x, y, z] == (min(total, 255) if keep[x, y, z] else 0), (seed, x, y, z)
    assert (fall(random_body(1, density=0.9), 1.0, heap="sum") == 255).any()  # deep heaps reach the cap
    with pytest.raises(ValueError, match="keep, sum"):
        fall(random_body(), 1.0, heap="add")


def test_an_acceleration_sets_how_far_each_frame_falls(conn):
    walk = frames_from_files(conn, [WALK], bones=mannequin_bones(), frames=slice(0, 1))
    frames = crumble(walk, 4, acceleration=3.0, conn=conn)
    assert [f.drop for f in frames] == [1.5, 6.0, 13.5, 24.0]  # a k^2 / 2
    vol = np.zeros((4, 5, 60), np.uint8)
    vol[1:3, 1:4, 30:40] = 9
    vol[0, 0, 5] = 1  # the floor
    assert np.array_equal(fall(vol, 0.25, drop=6.0)[1:3, 1:4, 24:34], vol[1:3, 1:4, 30:40])  # 6 down, in the air
    with pytest.raises(ValueError, match="per frame squared"):
        crumble(walk, 4, acceleration=-1.0, conn=conn)


def test_melt_and_crumble_at_once_shrink_the_falling_body_onto_the_standing_floor(tmp_path, conn):
    walk = frames_from_files(conn, [WALK], bones=mannequin_bones(), frames=slice(0, 1))
    frames = walk + crumble(walk, 3, melt=4, conn=conn)
    assert len(frames) == 5 and [f.dt_scale for f in frames[1:]] == [0.75, 0.5, 0.25, 0.0]
    rep = run_sequence(conn, frames, tmp_path / "m.zarr", SequenceSettings(mode="mottled"), on=RunOn(workers=1))
    filled = [r["filled"] for r in rep.records]
    assert filled[0] > filled[1] > filled[2] > filled[3] > 0 and filled[4] == 0  # melting while it falls
    floor = np.nonzero(read_store(tmp_path / "m.zarr").read_frame(0))[2].min()
    for i in (1, 2, 3):  # the shrunken body falls to the floor the whole body stood on, not to its own lowest voxel
        z = np.nonzero(read_store(tmp_path / "m.zarr").read_frame(i))[2]
        assert z.min() >= floor - 1
    assert np.nonzero(read_store(tmp_path / "m.zarr").read_frame(3))[2].min() <= floor


def test_cli_melt_with_crumble_an_acceleration_and_a_summed_heap(tmp_path):
    from runnable import volanim

    base = ["sequence", CONNECT, WALK, "--bones", ASSETS / "mannequin.bones", "--frames", "0:1", "--mode", "bone",
            "--workers", "1"]
    r = volanim(*base, "--crumble", "2", "--melt", "3", "--acceleration", "40", "--heap", "sum",
                "-o", tmp_path / "c.zarr")
    assert r.returncode == 0, r.stderr
    assert "4 made" in r.stdout and not read_store(tmp_path / "c.zarr").read_frame(3).any()
    both = volanim(*base, "--teleport", "2", "--melt", "3", "-o", tmp_path / "x.zarr")
    assert both.returncode == 2 and "--melt and --teleport" in both.stderr and not (tmp_path / "x.zarr").exists()
    neg = volanim(*base, "--crumble", "2", "--acceleration", "-1", "-o", tmp_path / "x.zarr")
    assert neg.returncode == 2 and "expected 0 or more" in neg.stderr


def test_a_few_volumes_make_many_crumbling_frames_and_one_frame_can_be_asked_for(tmp_path):
    """The thesis fed multiVolumeMelt "a few frames ... to produce a large number of crumbling volumes", and its
    desiredFrame made one frame alone; volanim refused fewer volumes than frames (#66). Counted by hand: 2
    volumes, 6 frames -> the first held for frames 1-3, the second for 4-6; frame 5 alone is frame 5 of all."""
    from runnable import volanim

    body = random_body(4, shape=(9, 8, 60))
    moved = np.roll(body, 6, axis=2)
    io.write_volume(tmp_path / "b.1.nrrd", body)
    io.write_volume(tmp_path / "b.2.nrrd", moved)
    r = volanim("crumble", tmp_path / "b.1.nrrd", tmp_path / "b.2.nrrd", "-n", "6", "-o", tmp_path / "f.%d.nrrd")
    assert r.returncode == 0, r.stderr
    floor, height = np.nonzero(body)[2].min(), np.ptp(np.nonzero(body)[2])
    for k in range(1, 7):
        source = body if k <= 3 else moved
        want = fall(source, k / 6, drop=height * (k / 6) ** 2, floor=floor)
        assert np.array_equal(io.read_volume(tmp_path / f"f.{k}.nrrd"), want), k
    one = volanim("crumble", tmp_path / "b.1.nrrd", tmp_path / "b.2.nrrd", "-n", "6", "--frame", "5",
                  "-o", tmp_path / "only.%d.nrrd")
    assert one.returncode == 0, one.stderr
    assert [p.name for p in tmp_path.glob("only.*")] == ["only.5.nrrd"]
    assert np.array_equal(io.read_volume(tmp_path / "only.5.nrrd"), io.read_volume(tmp_path / "f.5.nrrd"))
    out = volanim("crumble", tmp_path / "b.1.nrrd", "-n", "6", "--frame", "7", "-o", tmp_path / "x.%d.nrrd")
    assert out.returncode == 2 and "--frame 7 is not one of the crumble's frames 1..6" in out.stderr
    # numbered from --start, as the files are; the error says the user's numbers, not internal ones
    late = volanim("crumble", tmp_path / "b.1.nrrd", "-n", "6", "--start", "10", "--frame", "3", "-o",
                   tmp_path / "x.%d.nrrd")
    assert late.returncode == 2 and "--frame 3 is not one of the crumble's frames 10..15" in late.stderr
    # one frame of a long series reads the first volume and its own: a missing middle file is never opened
    for k in range(1, 7):
        io.write_volume(tmp_path / f"s.{k}.nrrd", body if k != 3 else moved)
    (tmp_path / "s.4.nrrd").write_bytes(b"not a volume")
    five = volanim("crumble", *[tmp_path / f"s.{k}.nrrd" for k in range(1, 7)], "-n", "6", "--frame", "5", "-o",
                   tmp_path / "five.%d.nrrd")
    assert five.returncode == 0, five.stderr
    want = fall(body, 5 / 6, drop=height * (5 / 6) ** 2, floor=floor)
    assert np.array_equal(io.read_volume(tmp_path / "five.5.nrrd"), want)


def test_crumble_command_drops_any_volume_series_onto_the_first_ones_floor(tmp_path):
    from runnable import volanim

    body = random_body(4, shape=(9, 8, 60))
    moved = np.roll(body, 6, axis=2)  # the next frame's body stands 6 voxels higher
    io.write_volume(tmp_path / "b.1.nrrd", body)
    io.write_volume(tmp_path / "b.2.nrrd", moved)
    r = volanim("crumble", tmp_path / "b.2.nrrd", tmp_path / "b.1.nrrd", "-n", "2", "--acceleration", "2",
                "-o", tmp_path / "f.%03d.VOL")  # given out of order: taken by number
    assert r.returncode == 0, r.stderr
    one, two = io.read_volume(tmp_path / "f.001.VOL"), io.read_volume(tmp_path / "f.002.VOL")
    floor = np.nonzero(body)[2].min()
    assert np.array_equal(one, fall(body, 0.5, drop=1.0))  # a k^2 / 2 = 1 voxel at frame 1
    assert np.array_equal(two, fall(moved, 1.0, drop=4.0, floor=floor))  # 4 voxels, onto the first one's floor
    assert np.array_equal(np.sort(two[two > 0]), np.sort(moved[moved > 0]))  # every grain kept
    s = volanim("crumble", tmp_path / "b.1.nrrd", "-n", "3", "--heap", "sum", "-o", tmp_path / "s.%d.nrrd")
    assert s.returncode == 0 and np.array_equal(io.read_volume(tmp_path / "s.3.nrrd"), fall(body, 1.0, heap="sum"))
    bad = volanim("crumble", tmp_path / "b.1.nrrd", tmp_path / "b.2.nrrd", "-n", "1", "-o", tmp_path / "x.%d.VOL")
    assert bad.returncode == 2 and "2 volumes for 1 frames" in bad.stderr and not list(tmp_path.glob("x.*"))
    nopattern = volanim("crumble", tmp_path / "b.1.nrrd", "-n", "3", "-o", tmp_path / "x.VOL")
    assert nopattern.returncode == 2 and "one number field" in nopattern.stderr and not (tmp_path / "x.VOL").exists()
