"""Worker processes, local or Dask, keep freed memory for the next task even where Dask's
``MALLOC_TRIM_THRESHOLD_`` is in the environment (a LocalCluster puts it in its parent's
environment, and a local pool started after it inherited it: every frame page-faulted its arrays
back in, and two workers ran 2x slower each)."""

from __future__ import annotations

import resource

import numpy as np

from volanim_core.parallel import executor

ROUNDS = 64


def faults_of_reused_arrays(payload, rounds: int) -> int:
    """Make and drop a 1 MiB array ``rounds`` times (a frame's scratch arrays); the page faults that cost.
    Under the 4 MiB at which numpy asks for huge pages, so each fresh mapping faults in 256 pages."""
    before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
    for _ in range(rounds):
        a = np.ones(1 << 20, np.uint8)
        del a
    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before


def nothing(payload) -> None:
    """The pool's per-worker install step (nothing to keep)."""


def test_a_local_pool_under_dasks_malloc_setting_reuses_freed_memory(monkeypatch):
    monkeypatch.setenv("MALLOC_TRIM_THRESHOLD_", "65536")  # what LocalCluster leaves in os.environ
    with executor(faults_of_reused_arrays, None, nothing, workers=2) as (submit, _, _n):
        faults = [submit(ROUNDS).result() for _ in range(2)]
    # without the fix: 256 faults a round (16 k); with it the first round maps the array, the rest reuse it
    assert max(faults) < 10 * ROUNDS, faults


def test_a_dask_worker_reuses_freed_memory():
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address="127.0.0.1:0") as cluster, Client(cluster) as client:
        # Dask starts its workers with MALLOC_TRIM_THRESHOLD_=65536 (distributed.nanny.pre-spawn-environ)
        assert client.run(lambda: __import__("os").environ.get("MALLOC_TRIM_THRESHOLD_"))
        with executor(faults_of_reused_arrays, None, nothing, scheduler=client) as (submit, _, _n):
            faults = [submit(ROUNDS).result() for _ in range(2)]
    assert max(faults) < 10 * ROUNDS, faults


def test_a_worker_whose_parent_died_while_it_started_ends_at_once():
    """#64: a parent killed while its pool's workers were still importing never sends them the death signal
    (it is asked for only once they start): one took a queued frame and outlived it by 3.6 s. A worker
    that finds another parent than the one that started it now ends in its initializer."""
    import subprocess
    import sys

    script = ("import os; from volanim_core.parallel import end_with_parent; "
              "end_with_parent(os.getppid()); print('kept'); end_with_parent(os.getppid() + 1); print('not ended')")
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=60)
    assert out.stdout.split() == ["kept"] and out.returncode == 1, (out.stdout, out.stderr)
