"""The ``volanim`` command line: one subcommand per tool of the old pipeline.

Each subcommand lives in the module of the core package it runs, with a
``register(subparsers)`` function; ``main`` turns library errors into one-line
messages (exit 2) and a cancel (Ctrl+C) into exit 130, never a traceback.

    volume_commands.py ....... info, convert, threshold, fill, crop, ... (the volume tools, io)
    skeleton_commands.py ..... skeletonize, isosurface (skeleton/)
    combine_commands.py ...... peek, onevolume, addskel (volumes with skeletons)
    rig_commands.py .......... autorig, connect, pose, straighten, the .tskel tools, mirror (rig/)
    motion_commands.py ....... keys, bvh2trans, trans2bvh, trans2positions, positions2trans, trans2tskel (motion/)
    reconstruct_commands.py .. bounds, reconstruct, compare, report, scan (reconstruct/)
    sequence_commands.py ..... crumble, sequence (sequence/)
    render_commands.py ....... render (render/)
    colour_commands.py ....... the palette tools (colour/)
    slicer_commands.py ....... markups, transforms, displacement (3D Slicer's files)
    view_command.py .......... view (a quick look)
    demo_command.py .......... warmup, demo
    _common.py ............... the options and argument types the commands share
"""

from __future__ import annotations

import argparse
import contextlib
import errno
import sys
from pathlib import Path

from volanim_core.errors import Cancelled, FormatError

from . import (
    colour_commands,
    combine_commands,
    demo_command,
    motion_commands,
    reconstruct_commands,
    render_commands,
    rig_commands,
    sequence_commands,
    skeleton_commands,
    slicer_commands,
    view_command,
    volume_commands,
)
from ._common import join_dash_values

EPILOG = """examples:
  volanim samples all -o data/                # the demo volumes, bones and the walk clip
  volanim info data/mannequin.VOL             # size, value range, bounds
  volanim threshold data/mannequin.VOL mask.VOL --range 1:255
  volanim demo -o demo-out/                   # the whole pipeline, headless

Run 'volanim COMMAND --help' for each command's options and an example."""


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="volanim",
        description="Volume animation: segment, skeletonize, connect, pose and reconstruct volumes.",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    from .. import __version__

    parser.add_argument("--version", action="version", version=f"volanim {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    # the pipeline's order: a volume, its skeleton, the rig, its motion, the reconstruction and its checks,
    # sequences and movies (each command's example runs on the files the ones before it wrote)
    for module in (volume_commands, skeleton_commands, combine_commands, rig_commands, motion_commands,
                   reconstruct_commands, sequence_commands, render_commands, colour_commands, slicer_commands,
                   view_command, demo_command):
        module.register(sub)
    return parser


def subcommands(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    """Each subcommand's parser, in the order ``volanim --help`` lists them."""
    return next(a.choices for a in parser._actions if isinstance(a, argparse._SubParsersAction))


OUTPUT_ARGS = ("output", "out", "dst", "o")


def _input_files(args) -> list[str]:
    """The command's input files as given (positional paths that exist), for naming them in errors."""
    found = []
    for key, value in vars(args).items():
        if key in OUTPUT_ARGS or not isinstance(value, str) or key == "command":
            continue
        with contextlib.suppress(OSError, ValueError):
            if Path(value).exists():
                found.append(value)
    return found


def describe(exc: BaseException, args) -> str:
    """One line for the user: FormatErrors and OSErrors name their file; other refusals get the input's name
    (but a connection's failure is the network's, not an input's: it names what it could not reach)."""
    text = str(exc) or type(exc).__name__
    if isinstance(exc, (FormatError, ConnectionError)):
        return text
    if isinstance(exc, OSError) and exc.filename:
        return f"{exc.filename}: {exc.strerror or text}"
    if isinstance(exc, OSError) and exc.errno == errno.ENOSPC:  # the output did not fit, not the input's fault
        outputs = [str(v) for k, v in vars(args).items() if k in OUTPUT_ARGS and isinstance(v, str | Path)]
        if outputs:
            return f"{', '.join(outputs)}: {text} ({_free(outputs[0])})"
    inputs = _input_files(args)
    if inputs and not any(Path(f).name in text for f in inputs):
        return f"{', '.join(inputs)}: {text}"
    return text


def _free(path: str) -> str:
    """How much room is left where ``path`` was being written, for a disk-full message."""
    import os

    from volanim_core.limits import human_bytes

    folder = Path(path).parent if not Path(path).is_dir() else Path(path)
    try:
        room = os.statvfs(folder if str(folder) else ".")
    except OSError:
        return "the free room could not be read"
    return f"{human_bytes(room.f_bavail * room.f_frsize)} free there"


def _quiet_stdout() -> None:
    """Point stdout at /dev/null, so the interpreter's final flush does not fail on the closed pipe."""
    import os

    with contextlib.suppress(OSError, ValueError):
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(join_dash_values(list(sys.argv[1:] if argv is None else argv)))
    if not getattr(args, "func", None):
        parser.print_help()
        return 0
    try:
        result = args.func(args)
    except BrokenPipeError:  # `volanim count … | head`: the reader had enough; not an error of ours
        _quiet_stdout()
        return 0
    except (FormatError, ValueError, OSError, MemoryError) as exc:
        print(f"volanim {args.command}: error: {describe(exc, args)}", file=sys.stderr)
        return 2
    except (Cancelled, KeyboardInterrupt):
        print(f"\nvolanim {args.command}: cancelled", file=sys.stderr)
        return 130
    return int(result or 0)
