"""Line reader shared by every text format.

    file bytes -> decode (UTF-8, no NUL) -> lines (CRLF ok) -> strip '#' comments
               -> (line number, tokens) records + header comments {key: value}

Tolerant of blank lines, comments, tabs and CRLF (FORMATS.md); everything else
is the caller's to validate, using :meth:`TextRecords.error` so messages carry
the file and line.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

from volanim_core.errors import FormatError

_HEADER = re.compile(r"^#\s*([A-Za-z_][\w ]*?)\s*:\s*(\S.*?)\s*$")


@dataclass
class TextRecords:
    """Non-empty, comment-stripped lines of a text file."""

    path: str
    records: list[tuple[int, list[str]]]
    header: dict[str, str] = field(default_factory=dict)
    first_comment: str | None = None

    def error(self, line: int | None, message: str) -> FormatError:
        return FormatError(self.path, message, line)


def read_records(path: str | Path, *, allow_empty: bool = False) -> TextRecords:
    """Read a text file into tokenised records.

    Header comments of the form ``# key: value`` (e.g. ``# metric: 345``) are
    collected in ``header`` with lower-case keys.
    """
    path = Path(path)
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise FormatError(path, f"cannot read file: {exc.strerror or exc}") from exc
    if b"\x00" in raw:
        raise FormatError(path, "this is a binary file, expected text")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw[: exc.start].count(b"\n") + 1
        raise FormatError(path, "not UTF-8 text, expected a text file", line) from exc
    records: list[tuple[int, list[str]]] = []
    header: dict[str, str] = {}
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
            line = line[:hash_at]
        tokens = line.split()
        if tokens:
            records.append((number, tokens))
    result = TextRecords(str(path), records, header, first_comment)
    if not records and not allow_empty:
        raise result.error(None, "the file is empty, expected at least one data line")
    return result


def parse_int(rec: TextRecords, line: int, token: str, what: str) -> int:
    """An integer token (``12`` or ``12.0``), else a FormatError naming ``what``."""
    try:
        return int(token)
    except ValueError:
        pass
    try:
        value = float(token)
    except ValueError:
        raise rec.error(line, f"expected an integer {what}, got {token!r}") from None
    if not value.is_integer():
        raise rec.error(line, f"expected an integer {what}, got {token!r}")
    return int(value)


def parse_float(rec: TextRecords, line: int, token: str, what: str) -> float:
    """A finite float token, else a FormatError naming ``what``."""
    try:
        value = float(token)
    except ValueError:
        raise rec.error(line, f"expected a number for {what}, got {token!r}") from None
    if value != value or value in (float("inf"), float("-inf")):
        raise rec.error(line, f"expected a finite number for {what}, got {token!r}")
    return value


def parse_metric(rec: TextRecords) -> str:
    """The ``# metric:`` header: ``euclid`` (default) or ``345``."""
    metric = rec.header.get("metric", "euclid").strip().lower()
    if metric in ("euclid", "euclidean"):
        return "euclid"
    if metric in ("345", "3-4-5", "chamfer"):
        return "345"
    raise rec.error(None, f"unknown '# metric: {metric}', expected 'euclid' or '345'")


def fmt_float(value: float) -> str:
    """Shortest text that reads back as exactly the same float."""
    value = float(value)
    return str(int(value)) if value.is_integer() and abs(value) < 1e15 else repr(value)
