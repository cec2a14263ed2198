"""Palette, alpha-map and remap-table text files (the colour tools; docs/formats.md#palette).

    # volanim palette 1        # volanim alpha 1            # volanim remap 1
    0 0 0                      # index alpha (0..1)          # old new
    224 172 140                0   0                         0 0
    ...                        1   0.6                       1 17
                               254 0.9                       ...

A palette holds one colour a line, ``R G B`` in 0..255; line k (blank lines and
``#`` comments not counted) is index k, counting from 0, at most 256 colours.
An alpha map is ``INDEX ALPHA`` control points, ascending, linear between and
held beyond the ends. A remap table is ``FROM TO`` lines, what ``volanim remap
--table`` reads. All follow the text conventions of the other files (``#``
comments, CRLF, tabs, a byte-order mark) and errors name the line.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .atomic import atomic_write_text
from .text import fmt_float, parse_float, parse_int, read_records

MAX_COLOURS = 256


def read_palette(path: str | Path) -> np.ndarray:
    """A palette file as an ``(N, 3)`` uint8 array, row k = index k."""
    rec = read_records(path)
    rows = []
    for line, tokens in rec.records:
        if len(tokens) != 3:
            raise rec.error(line, f"expected R G B (three whole numbers 0..255), got {len(tokens)} values")
        rgb = [parse_int(rec, line, t, name) for t, name in zip(tokens, ("red", "green", "blue"))]
        for v, name in zip(rgb, ("red", "green", "blue")):
            if not 0 <= v <= 255:
                raise rec.error(line, f"{name} must be 0..255, got {v}")
        rows.append(rgb)
        if len(rows) > MAX_COLOURS:
            raise rec.error(line, f"a palette has at most {MAX_COLOURS} colours (index volumes hold bytes)")
    return np.array(rows, np.uint8).reshape(-1, 3)


def write_palette(path: str | Path, palette: np.ndarray, comment: str = "") -> None:
    """Write ``(N, 3)`` colours, one ``R G B`` line each, atomically."""
    palette = np.asarray(palette)
    if palette.ndim != 2 or palette.shape[1] != 3 or not 1 <= len(palette) <= MAX_COLOURS:
        raise ValueError(f"a palette is 1..{MAX_COLOURS} RGB colours, got shape {palette.shape}")
    head = ["# volanim palette 1", "# R G B (0..255); line k is index k, counting from 0"]
    head += [f"# {c}" for c in comment.splitlines() if c]
    atomic_write_text(path, "\n".join(head + [f"{r} {g} {b}" for r, g, b in palette.astype(int)]) + "\n")


def read_alpha_map(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """An alpha map: ``(indices, alphas)``, ascending indices, alphas 0..1."""
    rec = read_records(path)
    values, alphas = [], []
    for line, tokens in rec.records:
        if len(tokens) != 2:
            raise rec.error(line, f"expected INDEX ALPHA (two numbers), got {len(tokens)}")
        v = parse_float(rec, line, tokens[0], "the index")
        a = parse_float(rec, line, tokens[1], "alpha")
        if not 0 <= a <= 1:
            raise rec.error(line, f"alpha is between 0 and 1, got {tokens[1]}")
        if values and v <= values[-1]:
            raise rec.error(line, f"indices must ascend: {tokens[0]} follows {fmt_float(values[-1])}")
        values.append(v)
        alphas.append(a)
    return np.array(values), np.array(alphas)


def write_alpha_map(path: str | Path, values, alphas) -> None:
    lines = ["# volanim alpha 1", "# index alpha (0..1), linear between"]
    # alphas rounded to 1e-9: arithmetic on them (a factor, a blend) would print 0.44999999999999996
    lines += [f"{fmt_float(v)} {fmt_float(round(float(a), 9))}" for v, a in zip(values, alphas)]
    atomic_write_text(path, "\n".join(lines) + "\n")


def write_remap_table(path: str | Path, table) -> None:
    """``table`` (old index -> new index, one entry per palette colour) as ``FROM TO`` lines, every
    index listed, as ``volanim remap --table`` reads them (indices past the table stay as they are)."""
    lines = ["# volanim remap 1", "# old-index new-index; apply with: volanim remap INDEX.vol OUT.vol --table THIS"]
    lines += [f"{a} {int(b)}" for a, b in enumerate(table)]
    atomic_write_text(path, "\n".join(lines) + "\n")
