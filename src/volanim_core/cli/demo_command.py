"""``volanim demo``: the whole pipeline, headless, on the bundled mannequin."""

from __future__ import annotations

from pathlib import Path

from ._common import add_command


def _demo(args) -> int:
    from volanim_core.pipeline_demo import run_demo

    run_demo(Path(args.output), sample=args.sample)
    return 0


def register(sub) -> None:
    p = add_command(sub, "demo", "Run the pipeline headless on a demo dataset and write every file.",
                    "volanim demo -o demo-out/", _demo)
    p.add_argument("-o", "--output", default="demo-out", help="folder for the results (default demo-out/)")
    p.add_argument("--sample", default="mannequin", choices=("mannequin", "frog"), help="dataset (default mannequin)")
