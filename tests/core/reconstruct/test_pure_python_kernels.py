"""The fill and label kernels run as plain Python (``NUMBA_DISABLE_JIT=1``, what ``make coverage`` measures
them with) and give what the compiled kernels give. Compiled numba code checks no bounds: the binary and
hotspot fills read each slice's row spans from a one-row array past its end, which only Python's
IndexError showed; the prefetch hint had no Python form at all."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np

from paths import REPO

SCRIPT = r"""
import sys
import numpy as np
sys.path.insert(0, sys.argv[2])
from core.reconstruct.test_engine import MODES, random_tskel
from volanim_core.reconstruct.breakage import components
from volanim_core.reconstruct.engine import reconstruct

out = {}
for metric in ("euclid", "345"):
    t = random_tskel(np.random.default_rng(7), n=40, metric=metric, size=16)
    source = np.random.default_rng(8).integers(1, 200, (16, 16, 16)).astype(np.uint8)
    for mode in MODES:
        r = reconstruct(t, mode=mode, source=source if mode == "sampled" else None, padding=1)
        out[f"{metric}-{mode}"] = r.volume
        out[f"{metric}-{mode}-pieces"] = np.array(components(r.volume))
np.savez(sys.argv[1], **out)
"""


def _run(tmp_path, jit: bool) -> dict:
    path = tmp_path / f"{'jit' if jit else 'python'}.npz"
    env = dict(os.environ)
    env.pop("NUMBA_DISABLE_JIT", None)
    if not jit:
        env["NUMBA_DISABLE_JIT"] = "1"
    done = subprocess.run([sys.executable, "-c", SCRIPT, str(path), str(REPO / "tests")], env=env,
                          capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    with np.load(path) as data:
        return dict(data)


def test_the_kernels_as_python_give_what_the_compiled_ones_give(tmp_path):
    compiled, python = _run(tmp_path, True), _run(tmp_path, False)
    assert compiled.keys() == python.keys() and len(compiled) == 20
    for key in compiled:
        np.testing.assert_array_equal(python[key], compiled[key], err_msg=key)
    assert compiled["euclid-binary"].any() and len(compiled["euclid-bone-pieces"]) >= 1
