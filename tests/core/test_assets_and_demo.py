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
