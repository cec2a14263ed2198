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
"""

from __future__ import annotations

import os
import sys
from concurrent.futures import Future
from contextlib import contextmanager
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

    # spawn, not fork: zarr's I/O thread, numba's threads and an OpenGL context do not survive a fork
    with ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn"), initializer=_start_worker,
                             initargs=(install, payload, os.getpid())) as pool:
        try:
            label = f"{workers} local worker{'s' if workers > 1 else ''}"
            yield (lambda *args: pool.submit(task, None, *args)), label, 2 * workers
        finally:
            pool.shutdown(wait=True, cancel_futures=True)


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


def _start_worker(install, payload, parent: int | None = None) -> None:
    """A local pool worker's initializer."""
    end_with_parent(parent)
    keep_freed_memory()
    install(payload)


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
