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


def _update_tables():
    import importlib.util

    spec = importlib.util.spec_from_file_location("update_tables", REPO / "docs" / "update_tables.py")
    update = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(update)
    return update


def test_the_commands_table_is_what_make_tables_writes():
    """Tables are written by the code that knows them (docs/update_tables.py), never typed: the volume
    tools table must equal what the parser gives now (the benchmark tables need the benchmarks, so
    they are only checked to be generated regions, each in one page)."""
    update = _update_tables()
    home = update.where("commands")
    text = home.read_text(encoding="utf-8")
    regions = update.regions(text)
    assert regions["commands"] == update.commands_table(), f"{home.name}'s command table is stale: make tables"
    found = {n: update.where(n) for n in update.SCRIPTS}  # each benchmark's tables have one region, in one page
    for name, page in found.items():
        body = update.regions(page.read_text(encoding="utf-8"))[name]
        assert "*Written by `benchmarks/" in body and "cores" in body, name
    new = update.replace_region(text, "commands", "| a |\n")
    assert update.regions(new)["commands"] == "| a |\n"
    assert {n: b for n, b in update.regions(new).items() if n != "commands"} == \
        {n: b for n, b in regions.items() if n != "commands"}


def test_make_tables_keeps_prose_edited_while_the_benchmarks_ran(tmp_path, monkeypatch):
    """The benchmarks take minutes; make docs read the README before them and wrote that text back
    with the new tables, losing any edit made meanwhile."""
    update = _update_tables()
    page = tmp_path / "page.md"
    page.write_text("intro\n<!-- make tables: commands -->\nold\n<!-- end: commands -->\n", encoding="utf-8")
    monkeypatch.setattr(update, "pages", lambda: [page])
    real = update.generate

    def generate_while_someone_edits(name):
        body = real(name)
        page.write_text(page.read_text(encoding="utf-8").replace("intro", "intro, edited"), encoding="utf-8")
        return body

    monkeypatch.setattr(update, "generate", generate_while_someone_edits)
    assert update.main(["commands"]) == 0
    text = page.read_text(encoding="utf-8")
    assert text.startswith("intro, edited\n") and update.regions(text)["commands"] == update.commands_table()
