"""The documentation stays true: docs/formats.md is tied to the readers' tests, and the README's
tables are generated, not typed.

docs/formats.md, the file contract in the repository, and the readers' tests are tied together.

Tests name the section they check with a ``# spec: docs/formats.md#<anchor>`` line; every
citation must point at a section that exists, and every section that defines a file (or a rule)
must be cited by at least one test.
"""

from __future__ import annotations

import re

from paths import REPO

DOC = REPO / "docs" / "formats.md"
# Sections that only group others (each of their subsections is a file with its own tests).
GROUPS = {"volumes", "skeletons", "bone-skeleton", "motion", "render", "tables", "other-volumes"}


def anchors() -> dict[str, int]:
    """Anchor -> heading level, from ``<a id="anchor"></a>`` lines right above headings."""
    text = DOC.read_text(encoding="utf-8")
    return {m[1]: len(m[2]) for m in re.finditer(r'^<a id="([\w-]+)"></a>\n(#{2,4}) ', text, flags=re.M)}


def citations() -> dict[str, list[str]]:
    cited: dict[str, list[str]] = {}
    for path in (REPO / "tests").rglob("*.py"):
        for anchor in re.findall(r"docs/formats\.md#([\w-]+)", path.read_text(encoding="utf-8")):
            cited.setdefault(anchor, []).append(str(path.relative_to(REPO)))
    return cited


def test_every_citation_points_at_a_section():
    known = anchors()
    wrong = {a: files for a, files in citations().items() if a not in known}
    assert not wrong, f"tests cite sections docs/formats.md does not have: {wrong}"


def test_every_file_section_is_checked_by_a_test():
    cited = citations()
    unchecked = [a for a in anchors() if a not in GROUPS and a not in cited]
    assert not unchecked, f"docs/formats.md sections no test cites: {unchecked}"


def test_the_readme_links_the_contract():
    readme = (REPO / "README.md").read_text(encoding="utf-8")
    assert "(docs/formats.md)" in readme and "../shared/" not in readme  # a clone has no ../shared


def test_the_readme_commands_table_is_what_make_docs_writes():
    """Tables are written by the code that knows them (docs/update_readme.py), never typed: the volume
    tools table must equal what the parser gives now (the benchmark tables need the benchmarks, so
    they are only checked to be generated regions)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("update_readme", REPO / "docs" / "update_readme.py")
    update = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(update)
    text = (REPO / "README.md").read_text(encoding="utf-8")
    regions = update.regions(text)
    assert regions["commands"] == update.commands_table(), "README's command table is stale: run `make docs`"
    assert set(update.SCRIPTS) <= set(regions), "every benchmark's tables have their README region"
    for name in update.SCRIPTS:
        assert "*Written by `benchmarks/" in regions[name] and "cores" in regions[name], name
    new = update.replace_region(text, "commands", "| a |\n")
    assert update.regions(new)["commands"] == "| a |\n" and update.regions(new)["thesis_tables"] == \
        regions["thesis_tables"]


def test_make_docs_keeps_prose_edited_while_the_benchmarks_ran(tmp_path, monkeypatch):
    """The benchmarks take minutes; make docs read the README before them and wrote that text back
    with the new tables, losing any edit made meanwhile."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("update_readme", REPO / "docs" / "update_readme.py")
    update = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(update)
    readme = tmp_path / "README.md"
    readme.write_text("intro\n<!-- make docs: commands -->\nold\n<!-- end: commands -->\n", encoding="utf-8")
    monkeypatch.setattr(update, "README", readme)
    real = update.generate

    def generate_while_someone_edits(name):
        body = real(name)
        readme.write_text(readme.read_text(encoding="utf-8").replace("intro", "intro, edited"), encoding="utf-8")
        return body

    monkeypatch.setattr(update, "generate", generate_while_someone_edits)
    assert update.main(["commands"]) == 0
    text = readme.read_text(encoding="utf-8")
    assert text.startswith("intro, edited\n") and update.regions(text)["commands"] == update.commands_table()
