"""Animations on disk: one ``.trans`` (and optionally ``.tskel``) per frame, ``NAME.0000.trans``, ...

Whatever made the matrices (a BVH clip, keyframes, the studio's timeline),
every frame ends as the same pair of files, which ``volanim sequence`` and
the old ``ReconstructEuclid`` workflow read.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from volanim_core.errors import FormatError
from volanim_core.progress import Reporter
from volanim_core.rig.bones import BoneSkeleton
from volanim_core.rig.connectivity import Connectivity, Trans
from volanim_core.rig.pose import root_bones
from volanim_core.rig.tskel_tools import check_root_order, connect_to_tskel


def frame_path(folder: str | Path, stem: str, frame: int, suffix: str = ".trans") -> Path:
    return Path(folder) / f"{stem}.{frame:04d}{suffix}"


def write_frames(folder, stem: str, bones: BoneSkeleton, matrices: np.ndarray, frames, *,
                 connect: Connectivity | None = None, progress=None, cancel=None) -> list[Path]:
    """Write ``matrices[i]`` as ``folder/stem.{frames[i]:04d}.trans`` (+ ``.tskel`` with ``connect``).

    Each file is written atomically; ``progress(done, total)`` after each frame,
    ``cancel()`` checked between frames. Returns the ``.trans`` paths.
    """
    from volanim_core import io

    frames = [int(f) for f in frames]
    if len(frames) != len(matrices):
        raise ValueError(f"{len(matrices)} frames of matrices for {len(frames)} frame numbers")
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    roots = root_bones(bones)
    trans = [Trans(roots, np.asarray(m), bones.geometry) for m in matrices]  # every frame checked before any file
    report = Reporter(progress, cancel)
    marker = incomplete_marker(out, stem)
    marker.write_text(f"{len(frames)} frames of {stem} were being written; this file goes when the last is\n")
    written = []
    for n, (frame, t) in enumerate(zip(frames, trans)):
        report(n, len(frames))
        written.append(frame_path(out, stem, frame))
        io.write_trans(written[-1], t)
        if connect is not None:
            io.write_tskel(frame_path(out, stem, frame, ".tskel"), connect_to_tskel(connect, t))
    marker.unlink()  # the frames are whole: a run killed, cancelled or out of room leaves the marker behind
    report(len(frames), len(frames))
    return written


def incomplete_marker(folder: str | Path, stem: str) -> Path:
    """``folder/STEM.incomplete``: there while ``write_frames`` writes a clip's frames, gone once all are."""
    return Path(folder) / f"{stem}.incomplete"


def check_complete(paths) -> None:
    """Refuse frames of a clip whose writing did not finish (a marker beside them, :func:`write_frames`)."""
    from volanim_core.errors import FormatError

    for p in paths:
        marker = incomplete_marker(Path(p).parent, _named(p)[0])
        if marker.is_file():
            raise FormatError(p, f"{marker.name} lies beside it: the run writing these frames stopped before the "
                                 "last (killed, cancelled or out of room); run it again to write them all")


def frame_number(path: str | Path) -> int | None:
    """The frame number in ``NAME.0012.trans`` (or ``NAME0012.trans``, ``12.trans``); None without one."""
    return _named(path)[1]


def _named(path) -> tuple[str, int | None]:
    """``NAME.0012.trans`` -> ("NAME", 12); a name without a number -> (its stem, None)."""
    m = re.match(r"^(.*?)\.?(\d+)$", Path(path).stem)
    return (m.group(1), int(m.group(2))) if m else (Path(path).stem, None)


def read_frames(paths, bones: BoneSkeleton, progress=None) -> tuple[np.ndarray, list[Path]]:
    """``.trans`` files (or one folder of them) as ``(F, B, 4, 4)`` matrices, in frame-number order.

    Every file must name our bones in our root order (FormatError naming the file otherwise);
    ``progress(done, total)`` after each file (a clip's thousand frames take seconds).
    """
    from volanim_core import io

    paths = [Path(p) for p in ([paths] if isinstance(paths, str | Path) else paths)]
    if len(paths) == 1 and paths[0].is_dir():
        folder = paths[0]
        paths = sorted(folder.glob("*.trans"))
        if not paths:
            raise FileNotFoundError(f"{folder}: no .trans files in this folder")
    paths.sort(key=lambda p: (frame_number(p) is None, frame_number(p) or 0, p.name))
    check_complete(paths)
    roots = root_bones(bones)
    mats = np.empty((len(paths), len(bones), 4, 4))
    report = Reporter(progress)
    for i, p in enumerate(paths):
        report(i, len(paths))
        trans = io.read_trans(p).on_grid(bones.geometry)
        try:
            check_root_order(roots, trans.bones, p.name, ".bones")
        except ValueError as exc:
            raise FormatError(p, str(exc)) from None
        mats[i] = trans.matrices
    report(len(paths), len(paths))
    return mats, paths
