"""Line reader shared by every text format.

    file bytes -> decode (UTF-8, no NUL, a leading byte-order mark dropped) -> lines (CRLF ok)
               -> strip '#' comments -> (line number, tokens) records + header comments {key: value}

Tolerant of blank lines, comments, tabs, CRLF and the byte-order mark Windows
editors write (docs/formats.md); everything else is the caller's to validate, using
:meth:`TextRecords.error` so messages carry the file and line.

Numbers are ASCII (``NUMBER``): Python's ``int()``/``float()`` also take
full-width digits (``１２``) and underscores (``1_2``), which our formats do not.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

from volanim_core.errors import FormatError
from volanim_core.limits import MAX_COORD

_HEADER = re.compile(r"^#\s*([A-Za-z_][\w ]*?)\s*:\s*(\S.*?)\s*$")
NUMBER = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
MAX_TEXT_BYTES = 2**31  # 2 GB of text is ~50 M points; anything larger is not one of our files



@dataclass
class TextRecords:
    """Non-empty, comment-stripped lines of a text file."""

    path: str
    records: list[tuple[int, list[str]]]
    header: dict[str, str] = field(default_factory=dict)
    first_comment: str | None = None
    header_lines: dict[str, int] = field(default_factory=dict)  # where each header comment stands

    def error(self, line: int | None, message: str) -> FormatError:
        return FormatError(self.path, message, line)


def read_records(path: str | Path, *, allow_empty: bool = False) -> TextRecords:
    """Read a text file into tokenised records.

    Header comments of the form ``# key: value`` (e.g. ``# metric: 345``) are
    collected in ``header`` with lower-case keys.
    """
    from volanim_core.io.files import regular_file_bytes

    path = Path(path)
    raw = regular_file_bytes(path, MAX_TEXT_BYTES, "text file")  # /dev/zero's size reads 0: it read forever
    if b"\x00" in raw:
        raise FormatError(path, "this is a binary file, expected text")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise FormatError(path, "not UTF-8 text, expected a text file", line) from exc
    text = text.removeprefix("\ufeff")
    records: list[tuple[int, list[str]]] = []
    header: dict[str, str] = {}
    header_lines: dict[str, int] = {}
    first_comment = None
    for number, line in enumerate(text.splitlines(), start=1):
        hash_at = line.find("#")
        if hash_at >= 0:
            comment = line[hash_at:]
            if first_comment is None and not records:
                first_comment = comment[1:].strip()
            m = _HEADER.match(comment.strip())
            if m:
                header[m.group(1).strip().lower()] = m.group(2)
                header_lines[m.group(1).strip().lower()] = number
            line = line[:hash_at]
        tokens = line.split()
        if tokens:
            records.append((number, tokens))
    result = TextRecords(str(path), records, header, first_comment, header_lines)
    if not records and not allow_empty:
        raise result.error(None, "the file is empty, expected at least one data line")
    return result


def is_number(token: str) -> bool:
    """An ASCII decimal number (no NaN, no infinity, no underscores, no full-width digits)."""
    return NUMBER.fullmatch(token) is not None


def parse_int(rec: TextRecords, line: int, token: str, what: str, limit: int = MAX_COORD) -> int:
    """An integer token (``12`` or ``12.0``) with ``|value| <= limit``, else a FormatError naming ``what``."""
    if not is_number(token):
        raise rec.error(line, f"expected an integer {what}, got {token!r}")
    value = float(token)
    if not value.is_integer():
        raise rec.error(line, f"expected an integer {what}, got {token!r}")
    if abs(value) > limit:
        raise rec.error(line, f"{what} {token} is out of range (at most {limit:,} in size)")
    return int(token) if token.lstrip("+-").isdigit() else int(value)


def parse_float(rec: TextRecords, line: int, token: str, what: str, limit: float = MAX_COORD) -> float:
    """A finite float token with ``|value| <= limit``, else a FormatError naming ``what``.

    Every number in our files is a voxel coordinate, a radius, a thinness or a
    matrix entry: none is meaningful beyond ``MAX_COORD``.
    """
    if token.isascii() and "_" not in token and token.strip() == token:  # what float() takes beyond is_number
        try:
            value = float(token)
        except ValueError:
            value = None
        # the common case, without the regex (a 1064-frame clip's .trans files hold 421 k numbers): finite,
        # in range and no nan/inf spelt out (float() takes "nan" and "infinity": they fail the range test)
        if value is not None and abs(value) <= limit:
            return value
    if not is_number(token):
        raise rec.error(line, f"expected a finite number for {what}, got {token!r}")
    value = float(token)
    if value in (float("inf"), float("-inf")):  # 1e999
        raise rec.error(line, f"expected a finite number for {what}, got {token!r}")
    if abs(value) > limit:
        raise rec.error(line, f"{what} {token} is out of range (at most {limit:,} in size)")
    return value


def parse_metric(rec: TextRecords) -> str:
    """The ``# metric:`` header: ``euclid`` (default) or ``345``."""
    metric = rec.header.get("metric", "euclid").strip().lower()
    if metric in ("euclid", "euclidean"):
        return "euclid"
    if metric in ("345", "3-4-5", "chamfer"):
        return "345"
    raise rec.error(None, f"unknown '# metric: {metric}', expected 'euclid' or '345'")


def parse_header(rec: TextRecords, key: str, parse, default):
    """The ``# KEY:`` header through ``parse(text)``, or ``default`` when the file has none; a ValueError
    from ``parse`` becomes the file's error at that header's line."""
    text = rec.header.get(key)
    if text is None:
        return default
    try:
        return parse(text)
    except ValueError as exc:
        raise rec.error(rec.header_lines.get(key), f"bad '# {key}:' header: {exc}") from None


def parse_geometry(rec: TextRecords):
    """The ``# geometry:`` header (docs/formats.md, "Physical space"); the identity when there is none."""
    from volanim_core.geometry import IDENTITY, Geometry

    return parse_header(rec, "geometry", Geometry.parse, IDENTITY)


def fmt_float(value: float) -> str:
    """Shortest text that reads back as exactly the same float."""
    value = float(value)
    return str(int(value)) if value.is_integer() and abs(value) < 1e15 else repr(value)
