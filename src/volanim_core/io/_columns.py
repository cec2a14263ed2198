"""Fast, strict parsing of numeric columns with line-numbered errors.

Vectorised conversion first (one ``np.array`` call over all tokens); only when
that fails does a per-token pass run, to find and name the first bad token.
"""

from __future__ import annotations

import numpy as np

from volanim_core.limits import MAX_COORD

from .text import TextRecords, parse_float, parse_int

_NUMBER_CHARS = set("0123456789+-.eE")


def parse_point_rows(
    rec: TextRecords, rows: list[tuple[int, list[str]]], ncols: tuple[int, ...], layout: str
) -> np.ndarray:
    """Parse ``x y z dt [thinness]`` rows into a float64 ``(N, max(ncols))`` array.

    Rows with fewer columns than the maximum get NaN in the missing ones.
    ``x y z`` must be integers within ``MAX_COORD``, every given value finite
    ASCII, and ``dt`` >= 0.
    """
    width = max(ncols)
    for line, toks in rows:
        if len(toks) not in ncols:
            want = " or ".join(str(n) for n in ncols)
            raise rec.error(line, f"expected {want} columns ({layout}), got {len(toks)}")
    out = np.full((len(rows), width), np.nan)
    if not rows:
        return out
    try:
        # float() would also take full-width digits, underscores, "nan": only ASCII digits, signs, '.', 'e'
        chars = set("".join("".join(t) for _, t in rows))
        if chars <= _NUMBER_CHARS:
            lengths = np.fromiter((len(t) for _, t in rows), np.int64, len(rows))
            if (lengths == width).all():
                out[:] = np.array([t for _, t in rows], dtype=np.float64)
            else:
                for k, (_, t) in enumerate(rows):
                    out[k, : len(t)] = np.array(t, dtype=np.float64)
            given = np.arange(width)[None, :] < lengths[:, None]
            ok = np.isfinite(out[given]).all() and (out[:, :3] == np.round(out[:, :3])).all()
            ok = ok and (np.abs(out[given]) <= MAX_COORD).all() and (out[:, 3] >= 0).all()
            if ok:
                return out
    except ValueError:
        pass
    # Slow path: locate the first bad token for the message.
    names = ("x", "y", "z", "dt", "thinness")
    for line, toks in rows:
        for j, tok in enumerate(toks):
            if j < 3:
                parse_int(rec, line, tok, f"coordinate {names[j]}")
            else:
                v = parse_float(rec, line, tok, names[j])
                if j == 3 and v < 0:
                    raise rec.error(line, f"expected dt >= 0, got {tok!r}")
    raise AssertionError("unreachable: vectorised parse failed but no bad token found")


def format_point_rows(points, dt, thinness=None) -> list[str]:
    """``x y z dt [thinness]`` lines, floats in shortest round-trip form."""
    from .text import fmt_float

    pts = np.asarray(points).tolist()
    dts = np.asarray(dt, dtype=np.float64).tolist()
    if thinness is None or np.all(np.isnan(thinness)):
        return [f"{p[0]} {p[1]} {p[2]} {fmt_float(d)}" for p, d in zip(pts, dts)]
    th = np.asarray(thinness, dtype=np.float64).tolist()
    return [
        f"{p[0]} {p[1]} {p[2]} {fmt_float(d)} {fmt_float(t)}"
        for p, d, t in zip(pts, dts, th)
    ]
