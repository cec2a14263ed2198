"""Run documented commands as a newcomer would: in order, in a fresh folder, as printed.

Used by tests/test_documented_commands.py (every ``--help`` example and
every shell block of the README).

A plain ``volanim ARGS`` line (globs expanded in the folder as bash does, an ``|| echo …`` tail
allowed) runs through the CLI's ``main()`` in this interpreter (:func:`run_in_process`): the same
parser, the same code and the same exit status, without a new interpreter, imports and kernel
loads per line (147 processes were 22 of the suite's 72 minutes). Anything else -- ``make``,
``volanim-studio``, pipes, redirections -- and the lines the caller picks to prove the installed
entry point run in bash as their own process (:func:`run`).
"""

from __future__ import annotations

import argparse
import contextlib
import glob
import io
import os
import re
import shlex
import subprocess
import sys
import threading
import traceback
import warnings
from pathlib import Path

BIN = Path(sys.executable).parent  # the venv's scripts: volanim, volanim-studio


def environment() -> dict:
    """The venv's scripts first on PATH; pyvista windows render off-screen and return (``volanim view``);
    the studio quits once it has loaded what it was asked to (``VOLANIM_STUDIO_SMOKE``)."""
    env = dict(os.environ)
    env["PATH"] = f"{BIN}{os.pathsep}{env.get('PATH', '')}"
    env["PYVISTA_OFF_SCREEN"] = "true"
    env["VOLANIM_STUDIO_SMOKE"] = "1"
    env["CI"] = "1"  # `make demo` opens no studio window
    return env


def documented_argv(command: str) -> tuple[list[str], bool] | None:
    """``(argv after 'volanim', may fail)`` of a plain ``volanim ARGS`` line, where ``may fail`` is an
    ``|| echo …`` tail; None when the line needs a shell (another program, a pipe, a redirection, ``&&``)."""
    line, may_fail = command.split("#")[0].strip(), False
    if " || " in line:
        line, rest = line.split(" || ", 1)
        if not rest.strip().startswith("echo "):
            return None
        may_fail = True
    if re.search(r"[|&;<>`$(){}]", line):
        return None
    words = shlex.split(line)
    if not words or words[0] != "volanim":
        return None
    return words[1:], may_fail


def expand_globs(argv: list[str], cwd: Path) -> list[str]:
    """Each word with ``*``, ``?`` or ``[`` replaced by the files it matches in ``cwd``, sorted, as bash does
    (a word that matches nothing stays as it is)."""
    out = []
    for word in argv:
        found = sorted(glob.glob(word, root_dir=cwd)) if re.search(r"[*?\[]", word) else []
        out.extend(found or [word])
    return out


_ONE_AT_A_TIME = threading.Lock()  # the working folder and the environment are the whole process's


def run_in_process(argv: list[str], cwd: Path) -> subprocess.CompletedProcess:
    """``volanim ARGV`` through ``volanim_core.cli.main`` in this interpreter, in ``cwd``, with the
    environment :func:`environment` gives a process (pyvista off-screen, the studio's smoke mode), its
    output captured; an exception that escapes ``main`` is a traceback and status 1, as in a process."""
    import pyvista

    from volanim_core.cli import main

    argv = expand_globs(argv, cwd)
    out, err = io.StringIO(), io.StringIO()
    with _ONE_AT_A_TIME, contextlib.chdir(cwd), _environ(environment()), _attribute(pyvista, "OFF_SCREEN", True), \
            contextlib.redirect_stdout(out), contextlib.redirect_stderr(err), warnings.catch_warnings():
        warnings.resetwarnings()  # a process prints a warning the command gives the user; the suite's filter
        warnings.simplefilter("default")  # would raise it, and pytest's recorder would keep it from stderr
        warnings.showwarning = lambda message, category, filename, lineno, file=None, line=None: sys.stderr.write(
            warnings.formatwarning(message, category, filename, lineno, line))
        try:
            code = main(argv)
        except SystemExit as exc:  # argparse refusing the line
            code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
        except Exception:  # noqa: BLE001 -- a process would print the traceback and exit 1
            traceback.print_exc()
            code = 1
    return subprocess.CompletedProcess(["volanim", *argv], code, out.getvalue(), err.getvalue())


@contextlib.contextmanager
def _environ(values: dict):
    before = dict(os.environ)
    os.environ.update(values)
    try:
        yield
    finally:
        os.environ.clear()
        os.environ.update(before)


@contextlib.contextmanager
def _attribute(obj, name: str, value):
    before = getattr(obj, name)
    setattr(obj, name, value)
    try:
        yield
    finally:
        setattr(obj, name, before)


def run_documented(command: str, cwd: Path, *, as_process: bool = False) -> subprocess.CompletedProcess:
    """One documented line: in this interpreter when it is a plain ``volanim`` line and ``as_process`` is
    False, else in bash as typed. An ``|| echo …`` line's failure is what the line expects."""
    plain = documented_argv(command)
    if plain is None or as_process:
        return run(command, cwd)
    argv, may_fail = plain
    result = run_in_process(argv, cwd)
    if may_fail and result.returncode:
        result.returncode = 0
    return result


def join_continuations(lines: list[str]) -> list[str]:
    """Commands from lines, joining those that end in a backslash with the next."""
    out, pending = [], ""
    for line in lines:
        if line.rstrip().endswith("\\"):
            pending += line.rstrip()[:-1] + " "
            continue
        out.append((pending + line).strip())
        pending = ""
    if pending:
        out.append(pending.strip())
    return [c for c in out if c and not c.startswith("#")]


def help_examples(parser: argparse.ArgumentParser) -> list[tuple[str, str]]:
    """``(command, example)`` for the top-level help and every subcommand's, in the order ``--help`` lists them."""
    found = []

    def take(name, epilog):
        lines = (epilog or "").splitlines()
        starts = [i for i, line in enumerate(lines) if line.startswith("examples")]
        if not starts:
            return
        body = []
        for line in lines[starts[0] + 1:]:
            if line and not line.startswith(" "):
                break
            body.append(line)
        found.extend((name, c) for c in join_continuations(body))

    from volanim_core.cli import subcommands

    take("volanim", parser.epilog)
    for name, sub in subcommands(parser).items():
        take(name, sub.epilog)
    return found


def volanim(*args, cwd=None, timeout: float = 300) -> subprocess.CompletedProcess:
    """``volanim ARGS`` through the CLI's ``main()`` in this interpreter (:func:`run_in_process`), output and
    exit status captured as a process would give them: the CLI tests' runner. A new interpreter a call cost
    2.3 s of imports and kernel loads (88 calls in the default tier); :func:`volanim_process` is the real
    process, for what only one shows (the installed entry point, a crash's exit status)."""
    return run_in_process([str(a) for a in args], Path(cwd) if cwd is not None else Path.cwd())


def volanim_process(*args, cwd=None, timeout: float = 300) -> subprocess.CompletedProcess:
    """``volanim ARGS`` as its own process (this interpreter's), output captured."""
    return subprocess.run([sys.executable, "-m", "volanim_core", *map(str, args)], capture_output=True, text=True,
                          timeout=timeout, cwd=cwd)


def shell_blocks(markdown: str) -> list[str]:
    """The text of every ```sh fenced block, in order."""
    return re.findall(r"^```sh\n(.*?)^```", markdown, flags=re.S | re.M)


def run(command: str, cwd: Path, timeout: float = 600) -> subprocess.CompletedProcess:
    """One shell command (bash, stop at the first failure), as typed."""
    return subprocess.run(["bash", "-e", "-o", "pipefail", "-c", command], cwd=cwd, env=environment(),
                          capture_output=True, text=True, timeout=timeout)


def check(result: subprocess.CompletedProcess, command: str) -> None:
    assert result.returncode == 0, (f"`{command}` exited {result.returncode}\n--- stdout\n{result.stdout[-3000:]}"
                                    f"\n--- stderr\n{result.stderr[-3000:]}")
