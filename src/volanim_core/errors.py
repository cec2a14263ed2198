"""Exceptions shared by the whole library.

Every reader raises :class:`FormatError` for a bad file, so callers (the CLI,
the studio) catch one type and show its message, which always names the file,
the line where there is one, and what was expected.
"""

from __future__ import annotations

from pathlib import Path


class FormatError(ValueError):
    """A file that does not follow ``docs/formats.md``.

    Parameters
    ----------
    path : str or Path
        The offending file.
    message : str
        What was wrong and what was expected.
    line : int, optional
        1-based line number for text formats.
    """

    def __init__(self, path: str | Path, message: str, line: int | None = None):
        self.path = str(path)
        self.line = line
        self.reason = message
        where = f"{self.path}:{line}" if line is not None else self.path
        super().__init__(f"{where}: {message}")

    def __reduce__(self):
        # pickled by its own arguments: a FormatError raised in a worker process (a frame read to render) came
        # back as "a worker process died", as unpickling called __init__ with the message alone (#89)
        return type(self), (self.path, self.reason, self.line)


class Cancelled(Exception):
    """Raised inside long computations when the caller's cancel flag is set."""
