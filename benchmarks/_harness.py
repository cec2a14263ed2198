"""Benchmark harness: each case runs in a fresh subprocess, so peak memory
(peak RSS of a warm call minus the RSS before it) and first-call (numba cache
load) times are real; the median of warm repeats gives the time.

A case is ``name -> callable(data) -> None``; ``data`` comes from a loader
that the child calls before measuring.
"""

from __future__ import annotations

import json
import resource
import statistics
import subprocess
import sys
import time

from volanim_core.limits import peak_rss  # VmHWM: a spawned child's own peak


def rss_bytes() -> int:
    with open("/proc/self/statm") as fh:
        return int(fh.read().split()[1]) * resource.getpagesize()


def _reset_peak() -> None:
    # Linux: writing 5 to clear_refs resets the peak RSS (VmHWM) of this process,
    # so imports and JIT compilation in the first call do not count as the case's memory.
    with open("/proc/self/clear_refs", "w") as fh:
        fh.write("5")


def child(cases: dict, loader, case: str, dataset: str, repeats: int) -> None:
    data = loader(dataset)
    fn = cases[case]
    t0 = time.perf_counter()
    fn(data)
    first = time.perf_counter() - t0
    _reset_peak()
    before = rss_bytes()
    fn(data)
    peak = peak_rss() - before
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn(data)
        times.append(time.perf_counter() - t0)
    print(json.dumps({"first": first, "time": statistics.median(times) if times else first, "peak": max(peak, 0)}))


def measure(script: str, case: str, dataset: str, repeats: int = 3, env=None) -> dict:
    out = subprocess.run([sys.executable, script, "--child", case, dataset, str(repeats)],
                         capture_output=True, text=True, env=env, check=False)
    if out.returncode:
        return {"error": out.stderr.strip().splitlines()[-1] if out.stderr else "failed"}
    return json.loads(out.stdout.strip().splitlines()[-1])


def best_of(fn, repeats: int = 5) -> float:
    """The fastest of ``repeats`` calls, in seconds (the least disturbed by the shared machine)."""
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)


def interleaved(fns: dict, rounds: int = 15) -> dict:
    """Median seconds of each of ``fns`` (name -> no-argument callable), called in turn round after
    round in this one process: the shared machine's speed drifts by 2x between minutes, so a ratio
    of two cases timed minutes apart (or in separate processes) is noise; taken round by round,
    both cases see the same machine. Each is called once first (compilation, caches)."""
    for fn in fns.values():
        fn()
    times = {name: [] for name in fns}
    for _ in range(rounds):
        for name, fn in fns.items():
            t0 = time.perf_counter()
            fn()
            times[name].append(time.perf_counter() - t0)
    return {name: statistics.median(ts) for name, ts in times.items()}


def table(rows: list[list], header: list[str]) -> str:
    """A plain-text table, or a Markdown one when ``VOLANIM_BENCH_MARKDOWN`` is set (``make docs``
    puts the benchmarks' own tables into the README)."""
    import os

    if os.environ.get("VOLANIM_BENCH_MARKDOWN"):
        cells = [[str(c).replace("|", "\\|") for c in r] for r in [header, *rows]]
        lines = ["| " + " | ".join(r) + " |" for r in cells]
        lines.insert(1, "|" + "---|" * len(header))
        return "\n".join(lines)
    cols = [header] + [[str(c) for c in r] for r in rows]
    widths = [max(len(r[i]) for r in cols) for i in range(len(header))]
    lines = [" | ".join(c.ljust(w) for c, w in zip(r, widths)) for r in cols]
    lines.insert(1, "-|-".join("-" * w for w in widths))
    return "\n".join(lines)
