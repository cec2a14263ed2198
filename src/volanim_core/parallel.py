"""Where many independent tasks run: this process, a local process pool, or a Dask cluster.

    with executor(task, payload, install, workers=N, scheduler=None) as (submit, label, n):
        futures = [submit(*args) for args in work]      # task(payload, *args) runs somewhere

One function serves frames of a sequence and frames of a render. The payload
(what every task needs: a connectivity, a source volume, render settings) is
handed to each worker once -- the local pool's initializer calls
``install(payload)`` and tasks get ``None``; a Dask cluster gets it scattered
and tasks get the future -- never once per task.
"""

from __future__ import annotations

import os
from concurrent.futures import Future
from contextlib import contextmanager


@contextmanager
def executor(task, payload, install, *, workers: int = 1, scheduler=None, isolate: bool = False):
    """``(submit(*args) -> Future, description, worker count)``; see the module docstring.

    ``scheduler``: a Dask scheduler address (``tcp://HOST:PORT``) or a ``distributed.Client``.
    ``isolate``: never run tasks in this process, even with one worker (the studio: an OpenGL
    context must not be made on a worker thread of a process whose main thread draws the window).
    """
    if scheduler is not None:
        from distributed import Client

        client = scheduler if isinstance(scheduler, Client) else Client(scheduler)
        try:
            shared = client.scatter(payload, broadcast=True, hash=False)  # shipped to each worker once
            ex = client.get_executor(pure=False)
            n = len(client.scheduler_info().get("workers", {}))
            yield (lambda *args: ex.submit(task, shared, *args)), f"Dask, {n} workers", n
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
    with ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn"), initializer=install,
                             initargs=(payload,)) as pool:
        try:
            label = f"{workers} local worker{'s' if workers > 1 else ''}"
            yield (lambda *args: pool.submit(task, None, *args)), label, workers
        finally:
            pool.shutdown(wait=True, cancel_futures=True)


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
