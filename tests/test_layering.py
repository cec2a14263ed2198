"""Architecture rules seen at run time, and the size rule. The import layers are contracts in pyproject.toml,
checked by tests/test_import_contracts.py."""

from __future__ import annotations

import pkgutil
import subprocess
import sys

import volanim_core

SCRIPT = """
import importlib, pkgutil, sys, volanim_core
for m in pkgutil.walk_packages(volanim_core.__path__, "volanim_core."):
    if not m.name.endswith("__main__"):
        importlib.import_module(m.name)
qt = sorted(n for n in sys.modules if n.split(".")[0] in ("PySide6", "PyQt5", "PyQt6", "pyvistaqt", "qtpy"))
print("QT:", qt)
"""


def test_core_never_imports_qt():
    out = subprocess.run([sys.executable, "-c", SCRIPT], capture_output=True, text=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert "QT: []" in out.stdout, out.stdout
    assert len(list(pkgutil.walk_packages(volanim_core.__path__))) > 10


def test_studio_model_never_imports_qt():
    code = "import sys, volanim_studio.model, volanim_studio.model.interaction, volanim_studio.tasks; " \
           "print(sorted(n for n in sys.modules if n.startswith(('PySide6', 'pyvistaqt'))))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert out.stdout.strip() == "[]", out.stdout + out.stderr


def test_studio_help():
    out = subprocess.run([sys.executable, "-m", "volanim_studio.app", "--help"], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0 and "--demo" in out.stdout and "examples:" in out.stdout


def test_no_module_over_450_lines():
    from pathlib import Path

    import volanim_studio

    roots = [Path(volanim_core.__file__).parent, Path(volanim_studio.__file__).parent]
    long = {p.name: n for r in roots for p in r.rglob("*.py") if (n := len(p.read_text().splitlines())) > 450}
    assert not long, long
