"""``make tables``: rewrite the generated regions of the docs pages from the code and the benchmarks that measure them.

A region is the text between ``<!-- make tables: NAME -->`` and ``<!-- end: NAME -->``, in any page of the
site (``docs/**/*.md``) or the README; each name appears once in all of them:

    commands           the volume-tools table, from the ``volanim`` parser (help text and first example)
    bench_*, thesis_*  every table a benchmark script prints (run with VOLANIM_BENCH_MARKDOWN=1), followed
                       by the machine and the date, so figures are never typed by hand

``python docs/update_tables.py [NAME ...]`` regenerates the named regions (default: all; the benchmarks take
about 15 minutes on 2 cores). ``--check commands`` exits 1 if a region differs from what would be written.
"""

from __future__ import annotations

import argparse
import datetime
import os
import platform
import re
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
DOCS = ROOT / "docs"
SCRIPTS = {  # region -> the benchmark script that measures it
    "bench_skeleton": "benchmarks/bench_skeleton.py",
    "bench_studio": "benchmarks/bench_studio.py",
    "bench_connect": "benchmarks/bench_connect.py",
    "bench_motion": "benchmarks/bench_motion.py",
    "bench_reconstruct": "benchmarks/bench_reconstruct.py",
    "bench_sequence": "benchmarks/bench_sequence.py",
    "bench_render": "benchmarks/bench_render.py",
    "bench_colour": "benchmarks/bench_colour.py",
    "thesis_tables": "benchmarks/thesis_tables.py",
}
REGION = re.compile(r"(<!-- make tables: (?P<name>[\w-]+) -->\n)(?P<body>.*?)(<!-- end: (?P=name) -->)", re.S)


def pages() -> list[Path]:
    """Every page that may hold regions: the README and the site's Markdown (not what a build made)."""
    return [README] + sorted(p for p in DOCS.rglob("*.md") if "_build" not in p.parts)


def regions(text: str) -> dict[str, str]:
    return {m["name"]: m["body"] for m in REGION.finditer(text)}


def where(name: str) -> Path:
    """The one page holding region ``name``."""
    found = [p for p in pages() if name in regions(p.read_text(encoding="utf-8"))]
    if len(found) != 1:
        raise ValueError(f"region {name!r} is in {len(found)} pages (expected one): {[str(p) for p in found]}")
    return found[0]


def replace_region(text: str, name: str, body: str) -> str:
    """``text`` with region ``name``'s body replaced (it must exist exactly once)."""
    found = [m for m in REGION.finditer(text) if m["name"] == name]
    if len(found) != 1:
        raise ValueError(f"region {name!r} appears {len(found)} times (expected once)")
    m = found[0]
    return text[: m.start("body")] + body.rstrip("\n") + "\n" + text[m.end("body"):]


def commands_table() -> str:
    """The volume tools: every subcommand before ``samples`` in ``volanim --help``, with its first example."""
    from volanim_core.cli import build_parser, subcommands

    rows = ["| command | what it does (the old tool) | example |", "|---|---|---|"]
    for name, sub in subcommands(build_parser()).items():
        if name == "samples":
            return "\n".join(rows) + "\n"
        example = sub.epilog.splitlines()[1].strip().split("   #")[0].strip()
        rows.append(f"| `{name}` | {sub.description} | `{example}` |")
    raise RuntimeError("no samples command")


def machine() -> str:
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{os.cpu_count()} cores ({cpu}), {platform.system()}"


def benchmark_tables(script: str) -> str:
    env = dict(os.environ, VOLANIM_BENCH_MARKDOWN="1")
    # stdout is the tables; stderr (a benchmark's own progress, warnings) goes on to the terminal
    out = subprocess.run([sys.executable, str(ROOT / script)], cwd=ROOT, env=env, stdout=subprocess.PIPE, text=True,
                         check=True).stdout
    stamp = f"*Written by `{script}` through `make tables` on {datetime.date.today()}, {machine()}.*"
    return f"{as_markdown(out)}\n\n{stamp}\n"


def as_markdown(output: str) -> str:
    """A benchmark's output for a page: its Markdown tables as they are, every other run of
    lines (captions, ratios against targets, notes) in a plain-text block, so columns stay aligned."""
    blocks, current, kind = [], [], None
    for line in output.strip().splitlines():
        k = "table" if line.startswith("|") else "blank" if not line.strip() else "text"
        if k == "blank":
            k = kind if kind == "text" else "blank"
        if k != kind and current:
            blocks.append((kind, current))
            current = []
        kind = k
        if k != "blank":
            current.append(line)
    if current:
        blocks.append((kind, current))
    parts = []
    for k, lines in blocks:
        while lines and not lines[-1].strip():
            lines.pop()
        parts.append("\n".join(lines) if k == "table" else "```text\n" + "\n".join(lines) + "\n```")
    return "\n\n".join(parts)


def generate(name: str) -> str:
    if name == "commands":
        return commands_table()
    return benchmark_tables(SCRIPTS[name])


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("names", nargs="*", help=f"regions (default all): commands {' '.join(SCRIPTS)}")
    p.add_argument("--check", action="store_true", help="report regions that differ; write nothing")
    args = p.parse_args(argv)
    names = args.names or [n for page in pages() for n in regions(page.read_text(encoding="utf-8"))]
    homes = {name: where(name) for name in names}
    bodies = {}
    for name in names:
        print(f"make tables: {name} ...", end=" ", flush=True)
        t0 = time.perf_counter()
        bodies[name] = generate(name)
        print(f"{time.perf_counter() - t0:.0f} s", flush=True)
    from volanim_core.io.atomic import atomic_write_text

    stale = []
    for page in sorted(set(homes.values())):
        # read again now: the benchmarks take minutes, and prose edited meanwhile must not be lost
        text = page.read_text(encoding="utf-8")
        mine = [n for n in names if homes[n] == page]
        stale += [n for n in mine if regions(text).get(n) != bodies[n]]
        for name in mine:
            text = replace_region(text, name, bodies[name])
        if not args.check:
            atomic_write_text(page, text)
    if args.check:
        if stale:
            print(f"stale regions: {', '.join(stale)} (run `make tables`)")
        return 1 if stale else 0
    print(f"{len(names)} regions written ({', '.join(stale) or 'none'} changed)")
    return 0


if __name__ == "__main__":
    sys.path.insert(0, str(ROOT / "src"))
    raise SystemExit(main())
