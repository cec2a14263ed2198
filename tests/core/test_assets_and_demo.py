"""The shipped assets are what the core regenerates; the headless demo runs end to end."""

from __future__ import annotations

import importlib.util

import numpy as np

from paths import ASSETS
from volanim_core import io
from volanim_core.pipeline_demo import run_demo


def test_assets_are_current(tmp_path):
    spec = importlib.util.spec_from_file_location("make_assets", ASSETS / "make_assets.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    for fresh in mod.make(tmp_path):
        assert fresh.read_bytes() == (ASSETS / fresh.name).read_bytes(), f"assets/{fresh.name} is stale: " \
            "run .venv/bin/python assets/make_assets.py"


def test_headless_demo_writes_every_stage(tmp_path, capsys):
    out = run_demo(tmp_path)
    text = capsys.readouterr().out
    for stage in ("[1] sample", "[2] skeleton", "[3] connectivity (bundled", "[4] identity", "[5] L_UPPERARM"):
        assert stage in text
    rest, _, _ = io.read_volume_grid(out["rest"])
    posed, origin, _ = io.read_volume_grid(out["posed"])
    source = out["sample"].volume
    assert set(np.unique(posed)) <= set(np.unique(source))  # sampled values come from the source
    assert (rest > 0).sum() > 0.99 * (source > 0).sum()
    assert origin[0] < 13  # the raised arm reaches further out than the rest pose
    # the real walk clip: frames across it written as .trans/.tskel and reconstructed
    assert "[6] walk.bvh: 1064 frames" in text and len(out["walk"]) == 8
    assert len(list((tmp_path / "walk").glob("walk.*.tskel"))) == 8
    first, o0, _ = io.read_volume_grid(tmp_path / "walk" / "walk.0000-sampled.vti")
    later, o1, _ = io.read_volume_grid(tmp_path / "walk" / "walk.0532-sampled.vti")
    assert abs(int((first > 0).sum()) - int((rest > 0).sum())) < 0.1 * (rest > 0).sum()  # same body, posed
    assert o1[1] < o0[1] - 100  # the mannequin walked forward (-y) across the clip
    from volanim_core.sequence import store

    assert "[7] sequence: 24 frames of one walk cycle and 10 of crumbling" in text
    assert store.open_frames(out["sequence"]).shape[0] == 34 and len(store.finished(out["sequence"])) == 34
    # the movie: every frame, the figure in the picture, and the heap at the end
    import imageio.v3 as iio

    movie = iio.imread(out["movie"], index=None)
    assert "[8] render: 34 frames" in text and movie.shape[1:3] == (240, 320) and 30 <= len(movie) <= 34
    lit = [(m[..., :3].astype(int).sum(-1) > 150).sum() for m in movie]
    assert min(lit) > 200 and lit[-1] < lit[0] / 2  # a figure in every frame; the heap is smaller
