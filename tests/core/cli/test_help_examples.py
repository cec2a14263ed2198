"""Every example in ``volanim --help`` and ``volanim COMMAND --help`` runs as printed.

They run in order in one fresh folder, as a newcomer would try them: first the
``samples`` example (every other example starts from its files), then each
command's examples in the order ``volanim --help`` lists the commands; an example
may use the files of an earlier one. The top-level examples run in a folder of
their own. ``volanim demo`` is the one example not run here: it is what
``make demo`` runs, and tests/test_readme.py runs that.
"""

from __future__ import annotations

from runnable import check, help_examples, run
from volanim_core.cli import build_parser

DEMO = "volanim demo -o demo-out/"


def examples():
    return help_examples(build_parser())


def test_the_examples_are_commands_of_their_own_program():
    found = examples()
    names = {name for name, _ in found}
    assert len(names) >= 30, "every subcommand has an example"
    for name, command in found:
        assert command.split()[0] == "volanim", command
        assert name == "volanim" or command.split()[1] == name, f"{name}'s example runs another command: {command}"
        assert "..." not in command and "HOST" not in command, f"placeholders do not run: {command}"


def test_every_help_example_runs_in_order_in_a_fresh_folder(tmp_path):
    found = examples()
    top = [c for name, c in found if name == "volanim"]
    per_command = [(n, c) for n, c in found if n != "volanim"]
    first = [c for n, c in per_command if n == "samples"]
    rest = [c for n, c in per_command if n != "samples"]
    demos = [c.split("#")[0].strip() for c in rest + top if c.startswith("volanim demo")]
    assert demos and set(demos) == {DEMO}, "volanim demo is skipped here only because test_readme runs it (make demo)"
    folder = tmp_path / "examples"
    folder.mkdir()
    for command in first + [c for c in rest if not c.startswith("volanim demo")]:
        check(run(command, folder), command)
    assert len(list(folder.glob("arm-bone.*x*x*.vol"))) == 1  # a headerless .vol is named by its size
    assert (folder / "walk.mp4").stat().st_size > 0 and (folder / "hull.png").stat().st_size > 0
    own = tmp_path / "top"
    own.mkdir()
    for command in top:
        if not command.startswith("volanim demo"):
            check(run(command, own), command)
