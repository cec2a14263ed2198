"""Run a fault corpus and tabulate it: tried / clean / crash / hang / memory / silent per target.

    python tests/faults/run.py          # the whole corpus (as test_fault_corpus.py runs it), table on stdout

Outcomes:
    clean   refused with FormatError/OSError (CLI: exit 2, no traceback) naming the file,
            or, for an "accept" case, worked (and passed its check)
    crash   any other exception type, a traceback, a process killed by a signal
    hang    no answer within the time limit
    memory  MemoryError or an allocation abort under the memory cap
    silent  returned normally from input it should have refused, or refused without naming
            the file (or without saying what the case's ``says`` lists), or a legitimate file
            refused / read wrong
"""

from __future__ import annotations

import json
import os
import queue
import resource
import subprocess
import sys
import tempfile
import threading
from collections import Counter, defaultdict
from pathlib import Path

HERE = Path(__file__).resolve().parent
READ_TIMEOUT = 90.0
CLI_TIMEOUT = 300.0  # a fresh process may compile numba kernels (~25 s cold)
OUTCOMES = ("clean", "crash", "hang", "memory", "silent")


def _limit_memory():
    cap = 6 << 30
    resource.setrlimit(resource.RLIMIT_AS, (cap, cap))


def _classify_reader(case, result: dict | None, folder: Path) -> tuple[str, str]:
    if result is None:
        return "hang", "no answer"
    outcome = result["outcome"]
    if outcome == "memory":
        return "memory", result.get("message", "")
    if outcome == "exception":
        return "crash", result["message"]
    if outcome == "crashed":
        text = result.get("message", "")
        return ("memory" if "bad_alloc" in text or "MemoryError" in text else "crash"), text
    if case.expect == "accept":
        if outcome == "returned" and result.get("ok"):
            return "clean", "accepted"
        return "silent", result.get("message", "accepted but read wrong")
    if outcome == "returned":
        return "silent", "accepted"
    named = Path(case.arg).name in result["message"] and _says(case, result["message"])
    return ("clean" if named else "silent"), result["message"][:300]


def _says(case, message: str) -> bool:
    """Whether a refusal says what the case asks of it beyond the file's name (#89: which other file, which
    bone, how they differ, what to do)."""
    return all(part in message for part in case.says)


def _pump(stream, lines: queue.Queue) -> None:
    """Forward a worker's output lines to ``lines`` (None at the end), so the runner can wait with a timeout."""
    with stream:
        for line in stream:
            lines.put(line)
    lines.put(None)


def _run_readers(cases, folder: Path) -> dict[int, tuple[str, str]]:
    spec = [{"target": c.target, "path": str(folder / str(i) / c.arg), "check": c.check} for i, c in cases]
    spec_file = folder / "spec.json"
    spec_file.write_text(json.dumps(spec))
    results: dict[int, dict | None] = {}
    first = 0
    while first < len(spec):
        proc = subprocess.Popen([sys.executable, str(HERE / "worker.py"), str(spec_file), str(first)],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=folder)
        lines: queue.Queue = queue.Queue()
        threading.Thread(target=_pump, args=(proc.stdout, lines), daemon=True).start()
        current = first
        while True:
            try:
                line = lines.get(timeout=READ_TIMEOUT)
            except queue.Empty:  # the current case hangs
                proc.kill()
                proc.wait()
                proc.stderr.close()
                results[current] = None
                first = current + 1
                break
            if line is None:  # the worker ended: all done, or it died in the current case
                proc.wait()
                with proc.stderr:
                    err = proc.stderr.read()[-400:]
                if current < len(spec) and current not in results:
                    results[current] = {"outcome": "crashed", "message": f"exit {proc.returncode}: {err}"}
                first = current + 1
                break
            msg = json.loads(line)
            if msg.get("started"):
                current = msg["index"]
            else:
                results[msg["index"]] = msg
                current = msg["index"] + 1
        if first >= len(spec):
            break
    return {i: _classify_reader(cases[k][1], results.get(k), folder) for k, (i, _) in enumerate(cases)}


def _run_cli(case, folder: Path) -> tuple[str, str]:
    args = case.arg.format(d=str(folder)).split()
    env = dict(os.environ, PYTHONWARNINGS="ignore")
    try:
        out = subprocess.run([sys.executable, "-m", "volanim_core", *args], capture_output=True, text=True,
                             timeout=CLI_TIMEOUT, preexec_fn=_limit_memory, env=env, cwd=folder)
    except subprocess.TimeoutExpired:
        return "hang", f"over {CLI_TIMEOUT:.0f} s"
    err = out.stderr
    if out.returncode < 0:
        return ("memory" if "bad_alloc" in err else "crash"), f"signal {-out.returncode}: {err[-200:]}"
    if "Traceback" in err:
        return ("memory" if "MemoryError" in err else "crash"), err[-300:]
    if case.expect == "accept":
        return ("clean", "exit 0") if out.returncode == 0 else ("silent", f"refused: {err.strip()[:160]}")
    if out.returncode == 0:
        return "silent", f"exit 0: {out.stdout.strip()[-160:]}"
    files = [part for name in (*case.files, *case.sparse, *case.links)
             for part in (Path(name).name, Path(name).parts[0])]
    named = (any(f in err for f in files) or "error: argument" in err) and _says(case, err)
    return ("clean" if named else "silent"), err.strip()[-300:]


def run_corpus(cases, folder: Path) -> list[tuple[object, str, str]]:
    """``(case, outcome, detail)`` for every case; each case gets its own sub-folder."""
    for i, case in enumerate(cases):
        (folder / str(i)).mkdir(parents=True, exist_ok=True)
        case.write(folder / str(i))
    readers = [(i, c) for i, c in enumerate(cases) if not c.target.startswith("cli:")]
    outcomes = _run_readers(readers, folder) if readers else {}
    for i, case in enumerate(cases):
        if case.target.startswith("cli:"):
            outcomes[i] = _run_cli(case, folder / str(i))
    return [(case, *outcomes[i]) for i, case in enumerate(cases)]


def table(rows) -> str:
    per: dict[str, Counter] = defaultdict(Counter)
    for case, outcome, _ in rows:
        per[case.target][outcome] += 1
        per["all"][outcome] += 1
    width = max(len(t) for t in per) + 2
    lines = [f"{'target':<{width}}{'tried':>6}" + "".join(f"{o:>8}" for o in OUTCOMES)]
    for target in sorted(per, key=lambda t: (t == "all", t)):
        c = per[target]
        lines.append(f"{target:<{width}}{sum(c.values()):>6}" + "".join(f"{c[o]:>8}" for o in OUTCOMES))
    bad = [(case, outcome, detail) for case, outcome, detail in rows if outcome != "clean"]
    for case, outcome, detail in bad:
        lines.append(f"  {outcome.upper()}: {case.target} / {case.name}: {detail}")
    return "\n".join(lines)


if __name__ == "__main__":
    sys.path.insert(0, str(HERE.parents[1]))
    sys.path.insert(0, str(HERE.parent))  # tests/: paths.py
    from tests.faults.test_fault_corpus import CASES

    with tempfile.TemporaryDirectory() as tmp:
        print(table(run_corpus(CASES, Path(tmp))))
