"""Sequences: one grid for every frame, bit-identical on 1 worker, 2 workers and a Dask cluster, resumable
after a kill -9, and each frame equal to the single-frame reconstruction placed in the shared grid."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from paths import ASSETS, WALK  # WALK: the real clip, bundled with its MIT licence
from volanim_core import io
from volanim_core.cli import main
from volanim_core.errors import FormatError
from volanim_core.io.frame_files import write_frames
from volanim_core.limits import human_bytes
from volanim_core.parallel import RunOn
from volanim_core.reconstruct.engine import reconstruct
from volanim_core.samples import mannequin_bones
from volanim_core.sequence import store
from volanim_core.sequence.checked import read_store
from volanim_core.sequence.effects import melt
from volanim_core.sequence.frames import frames_from_files
from volanim_core.sequence.run import (
    DASK_TASK_SECONDS,
    SequenceSettings,
    frame_boxes,
    frame_grids,
    frames_per_task,
    run_sequence,
    shared_bounds,
)

CONNECT = ASSETS / "mannequin.0.50.connect"


@pytest.fixture(scope="module")
def conn():
    return io.read_connect(CONNECT)


@pytest.fixture(scope="module")
def walk(conn):
    """Six frames across the first stride of the real walk."""
    return frames_from_files(conn, [WALK], bones=mannequin_bones(), frames=slice(0, 120, 20))


def frames_of(path) -> list[np.ndarray]:
    return [np.asarray(f) for f in store.open_frames(path)[:]]


# full tier only, so that make test stays under 10 minutes: the one proof that a real Dask cluster (loopback)
# makes the frames one worker and a local pool make
@pytest.mark.slow
def test_one_worker_two_workers_and_a_dask_cluster_make_identical_frames(tmp_path, conn):
    """24 short frames: Dask gets them several to a task once the first are timed (a task costs the
    workers milliseconds of scheduling), and that changes nothing in the frames. Each frame counts as
    0.1 s here (``frame_seconds``), so the tasks are known whatever the machine's load."""
    from distributed import Client, LocalCluster, get_task_stream

    walk = frames_from_files(conn, [WALK], bones=mannequin_bones(), frames=slice(0, 240, 10))
    one = run_sequence(conn, walk, tmp_path / "one.zarr", SequenceSettings(mode="bone"), on=RunOn(workers=1))
    two = run_sequence(conn, walk, tmp_path / "two.zarr", SequenceSettings(mode="bone"), on=RunOn(workers=2))
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address="127.0.0.1:0") as cluster, Client(cluster) as client:
        with get_task_stream(client) as tasks:
            dask = run_sequence(conn, walk, tmp_path / "dask.zarr", SequenceSettings(mode="bone"),
                                on=RunOn(scheduler=client), frame_seconds=lambda rec: 0.1)
        ran_on = {w["host"] for w in client.scheduler_info()["workers"].values()}
    assert ran_on == {"127.0.0.1"} and dask.workers == "Dask, 2 workers"
    # 4 in flight (2 a worker), one frame each until one is timed; then 0.5 s / 0.1 s = 5 frames a task,
    # the last tasks splitting what is left four ways: 1 1 1 1, then 5 4 3 2 2 1 1 1 1
    assert len(tasks.data) == 13
    a, b, c = (frames_of(tmp_path / f"{n}.zarr") for n in ("one", "two", "dask"))
    assert len(a) == 24 and all(np.array_equal(x, y) and np.array_equal(x, z) for x, y, z in zip(a, b, c))
    assert [r["sha256"] for r in one.records] == [r["sha256"] for r in dask.records]
    assert [r["index"] for r in dask.records] == list(range(24))
    assert len({r["sha256"] for r in two.records}) == 24  # the frames differ from each other
    assert all(r["filled"] > 0 and "peak_rss" in r for r in dask.records)


def test_one_worker_reports_each_frame_before_making_the_next(tmp_path, conn, walk):
    """In this process a task runs when submitted: keeping two in flight made two frames before the
    first was reported (progress came in pairs, and a kill lost a finished frame)."""
    made_when_reported = []

    def on_frame(rec, done, total):
        made_when_reported.append(sum(bool(np.any(f)) for f in frames_of(tmp_path / "s.zarr")))

    run_sequence(conn, walk[:3], tmp_path / "s.zarr", SequenceSettings(mode="binary"), on=RunOn(workers=1),
                 on_frame=on_frame)
    assert made_when_reported == [1, 2, 3]


@pytest.mark.long("starts a spawned worker process (imports numba and the kernels)")
def test_an_isolated_run_makes_its_frames_in_a_worker_process_and_the_same_frames(tmp_path, conn, walk):
    """``RunOn(isolate=True)`` was kept by renders and dropped by sequences: one worker then ran in this
    process, against what the caller asked."""
    here = run_sequence(conn, walk[:2], tmp_path / "here.zarr", SequenceSettings(mode="binary"), on=RunOn(workers=1))
    away = run_sequence(conn, walk[:2], tmp_path / "away.zarr", SequenceSettings(mode="binary"),
                        on=RunOn(workers=1, isolate=True))
    assert here.workers == "1 worker (this process)" and away.workers == "1 local worker"
    assert [r["sha256"] for r in here.records] == [r["sha256"] for r in away.records]


@pytest.mark.slow  # a spawned worker's start-up (8 s): the full tier
def test_a_worker_reports_its_own_peak_memory_not_its_parents(tmp_path, conn, walk):
    """#87: each frame's ``peak_rss`` came from ``getrusage``, whose maximum survives ``exec``: a spawned worker
    reported the RSS of the process that started it. Measured with the full-size mannequin held by its
    parent, every worker "peaked" at 4.47 GB. Here the parent holds 1.5 GB; a worker making small frames
    holds a few hundred MB."""
    held = np.ones(1_500_000_000, np.uint8)  # touched: resident in this process
    rep = run_sequence(conn, walk[:2], tmp_path / "w.zarr", SequenceSettings(mode="binary"),
                       on=RunOn(workers=1, isolate=True))
    assert held[-1] == 1 and rep.workers == "1 local worker"
    peaks = [r["peak_rss"] for r in rep.records]
    assert all(50 * 2**20 < p < 1_000_000_000 for p in peaks), peaks


def test_frames_per_task_makes_tasks_of_the_length_asked_from_the_frames_timed_so_far():
    assert frames_per_task([], DASK_TASK_SECONDS) == 1  # nothing timed yet
    assert frames_per_task([0.03] * 5, 0.0) == 1  # a local pool: a task costs microseconds
    assert frames_per_task([0.03] * 5, 0.25) == 8
    assert frames_per_task([0.001] * 5, 0.25) == 16  # at most 16: progress and a kill's loss stay small
    assert frames_per_task([0.6, 0.7], 0.25) == 1
    assert frames_per_task([1.0] * 40 + [0.05] * 32, 0.25) == 5  # the recent frames (a crumble slows down)


def test_every_frame_is_the_single_frame_reconstruction_placed_in_the_shared_grid(tmp_path, conn, walk):
    frames = walk + melt(walk, 2)
    rep = run_sequence(conn, frames, tmp_path / "s.zarr", SequenceSettings(mode="mottled", padding=3))
    bounds = shared_bounds(conn, frames, 3)
    assert rep.bounds == bounds and read_store(tmp_path / "s.zarr").origin_xyz == bounds.lo
    assert store.open_frames(tmp_path / "s.zarr").shape == (8, *bounds.shape[::-1])
    for i, spec in enumerate(frames):
        alone = reconstruct(spec.tskel(conn), mode="mottled")  # its own tight grid
        placed = np.zeros(bounds.shape, alone.volume.dtype)
        at = np.subtract(alone.origin, bounds.lo)
        placed[at[0]:at[0] + alone.volume.shape[0], at[1]:at[1] + alone.volume.shape[1],
               at[2]:at[2] + alone.volume.shape[2]] = alone.volume
        assert np.array_equal(read_store(tmp_path / "s.zarr").read_frame(i), placed), f"frame {i}"
        # what renders read (#87): the frame's own region at its corner, holding every filled voxel
        part, corner = read_store(tmp_path / "s.zarr").read_part(i)
        assert part.size < placed.size and part.sum(dtype=np.int64) == placed.sum(dtype=np.int64), f"frame {i}"
        assert np.array_equal(part, placed[tuple(slice(c, c + n) for c, n in zip(corner, part.shape))]), f"frame {i}"
    assert rep.records[-1]["filled"] < rep.records[0]["filled"] / 2  # melting
    # OME-Zarr (NGFF 0.5) metadata a viewer reads: axes t, z, y, x and the origin as a translation
    import zarr

    ms = zarr.open_group(str(tmp_path / "s.zarr"), mode="r").attrs["ome"]["multiscales"][0]
    assert [a["name"] for a in ms["axes"]] == ["t", "z", "y", "x"] and ms["datasets"][0]["path"] == "0"
    translation = ms["datasets"][0]["coordinateTransformations"][1]["translation"]
    assert translation == [0.0, *map(float, bounds.lo[::-1])]


def test_a_run_that_cannot_fit_says_how_large_its_largest_frame_is(tmp_path, conn, walk):
    """A frame is reconstructed in its own box of the shared grid, so that box (not the walk's whole
    grid) is what each worker needs; the refusal comes before anything is written."""
    bounds = shared_bounds(conn, walk)
    grids = frame_grids(walk, frame_boxes(conn, walk), bounds)
    largest = max(grids, key=lambda g: np.prod(g.shape))
    assert all(np.all(np.greater_equal(g.lo, bounds.lo)) and np.all(np.less_equal(g.hi, bounds.hi)) for g in grids)
    assert np.prod(largest.shape) < np.prod(bounds.shape)  # the body's box is smaller than the walk's grid
    with pytest.raises(ValueError, match=rf"each frame needs .* \(grid {'x'.join(map(str, largest.shape))} = "):
        run_sequence(conn, walk, tmp_path / "s.zarr", SequenceSettings(mode="bone"), on=RunOn(workers=10**6))
    assert not (tmp_path / "s.zarr").exists()


def test_a_run_killed_while_making_its_store_is_run_again_by_the_same_command(tmp_path, conn, walk):
    """#64: killed 2.35 s in, before the store's plan was written, the rerun refused with "walk.zarr exists
    and is not a volanim sequence". The store is now made beside its target and renamed whole: what such a
    kill leaves is a temporary of a dead process, which the rerun sweeps."""
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True,
                          text=True).stdout.strip()
    half = tmp_path / f".walk.zarr.{dead}-0123abcd.tmp"
    (half / "0").mkdir(parents=True)
    (half / "zarr.json").write_text('{"zarr_format": 3, "node_type": "group"}')
    out = tmp_path / "walk.zarr"
    rep = run_sequence(conn, walk[:2], out, SequenceSettings(mode="bone"))
    assert rep.skipped == 0 and len(store.finished(out)) == 2
    assert not half.exists() and sorted(p.name for p in tmp_path.iterdir()) == ["walk.zarr"]


# spec: docs/formats.md#zarr
@pytest.mark.long("kill -9 of a real sequence run, then the same command: nothing finished is lost or redone")
def test_a_killed_run_resumes_and_redoes_nothing_complete(tmp_path):
    frames = tmp_path / "frames"
    conn = io.read_connect(CONNECT)
    clip = frames_from_files(conn, [WALK], bones=mannequin_bones(), frames=slice(0, 240, 10))
    write_frames(frames, "walk", mannequin_bones(), np.array([f.matrices for f in clip]), [f.number for f in clip])
    out = tmp_path / "walk.zarr"
    trans = [str(p) for p in sorted(frames.glob("*.trans"))]
    cmd = [sys.executable, "-m", "volanim_core.cli", "sequence", str(CONNECT), *trans, "--mode", "bone", "--workers",
           "1", "-o", str(out)]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    deadline = time.monotonic() + 300
    while len(store.finished(out)) < 5 and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.01)
    os.killpg(proc.pid, signal.SIGKILL)
    proc.wait()
    complete = store.finished(out)
    assert 5 <= len(complete) < 24, "the kill came half-way"
    made = []
    rep = run_sequence(conn, frames_from_files(conn, sorted(frames.glob("*.trans"))), out,
                       SequenceSettings(mode="bone"), on_frame=lambda rec, done, total: made.append(rec["index"]))
    assert rep.skipped == len(complete) and sorted(made) == sorted(set(range(24)) - set(complete))
    clean = run_sequence(conn, frames_from_files(conn, sorted(frames.glob("*.trans"))), tmp_path / "clean.zarr",
                         SequenceSettings(mode="bone"))
    assert [r["sha256"] for r in rep.records] == [r["sha256"] for r in clean.records]
    assert all(np.array_equal(x, y) for x, y in zip(frames_of(out), frames_of(tmp_path / "clean.zarr")))


# spec: docs/formats.md#zarr
def test_cli_prints_the_table_writes_per_frame_files_and_refuses_another_plan(tmp_path, capsys):
    out = tmp_path / "w.zarr"
    args = ["sequence", str(CONNECT), str(WALK), "--bones", str(ASSETS / "mannequin.bones"), "--frames", "0:40:20",
            "--mode", "bone", "--workers", "1", "-o", str(out), "--every-frame-as", str(tmp_path / "f" / "w.%04d.nrrd")]
    assert main(args) == 0
    text = capsys.readouterr().out
    assert "loss %" in text and "wrote" in text and "2 made, 0 already complete" in text
    size = sum(p.stat().st_size for p in out.rglob("*") if p.is_file())  # #87: the cost said at the end
    said = re.search(r"s a frame made this run; a frame [\d.]+ s on its worker \(mean\), worker peak .+; store "
                     r"(.+), .+ a frame", text)
    assert said and said[1] == human_bytes(size), text
    vol, placed, _ = io.read_scan(tmp_path / "f" / "w.0020.nrrd")
    origin = placed.origin  # the geometry's origin: where voxel [0, 0, 0] is
    assert np.array_equal(vol, read_store(out).read_frame(1))
    assert tuple(int(v) for v in origin) == read_store(out).origin_xyz
    assert main(args) == 0 and "0 made, 2 already complete" in capsys.readouterr().out
    assert main(args[:-4] + ["-o", str(out), "--padding", "5"]) == 2
    assert "holds another sequence" in capsys.readouterr().err
    assert main(args[:-4] + ["-o", str(out), "--padding", "5", "--force"]) == 0
    # a cache (the studio's movie): another sequence there is replaced, the same one resumes
    conn = io.read_connect(CONNECT)
    frames = frames_from_files(conn, [WALK], bones=mannequin_bones(), frames=slice(0, 20, 10))
    rep = run_sequence(conn, frames, out, SequenceSettings(mode="bone"), existing="replace-other")
    assert rep.computed == 2 and rep.skipped == 0
    again = run_sequence(conn, frames, out, SequenceSettings(mode="bone"), existing="replace-other")
    assert again.computed == 0 and again.skipped == 2


def test_refusals_name_what_is_wrong(tmp_path, conn, walk):
    with pytest.raises(ValueError, match="100000 workers need .* available"):
        run_sequence(conn, walk, tmp_path / "m.zarr", SequenceSettings(mode="bone"), on=RunOn(workers=100_000))
    (tmp_path / "notes").mkdir()
    (tmp_path / "notes" / "a.txt").write_text("mine")
    with pytest.raises(ValueError, match="not a volanim sequence"):
        run_sequence(conn, walk, tmp_path / "notes", SequenceSettings(mode="bone"))
    with pytest.raises(ValueError, match="not a volanim sequence"):
        run_sequence(conn, walk, tmp_path / "notes", SequenceSettings(mode="bone"), existing="redo")  # not even redo
    assert (tmp_path / "notes" / "a.txt").read_text() == "mine"
    for settings, on, match in ((SequenceSettings("bone", every_frame_as=str(tmp_path / "f.vti")), RunOn(),
                                 "one number field"),
                                (SequenceSettings("bone", every_frame_as=str(tmp_path / "f.%d.png")), RunOn(),
                                 r"must end in \.vti"),
                                (SequenceSettings("bone", fps=0.0), RunOn(), "fps must be above 0"),
                                (SequenceSettings("bone"), RunOn(workers=0), "workers must be 1 or more"),
                                (SequenceSettings("bone"), RunOn(), "existing must be one of")):
        with pytest.raises(ValueError, match=match):
            run_sequence(conn, walk, tmp_path / "bad.zarr", settings, on=on,
                         existing="overwrite" if match.startswith("existing") else "resume")
    assert not (tmp_path / "bad.zarr").exists()  # refused before anything was written
    with pytest.raises(ValueError, match="needs the source"):
        run_sequence(conn, walk, tmp_path / "s.zarr", SequenceSettings(mode="sampled"))
    from volanim_core.rig.tskel_tools import identity_tskel

    io.write_tskel(tmp_path / "x.0001.tskel", identity_tskel(conn.take(np.arange(100))))
    with pytest.raises(FormatError, match=r"x\.0001\.tskel.*not the \.connect"):
        frames_from_files(conn, [tmp_path / "x.0001.tskel"])
    with pytest.raises(ValueError, match="needs the bone skeleton"):
        frames_from_files(conn, [WALK])


@pytest.mark.parametrize("option", [["--workers", "0"], ["--fps", "0"], ["--melt", "-2"],
                                    ["--every-frame-as", "frames/walk.vti"], ["--down=up"],
                                    ["--teleport", "2", "--crumble", "3"]])  # --melt and --crumble combine (#43)
def test_bad_options_are_argument_errors_naming_the_option(tmp_path, capsys, option):
    with pytest.raises(SystemExit) as exc:
        main(["sequence", str(CONNECT), str(WALK), "--bones", str(ASSETS / "mannequin.bones"), "-o",
              str(tmp_path / "x.zarr"), *option])
    assert exc.value.code == 2 and f"argument {option[0].split('=')[0]}" in capsys.readouterr().err
    assert not (tmp_path / "x.zarr").exists()


def test_a_scheduler_that_cannot_be_reached_is_named_and_announced(tmp_path, capsys):
    """The wait for a Dask scheduler (30 s by default) is announced before it starts, and its failure names
    the scheduler, not the input files (it used to read "CONNECT, BONES: Timed out trying to connect ...")."""
    import socket

    import dask
    import distributed  # noqa: F401 -- first: its import adds dask's "distributed" config, which a
    # dask.config.set made before it would take away again on leaving (every later LocalCluster: KeyError)

    with socket.socket() as s:  # a free port on the loopback interface: nothing listens there
        s.bind(("127.0.0.1", 0))
        address = f"tcp://127.0.0.1:{s.getsockname()[1]}"
    args = ["sequence", str(CONNECT), str(WALK), "--bones", str(ASSETS / "mannequin.bones"), "--frames", "0:20:10",
            "--mode", "bone", "--scheduler", address, "-o", str(tmp_path / "w.zarr")]
    with dask.config.set({"distributed.comm.timeouts.connect": "1s"}):
        assert main(args) == 2
    err = capsys.readouterr().err
    assert f"connecting to the Dask scheduler at {address}" in err
    error = err.strip().splitlines()[-1]
    assert error.startswith(f"volanim sequence: error: cannot reach the Dask scheduler at {address}"), error
    assert CONNECT.name not in error


@pytest.mark.parametrize("direction, scale, exact", [
    ((1, 0, 0, 0, 1, 0, 0, 0, 1), (0.5, 0.5, 2.0), True),
    ((-1, 0, 0, 0, -1, 0, 0, 0, 1), (-0.5, -0.5, 2.0), True),  # a scan stored RAS, read into LPS
    ((0, 0, 1, 1, 0, 0, 0, 1, 0), (0.5, 0.5, 2.0), False),  # a sagittal acquisition: axes swapped
    ((0.8, -0.6, 0, 0.6, 0.8, 0, 0, 0, 1), (0.5, 0.5, 2.0), False),  # tilted
])
def test_ome_scale_says_a_reversed_axis_and_owns_up_to_what_it_cannot(direction, scale, exact):
    from volanim_core.geometry import Geometry

    assert store.ome_scale(Geometry((0.5, 0.5, 2.0), (1, 2, 3), direction)) == (scale, exact)


def test_the_workers_of_a_killed_run_end_with_it(tmp_path):
    """#64: killing `volanim sequence` (-9) left its two pool workers running for over 30 s in 4 of 10 kills.
    Each worker now dies with the process that started it."""
    clip = frames_from_files(io.read_connect(CONNECT), [WALK], bones=mannequin_bones(), frames=slice(0, 480, 10))
    frames = tmp_path / "frames"
    write_frames(frames, "walk", mannequin_bones(), np.array([f.matrices for f in clip]), [f.number for f in clip])
    out = tmp_path / "walk.zarr"
    trans = [str(p) for p in sorted(frames.glob("*.trans"))]
    cmd = [sys.executable, "-m", "volanim_core.cli", "sequence", str(CONNECT), *trans, "--mode", "bone", "--workers",
           "2", "-o", str(out)]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 300
    while not store.finished(out) and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.01)
    children = [int(p) for p in subprocess.run(["pgrep", "-P", str(proc.pid)], capture_output=True,
                                               text=True).stdout.split()]
    workers = [p for p in children if "spawn_main" in Path(f"/proc/{p}/cmdline").read_bytes().decode(errors="replace")]
    assert len(workers) == 2 and proc.poll() is None, (children, proc.poll())
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    while any(Path(f"/proc/{p}").exists() and "Z" not in _state(p) for p in workers) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not [p for p in workers if Path(f"/proc/{p}").exists() and "Z" not in _state(p)]


def _state(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return "Z"
