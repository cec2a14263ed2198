"""Where many independent tasks run: this process, a local process pool, or a Dask cluster.

    with executor(task, payload, install, workers=N, scheduler=None) as (submit, label, in_flight):
        futures = [submit(*args) for args in work]      # task(payload, *args) runs somewhere
        # keep ``in_flight`` submitted and not yet collected: 2 per worker (one running, one queued so no
        # worker waits on the driver), 1 in this process (a task runs when it is submitted)

One function serves frames of a sequence and frames of a render. The payload
(what every task needs: a connectivity, a source volume, render settings) is
handed to each worker once -- the local pool's initializer calls
``install(payload)`` and tasks get ``None``; a Dask cluster gets it scattered
and tasks get the future -- never once per task.

Every worker process, local or Dask, first undoes ``MALLOC_TRIM_THRESHOLD_``
(:func:`keep_freed_memory`).

    finished, pending = wait_some(pending, cancel)   # cancel() is asked while waiting, not only between tasks

A local worker that dies (killed, out of memory) fails the job at once with a
ChildProcessError that says so; a job that is cancelled or fails ends its pool's
processes after a short grace, so a hung worker never holds it (#83: a dead
render worker left the studio at 0 % and Cancel did nothing for a minute).
"""

from __future__ import annotations

import os
import sys
from concurrent.futures import Future
from contextlib import contextmanager, suppress
from dataclasses import dataclass
from functools import cache


@dataclass(frozen=True)
class RunOn:
    """Where a job's tasks run (a sequence's frames, a render's pictures): ``workers`` local processes
    (1: this process), or the Dask ``scheduler`` at an address (``tcp://HOST:PORT``) or a
    ``distributed.Client``; ``threads_per_worker`` numba threads in each (sequences); ``isolate``: never in
    this process, even with one worker (see :func:`executor`)."""

    workers: int | None = None
    scheduler: object = None
    threads_per_worker: int = 1
    isolate: bool = False


THIS_PROCESS = RunOn()  # one worker, this process: the default of every job


@contextmanager
def executor(task, payload, install, *, workers: int = 1, scheduler=None, isolate: bool = False):
    """``(submit(*args) -> Future, description, tasks to keep in flight)``; see the module docstring.

    ``scheduler``: a Dask scheduler address (``tcp://HOST:PORT``) or a ``distributed.Client``.
    ``isolate``: never run tasks in this process, even with one worker (the studio: an OpenGL
    context must not be made on a worker thread of a process whose main thread draws the window).
    """
    if scheduler is not None:
        from distributed import Client

        client = scheduler if isinstance(scheduler, Client) else dask_client(scheduler)
        try:
            shared = client.scatter(payload, broadcast=True, hash=False)  # shipped to each worker once
            ex = client.get_executor(pure=False)
            n = len(client.scheduler_info().get("workers", {}))
            yield (lambda *args: ex.submit(_on_dask_worker, task, shared, *args)), f"Dask, {n} workers", 2 * max(n, 1)
        finally:
            if client is not scheduler:
                client.close()
        return
    if workers <= 1 and not isolate:
        install(payload)
        yield (lambda *args: _inline(task, args)), "1 worker (this process)", 1
        return
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor
    from concurrent.futures.process import BrokenProcessPool

    # spawn, not fork: zarr's I/O thread, numba's threads and an OpenGL context do not survive a fork. The
    # payload goes through a file, not the initializer's arguments: spawn writes those into a pipe whose
    # reading end the parent itself holds open until the write ends, so a worker that died while starting
    # (killed, out of memory) left a payload larger than the pipe's 64 KiB blocked there forever, and the
    # job with it (#83: a render stuck at 0 %, deaf to Cancel).
    with _payload_file(payload) as payload_path, ProcessPoolExecutor(
            workers, mp_context=multiprocessing.get_context("spawn"), initializer=_start_worker,
            initargs=(install, payload_path, os.getpid())) as pool:
        submitted: list[Future] = []

        def submit(*args) -> Future:
            fut = pool.submit(task, None, *args)
            submitted.append(fut)
            return fut

        label = f"{workers} local worker{'s' if workers > 1 else ''}"
        try:
            yield submit, label, 2 * workers
        except BrokenProcessPool:
            _stop_workers(pool, [])
            raise ChildProcessError(
                f"a worker process ({label}) died while working: killed, or out of memory; what was finished "
                "before is kept, so running it again goes on from there") from None
        except BaseException:  # cancelled, or an error: the running tasks get a moment, then their processes go
            _stop_workers(pool, submitted)
            raise
        finally:
            pool.shutdown(wait=True, cancel_futures=True)


#: How long a cancelled or failed job's running tasks may take to finish (a frame being written is kept)
#: before their processes are ended: a hung or very slow worker must not hold the job (#83).
STOP_GRACE_SECONDS = 2.0


def _stop_workers(pool, submitted: list[Future]) -> None:
    """Kill the pool's processes once the tasks under way finished or ``STOP_GRACE_SECONDS`` passed (what
    has not started is cancelled by the pool's own shutdown: a future cancelled here, behind the pool's
    back, made its manager thread fail with InvalidStateError once the pool broke)."""
    from concurrent.futures import wait

    running = [f for f in submitted if f.running()]
    if running:
        wait(running, timeout=STOP_GRACE_SECONDS)
    kill = getattr(pool, "kill_workers", None)  # Python 3.14
    if kill is not None:
        kill()
        return
    for proc in list((getattr(pool, "_processes", None) or {}).values()):  # the same on 3.11-3.13
        if proc.is_alive():
            proc.kill()  # SIGKILL: a stopped (hung, swapped-out) process never acts on SIGTERM


def wait_some(pending, cancel=None, *, poll_seconds: float = 0.25):
    """``(finished, rest)`` of the futures ``pending``, at least one finished; ``cancel()`` is asked every
    ``poll_seconds`` meanwhile (Cancelled when it says so), so a job waiting on one long or hung task still
    stops when told. Without ``cancel``: concurrent.futures.wait(FIRST_COMPLETED)."""
    from concurrent.futures import FIRST_COMPLETED, wait

    from volanim_core.errors import Cancelled

    while True:
        finished, rest = wait(pending, timeout=None if cancel is None else poll_seconds,
                              return_when=FIRST_COMPLETED)
        if finished:
            return finished, rest
        if cancel():
            raise Cancelled("cancelled by the user")


def dask_client(address: str):
    """A ``distributed.Client`` of the scheduler at ``address``; one not reached (within Dask's
    ``distributed.comm.timeouts.connect``, 30 s by default) is a ConnectionError that names it."""
    from distributed import Client

    try:
        return Client(address)
    except OSError as exc:  # distributed's "Timed out trying to connect to ... after 30 s"
        raise ConnectionError(f"cannot reach the Dask scheduler at {address}: {exc}") from exc


@cache  # once per process
def keep_freed_memory() -> None:
    """Let this process's malloc keep freed memory for the next frame, as glibc does by default.

    Dask sets ``MALLOC_TRIM_THRESHOLD_=65536`` for its workers -- and in the environment of the
    process that starts a ``LocalCluster``, so a local pool started after it inherits it too. A
    fixed trim threshold turns off glibc's growing mmap threshold: every array over 128 KiB is then
    mapped fresh and page-faulted in, 4 KiB at a time, every frame. Measured on the frog: 47 k page
    faults and +93 ms of kernel time a frame (166 -> 243 ms), and two such workers 2x slower each.
    The fix sets glibc's own defaults' ceiling: arrays under 32 MiB reuse freed memory and up to
    64 MiB of it is kept. Only where the variable is set, and only on glibc (Linux).
    """
    if "MALLOC_TRIM_THRESHOLD_" not in os.environ or not sys.platform.startswith("linux"):
        return
    import ctypes

    try:
        libc = ctypes.CDLL("libc.so.6")
    except OSError:  # not glibc (musl): its malloc has no such setting
        return
    m_trim_threshold, m_mmap_threshold = -1, -3  # <malloc.h>
    libc.mallopt(m_mmap_threshold, 32 << 20)
    libc.mallopt(m_trim_threshold, 64 << 20)


def end_with_parent(parent: int | None = None) -> None:
    """Ask Linux to kill this process when the one that started it dies (prctl PR_SET_PDEATHSIG): a
    ``sequence`` killed with -9 left its pool's workers computing frames for half a minute (#64).
    ``parent``: its pid. A parent killed while this process was still starting (its imports take
    seconds) never signals it, so it ends here instead of taking a queued frame."""
    import ctypes
    import signal

    try:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(1, int(signal.SIGKILL), 0, 0, 0)  # 1: PR_SET_PDEATHSIG
    except (OSError, AttributeError):  # not Linux: the pool's own shutdown is all there is
        return
    if parent is not None and os.getppid() != parent:
        os._exit(1)


@contextmanager
def _payload_file(payload):
    """``payload`` pickled once into a private temporary file (its path while the pool lives)."""
    import pickle
    import tempfile

    fd, path = tempfile.mkstemp(prefix="volanim-payload-", suffix=".pickle")
    try:
        with os.fdopen(fd, "wb") as fh:
            pickle.dump(payload, fh, protocol=pickle.HIGHEST_PROTOCOL)
        yield path
    finally:
        with suppress(OSError):
            os.unlink(path)


def _start_worker(install, payload_path: str, parent: int | None = None) -> None:
    """A local pool worker's initializer: the payload read from its file (see :func:`executor`)."""
    import pickle

    end_with_parent(parent)
    keep_freed_memory()
    with open(payload_path, "rb") as fh:
        install(pickle.load(fh))


def _on_dask_worker(task, *args):
    """A task on a Dask worker (the first one there tunes malloc for the rest)."""
    keep_freed_memory()
    return task(*args)


def _inline(task, args) -> Future:
    """A finished Future, so this process runs tasks through the same loop as a pool."""
    fut: Future = Future()
    try:
        fut.set_result(task(None, *args))
    except Exception as exc:  # handed to the caller through the future, like a pool would
        fut.set_exception(exc)
    return fut


def default_workers() -> int:
    """The cores this process may use."""
    return max(1, len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1)
