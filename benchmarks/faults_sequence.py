"""Faults at the thesis's full size (#87 item 3): a worker killed, the client killed, the disk filling.

Each run is `volanim sequence` as a user types it, on the full-size walking mannequin
(`volanim samples mannequin-full`, 580 x 338 x 1880), sampled mode, a Dask LocalCluster of 2 workers
(`--cluster-config`), FRAMES walk frames. Every run's frames are compared, sha256 against sha256 (the
store's own manifest), with the same frames made by one worker (`--workers 1`):

    worker   SIGKILL to the worker process that recorded the frame which took the run past 30 %
             (its pid is in the manifest); the nanny starts a new one and Dask reruns its task
    client   SIGKILL to the whole `volanim sequence` process group (client, scheduler, nannies and
             workers: a LocalCluster lives in the client) past 60 %; then the same command again,
             which must say it made only the frames not yet recorded
    disk     the store on a tmpfs too small for the frames (a mount namespace of its own: `unshare`,
             no root needed); the run must stop naming the store and the room it needs, keeping what it
             wrote; the tmpfs is then made larger and the same command finishes the rest

    .venv/bin/python benchmarks/faults_sequence.py [FRAMES] [--size full|large]   # default 10, full
"""

from __future__ import annotations

import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))
from _harness import table  # noqa: E402

from volanim_core.sequence.store import bytes_on_disk, finished  # noqa: E402

VOLANIM = [sys.executable, "-m", "volanim_core"]


def manifest(store: Path) -> dict[int, dict]:
    """The frames recorded complete, read as `volanim sequence` reads them (a line being written is skipped)."""
    return finished(store)


def sequence_args(folder: Path, name: str, frames: int, out: Path) -> list[str]:
    return [*VOLANIM, "sequence", str(folder / f"{name}.connect"), str(folder / "walk.bvh"), "--bones",
            str(folder / f"{name}.bones"), "--frames", f"0:{10 * frames}:10", "--mode", "sampled", "--source",
            str(folder / f"{name}.VOL"), "-o", str(out)]


def wait_for(store: Path, count: int, proc: subprocess.Popen) -> dict[int, dict]:
    """The manifest once it holds ``count`` frames (the run still going)."""
    while True:
        got = manifest(store)
        if len(got) >= count:
            return got
        if proc.poll() is not None:
            raise RuntimeError(f"the run ended (exit {proc.returncode}) before {count} frames were recorded")
        time.sleep(0.2)


def run(args: list[str], log: Path) -> subprocess.CompletedProcess:
    with open(log, "w") as fh:
        return subprocess.run(args, stdout=fh, stderr=subprocess.STDOUT, text=True)


def start(args: list[str], log: Path) -> subprocess.Popen:
    """The run in a process group of its own (a kill reaches its LocalCluster too), its output to ``log``."""
    with open(log, "w") as fh:  # the child keeps its own copy of the descriptor
        return subprocess.Popen(args, stdout=fh, stderr=subprocess.STDOUT, start_new_session=True)


def same(store: Path, ref: dict[int, dict]) -> str:
    got = manifest(store)
    equal = sum(got.get(i, {}).get("sha256") == r["sha256"] for i, r in ref.items())
    return f"{equal}/{len(ref)}"


def worker_killed(folder, name, frames, cluster, ref, logs) -> list:
    out = folder / "worker.zarr"
    proc = start([*sequence_args(folder, name, frames, out), "--cluster-config", str(cluster)], logs / "worker.log")
    at = -(-3 * frames // 10)
    got = wait_for(out, at, proc)
    victim = int(max(got.values(), key=lambda r: r["finished"])["worker"].rsplit(":", 1)[1])
    os.kill(victim, signal.SIGKILL)
    t_kill = time.time()
    code = proc.wait()
    after = manifest(out)
    by_victim = sum(r["worker"].endswith(f":{victim}") for r in after.values())
    made_after = sum(r["finished"] > t_kill for r in after.values())
    return ["worker", f"SIGKILL pid {victim} (a worker) after {len(got)} of {frames} frames", code,
            f"{by_victim} frames by the killed worker; {made_after} made after the kill by the others",
            same(out, ref)]


def client_killed(folder, name, frames, cluster, ref, logs) -> list:
    out = folder / "client.zarr"
    args = [*sequence_args(folder, name, frames, out), "--cluster-config", str(cluster)]
    proc = start(args, logs / "client-1.log")
    at = -(-6 * frames // 10)
    wait_for(out, at, proc)
    os.killpg(proc.pid, signal.SIGKILL)  # the client and its LocalCluster: every process of the run
    proc.wait()
    kept = len(manifest(out))
    second = run(args, logs / "client-2.log")
    said = re.search(r"(\d+) made, (\d+) already complete", (logs / "client-2.log").read_text())
    made, skipped = (int(said[1]), int(said[2])) if said else (None, None)
    ok = said is not None and skipped == kept and made == frames - kept
    return ["client", f"SIGKILL to the process group after {kept} of {frames} frames were recorded",
            second.returncode, f"rerun: {made} made, {skipped} already complete ({'as it should' if ok else 'WRONG'})",
            same(out, ref)]


DISK_SCRIPT = """
set -u
mount -t tmpfs -o size={small} tmpfs "{disk}" || exit 90
"$@" > "{logs}/disk-1.log" 2>&1; echo "first exit $?" >> "{logs}/disk-1.log"
ls "{disk}/walk.zarr/volanim-frames.jsonl" > /dev/null 2>&1 && wc -l < "{disk}/walk.zarr/volanim-frames.jsonl" \
    > "{logs}/disk-kept.txt"
mount -o remount,size={large} "{disk}" || exit 91
"$@" > "{logs}/disk-2.log" 2>&1; echo "second exit $?" >> "{logs}/disk-2.log"
mkdir -p "{logs}/disk-store" && cp "{disk}/walk.zarr/volanim-frames.jsonl" "{logs}/disk-store/"
"""


def disk_filled(folder, name, frames, cluster, ref, logs, frame_bytes: int) -> list:
    disk = folder / "disk"
    disk.mkdir()
    small = max(frame_bytes * frames // 2, 1 << 20)  # room for about half the frames
    script = DISK_SCRIPT.format(small=small, large=small * 8, disk=disk, logs=logs)
    args = [*sequence_args(folder, name, frames, disk / "walk.zarr"), "--cluster-config", str(cluster)]
    out = subprocess.run(["unshare", "--user", "--map-root-user", "--mount", "sh", "-c", script, "sh", *args],
                         capture_output=True, text=True)
    first = (logs / "disk-1.log").read_text()
    said = [line for line in first.splitlines() if "error" in line.lower() or "room" in line][-1:]
    kept = int((logs / "disk-kept.txt").read_text()) if (logs / "disk-kept.txt").exists() else 0
    second = (logs / "disk-2.log").read_text()
    resumed = re.search(r"(\d+) made, (\d+) already complete", second)
    return ["disk", f"a {small / 2**20:.1f} MB tmpfs, then remounted at {8 * small / 2**20:.1f} MB",
            f"{out.returncode} ({first.splitlines()[-1] if first else '?'})",
            f"said: {said[0].strip() if said else '(nothing)'}; {kept} frames kept; rerun: "
            f"{resumed[0] if resumed else second[-300:]}", same(logs / "disk-store", ref)]


def main() -> None:
    argv = sys.argv[1:]
    name = "mannequin-large" if "--size" in argv and argv[argv.index("--size") + 1] == "large" else "mannequin-full"
    if "--size" in argv:
        del argv[argv.index("--size"):argv.index("--size") + 2]
    frames = int(argv[0]) if argv else 10
    with tempfile.TemporaryDirectory(dir=os.environ.get("VOLANIM_BENCH_DIR")) as tmp:
        folder = Path(tmp)
        logs = folder / "logs"
        logs.mkdir()
        t0 = time.perf_counter()
        for what in (name, "walk", "cluster"):
            done = run([*VOLANIM, "samples", what, "-o", str(folder)], logs / f"samples-{what}.log")
            if done.returncode:
                sys.exit((logs / f"samples-{what}.log").read_text()[-2000:])
        bones = folder / f"{name}.bones"
        assert bones.exists(), sorted(os.listdir(folder))
        made = time.perf_counter() - t0
        ref_store = folder / "one.zarr"
        t0 = time.perf_counter()
        one = run([*sequence_args(folder, name, frames, ref_store), "--workers", "1"], logs / "one.log")
        if one.returncode:
            sys.exit((logs / "one.log").read_text()[-2000:])
        one_s = time.perf_counter() - t0
        ref = manifest(ref_store)
        frame_bytes = bytes_on_disk(ref_store) // frames
        shutil.rmtree(ref_store)
        cluster = folder / "cluster-local.yaml"
        rows = [worker_killed(folder, name, frames, cluster, ref, logs),
                client_killed(folder, name, frames, cluster, ref, logs),
                disk_filled(folder, name, frames, cluster, ref, logs, frame_bytes)]
        print(f"\nfaults at {name} ({frames} walk frames, sampled, LocalCluster of 2 workers); sample made in "
              f"{made:.0f} s; the one-worker reference in {one_s:.0f} s; the store "
              f"{frame_bytes / 2**20:.2f} MB a frame")
        print(table(rows, ["fault", "how", "exit", "what happened", "frames identical to 1 worker"]))
        keep = os.environ.get("VOLANIM_BENCH_LOGS")
        if keep:
            shutil.copytree(logs, keep, dirs_exist_ok=True)


if __name__ == "__main__":
    main()
