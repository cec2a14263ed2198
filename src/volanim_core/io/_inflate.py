"""Inflating gzip (or zlib) data with a cap, so a small bomb cannot take the machine's memory."""

from __future__ import annotations

import zlib
from collections.abc import Iterator
from pathlib import Path

from volanim_core.errors import FormatError

CHUNK = 1 << 20


def inflate_capped(path: Path, fh, cap: int) -> Iterator[bytes]:
    """The inflated data of ``fh`` from its current position, in chunks, stopping after ``cap`` bytes
    (or at the end of the stream). Corrupt data is a FormatError naming ``path``."""
    inflater = zlib.decompressobj(wbits=47)  # gzip or zlib header, detected
    done = 0
    try:
        while done < cap and not inflater.eof:
            chunk = inflater.unconsumed_tail or fh.read(CHUNK)
            if not chunk:
                return
            out = inflater.decompress(chunk, min(cap - done, 4 * CHUNK))
            done += len(out)
            yield out
    except zlib.error as exc:
        raise FormatError(path, f"its compressed data is corrupt: {exc}") from None
