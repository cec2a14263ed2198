"""Where the repository's files are, for tests at any depth of ``tests/``."""

from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
ASSETS = REPO / "assets"
WALK = REPO / "src" / "volanim_core" / "sample_data" / "walk.bvh"  # the real clip of ../shared/data, MIT
