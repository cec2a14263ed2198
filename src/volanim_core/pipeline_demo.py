"""The headless demo run behind ``make demo`` and ``volanim demo``.

    sample volume --> NAME.VOL + .bones  (summary printed)
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from . import samples, volume
from .io import write_bones, write_connections, write_raw


def _say(msg: str) -> None:
    print(msg, flush=True)


def run_demo(folder: Path, sample: str = "mannequin") -> dict:
    """Run every stage available on ``sample`` and write the files into ``folder``."""
    folder.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    s = samples.load(sample)
    vol_path = folder / f"{sample}.VOL"
    write_raw(vol_path, s.volume)
    b = volume.tight_bounds(s.volume)
    counts = volume.histogram(s.volume)
    _say(f"[1/1] sample {sample}: {s.volume.shape} voxels, {int(np.count_nonzero(s.volume))} in the object, "
         f"tight bounds {b}, {int((counts[1:] > 0).sum())} distinct values -> {vol_path}")
    if s.bones is not None:
        write_bones(folder / f"{sample}.bones", s.bones)
        write_connections(folder / f"{sample}.connections", s.bones)
        _say(f"      bone skeleton: {len(s.bones.joints)} joints, {len(s.bones)} bones -> {sample}.bones")
    _say(f"done in {time.perf_counter() - t0:.1f} s; files in {folder}/")
    return {"volume": vol_path}
