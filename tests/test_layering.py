"""Architecture rules checked mechanically (napari style)."""

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
    code = "import sys, volanim_studio.model, volanim_studio.model.modes, volanim_studio.tasks; " \
           "print(sorted(n for n in sys.modules if n.startswith(('PySide6', 'pyvistaqt'))))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert out.stdout.strip() == "[]", out.stdout + out.stderr


def test_studio_help():
    out = subprocess.run([sys.executable, "-m", "volanim_studio.app", "--help"], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0 and "--demo" in out.stdout and "examples:" in out.stdout


# Where VTK/pyvista may be imported in the core: file formats, rendering, and the sample that
# locates the frog file inside pyvista's wheel (it is then read like any other .vti).
VTK_ALLOWED = ("volanim_core/io/", "volanim_core/render/", "volanim_core/samples.py", "volanim_core/isosurface.py")


def _imports(path) -> set[str]:
    import ast

    tree = ast.parse(path.read_text())
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names |= {a.name.split(".")[0] for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
            names.add(node.module.split(".")[0])
    return names


def test_only_io_and_render_import_vtk_in_the_core():
    from pathlib import Path

    root = Path(volanim_core.__file__).parent
    bad = [str(p.relative_to(root.parent)) for p in root.rglob("*.py")
           if _imports(p) & {"vtk", "pyvista", "vtkmodules"}
           and not str(p.relative_to(root.parent)).startswith(VTK_ALLOWED)]
    assert not bad, f"VTK/pyvista imported outside io/ and render/: {bad}"


def test_studio_model_imports_neither_qt_nor_vtk():
    from pathlib import Path

    import volanim_studio

    model = Path(volanim_studio.__file__).parent / "model"
    bad = [p.name for p in model.rglob("*.py")
           if _imports(p) & {"PySide6", "pyvistaqt", "vtk", "pyvista", "vtkmodules", "matplotlib"}]
    assert not bad, bad


def _relative_imports(path) -> set[str]:
    import ast

    return {node.module or "" for node in ast.walk(ast.parse(path.read_text()))
            if isinstance(node, ast.ImportFrom) and node.level}


def test_qt_panels_talk_to_the_model_not_the_scene():
    """Panels bind to the document and settings; only the window and controllers hold the scene."""
    from pathlib import Path

    import volanim_studio

    qt = Path(volanim_studio.__file__).parent / "qt"
    panels = [p for p in qt.glob("*.py") if p.stem.endswith(("_panel", "_dialog"))]
    assert len(panels) >= 5
    bad = [p.name for p in panels if any(m.startswith("scene") or m.startswith("..scene")
                                          for m in _relative_imports(p))]
    assert not bad, bad


def test_no_module_over_450_lines():
    from pathlib import Path

    import volanim_studio

    roots = [Path(volanim_core.__file__).parent, Path(volanim_studio.__file__).parent]
    long = {p.name: n for r in roots for p in r.rglob("*.py") if (n := len(p.read_text().splitlines())) > 450}
    assert not long, long


# The core's layers, lowest first (napari checks its own with import-linter contracts): a package
# imports only packages of its layer or below. io, colour and skeleton read and write the camera,
# transfer functions and surfaces as plain data (volanim_core.camera, .transfer_function,
# .isosurface), never through the renderer; nothing below the command line imports it.
LAYERS = [
    {"errors", "limits", "progress", "geometry", "modes", "camera", "transfer_function", "isosurface", "parallel",
     "memo"},
    # volume tools and the values every file and tool reads (float_to_uint8, to_grey, finite_range): below io
    {"volume"},
    # files hold skeletons and bones (io reads them into their types): one layer, which never imports the renderer
    {"io", "skeleton", "colour", "rig", "mannequin_body"},
    {"reconstruct", "motion"},
    {"sequence", "render", "samples", "ant_sample", "warmup", "posed_truth"},
    {"pipeline_demo"},
    {"cli", "__main__"},
]


def _core_imports(path, package: str) -> set[str]:
    """The top-level ``volanim_core`` modules/packages a file imports (absolute or relative)."""
    import ast

    out = set()
    parts = package.split(".")
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            out |= {a.name.split(".")[1] for a in node.names if a.name.startswith("volanim_core.")}
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = parts[: len(parts) - node.level + 1]
                name = ".".join(base + ([node.module] if node.module else []))
            else:
                name = node.module or ""
            if name.startswith("volanim_core."):
                out.add(name.split(".")[1])
            elif name == "volanim_core":
                out |= {a.name for a in node.names}
    return out


def test_the_core_s_layers_import_only_downwards():
    from pathlib import Path

    root = Path(volanim_core.__file__).parent
    rank = {name: k for k, layer in enumerate(LAYERS) for name in layer}
    top = {p.stem if p.is_file() else p.name for p in root.iterdir()
           if (p.suffix == ".py" and p.stem != "__init__") or (p.is_dir() and (p / "__init__.py").exists())}
    assert top <= set(rank), f"put these in a layer: {sorted(top - set(rank))}"
    bad = []
    for path in root.rglob("*.py"):
        rel = path.relative_to(root)
        if rel.parts[0] == "__init__.py":
            continue
        own = rel.parts[0].removesuffix(".py")
        package = ".".join(["volanim_core", *rel.parts[:-1]]) if len(rel.parts) > 1 else "volanim_core"
        for used in _core_imports(path, package):
            if used in rank and rank[used] > rank[own]:
                bad.append(f"{rel} imports {used}")
    assert not bad, bad
