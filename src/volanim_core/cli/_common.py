"""Argument helpers shared by the subcommand modules."""

from __future__ import annotations

import argparse
import dataclasses
import math
import re
import sys
import time
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from volanim_core.geometry import IDENTITY
from volanim_core.io import read_scan, write_output
from volanim_core.io.text import is_number
from volanim_core.volume import Bounds, is_colour, to_grey

#: What every ``--help`` example assumes; tests/test_documented_commands.py runs them all in order.
EXAMPLES_HEADER = "examples (in a folder where `volanim samples all -o .` ran; earlier commands' files are used):"


def add_command(sub, name: str, help: str, example: str | tuple[str, ...], func) -> argparse.ArgumentParser:
    """A subparser whose ``--help`` ends with examples: each one a command that runs as shown
    (a long one may continue over lines ending in a backslash; ``# ...`` comments)."""
    examples = (example,) if isinstance(example, str) else example
    lines = [f"  {line}" if i == 0 else f"      {line.strip()}"
             for ex in examples for i, line in enumerate(ex.split("\n"))]
    p = sub.add_parser(
        name, help=help, description=help, epilog=EXAMPLES_HEADER + "\n" + "\n".join(lines),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.set_defaults(func=func)
    return p


def add_volume_in(p: argparse.ArgumentParser, name: str = "volume", help: str = "input volume") -> None:
    p.add_argument(name, help=f"{help} (.vol with --dims or NAME.XxYxZ.vol, .VOL, .vti, .nrrd/.nhdr, .nii(.gz), "
                   ".mha/.mhd, .mgz, a 3-D .tif, a DICOM folder or file, or a folder of slices)")


def add_joints(p: argparse.ArgumentParser, what: str = "the file's") -> None:
    """``--joints rigid|smooth`` and ``--blend W`` (rig/skinning.py); :func:`joints_of` reads them."""
    p.add_argument("--joints", choices=("rigid", "smooth"),
                   help=f"how bones meet: rigid (each point follows its bone) or smooth (points near a joint blend "
                        f"their bones' motions, dual quaternions); default {what}")
    p.add_argument("--blend", metavar="W",
                   help="smooth joints' blend width: times each bone's thickness (default 1), or millimetres "
                        "like 12mm")


def joints_of(args, conn):
    """``conn`` (a connectivity or frame) with the joints ``--joints``/``--blend`` ask for; as it is without them."""
    from volanim_core.rig.skinning import Joints

    if args.joints is None and args.blend is None:
        return conn
    kind = args.joints or ("smooth" if args.blend is not None else conn.joints.kind)
    if kind == "rigid" and args.blend is not None:
        raise ValueError("--blend is the width of smooth joints; it means nothing with --joints rigid")
    return conn.with_joints(Joints.parse(kind, args.blend))


def add_dims(p: argparse.ArgumentParser) -> None:
    p.add_argument("--dims", nargs=3, type=ascii_int, metavar=("X", "Y", "Z"), help="dimensions of a headerless .vol")
    p.add_argument("--series", help="the DICOM series to read from a folder holding several (its UID or number)")


def load_scan(path: str, args, *, colour: bool | str = False):
    """The volume and its geometry (:func:`io.read_scan`) with the command's ``--dims`` and ``--series``.

    ``colour``: True, the command keeps colour (RGB voxels come as ``data[x, y, z, channel]``);
    ``"luminance"``, it reads a colour volume's luminance and says so (segmenting a colour scan: its output
    is no volume to keep colour in); False, a colour volume is refused in words rather than handed over as
    grey: a tool that quietly turned colour into grey (resample, crop, flip did, #66) loses what the user
    came for."""
    scan = read_scan(path, dims=getattr(args, "dims", None), series=getattr(args, "series", None), colour=True)
    if is_colour(scan.data) and colour == "luminance":
        print(f"note: {path} is a colour volume; read as its luminance (0.299 R + 0.587 G + 0.114 B, a dark "
              f"colour at least 1: every non-black voxel is part of the object)")
        grey = np.asfortranarray(to_grey(scan.data))
        grey[(grey == 0) & scan.data.any(axis=3)] = 1  # (0, 0, 2) rounds to 0: it would drop out of the body
        return dataclasses.replace(scan, data=grey)
    if is_colour(scan.data) and not colour:
        command = getattr(args, "command", None) or "this command"
        raise ValueError(f"{path} is a colour (RGB) volume, and `volanim {command}` works on one value a voxel; "
                         f"it would drop the colour. Make a grey copy first if that is what you want: "
                         f"volanim convert {path} grey.nrrd --grey")
    return scan


def load_source(args, frame, *, colour: bool = False):
    """``--source``: the volume a frame (a ``Tskel`` or ``Connectivity``) samples and its geometry, or
    ``(None, None)``. Settles the frame's grid against the source (``frame.geometry``; a note when it
    had to assume one) and refuses a sampled frame that misses the source (reconstruct, sequence)."""
    from volanim_core.reconstruct.source_space import check_source_overlap, source_geometry_for

    if not args.source:
        if getattr(args, "mode", None) == "sampled":
            raise ValueError("sampled mode needs --source VOLUME")
        return None, None
    source, geometry, _ = load_scan(args.source, args, colour=colour)
    frame.geometry, note = source_geometry_for(frame.geometry, geometry)
    if note:
        print(f"note: {note}")
    if getattr(args, "mode", None) == "sampled":
        check_source_overlap(frame, source.shape, geometry)
    return source, geometry


def load(path: str, args, *, colour: bool | str = False) -> object:
    return load_scan(path, args, colour=colour).data


def save(path: str, vol, geometry=IDENTITY) -> Path:
    """Write a volume and say where (:func:`io.write_output`: a headerless ``.vol`` is named by its size)."""
    path, note = write_output(path, vol, geometry)
    if note:
        print(f"note: {note}")
    print(f"wrote {path} ({vol.shape[0]}x{vol.shape[1]}x{vol.shape[2]}, {vol.dtype}{' RGB' if vol.ndim == 4 else ''})")
    return path


_INFINITY = re.compile(r"[+-]?inf(?:inity)?", re.IGNORECASE)


def ascii_float(text: str) -> float:
    """A number as users type it in ASCII (``-inf`` allowed; NaN, ``1_2`` and full-width digits are not:
    Python's ``float()`` accepts all three)."""
    if is_number(text) or _INFINITY.fullmatch(text):
        return float(text)
    raise argparse.ArgumentTypeError(f"expected a number, got {text!r}")


def finite_float(text: str) -> float:
    value = ascii_float(text)
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"expected a finite number, got {text!r}")
    return value


def ascii_int(text: str) -> int:
    """A whole number in ASCII digits (Python's ``int()`` also takes ``１２`` and ``1_2``)."""
    if re.fullmatch(r"[+-]?[0-9]+", text):
        return int(text)
    raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}")


def _at_least(parse, low: float, strict: bool, what: str):
    """An argparse type: ``parse(text)`` (a whole or finite number), refused below ``low`` (or at it if ``strict``)."""
    def check(text: str):
        value = parse(text)
        if value < low or (strict and value == low):
            raise argparse.ArgumentTypeError(f"expected {what}, got {text!r}")
        return value

    check.__doc__ = f"{what} ({parse.__name__})"
    return check


positive_float = _at_least(finite_float, 0, True, "a number above 0")  # frame rates
positive_int = _at_least(ascii_int, 1, False, "1 or more")  # workers, threads, frames
non_negative_float = _at_least(finite_float, 0, False, "0 or more")  # accelerations
non_negative_int = _at_least(ascii_int, 0, False, "0 or more")  # first numbers of a series


AXIS_OPTIONS = ("--down", "--up", "--forward", "--floor")  # options whose value is a signed axis such as -z
_SIGNED_AXIS = re.compile(r"-[xyz]", re.IGNORECASE)
RANGE_OPTIONS = ("--threshold", "--range", "--window")  # LO[:HI]: a CT body starts at -300 HU
_NEGATIVE_RANGE = re.compile(r"-[0-9.][0-9.eE+-]*(?::[0-9.eE+-]*)?")


def join_dash_values(argv: list[str]) -> list[str]:
    """``--opt -inf`` -> ``--opt=-inf``, ``--down -z`` -> ``--down=-z`` and ``--threshold -300:3000`` ->
    ``--threshold=-300:3000``: argparse takes a value that starts with a dash for an option and refuses
    it. A signed axis or a range is joined only after the options that take one, so no short option
    elsewhere is swallowed."""
    out: list[str] = []
    for token in argv:
        prev = out[-1] if out else ""
        joinable = prev.startswith("--") and "=" not in prev and (
            (_INFINITY.fullmatch(token) and token.startswith("-"))
            or (prev in AXIS_OPTIONS and _SIGNED_AXIS.fullmatch(token))
            or (prev in RANGE_OPTIONS and _NEGATIVE_RANGE.fullmatch(token)))
        if joinable:
            out[-1] = f"{prev}={token}"
        else:
            out.append(token)
    return out


def parse_range(text: str) -> tuple[float, float | None]:
    """``LO`` or ``LO:HI``."""
    lo, _, hi = text.partition(":")
    try:
        return finite_float(lo), (finite_float(hi) if hi else None)
    except argparse.ArgumentTypeError:
        raise argparse.ArgumentTypeError(f"expected LO or LO:HI, got {text!r}") from None


def bounds_arg(values, *, inclusive: bool = True, option: str = "--bounds") -> Bounds:
    """Six numbers ``x0 y0 z0 x1 y1 z1`` as (inclusive) :class:`Bounds`. ``inclusive=False``: the thesis's
    CropVolume and Fill convention, the stop excluded ("up to, but not including"): ``0 0 0 2 2 2`` is 2x2x2."""
    lo, hi = tuple(values[:3]), tuple(values[3:])
    if inclusive:
        return Bounds(lo, hi)
    if any(h <= v for v, h in zip(lo, hi)):
        raise ValueError(f"{option} {' '.join(map(str, values))}: the stop x1 y1 z1 is excluded (the thesis's "
                         f"convention), so each must be greater than its start; --inclusive takes them as the last "
                         f"voxels")
    return Bounds(lo, tuple(h - 1 for h in hi))


def stop_exclusive(b: Bounds) -> str:
    """``b`` as the six numbers crop and fill take: the stop excluded."""
    return " ".join(str(int(v)) for v in (*b.lo, *(h + 1 for h in b.hi)))


def add_pool(p, verb: str) -> None:
    """``--workers``, ``--scheduler`` and ``--cluster-config``: where ``verb`` runs (one of them)."""
    pool = p.add_mutually_exclusive_group()
    pool.add_argument("--workers", type=positive_int, help="local worker processes (default: every core)")
    pool.add_argument("--scheduler", metavar="tcp://HOST:PORT", help=f"{verb} on this Dask cluster instead")
    pool.add_argument("--cluster-config", metavar="FILE.yaml",
                      help=f"{verb} on a Dask cluster this file starts (dask-ctl's spec: module, class, kwargs; "
                      "e.g. dask_jobqueue's SLURMCluster), closed at the end; see docs/tutorials/cluster.md")


def local_workers(args) -> int | None:
    """``--workers`` (default: every core), or None on a Dask cluster (``--scheduler``, ``--cluster-config``)."""
    if args.scheduler or args.cluster_config:
        return None
    from volanim_core.parallel import default_workers

    return default_workers() if args.workers is None else args.workers


@contextmanager
def dask_scheduler(args):
    """A ``distributed.Client`` of ``--scheduler``'s cluster or of the one ``--cluster-config`` starts, its
    dashboard said on stderr, closed on leaving (a started cluster too); None for local workers. The wait to
    reach a scheduler (up to Dask's connect timeout, 30 s by default) is announced first, as nothing else is
    printed meanwhile."""
    def say(text):
        print(text, file=sys.stderr, flush=True)

    if args.cluster_config:
        from volanim_core.cluster_config import started_cluster

        with started_cluster(args.cluster_config, say=say) as client:
            yield client
    elif args.scheduler:
        from volanim_core.cluster_config import dashboard
        from volanim_core.parallel import dask_client

        say(f"connecting to the Dask scheduler at {args.scheduler} ...")
        with dask_client(args.scheduler) as client:
            say(f"connected to {args.scheduler}{dashboard(client)}")
            yield client
    else:
        yield None


class FrameProgress:
    """``frame done/total  N frames/s  ETA m:ss`` on one stderr line (sequence, render).

    Called as ``progress(anything, done, total)`` after each frame; frames complete
    before this run (a resume) count toward done, not toward the rate.
    """

    def __init__(self):
        self.t0 = time.perf_counter()
        self.before = None

    def __call__(self, _item, done: int, total: int) -> None:
        if self.before is None:
            self.before = done - 1
        made = done - self.before
        elapsed = time.perf_counter() - self.t0
        rate = made / elapsed if elapsed > 0 else 0.0
        eta = (total - done) / rate if rate > 0 else 0.0
        print(f"\rframe {done}/{total}  {rate:.2f} frames/s  ETA {int(eta) // 60}:{int(eta) % 60:02d}   ",
              end="", file=sys.stderr, flush=True)


def checked_by(target: str, strip: str = ""):
    """An argparse type that keeps the text when ``MODULE:FUNCTION`` (imported at first use, so the
    parser stays light) accepts it; the ValueError it raises becomes the argument error (``strip``
    removed from its front)."""
    module, name = target.split(":")

    def parse(text: str) -> str:
        import importlib

        try:
            getattr(importlib.import_module(module), name)(text)
        except ValueError as exc:
            raise argparse.ArgumentTypeError(str(exc).removeprefix(strip.format(text=text))) from None
        return text

    parse.__name__ = name  # argparse names the type in "invalid <name> value" messages
    return parse
