"""Each package's map (its ``__init__`` docstring) names modules that exist: a renamed or moved file fails
here, not in a newcomer's search (#68)."""

from __future__ import annotations

import ast
import re
from pathlib import Path

from paths import REPO

SRC = REPO / "src"
# a module named in a map: ``name.py`` or ``dir/name.py``; ``*_panel.py`` is a pattern, not a name
NAMED = re.compile(r"(?<![\w*/])((?:[a-z_][a-z0-9_]*/)*[a-z_][a-z0-9_]*\.py)\b")


def _maps() -> list[Path]:
    return sorted(SRC.rglob("__init__.py"))


def _named(init: Path) -> list[str]:
    return NAMED.findall(ast.get_docstring(ast.parse(init.read_text(encoding="utf-8"))) or "")


def _exists(init: Path, name: str) -> bool:
    """A bare name is the package's own module; a path (``io/bvh_files.py``) may be a neighbour's."""
    here = init.parent
    if "/" not in name:
        return (here / name).is_file()
    return any((base / name).is_file() for base in (here, here.parent, SRC / "volanim_core", REPO))


def _unnamed(init: Path) -> list[str]:
    """The package's public modules its map leaves out (``_kernels``-style private ones may go unnamed)."""
    named = {n.rsplit("/", 1)[-1] for n in _named(init) if "/" not in n or n.startswith(init.parent.name + "/")}
    return sorted(p.name for p in init.parent.glob("*.py")
                  if not p.name.startswith("_") and p.name not in named)


def test_every_module_a_package_map_names_exists():
    maps = _maps()
    assert len(maps) >= 12
    missing = {str(init.relative_to(REPO)): [n for n in _named(init) if not _exists(init, n)] for init in maps}
    assert not {k: v for k, v in missing.items() if v}, "package maps name files that are not there"
    assert sum(len(_named(init)) for init in maps) >= 40, "the maps name their modules"


def test_every_public_module_is_on_its_package_s_map():
    unnamed = {str(init.relative_to(REPO)): _unnamed(init) for init in _maps()}
    assert not {k: v for k, v in unnamed.items() if v}, "add these to their package's map"


def test_the_check_catches_a_renamed_module(tmp_path):
    pkg = tmp_path / "pkg"
    pkg.mkdir()
    (pkg / "__init__.py").write_text('"""Map.\n\n    here.py ... it\n    gone.py ... renamed\n    *_panel.py\n"""\n')
    (pkg / "here.py").write_text("")
    assert _named(pkg / "__init__.py") == ["here.py", "gone.py"]
    assert _exists(pkg / "__init__.py", "here.py") and not _exists(pkg / "__init__.py", "gone.py")
    (pkg / "new.py").write_text("")
    assert _unnamed(pkg / "__init__.py") == ["new.py"]
