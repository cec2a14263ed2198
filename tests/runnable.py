"""Run documented commands as a newcomer would: in order, in a fresh folder, with the installed scripts.

Used by tests/test_documented_commands.py (every ``--help`` example and
every shell block of the README).
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
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
    """``volanim ARGS`` as its own process (this interpreter's), output captured: the CLI tests' runner."""
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
