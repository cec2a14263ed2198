"""The studio's view is drawn by the widget's paint, never by a pyvista call at once.

pyvista's plotter methods that take ``render=True`` by default (``add_text``, ``add_mesh``, ``remove_actor``,
``reset_camera``, ...) draw the whole view on the calling thread before they return: in the studio that is
the GUI thread, 50-190 ms of software GL each. ``SceneView.render`` asks the widget for one paint instead, so
every such call in the studio passes ``render=False``. A proof failed on the stale-picture note's ``add_text``
(184 ms of the GUI thread while dragging a bone); this finds the next one before a user does."""

from __future__ import annotations

import ast
import inspect
from pathlib import Path

from pyvista.plotting.plotter import BasePlotter
from pyvista.plotting.renderer import Renderer
from pyvista.plotting.scalar_bars import ScalarBars

STUDIO = Path(__file__).resolve().parents[3] / "src" / "volanim_studio"


def _rendering_methods() -> set[str]:
    """pyvista's plotter, renderer and scalar-bar methods that draw at once unless given ``render=False``."""
    names = set()
    for cls in (BasePlotter, Renderer, ScalarBars):
        for name, f in inspect.getmembers(cls, inspect.isfunction):
            parameter = inspect.signature(f).parameters.get("render")
            if parameter is not None and parameter.default is True:
                names.add(name)
    return names


def test_pyvista_s_own_renders_are_known():
    """The list is read from pyvista itself, so a new release's renaming cannot empty it unnoticed."""
    assert {"add_text", "add_mesh", "add_actor", "remove_actor", "remove_scalar_bar", "reset_camera"} <= \
        _rendering_methods()


def test_no_studio_call_makes_pyvista_draw_at_once():
    methods = _rendering_methods()
    at_once = []
    for path in sorted(STUDIO.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr in methods:
                render = {k.arg: k.value for k in node.keywords}.get("render")
                if not (isinstance(render, ast.Constant) and render.value is False):
                    at_once.append(f"{path.relative_to(STUDIO.parent)}:{node.lineno} {node.func.attr}")
    assert not at_once, "pass render=False (the view's render() asks the widget for a paint):\n" + \
        "\n".join(at_once)
