"""The import contracts of ``pyproject.toml``, checked on a source tree (#68).

    src/ --grimp--> the import graph (every import statement: top level, in a function, under TYPE_CHECKING)
        + imports made by name: ``importlib.import_module("m")``, ``__import__("m")``, and a string naming a
          module of ours or one the graph holds (``"volanim_core.rig.attach"``, ``"pkg.mod:function"``)
        --import-linter's contracts (pyproject.toml)--> the contracts broken
        --the panels' rule (below)-->                   broken too, as ``panels-via-model``

Why the names: ``lint-imports`` sees statements only, so ``importlib.import_module("volanim_studio...")`` in
the core would pass it. Why the panels' rule here: import-linter's module expressions cannot say "every
module whose name ends in ``_panel``", and a new panel must not slip through a list.

Run as a script it checks one tree, applying each ``--case FILE TEXT`` to a scratch copy in turn (the
contract tests' bad imports), and prints one JSON line per check: ``{"case": ..., "broken": [ids]}``.
It runs in its own process so that the tree it checks is the one found on ``sys.path``.
"""

from __future__ import annotations

import argparse
import ast
import contextlib
import io
import json
import re
import sys
from pathlib import Path

DOTTED = re.compile(r"^[A-Za-z_]\w*(\.[A-Za-z_]\w*)+(:[A-Za-z_]\w*)?$")
OURS = ("volanim_core", "volanim_studio")
NAMING = re.compile(r"import_module|__import__|['\"]volanim_(core|studio)\.")
PANELS = re.compile(r"^volanim_studio\.qt\.\w+_(panel|dialog)$")


def named_imports(src: Path, graph) -> list[tuple[str, str, int]]:
    """``(importer, imported, line)`` for every module a file names in a string: the argument of
    ``import_module``/``__import__`` (any module the graph holds), or a dotted name of ours (``volanim_core.x``,
    ``volanim_core.x:f``)."""
    roots = {m.split(".")[0] for m in graph.modules}
    out = []
    for path in sorted(src.rglob("*.py")):
        rel = path.relative_to(src).with_suffix("")
        importer = ".".join(rel.parts[:-1] if rel.name == "__init__" else rel.parts)
        if importer not in graph.modules:
            continue
        text_of_file = path.read_text(encoding="utf-8")
        if not NAMING.search(text_of_file):  # (parsing every file takes seconds; few name a module)
            continue
        for node in ast.walk(ast.parse(text_of_file)):
            text = None
            if isinstance(node, ast.Call) and node.args and isinstance(node.args[0], ast.Constant):
                func = node.func
                name = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")
                if name in ("import_module", "__import__") and isinstance(node.args[0].value, str):
                    text = node.args[0].value
            elif isinstance(node, ast.Constant) and isinstance(node.value, str) and DOTTED.match(node.value) \
                    and node.value.split(".")[0] in OURS:  # ("zarr.json" is a file's name, not a module)
                text = node.value
            if text and text.split(".")[0].split(":")[0] in roots:
                module = text.split(":")[0]
                while module not in graph.modules and "." in module:  # "pkg.mod.function" names pkg.mod
                    module = module.rsplit(".", 1)[0]
                if module in graph.modules and module != importer:
                    out.append((importer, module, node.lineno))
    return out


def build_graph(src: Path, roots: list[str], include_external_packages: bool = True):
    """The grimp graph of ``roots`` (found under ``src``), with the imports made by name added."""
    import grimp

    graph = grimp.build_graph(*roots, include_external_packages=include_external_packages, cache_dir=None)
    for importer, imported, line in named_imports(src, graph):
        graph.add_import(importer=importer, imported=imported, line_number=line,
                         line_contents=f"(by name) {imported}")
    return graph


def panels_via_model(graph) -> list[str]:
    """The studio's panels and dialogs bind to the document and settings, never to the scene: only the
    main window and the controllers hold it."""
    panels = [m for m in graph.modules if PANELS.match(m)]
    if len(panels) < 5:
        return [f"found {len(panels)} panels: has the studio's qt package moved?"]
    return [f"{p} imports {i}" for p in sorted(panels) for i in sorted(graph.find_modules_directly_imported_by(p))
            if i == "volanim_studio.scene" or i.startswith("volanim_studio.scene.")]


def check(tree: Path) -> tuple[list[str], str]:
    """The ids of the contracts broken in ``tree`` (holding ``src/`` and ``pyproject.toml``), and a report."""
    from importlinter import configuration
    from importlinter.application import use_cases
    from importlinter.application.app_config import settings
    from importlinter.application.rendering import render_report

    configuration.configure()
    src = tree / "src"

    class NamedImportsBuilder:
        def build(self, root_package_names, cache_dir, include_external_packages=False,
                  exclude_type_checking_imports=False):
            return build_graph(src, root_package_names, bool(include_external_packages))

    settings.configure(GRAPH_BUILDER=NamedImportsBuilder())
    use_cases._register_built_in_contract_types()  # (lint_imports does this first; create_report does not)
    options = use_cases.read_user_options(str(tree / "pyproject.toml"))
    report = use_cases.create_report(options, cache_dir=None)
    broken = [contract.contract_options["id"] for contract, result in report.get_contracts_and_checks()
              if not result.kept]
    panels = panels_via_model(report.graph)
    if panels:
        broken.append("panels-via-model")
    text = io.StringIO()
    with contextlib.redirect_stdout(text):
        render_report(report)
    return broken, text.getvalue() + "".join(f"\npanels-via-model: {p}" for p in panels)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("tree", type=Path, help="a folder holding src/ and pyproject.toml")
    parser.add_argument("--case", nargs=3, action="append", default=[], metavar=("NAME", "FILE", "TEXT"),
                        help="append TEXT to src/FILE, check, and put the file back (repeatable)")
    args = parser.parse_args(argv)
    src = (args.tree / "src").resolve()
    sys.path.insert(0, str(src))
    import importlib.util

    for root in ("volanim_core", "volanim_studio"):  # the tree checked is the one given, not an installed one
        found = Path(importlib.util.find_spec(root).origin).resolve()
        if src not in found.parents:
            raise SystemExit(f"{root} resolves to {found}, not under {src}")
    cases = [("as it is", None, None)] + [(n, f, t) for n, f, t in args.case]
    for name, file, text in cases:
        path = src / file if file else None
        before = path.read_text(encoding="utf-8") if path and path.exists() else None
        if path:
            path.write_text((before or "") + text.replace("\\n", "\n"), encoding="utf-8")
        try:
            broken, report = check(args.tree)
        finally:
            if path and before is None:
                path.unlink()
            elif path:
                path.write_text(before, encoding="utf-8")
        print(json.dumps({"case": name, "broken": broken, "report": report}), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
