"""volanim's own Sphinx extension: the pages made from the code, and HTML anchors as link targets.

    builder-inited --> reference/cli.md        every ``volanim`` subcommand's --help, from build_parser()
                   --> reference/shortcuts.md  the studio's shortcuts, from volanim_studio.shortcuts (F1's table)
    source-read    --> ``<a id="NAME"></a>`` lines become MyST targets ``(NAME)=``, so ``formats.md#NAME``
                       links (which GitHub follows through the HTML anchor) are checked by the build too

The generated pages are written under ``docs/reference/`` and ignored by git: they are never typed.
"""

from __future__ import annotations

import re
from pathlib import Path

ANCHOR = re.compile(r'^<a id="([\w-]+)"></a>\s*$', re.M)
GENERATED = ("reference/cli.md", "reference/shortcuts.md")


def cli_page() -> str:
    """The command-line reference: the top-level help, then each subcommand's, in ``volanim --help``'s order."""
    from volanim_core.cli import build_parser, subcommands

    parser = build_parser()
    out = ["# Command line: `volanim`", "",
           "Generated from the `volanim` parsers at build time: this is exactly what `volanim --help` and "
           "`volanim COMMAND --help` print. Every example below runs in CI, in order, in a fresh folder.", "",
           "```text", parser.format_help().rstrip(), "```", ""]
    for name, sub in subcommands(parser).items():
        out += [f"## volanim {name}", "", "```text", sub.format_help().rstrip(), "```", ""]
    return "\n".join(out)


def shortcuts_page() -> str:
    from volanim_studio.shortcuts import SHORTCUTS

    rows = [f"| {key} | {action} |" for key, action in SHORTCUTS]
    return "\n".join(["# Studio shortcuts", "",
                      "The table the studio shows on F1 (*Help → Shortcuts*), generated from the same list "
                      "(`volanim_studio.shortcuts.SHORTCUTS`).", "", "| key | action |", "|---|---|", *rows, ""])


def write_generated(app) -> None:
    src = Path(app.srcdir)
    for name, make in zip(GENERATED, (cli_page, shortcuts_page)):
        path = src / name
        text = make()
        if not path.exists() or path.read_text(encoding="utf-8") != text:  # unchanged: Sphinx keeps its cache
            path.write_text(text, encoding="utf-8")


def anchors_to_targets(app, docname, source) -> None:
    source[0] = ANCHOR.sub(lambda m: f"({m[1]})=", source[0])


def setup(app):
    app.connect("builder-inited", write_generated)
    app.connect("source-read", anchors_to_targets)
    return {"version": "1", "parallel_read_safe": True, "parallel_write_safe": True}
