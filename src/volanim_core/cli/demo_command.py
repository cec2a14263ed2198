"""``volanim demo``: the whole pipeline, headless, on the bundled mannequin; ``volanim warmup``: its kernels
compiled once, ahead of any real work."""

from __future__ import annotations

from pathlib import Path

from ._common import add_command


def _demo(args) -> int:
    from volanim_core.pipeline_demo import run_demo

    run_demo(Path(args.output), sample=args.sample)
    return 0


def _warmup(args) -> int:
    import sys

    from volanim_core.progress import TextProgress
    from volanim_core.warmup import compile_kernels

    bar = TextProgress("compiling kernels")
    seconds = compile_kernels(progress=bar)
    bar.close()
    print(f"kernels ready in {seconds:.1f} s (kept in the package's __pycache__: later runs load them)",
          file=sys.stdout)
    return 0


def register(sub) -> None:
    add_command(sub, "warmup", "Compile every numba kernel once (a fresh install: ~30 s; then well under a second), "
                "so no command or studio action waits on a compile.", "volanim warmup", _warmup)
    p = add_command(sub, "demo", "Run the pipeline headless on a demo dataset and write every file.",
                    "volanim demo -o demo-out/", _demo)
    p.add_argument("-o", "--output", default="demo-out", help="folder for the results (default demo-out/)")
    p.add_argument("--sample", default="mannequin", choices=("mannequin", "frog"), help="dataset (default mannequin)")
