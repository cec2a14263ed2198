"""Argument helpers shared by the subcommand modules."""

from __future__ import annotations

import argparse

from volanim_core.io import read_volume, write_volume
from volanim_core.volume import Bounds


def add_command(sub, name: str, help: str, example: str, func) -> argparse.ArgumentParser:
    """A subparser whose ``--help`` ends with an example."""
    p = sub.add_parser(
        name, help=help, description=help, epilog=f"example:\n  {example}",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.set_defaults(func=func)
    return p


def add_volume_in(p: argparse.ArgumentParser, name: str = "volume", help: str = "input volume") -> None:
    p.add_argument(name, help=f"{help} (.vol with --dims or NAME.XxYxZ.vol, .VOL, .vti, .nrrd, .nii, .mha, "
                   "or a folder of slices)")


def add_dims(p: argparse.ArgumentParser) -> None:
    p.add_argument("--dims", nargs=3, type=int, metavar=("X", "Y", "Z"), help="dimensions of a headerless .vol")


def load(path: str, args) -> object:
    return read_volume(path, dims=getattr(args, "dims", None))


def save(path: str, vol, **kw) -> None:
    write_volume(path, vol, **kw)
    print(f"wrote {path} ({vol.shape[0]}x{vol.shape[1]}x{vol.shape[2]}, {vol.dtype})")


def parse_range(text: str) -> tuple[float, float | None]:
    """``LO`` or ``LO:HI``."""
    lo, _, hi = text.partition(":")
    try:
        return float(lo), (float(hi) if hi else None)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected LO or LO:HI, got {text!r}") from None


def bounds_arg(values) -> Bounds:
    return Bounds(tuple(values[:3]), tuple(values[3:]))
