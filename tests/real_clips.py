"""Real motion-capture clips that other projects publish, read unmodified from their sources on PyPI.

Why fetched, not vendored: bvhtools' ``test.bvh``/``test2.bvh`` are LAFAN1 clips (Ubisoft La Forge,
CC BY-NC-ND 4.0: no derivatives, so no excerpt may be committed here), and the other clips' first
sources are not stated beside them (tests/data/README.md). The source distributions are pinned by
sha256 and downloaded once into ``.cache/real-clips/`` (``make test`` has PyPI; so does CI).
"""

from __future__ import annotations

import hashlib
import io
import subprocess
import sys
import tarfile
from pathlib import Path

CACHE = Path(__file__).resolve().parents[1] / ".cache" / "real-clips"

SDISTS = {
    "bvhtools==1.6.0": ("bvhtools-1.6.0.tar.gz",
                        "840c67a4d94c4c4732d1a729eac0ba6b0cad7c334aed2773ea2ff15ffe64c144"),
    "bvhtoolbox==0.1.3": ("bvhtoolbox-0.1.3.tar.gz",
                          "2d9dcae87cd6bfa28c89463450de84497e612682ca0697ea088fc7f2ef0f937f"),
}
# name -> (sdist, member): the naming styles #39 names
CLIPS = {
    "lafan_test": ("bvhtools==1.6.0", "bvhtools-1.6.0/testBvhFiles/test.bvh"),  # LAFAN: rest along x, cm
    "lafan_test2": ("bvhtools==1.6.0", "bvhtools-1.6.0/testBvhFiles/test2.bvh"),
    "blender": ("bvhtools==1.6.0", "bvhtools-1.6.0/testBvhFiles/test3.bvh"),  # .L/.R, metres, 6-channel joints
    "mocapbank": ("bvhtoolbox==0.1.3", "bvhtoolbox-0.1.3/tests/example_files/test_mocapbank.bvh"),  # Biovision
    "mixamo": ("bvhtoolbox==0.1.3", "bvhtoolbox-0.1.3/tests/example_files/test_freebvh.bvh"),  # mixamorig:
}


def _sdist(spec: str) -> bytes:
    name, digest = SDISTS[spec]
    path = CACHE / name
    if not path.is_file():
        CACHE.mkdir(parents=True, exist_ok=True)
        subprocess.run([sys.executable, "-m", "pip", "download", "--quiet", "--no-deps", "--no-binary", ":all:",
                        spec, "-d", str(CACHE)], check=True, timeout=300)
    data = path.read_bytes()
    if hashlib.sha256(data).hexdigest() != digest:
        raise RuntimeError(f"{path}: not the published {spec} (sha256 differs); delete it to fetch again")
    return data


def clip(name: str) -> Path:
    """The clip's path in the cache, fetched and checked on first use."""
    spec, member = CLIPS[name]
    out = CACHE / f"{name}.bvh"
    if not out.is_file():
        with tarfile.open(fileobj=io.BytesIO(_sdist(spec)), mode="r:gz") as tar:
            out.write_bytes(tar.extractfile(member).read())
    return out
