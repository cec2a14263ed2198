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


def _imports_of_ours(path):
    """``(line, module, name)`` for every ``from volanim_... import name`` in a file, at any depth."""
    import ast

    tree = ast.parse(path.read_text(encoding="utf-8"))
    parts = ["volanim_studio" if "volanim_studio" in path.parts else "volanim_core",
             *path.parts[path.parts.index("src") + 2:-1]]
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            module = ".".join(parts[: len(parts) - node.level + 1] + ([node.module] if node.module else [])) \
                if node.level else node.module or ""
            if module.split(".")[0] in ("volanim_core", "volanim_studio"):
                out += [(node.lineno, module, a.name) for a in node.names]
    return out


def test_every_name_imported_from_our_packages_exists():
    """A rename leaves no stale import behind, not even inside a function that only a menu reaches (#68:
    ``from volanim_studio.scene import camera`` outlived the module's rename, and only a timeline test's
    teardown saw it)."""
    import importlib
    from pathlib import Path

    import volanim_studio

    roots = [Path(volanim_core.__file__).parent, Path(volanim_studio.__file__).parent]
    missing = []
    for path in (p for r in roots for p in r.rglob("*.py")):
        for line, module, name in _imports_of_ours(path):
            try:
                found = importlib.import_module(module)
            except ImportError:
                missing.append(f"{path.name}:{line}: no module {module}")
                continue
            if not hasattr(found, name):
                try:
                    importlib.import_module(f"{module}.{name}")
                except ImportError:
                    missing.append(f"{path.name}:{line}: {module} has no {name}")
    assert not missing, missing
