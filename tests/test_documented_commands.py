"""The documented commands run as printed: every ```sh block of the README and of the docs site's tutorials,
and every example in ``volanim --help`` and ``volanim COMMAND --help``.

**README and tutorials.** Every ```sh block of the README, then of each tutorial page in the order of
``docs/tutorials/index.md``'s table of contents, in one fresh folder (a page may use what an earlier one
made, as a reader following them in order has it). The README's opening block is the two
commands every newcomer types: ``make demo`` runs against this repository with its output folder
in the fresh folder (``DEMO_OUT``; later blocks use ``demo-out/``), and ``make test`` is skipped
because it is the command running this test. Studio commands start the real window, load what
they were given and quit (``VOLANIM_STUDIO_SMOKE``: status 1 if an error dialog appeared);
``volanim view`` renders off-screen and returns (``PYVISTA_OFF_SCREEN``). The demo's own results
are checked here too, so the demo runs once per test session.

**--help examples.** In order in another fresh folder, as a newcomer would try them: first the
``samples`` example (every other example starts from its files), then each command's examples in
the order ``volanim --help`` lists the commands; an example may use the files of an earlier one.
The top-level examples run in a folder of their own. ``volanim demo`` is the one example not run
there: it is what ``make demo`` runs, and the README chain runs that.

**Where they run** (``runnable.run_documented``). Plain ``volanim`` lines run through the CLI's
``main()`` in this interpreter; the first example of every subcommand runs as its own process with
the installed ``volanim`` script, so each subcommand's entry point is proven too, as are ``make demo``
and the studio. The two chains are ``slow`` (``make test-all``); the default tier checks that every
documented line is accepted by its subcommand's parser, in a second.
"""

from __future__ import annotations

import numpy as np
import pytest

from paths import REPO
from runnable import check, documented_argv, help_examples, join_continuations, run, run_documented, shell_blocks
from volanim_core import io
from volanim_core.cli import build_parser
from volanim_core.cli._common import join_dash_values

FIRST_BLOCK = ["make demo", "make test"]
DEMO = "volanim demo -o demo-out/"


def _commands(block: str) -> list[str]:
    return [line.split("#")[0].strip() for line in block.splitlines() if line.split("#")[0].strip()]


def tutorial_pages() -> list:
    """The tutorials in the order of their table of contents (``docs/tutorials/index.md``)."""
    index = (REPO / "docs" / "tutorials" / "index.md").read_text(encoding="utf-8")
    toc = index.split("```{toctree}", 1)[1].split("```", 1)[0]
    names = [line.strip() for line in toc.splitlines() if line.strip() and not line.strip().startswith(":")]
    return [REPO / "docs" / "tutorials" / f"{name}.md" for name in names]


def _readme_blocks() -> list[str]:
    return shell_blocks((REPO / "README.md").read_text(encoding="utf-8"))


def _readme_lines() -> list[str]:
    """Every command of the README after its opening block, then of every tutorial, continuation lines joined."""
    blocks = _readme_blocks()[1:] + [b for page in tutorial_pages() for b in shell_blocks(page.read_text("utf-8"))]
    return [c for b in blocks for c in join_continuations(b.splitlines())]


def test_the_readme_opens_with_the_two_commands():
    blocks = _readme_blocks()
    assert _commands(blocks[0]) == FIRST_BLOCK
    assert len(blocks) >= 2, "the quick start"
    pages = tutorial_pages()
    assert len(pages) >= 12 and all(p.is_file() for p in pages), pages
    blocks += [b for page in pages for b in shell_blocks(page.read_text(encoding="utf-8"))]
    assert len(blocks) >= 20, "the tutorials' command blocks"
    commands = [c for b in blocks[1:] for c in _commands(b)]
    assert not [c for c in commands if "..." in c or "HOST" in c], "a shell block is run: no placeholders in it"


def test_the_help_examples_are_commands_of_their_own_program():
    found = help_examples(build_parser())
    assert len({name for name, _ in found}) >= 30, "every subcommand has an example"
    for name, command in found:
        assert command.split()[0] == "volanim", command
        assert name == "volanim" or command.split()[1] == name, f"{name}'s example runs another command: {command}"
        assert "..." not in command and "HOST" not in command, f"placeholders do not run: {command}"
    demos = [c.split("#")[0].strip() for _, c in found if c.startswith("volanim demo")]
    assert demos and set(demos) == {DEMO}, "volanim demo is skipped in the examples only because make demo runs it"


def test_every_documented_volanim_line_is_accepted_by_its_subcommand_s_parser(capsys):
    """The default tier's check of the chains: every README, tutorial and --help line that runs ``volanim`` parses
    (an option renamed or removed, a typo, a missing argument); running them is ``make test-all``'s."""
    lines = _readme_lines() + [c for _, c in help_examples(build_parser())]
    plain = [(line, documented_argv(line)) for line in lines]
    assert sum(p is not None for _, p in plain) >= 150, "the documented lines are found"
    refused = []
    for line, found in plain:
        if found is None:
            assert line.split()[0] in ("volanim-studio", "volanim"), f"a documented line runs another program: {line}"
            continue
        try:
            build_parser().parse_args(join_dash_values(found[0]))
        except SystemExit:
            refused.append(f"{line}\n    {capsys.readouterr().err.strip().splitlines()[-1]}")
    assert not refused, "documented lines the parser refuses:\n" + "\n".join(refused)


@pytest.mark.slow
def test_the_readme_and_the_tutorials_run_as_printed_in_a_fresh_folder(tmp_path):
    folder = tmp_path / "newcomer"
    folder.mkdir()
    demo = run(f"make -s -C {REPO} demo DEMO_OUT={folder / 'demo-out'}", folder)
    check(demo, "make demo")
    _check_demo(demo.stdout, folder / "demo-out")
    for command in _readme_lines():
        check(run_documented(command, folder), command)
    # what the blocks promise, spot-checked
    assert (folder / "data" / "walk.bvh").is_file() and (folder / "data" / "frog.VOL").is_file()
    assert (folder / "mannequin.0.50.connect").is_file() and len(list((folder / "walk").glob("*.tskel"))) > 10
    assert (folder / "walk.mp4").stat().st_size > 0 and (folder / "skin.tf").is_file()
    assert len(list((folder / "frames").glob("walk.*.vti"))) == len(list((folder / "walk").glob("*.trans")))


@pytest.mark.slow
def test_every_help_example_runs_as_printed_in_fresh_folders(tmp_path):
    found = help_examples(build_parser())
    top = [c for name, c in found if name == "volanim" and not c.startswith("volanim demo")]
    first = [(n, c) for n, c in found if n == "samples"]
    rest = [(n, c) for n, c in found if n not in ("volanim", "samples") and not c.startswith("volanim demo")]
    folder = tmp_path / "commands"
    folder.mkdir(parents=True)
    proven: set[str] = set()  # subcommands whose entry point ran as a process
    for name, command in first + rest:
        check(run_documented(command, folder, as_process=name not in proven), command)
        proven.add(name)
    assert len(proven) >= 30
    assert len(list(folder.glob("arm-bone.*x*x*.vol"))) == 1  # a headerless .vol is named by its size
    assert (folder / "walk.mp4").stat().st_size > 0 and (folder / "hull.png").stat().st_size > 0
    own = tmp_path / "top"
    own.mkdir()
    for command in top:
        check(run_documented(command, own), command)


def _check_demo(text: str, out) -> None:
    """What `make demo` promises: every stage's file, sampled values from the source, the walk, the movie."""
    for stage in ("[1] sample", "[2] skeleton", "[3] connectivity (bundled", "[4] identity", "[5] L_UPPERARM",
                  "[6] walk.bvh: 1064 frames", "[7] sequence: 24 frames of one walk cycle and 10 of crumbling",
                  "[8] render: 34 frames"):
        assert stage in text, stage
    source = io.read_volume(out / "mannequin.VOL")
    rest = io.read_scan(out / "rest-sampled.vti").data
    posed, placed, _ = io.read_scan(out / "arm-sampled.vti")
    origin = placed.origin  # the geometry's origin: where voxel [0, 0, 0] is
    assert set(np.unique(posed)) <= set(np.unique(source))  # sampled values come from the source
    assert (rest > 0).sum() > 0.99 * (source > 0).sum()
    assert origin[0] < 13  # the raised arm reaches further out than the rest pose
    assert len(list((out / "walk").glob("walk.*.tskel"))) == 8
    first, placed, _ = io.read_scan(out / "walk" / "walk.0000-sampled.vti")
    o0 = placed.origin  # the geometry's origin: where voxel [0, 0, 0] is
    _, placed, _ = io.read_scan(out / "walk" / "walk.0532-sampled.vti")
    o1 = placed.origin  # the geometry's origin: where voxel [0, 0, 0] is
    assert abs(int((first > 0).sum()) - int((rest > 0).sum())) < 0.1 * (rest > 0).sum()  # same body, posed
    assert o1[1] < o0[1] - 100  # the mannequin walked forward (-y) across the clip
    from volanim_core.sequence import store

    assert store.open_frames(out / "walk.zarr").shape[0] == 34 and len(store.finished(out / "walk.zarr")) == 34
    import imageio.v3 as iio

    movie = iio.imread(out / "walk.gif", index=None)
    assert movie.shape[1:3] == (240, 320) and 30 <= len(movie) <= 34
    lit = [(m[..., :3].astype(int).sum(-1) > 150).sum() for m in movie]
    assert min(lit) > 200 and lit[-1] < lit[0] / 2  # a figure in every frame; the heap is smaller
