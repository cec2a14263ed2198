"""Reading a file we were only given a name of: a regular file, of bounded size, and JSON through one
checked number parser.

    path --regular_file_bytes(limit)--> bytes     (a device, a FIFO, a folder or a file over ``limit``: FormatError)
    path --load_json(limit)-----------> value     (numbers: finite, whole numbers within int64;
                                                   nesting past what Python parses: FormatError)

``/dev/zero`` named as a project's clip or bones read until memory ran out (9.5 GB), because its size
reads 0; a 401-digit integer in a project raised OverflowError where a float was made of it, and
100 000 nested arrays raised RecursionError. Every JSON file and every file named inside another goes
through here, so each reader refuses them with the file's name.
"""

from __future__ import annotations

import json
import math
import os
import stat
from pathlib import Path

from volanim_core.errors import FormatError

MAX_JSON_BYTES = 64 << 20  # a project, a plan or a store's metadata: kilobytes; 64 MB is no such file
MAX_INT = 2**63 - 1


def regular_file_bytes(path, limit: int, what: str = "file") -> bytes:
    """The bytes of ``path``, which must be a regular file of at most ``limit`` bytes (FormatError or, when it
    cannot be read, FormatError with the reason)."""
    path = Path(path)
    try:
        with open(path, "rb") as fh:
            st = os.fstat(fh.fileno())
            if not stat.S_ISREG(st.st_mode):
                raise FormatError(path, f"is not a regular file (a device, a pipe or a folder); expected a {what}")
            if st.st_size > limit:
                raise FormatError(path, f"is {st.st_size:,} bytes; a {what} is at most {limit:,}")
            data = fh.read(limit + 1)  # a file that grew since: never more than the limit
    except OSError as exc:
        raise FormatError(path, f"cannot read file: {exc.strerror or exc}") from exc
    if len(data) > limit:
        raise FormatError(path, f"is over {limit:,} bytes; a {what} is at most {limit:,}")
    return data


def _int(text: str) -> int:
    if len(text.lstrip("-")) > 19 or abs(value := int(text)) > MAX_INT:
        raise ValueError(f"a whole number out of range ({text[:20]}{'...' if len(text) > 20 else ''}, "
                         f"{len(text.lstrip('-'))} digits)")
    return value


def _float(text: str) -> float:
    value = float(text)
    if not math.isfinite(value):
        raise ValueError(f"a number out of range ({text[:24]})")
    return value


def _constant(name: str):
    raise ValueError(f"{name} is not a number volanim reads")


#: ``json.loads(text, **CHECKED_NUMBERS)``: finite floats and int64 whole numbers, NaN and Infinity refused
#: (ValueError, not JSONDecodeError)
CHECKED_NUMBERS = {"parse_int": _int, "parse_float": _float, "parse_constant": _constant}


def parse_json(path, text: str | bytes):
    """JSON with checked numbers (:data:`CHECKED_NUMBERS`); FormatError naming ``path`` (and the line, for
    syntax errors)."""
    try:
        return json.loads(text, **CHECKED_NUMBERS)
    except json.JSONDecodeError as exc:
        raise FormatError(path, f"not JSON ({exc.msg})", exc.lineno) from None
    except RecursionError:
        raise FormatError(path, "JSON nested too deeply") from None
    except UnicodeDecodeError:
        raise FormatError(path, "not UTF-8 text, expected JSON") from None
    except ValueError as exc:  # the number hooks
        raise FormatError(path, f"holds {exc}") from None


def load_json(path, limit: int = MAX_JSON_BYTES, what: str = "JSON file"):
    """:func:`parse_json` of a regular file of at most ``limit`` bytes."""
    return parse_json(path, regular_file_bytes(path, limit, what))


def resolved(path) -> Path:
    """``Path(path).resolve()``, a symbolic-link loop refused as FormatError naming the path (Python raises
    RuntimeError "Symlink loop", which reached users of ``render`` and ``view`` as a traceback)."""
    try:
        return Path(path).resolve()
    except (RuntimeError, OSError) as exc:
        raise FormatError(path, f"its path cannot be resolved ({exc}): a symbolic link that leads back to "
                                "itself?") from None
