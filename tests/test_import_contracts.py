"""The layers hold, and each rule catches the import it forbids (#68).

The contracts live in ``pyproject.toml`` (import-linter, as napari keeps its layers); ``import_contracts.py``
checks them on a tree, counting imports made by name as well. Each bad import below is added to a scratch
copy of the source, and the contract that forbids it must break, naming the import.
"""

from __future__ import annotations

import json
import shutil
import subprocess
import sys

import pytest

from paths import REPO

SCRIPT = REPO / "tests" / "import_contracts.py"

# (what a careless change does, the file it lands in, the text appended, the contract that must break,
# a word the report must name)
BAD_IMPORTS = [
    ("io imports the renderer", "volanim_core/io/bones_files.py",
     "\nfrom volanim_core.render import scene as _bad\n", "core-layers", "volanim_core.io.bones_files"),
    ("the value helpers' module reaches back up into io", "volanim_core/volume.py",
     "\nfrom volanim_core.io import raw_volumes as _bad\n", "core-layers", "volanim_core.volume"),
    ("motion and reconstruct, one layer, import each other", "volanim_core/motion/keyframes.py",
     "\ndef _bad():\n    from volanim_core.reconstruct import engine\n", "core-layers",
     "volanim_core.motion.keyframes"),
    ("a new top-level module in no layer", "volanim_core/stray.py",
     "\nimport numpy\n", "core-layers", "volanim_core.stray"),
    ("the core imports the studio", "volanim_core/rig/pose.py",
     "\ndef _bad():\n    from volanim_studio.model import document\n", "core-without-gui", "volanim_core.rig.pose"),
    ("a lazy PySide6 import in the core", "volanim_core/sequence/run.py",
     "\ndef _bad():\n    from PySide6 import QtCore\n", "core-without-gui", "volanim_core.sequence.run"),
    ("the studio imported only for type hints", "volanim_core/render/movie.py",
     "\nfrom typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from volanim_studio.model.document import Document\n",
     "core-without-gui", "volanim_core.render.movie"),
    ("the studio imported by name through importlib", "volanim_core/colour/palette.py",
     "\ndef _bad():\n    import importlib\n    return importlib.import_module('volanim_studio.qt.main_window')\n",
     "core-without-gui", "volanim_core.colour.palette"),
    ("VTK in the rig", "volanim_core/rig/bones.py",
     "\ndef _bad():\n    import pyvista\n", "vtk-in-files-and-rendering", "volanim_core.rig.bones"),
    ("a lazy pyvistaqt in the studio's model", "volanim_studio/model/document.py",
     "\ndef _bad():\n    import pyvistaqt\n", "model-without-view", "volanim_studio.model.document"),
    ("the model imports the scene", "volanim_studio/model/posing.py",
     "\nfrom volanim_studio.scene import view as _bad\n", "studio-layers", "volanim_studio.model.posing"),
    ("the scene imports a Qt panel", "volanim_studio/scene/hull_layer.py",
     "\ndef _bad():\n    from volanim_studio.qt import status_line\n", "studio-layers",
     "volanim_studio.scene.hull_layer"),
    ("a panel imports the scene, absolutely", "volanim_studio/qt/pose_panel.py",
     "\ndef _bad():\n    from volanim_studio.scene.view import View\n", "panels-via-model",
     "volanim_studio.qt.pose_panel"),
    ("two modules of one package import each other", "volanim_core/rig/templates.py",
     "\ndef _bad():\n    from volanim_core.rig import autorig\n", "no-cycles", ".templates -> .autorig"),
    ("two packages of the studio import each other through a string", "volanim_studio/tasks.py",
     "\n_BAD = 'volanim_studio.qt.worker:Worker'\n", "studio-layers", "volanim_studio.tasks"),
]


def _run(tree, *cases) -> list[dict]:
    args = [sys.executable, str(SCRIPT), str(tree)]
    for name, file, text, *_ in cases:
        args += ["--case", name, file, text]
    out = subprocess.run(args, capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr
    return [json.loads(line) for line in out.stdout.splitlines() if line.startswith("{")]


def test_the_import_contracts_hold():
    (result,) = _run(REPO)
    assert result["broken"] == [], result["report"]
    assert "Contracts: 6 kept, 0 broken." in result["report"]


@pytest.mark.long("one import graph per bad import: half a second each")
def test_each_bad_import_breaks_the_rule_that_forbids_it(tmp_path):
    shutil.copytree(REPO / "src", tmp_path / "src", ignore=shutil.ignore_patterns("__pycache__", "*.egg-info"))
    shutil.copy(REPO / "pyproject.toml", tmp_path)
    results = _run(tmp_path, *BAD_IMPORTS)
    assert [r["case"] for r in results] == ["as it is", *(b[0] for b in BAD_IMPORTS)]
    assert results[0]["broken"] == [], results[0]["report"]
    missed = [(name, r["broken"]) for (name, _, _, rule, _), r in zip(BAD_IMPORTS, results[1:])
              if rule not in r["broken"]]
    assert not missed, missed
    unnamed = [name for (name, _, _, _, where), r in zip(BAD_IMPORTS, results[1:]) if where not in r["report"]]
    assert not unnamed, unnamed
    assert (tmp_path / "src" / "volanim_core" / "rig" / "pose.py").read_text() == \
        (REPO / "src" / "volanim_core" / "rig" / "pose.py").read_text()  # every case put back
    assert not (tmp_path / "src" / "volanim_core" / "stray.py").exists()
