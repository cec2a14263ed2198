"""The numba reconstruction against the NumPy oracle (tests/naive.py), and its promises."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import naive
from volanim_core import samples
from volanim_core.errors import Cancelled
from volanim_core.geometry import Geometry
from volanim_core.reconstruct.engine import grid_bounds, reconstruct
from volanim_core.reconstruct.speedups import Speedups
from volanim_core.rig.connectivity import BoneSegment, Tskel
from volanim_core.skeleton.skeletonize import skeletonize
from volanim_core.volume import Bounds

NO_CUT = Speedups(cut=False)  # the overdraw cut off: every sphere visits its whole ball


def random_rigid(rng, centre, quarter_turns=False):
    m = np.eye(4)
    if quarter_turns:
        m[:3, :3] = Rotation.from_euler("xyz", rng.integers(0, 4, 3) * 90, degrees=True).as_matrix()
    else:
        m[:3, :3] = Rotation.random(random_state=rng.integers(1 << 30)).as_matrix()
    c = np.asarray(centre, float)
    m[3, :3] = c - c @ m[:3, :3] + rng.normal(0, 2, 3)  # rotate about centre, then shift
    return m


def random_tskel(rng, n=25, nbones=3, metric="euclid", size=14, quarter_turns=False, identity=False):
    pts = rng.integers(2, size - 2, (n, 3))
    pts = np.unique(pts, axis=0)
    if metric == "euclid":
        dt = np.sqrt(rng.integers(1, 14, len(pts)).astype(float))
    else:
        dt = rng.integers(3, 13, len(pts)).astype(float)
    bone = np.sort(rng.integers(0, nbones, len(pts)))  # grouped by bone, as files list them
    mats = np.array([np.eye(4) if identity else random_rigid(rng, (size / 2,) * 3, quarter_turns)
                     for _ in range(nbones)])
    bones = [BoneSegment((b, 0, 0), (b, 1, 0), f"B{b}") for b in range(nbones)]
    return Tskel(bones, mats, pts, dt, None, bone, metric=metric)


MODES = ["binary", "mottled", "bone", "hotspot", "sampled"]


# spec: docs/formats.md#reconstruction
@pytest.mark.parametrize("metric", ["euclid", "345"])
@pytest.mark.parametrize("mode", MODES)
def test_kernel_equals_oracle_on_random_cases(rng, metric, mode):
    source = rng.integers(1, 256, (14, 14, 14)).astype(np.uint8)
    for case in range(12):
        t = random_tskel(rng, metric=metric, quarter_turns=case % 3 == 0, identity=case % 4 == 1)
        b = grid_bounds(t, padding=1)
        if case % 5 == 2:  # given bounds that clip the spheres
            b = Bounds(tuple(v + 3 for v in b.lo), tuple(v - 3 for v in b.hi))
        r = reconstruct(t, mode=mode, source=source, bounds=b)
        want, best, ties = naive.reconstruct(t, b, mode=mode, source=source)
        assert r.volume.dtype == want.dtype
        same = r.volume == want
        assert same[~ties].all(), f"case {case}: {(~same & ~ties).sum()} voxels differ"
        filled = np.isfinite(best).sum() if mode != "hotspot" else (want > 0).sum()
        assert r.stats["filled"] == filled
        if mode == "hotspot":
            assert r.stats["hotspot_max"] == want.max()


@pytest.mark.parametrize("mode", ["bone", "sampled"])
def test_grids_a_few_voxels_wide_and_spheres_at_their_edges_equal_the_oracle(rng, mode):
    """A small sphere's rows are swept in whole vectors of 4 voxels, shifted left at the grid's right
    edge and left as they are where the grid is narrower than that: every case must match the oracle."""
    source = rng.integers(1, 256, (14, 14, 14)).astype(np.uint8)
    for width in range(1, 10):
        t = random_tskel(rng, n=40, identity=True)
        b = grid_bounds(t, padding=0)
        for x0 in (b.lo[0], b.hi[0] - width + 1, (b.lo[0] + b.hi[0]) // 2):  # the left edge, the right, between
            bounds = Bounds((x0, b.lo[1], b.lo[2]), (x0 + width - 1, b.hi[1], b.hi[2]))
            r = reconstruct(t, mode=mode, source=source, bounds=bounds)
            want, best, ties = naive.reconstruct(t, bounds, mode=mode, source=source)
            assert ((r.volume == want) | ties).all(), (width, x0)
            assert r.stats["filled"] == np.isfinite(best).sum()


# spec: docs/formats.md#reconstruction
@pytest.mark.parametrize("kernel", [3, 5])
def test_smoothed_sampling_equals_oracle(rng, kernel):
    source = rng.integers(0, 256, (14, 14, 14)).astype(np.uint8)
    for _ in range(4):
        t = random_tskel(rng)
        b = grid_bounds(t, padding=1)
        r = reconstruct(t, mode="sampled", source=source, kernel=kernel, bounds=b)
        want, _, ties = naive.reconstruct(t, b, mode="sampled", source=source, kernel=kernel)
        assert (r.volume == want)[~ties].all()


@pytest.mark.parametrize("mode", MODES)
def test_one_and_two_threads_bit_identical(rng, mode):
    source = rng.integers(0, 256, (20, 20, 20)).astype(np.uint8)
    t = random_tskel(rng, n=300, size=20)
    a = reconstruct(t, mode=mode, source=source, threads=1)
    b = reconstruct(t, mode=mode, source=source, threads=2)
    assert np.array_equal(a.volume, b.volume) and a.stats["filled"] == b.stats["filled"]


@pytest.mark.parametrize("metric", ["euclid", "345"])
@pytest.mark.parametrize("mode", MODES)
def test_a_previous_result_passed_as_out_gives_what_a_fresh_array_gives(rng, mode, metric):
    """The kernel reads a voxel's stencil only where the output is still 0, so ``out=`` must come back
    zeroed: a previous frame's volume (same grid, other owners) must leave no trace in the next."""
    source = rng.integers(1, 256, (20, 20, 20)).astype(np.uint8)
    a, b = random_tskel(rng, n=300, size=20, metric=metric), random_tskel(rng, n=300, size=20, metric=metric)
    bounds = Bounds((-8, -8, -8), (28, 28, 28))
    first = reconstruct(a, mode=mode, source=source, bounds=bounds)
    fresh = reconstruct(b, mode=mode, source=source, bounds=bounds)
    reused = reconstruct(b, mode=mode, source=source, bounds=bounds, out=first.volume)
    assert np.shares_memory(reused.volume, first.volume)  # the array was reused, not replaced
    assert np.array_equal(reused.volume, fresh.volume) and reused.stats["filled"] == fresh.stats["filled"]


def test_in_memory_order_reconstructs_like_the_written_file(tmp_path, rng):
    from volanim_core import io

    t = random_tskel(rng, n=80)
    shuffled = rng.permutation(len(t))
    mixed = Tskel(t.bones, t.matrices, t.points[shuffled], t.dt[shuffled], None, t.bone[shuffled])
    io.write_tskel(tmp_path / "m.tskel", mixed)
    back = io.read_tskel(tmp_path / "m.tskel")
    for mode in ("mottled", "bone"):
        assert np.array_equal(reconstruct(mixed, mode=mode).volume, reconstruct(back, mode=mode).volume)


@pytest.mark.parametrize("rows", [True, False])
@pytest.mark.parametrize("mode", ["binary", "mottled", "bone", "sampled"])
def test_overdraw_cut_changes_nothing_but_visits(rng, mode, rows, monkeypatch):
    """Every sphere cut, however small: row by row (``rows``), or as the kernel cuts a sphere below radius 10
    (slices a plane covers skipped, the rest swept)."""
    from volanim_core.reconstruct import _kernels, plan

    monkeypatch.setattr(plan, "CUT_MIN_RADIUS", 0.0)
    if rows:
        monkeypatch.setattr(_kernels, "ROW_CUT_R2", 0.0)
    source = rng.integers(1, 256, (30, 30, 30)).astype(np.uint8)
    t = random_tskel(rng, n=800, size=30, nbones=2)
    cut = reconstruct(t, mode=mode, source=source)
    full = reconstruct(t, mode=mode, source=source, speedups=NO_CUT)
    assert np.array_equal(cut.volume, full.volume)
    assert cut.stats["filled"] == full.stats["filled"]
    assert cut.stats["visits"] < full.stats["visits"]


def test_overdraw_cut_on_large_rotated_spheres_changes_nothing_but_visits(rng):
    """Spheres as large as the cut's minimum radius and larger, on rotated bones: the planes are
    chosen slice by slice (dropped where they miss the disc, the slice skipped where one covers it)."""
    from volanim_core.reconstruct.neighbours import CUT_MIN_RADIUS

    source = rng.integers(1, 256, (60, 60, 60)).astype(np.uint8)
    for case in range(3):
        t = random_tskel(rng, n=120, size=60, nbones=2, quarter_turns=case == 0)
        t = Tskel(t.bones, t.matrices, t.points, np.sqrt(rng.integers(int(CUT_MIN_RADIUS**2) - 20, 200, len(t))),
                  None, t.bone)
        cut = reconstruct(t, mode="bone", source=source)
        full = reconstruct(t, mode="bone", source=source, speedups=NO_CUT)
        assert np.array_equal(cut.volume, full.volume) and cut.stats["filled"] == full.stats["filled"]
        assert cut.stats["visits"] < full.stats["visits"]
    want, _, ties = naive.reconstruct(t, cut.bounds, mode="bone", source=source)
    assert (cut.volume == want)[~ties].all()


def test_visits_are_the_voxels_examined_and_filled_the_voxels_won():
    """A small sphere sweeps the x-box of each slice's disc (every voxel strictly within the disc's
    half-width of the centre) on the rows that cross the disc: ``visits`` counts those voxels, corners
    outside the sphere included (the kernel's work), while ``filled`` counts only the voxels won."""
    bone = [BoneSegment((0, 0, 0), (1, 0, 0))]
    c, r2 = np.array([10.3, 10.6, 10.2]), 7.0
    m = np.eye(4)
    m[3, :3] = c - 10  # a centre off the voxels, so the boxes hold corners outside the sphere
    t = Tskel(bone, m[None], [[10, 10, 10]], [np.sqrt(r2)], None, [0])
    b = Bounds((0, 0, 0), (20, 20, 20))
    r = reconstruct(t, mode="bone", bounds=b)
    x = np.arange(21.0)
    examined = 0
    for z in x:
        for y in x:
            rest = r2 - (z - c[2]) ** 2  # the slice disc's squared half-width
            if (y - c[1]) ** 2 + (z - c[2]) ** 2 < r2:
                examined += int(((x - c[0]) ** 2 < rest).sum())
    inside = ((x[:, None, None] - c[0]) ** 2 + (x[None, :, None] - c[1]) ** 2
              + (x[None, None, :] - c[2]) ** 2 < r2).sum()
    assert r.stats["filled"] == inside == (r.volume > 0).sum()
    assert r.stats["visits"] == examined > inside


def test_a_plane_along_y_or_z_cuts_rows_or_whole_slices_exactly():
    """Neighbours straight above (z), beside (y) and ahead (x): a bisector parallel to the rows
    cuts whole rows, one parallel to the slices cuts whole slices, one across the rows cuts runs."""
    bone = [BoneSegment((0, 0, 0), (1, 0, 0))]
    pts = [[20, 20, 20], [20, 20, 27], [20, 27, 20], [27, 20, 20], [13, 20, 20]]
    t = Tskel(bone, np.eye(4)[None], pts, [11.0, 13.0, 13.0, 13.0, 12.0], None, [0] * 5)
    b = Bounds((0, 0, 0), (40, 40, 40))
    cut = reconstruct(t, mode="mottled", bounds=b)
    full = reconstruct(t, mode="mottled", bounds=b, speedups=NO_CUT)
    assert np.array_equal(cut.volume, full.volume)
    assert cut.stats["visits"] < full.stats["visits"]
    want, _, ties = naive.reconstruct(t, b, mode="mottled")
    assert (cut.volume == want)[~ties].all()


# spec: docs/formats.md#reconstruction
def test_ties_go_to_the_first_sphere_in_file_order():
    # two equal spheres, centres 2 apart: the mid-plane voxels are equidistant
    bones = [BoneSegment((0, 0, 0), (1, 0, 0))]
    t = Tskel(bones, np.eye(4)[None], [[5, 5, 5], [7, 5, 5]], [2.5, 2.5], None, [0, 0])
    r = reconstruct(t, mode="mottled", bounds=Bounds((0, 0, 0), (12, 10, 10)))
    first, second = r.volume[5, 5, 5], r.volume[7, 5, 5]
    assert first != second and r.volume[6, 5, 5] == first and r.volume[6, 6, 5] == first


def _all_voxel_tskel(mask, metric="euclid"):
    s = skeletonize(mask, metric=metric, min_thinness=-np.inf)
    bones = [BoneSegment((0, 0, 0), (1, 0, 0), "ALL")]
    return Tskel(bones, np.eye(4)[None], s.points, s.dt, s.thinness, np.zeros(len(s), int), metric=metric)


@pytest.mark.parametrize("metric", ["euclid", "345"])
def test_identity_with_all_voxels_reproduces_source(metric):
    s = samples.mannequin()
    # a 60-voxel-high slab of the mannequin keeps the test quick
    src = np.zeros_like(s.volume)
    src[:, :, 150:210] = s.volume[:, :, 150:210]
    t = _all_voxel_tskel(src > 0, metric)
    full = Bounds((0, 0, 0), tuple(v - 1 for v in src.shape))
    sampled = reconstruct(t, mode="sampled", source=src, bounds=full)
    assert np.array_equal(sampled.volume, src)
    binary = reconstruct(t, mode="binary", bounds=full, value=1)
    assert np.array_equal(binary.volume, (src > 0).astype(np.uint8))


def test_aliascube_rotated_45_stays_sharp():
    cube = samples.aliascube().volume
    s = skeletonize(cube > 0)  # its default skeleton (thinness >= 0.5)
    t = Tskel([BoneSegment((0, 0, 0), (1, 0, 0))], np.eye(4)[None], s.points, s.dt, s.thinness, np.zeros(len(s), int))
    rot = np.eye(4)
    rot[:3, :3] = Rotation.from_euler("z", 45, degrees=True).as_matrix().T  # row-vector convention
    c = np.array([63.5, 63.5, 63.5])
    rot[3, :3] = c - c @ rot[:3, :3]
    t.matrices[:] = rot
    b = Bounds((0, 0, 0), (127, 127, 127))
    r = reconstruct(t, mode="sampled", source=cube, bounds=b)
    filled = r.volume > 0
    q = np.argwhere(filled)
    src = (q @ np.linalg.inv(rot)[:3, :3] + np.linalg.inv(rot)[3, :3])
    near = np.floor(src + 0.5).astype(int)
    tie = (np.abs(src - np.floor(src) - 0.5) < 1e-6).any(1)
    assert (r.volume[tuple(q.T)] == cube[tuple(near.T)])[~tie].all()
    assert set(np.unique(r.volume)) == {0, 50, 250}  # no blending: squares stay sharp
    binary = reconstruct(t, mode="binary", bounds=b)
    assert r.stats["filled"] == binary.stats["filled"] == (binary.volume > 0).sum()
    assert r.stats["filled"] >= filled.sum() > 0.5 * (cube > 0).sum()


def test_clipping_is_counted_not_fatal():
    bones = [BoneSegment((0, 0, 0), (1, 0, 0))]
    t = Tskel(bones, np.eye(4)[None], [[5, 5, 5]], [3.0], None, [0])
    whole = reconstruct(t)
    half = reconstruct(t, bounds=Bounds((5, 0, 0), (20, 20, 20)))
    assert half.stats["filled"] + half.stats["clipped"] == whole.stats["filled"]
    far = reconstruct(t, bounds=Bounds((50, 50, 50), (60, 60, 60)))
    assert far.stats["filled"] == 0 and far.stats["clipped"] == whole.stats["filled"]


def test_empty_bone_zero_points_and_singular_matrix():
    bones = [BoneSegment((0, 0, 0), (1, 0, 0), "A"), BoneSegment((1, 0, 0), (2, 0, 0), "EMPTY")]
    t = Tskel(bones, np.tile(np.eye(4), (2, 1, 1)), [[5, 5, 5]], [2.0], None, [0])
    assert reconstruct(t, mode="bone").volume.max() == 1
    none = Tskel(bones, np.tile(np.eye(4), (2, 1, 1)), np.zeros((0, 3)), [], None, [])
    r = reconstruct(none)
    assert r.stats["filled"] == 0 and r.volume.shape == (1, 1, 1)
    t.matrices[1, 1, 1] = 0  # EMPTY becomes singular
    with pytest.raises(ValueError, match="bone 1 \\(EMPTY\\): its matrix is singular"):
        reconstruct(t)


def test_bad_arguments():
    t = random_tskel(np.random.default_rng(0))
    with pytest.raises(ValueError, match="mode must be"):
        reconstruct(t, mode="fancy")
    with pytest.raises(ValueError, match="needs the source"):
        reconstruct(t, mode="sampled")
    with pytest.raises(ValueError, match="kernel"):
        reconstruct(t, mode="sampled", source=np.zeros((2, 2, 2)), kernel=4)


class FakeClock:
    """Each reading is ``step`` seconds after the one before: every launch seems to take ``step``."""

    def __init__(self, step: float):
        self.now, self.step = 0.0, step

    def __call__(self) -> float:
        self.now += self.step
        return self.now


def test_a_fast_call_is_one_launch_after_the_first_and_a_slow_one_reports_often():
    """Launches are sized to last LAUNCH_SECONDS after a small first one: few for a fast call (each
    launch waits for its slowest thread), many -- progress and cancel -- for a slow one. The pace is read
    off an injected clock, so the launches are exact whatever the machine's load."""
    import numba

    from volanim_core.reconstruct import engine as rec

    t = Tskel([BoneSegment((0, 0, 0), (0, 0, 300))], np.eye(4)[None], [[5, 5, z] for z in range(0, 300, 2)],
              [3.0] * 150, None, [0] * 150)
    threads = min(2, numba.config.NUMBA_NUM_THREADS)
    calls = []
    fast = reconstruct(t, mode="bone", progress=lambda d, n: calls.append(d), threads=threads,
                       clock=FakeClock(1e-6))
    nz = fast.volume.shape[2]
    first = max(threads * 8, nz // 16)
    assert calls == [0, first, nz]  # the first launch, then the rest in one
    calls.clear()
    slow = reconstruct(t, mode="bone", progress=lambda d, n: calls.append(d), threads=threads, clock=FakeClock(1.0))
    # a launch of L slices took 1 s: the next is L * LAUNCH_SECONDS long, never under 4 per thread
    step = max(threads * 4, int(first * rec.LAUNCH_SECONDS))
    assert calls == [0, *range(first, nz, step), nz] and len(calls) > 10
    assert np.array_equal(slow.volume, fast.volume)  # launches change nothing in the result


def test_launches_cover_the_grid_in_order_with_the_real_clock():
    """The same with the machine's own clock: however the launches fall, progress only moves forward and
    ends at the last slice (no count: it depends on the machine's load)."""
    t = Tskel([BoneSegment((0, 0, 0), (0, 0, 300))], np.eye(4)[None], [[5, 5, z] for z in range(0, 300, 2)],
              [3.0] * 150, None, [0] * 150)
    calls = []
    r = reconstruct(t, mode="bone", progress=lambda d, n: calls.append(d))
    assert calls[0] == 0 and calls == sorted(set(calls)) and calls[-1] == r.volume.shape[2]


def test_progress_and_cancel():
    t = random_tskel(np.random.default_rng(1), n=200, size=30)
    seen = []
    reconstruct(t, progress=lambda d, n: seen.append((d, n)))
    assert seen[0][0] == 0 and seen[-1][0] == seen[-1][1]
    with pytest.raises(Cancelled):
        reconstruct(t, cancel=lambda: True)


def test_cropped_source_with_origin(rng):
    src = rng.integers(1, 256, (14, 14, 14)).astype(np.uint8)
    t = random_tskel(rng)
    b = grid_bounds(t)
    full = reconstruct(t, mode="sampled", source=src, bounds=b)
    crop = reconstruct(t, mode="sampled", source=src[2:, 3:, 1:],
                       source_geometry=Geometry(origin=(2, 3, 1)), bounds=b)
    # every voxel sampled from inside the crop agrees; outside the crop reads 0
    differ = full.volume != crop.volume
    assert (crop.volume[differ] == 0).all()


def test_concurrent_reconstructions_do_not_share_scratch_memory(rng):
    """The studio reconstructs on the GUI thread (live) while a worker makes the full preview."""
    import threading

    frames = [random_tskel(np.random.default_rng(s), n=600, size=40, nbones=3) for s in (1, 2)]
    want = [reconstruct(t, mode="mottled", bounds=Bounds((-20,) * 3, (60,) * 3)).volume for t in frames]
    errors = []

    def work(k):
        for _ in range(15):
            got = reconstruct(frames[k], mode="mottled", bounds=Bounds((-20,) * 3, (60,) * 3), threads=1).volume
            if not np.array_equal(got, want[k]):
                errors.append(k)

    threads = [threading.Thread(target=work, args=(k,)) for k in (0, 1)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors


def test_neighbours_refer_to_the_callers_order(rng, monkeypatch):
    """reconstruct() groups points by bone; neighbours the caller computed on its own order must follow."""
    from volanim_core.reconstruct import plan
    from volanim_core.reconstruct.neighbours import sphere_neighbours

    monkeypatch.setattr(plan, "CUT_MIN_RADIUS", 0.0)
    t = random_tskel(rng, n=500, size=30)
    mixed_order = rng.permutation(len(t))
    mixed = Tskel(t.bones, t.matrices, t.points[mixed_order], t.dt[mixed_order], None, t.bone[mixed_order])
    cut = reconstruct(mixed, mode="mottled", neighbours=sphere_neighbours(mixed))
    plain = reconstruct(mixed, mode="mottled", speedups=NO_CUT)
    assert np.array_equal(cut.volume, plain.volume)


def test_cancel_is_checked_while_sampling_not_only_while_filling(monkeypatch):
    """The sampled pass used to run in one uninterruptible call after the last progress report."""
    from volanim_core.reconstruct import engine as rec

    monkeypatch.setattr(rec, "LAUNCH_SECONDS", 0.0)  # launches as short as on a volume that takes minutes
    mask = np.zeros((20, 20, 40), bool)
    mask[5:15, 5:15, 2:38] = True
    pts = np.argwhere(mask)
    t = Tskel([BoneSegment((10, 10, 2), (10, 10, 38))], np.eye(4)[None], pts, np.full(len(pts), 1.5), None,
              np.zeros(len(pts), int))
    source = mask.astype(np.uint8) * 100
    calls = []

    def progress(done, total):
        calls.append((done, total))

    reconstruct(t, mode="sampled", source=source, progress=progress)
    nz = calls[0][1] // 2
    assert [d for d, _ in calls if d > nz], "progress is reported during the sampling pass"
    calls.clear()
    with pytest.raises(Cancelled):
        reconstruct(t, mode="sampled", source=source, progress=lambda d, t: calls.append((d, t)),
                    cancel=lambda: len(calls) and calls[-1][0] > nz)


@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("mode", ["bone", "mottled", "sampled"])
def test_runs_in_one_row_in_any_order_over_a_stencil_slice_an_earlier_slice_used(mode, threads):
    """A thread's stencil is one slice, reused slice after slice and never reset: a voxel's stencil
    counts only once a sphere of this slice has won it. Runs landing right, then left, then in
    the gaps must win every voxel, never lose to the small distances an earlier slice left."""
    bounds = Bounds((0, 0, 0), (39, 4, 11))
    bone = [BoneSegment((0, 2, 2), (39, 2, 2))]
    xs = [20, 34, 5, 12, 27]  # middle, far right, far left, then both gaps
    # first a big sphere over the whole row in slices 0..5, then small ones in slices 7..9
    pts = [[20, 2, 2]] + [[x, 2, 8] for x in xs]
    t = Tskel(bone, np.eye(4)[None], pts, [4.0] + [1.5] * len(xs), None, [0] * len(pts))
    source = np.arange(40 * 5 * 12, dtype=np.uint16).reshape(40, 5, 12)
    r = reconstruct(t, mode=mode, source=source, bounds=bounds, threads=threads)
    want, best, _ = naive.reconstruct(t, bounds, mode=mode, source=source)
    assert np.array_equal(r.volume, want)
    assert r.stats["filled"] == np.isfinite(best).sum()
    assert (want[:, :, 7:10] > 0).sum() == 19 * len(xs)  # centre, 6 faces, 12 edges (sqrt 2 < 1.5)
