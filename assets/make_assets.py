"""Regenerate the files in assets/ (deterministic; tests check they are current).

    mannequin.bones              the demo mannequin's bone skeleton
    mannequin.0.50.connect       its skeleton at thinness >= 0.5, each point on its nearest bone

Run: .venv/bin/python assets/make_assets.py
"""

from __future__ import annotations

from pathlib import Path

from volanim_core import io, samples
from volanim_core.rig.attach import connect_nearest
from volanim_core.skeleton.skeletonize import DEFAULT_MIN_THINNESS, skeletonize

HERE = Path(__file__).parent


def make(folder: Path = HERE) -> list[Path]:
    s = samples.mannequin()
    skel = skeletonize(s.mask, min_thinness=DEFAULT_MIN_THINNESS)
    bones_path = folder / "mannequin.bones"
    connect_path = folder / io.connect_filename("mannequin", DEFAULT_MIN_THINNESS)
    io.write_bones(bones_path, s.bones)
    io.write_connect(connect_path, connect_nearest(skel, s.bones), thinness=DEFAULT_MIN_THINNESS)
    return [bones_path, connect_path]


if __name__ == "__main__":
    for p in make():
        print(f"wrote {p}")
