"""The top-level API (``volanim_core.NAME`` for each studio tool) is reachable whatever was imported first."""

from __future__ import annotations

import subprocess
import sys


def test_every_top_level_tool_is_a_function_after_every_module_is_imported():
    """``volanim_core.reconstruct`` was listed as the engine's function, but the subpackage of the same name
    is that attribute as soon as anything imports it: a script calling it got "'module' object is not
    callable" (found by the docs site's gallery)."""
    code = ("import importlib, pkgutil, volanim_core\n"
            "for m in pkgutil.walk_packages(volanim_core.__path__, 'volanim_core.'):\n"
            "    if not m.name.endswith('__main__'): importlib.import_module(m.name)\n"
            "bad = [n for n in volanim_core.__all__ if n != '__version__' and not callable(getattr(volanim_core, n))]\n"
            "print(bad)\n"
            "from volanim_core.reconstruct import reconstruct\n"
            "print(callable(reconstruct))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split("\n")[:2] == ["[]", "True"], out.stdout
