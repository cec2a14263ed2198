"""The headless demo run behind ``make demo`` and ``volanim demo``.

    sample volume --> NAME.VOL + NAME.bones
      --skeletonize--> NAME.mskel, --isosurface--> NAME-hull.ply
      (the reconstruction stages are appended by later modules)
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from . import samples, volume
from .io import write_bones, write_connections, write_mskel, write_raw
from .isosurface import isosurface, write_mesh
from .progress import TextProgress
from .skeletonize import skeletonize


def _say(msg: str) -> None:
    print(msg, flush=True)


def run_demo(folder: Path, sample: str = "mannequin") -> dict:
    """Run every stage on ``sample`` and write the files into ``folder``; returns their paths."""
    folder.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    out: dict = {}
    s = samples.load(sample)
    out["volume"] = folder / f"{sample}.VOL"
    write_raw(out["volume"], s.volume)
    b = volume.tight_bounds(s.volume)
    counts = volume.histogram(s.volume)
    _say(f"[1] sample {sample}: {s.volume.shape} voxels, {int(np.count_nonzero(s.volume))} in the object, "
         f"tight bounds {b}, {int((counts[1:] > 0).sum())} distinct values -> {out['volume'].name}")
    if s.bones is not None:
        out["bones"] = folder / f"{sample}.bones"
        write_bones(out["bones"], s.bones)
        write_connections(folder / f"{sample}.connections", s.bones)
        _say(f"    bone skeleton: {len(s.bones.joints)} joints, {len(s.bones)} bones -> {out['bones'].name}")

    t = time.perf_counter()
    skel = skeletonize(s.mask, progress=TextProgress("    skeletonize"))
    out["mskel"] = folder / f"{sample}.mskel"
    write_mskel(out["mskel"], skel)
    _say(f"[2] skeleton: {len(skel)} points, thinness {skel.thinness.min():.2f}..{skel.thinness.max():.2f}, "
         f"dt up to {skel.dt.max():.1f}, {time.perf_counter() - t:.2f} s -> {out['mskel'].name}")
    t = time.perf_counter()
    verts, faces = isosurface(s.mask)
    out["hull"] = folder / f"{sample}-hull.ply"
    write_mesh(out["hull"], verts, faces)
    _say(f"    hull: {len(faces)} triangles, {time.perf_counter() - t:.2f} s -> {out['hull'].name}")
    out["skeleton"] = skel
    out["sample"] = s
    _say(f"done in {time.perf_counter() - t0:.1f} s; files in {folder}/")
    return out
