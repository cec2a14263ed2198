"""Flake check: run a test tier several times under a CPU load and name every test whose result changes.

    python tests/flake.py --runs 3 --load 2 -- -n 2 -m "not slow"      (make flake)

Each run is ``pytest ARGS --junitxml`` in this interpreter's environment while ``--load`` busy processes
spin beside it (what a shared machine or a CI neighbour does to timings). A test whose outcome (passed,
failed, error, skipped) differs between runs is a flake: it passes or fails by luck, and is listed with
its outcomes per run. Exit status 1 when there is any, 0 when every test gave the same result every time
(a test that fails every time is a defect, not a flake: it is listed apart and makes the status 1 too).
"""

from __future__ import annotations

import argparse
import multiprocessing
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def _spin(stop) -> None:
    while not stop.is_set():
        sum(i * i for i in range(10_000))


def outcomes(junit: Path) -> dict[str, str]:
    """``{test id: outcome}`` from a JUnit XML report."""
    found = {}
    for case in ET.parse(junit).iter("testcase"):
        name = f"{case.get('classname')}::{case.get('name')}"
        kinds = {child.tag for child in case}
        found[name] = ("failed" if "failure" in kinds else "error" if "error" in kinds
                       else "skipped" if "skipped" in kinds else "passed")
    return found


def compare(runs: list[dict[str, str]]) -> tuple[dict[str, list[str]], dict[str, list[str]]]:
    """``(flaky, always failing)``: tests whose outcome differs between runs (a test missing from a run
    counts as 'absent'), and tests that failed or errored in every run."""
    names = sorted(set().union(*runs))
    every = {n: [r.get(n, "absent") for r in runs] for n in names}
    flaky = {n: o for n, o in every.items() if len(set(o)) > 1}
    broken = {n: o for n, o in every.items() if len(set(o)) == 1 and o[0] in ("failed", "error")}
    return flaky, broken


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--runs", type=int, default=3, help="how many times to run the tier (default 3)")
    parser.add_argument("--load", type=int, default=2, help="busy processes beside each run (default 2: both cores)")
    parser.add_argument("pytest_args", nargs="*", help="after --: pytest's own arguments (default: -m 'not slow')")
    args = parser.parse_args(argv)
    pytest_args = args.pytest_args or ["-m", "not slow"]
    stop = multiprocessing.Event()
    load = [multiprocessing.Process(target=_spin, args=(stop,), daemon=True) for _ in range(args.load)]
    for p in load:
        p.start()
    runs, folder = [], Path(tempfile.mkdtemp(prefix="volanim-flake-"))
    try:
        for i in range(args.runs):
            junit = folder / f"run{i}.xml"
            t0 = time.monotonic()
            done = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                                   f"--junitxml={junit}", *pytest_args], cwd=REPO)
            runs.append(outcomes(junit))
            counts = {k: list(runs[-1].values()).count(k) for k in ("passed", "failed", "error", "skipped")}
            print(f"flake: run {i + 1}/{args.runs} under {args.load} busy processes: exit {done.returncode}, "
                  f"{counts}, {time.monotonic() - t0:.0f} s", flush=True)
    finally:
        stop.set()
        for p in load:
            p.join(5)
    flaky, broken = compare(runs)
    print(f"flake: {len(runs[0])} tests, {args.runs} runs: {len(flaky)} changed result, {len(broken)} failed every run")
    for name, seen in flaky.items():
        print(f"  FLAKY   {name}: {' / '.join(seen)}")
    for name in broken:
        print(f"  FAILING {name}")
    return 1 if flaky or broken else 0


if __name__ == "__main__":
    sys.exit(main())
