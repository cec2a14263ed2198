"""The shipped assets are what the core regenerates."""

from __future__ import annotations

import importlib.util

from paths import ASSETS


def test_assets_are_current(tmp_path):
    spec = importlib.util.spec_from_file_location("make_assets", ASSETS / "make_assets.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    for fresh in mod.make(tmp_path):
        assert fresh.read_bytes() == (ASSETS / fresh.name).read_bytes(), f"assets/{fresh.name} is stale: " \
            "run .venv/bin/python assets/make_assets.py"


# The headless demo (`make demo`) runs end to end in tests/test_documented_commands.py, with its checks.
