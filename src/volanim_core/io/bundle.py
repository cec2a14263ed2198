"""Several files saved as one unit: content-named data files, then a manifest renamed into place last.

    NAME.volanim                 the manifest (JSON); names its data files and their SHA-256
    NAME.volanim.d/              the data files, named by content: bones-1a2b3c4d5e6f.bones, ...
    NAME.volanim.d/previous.json the manifest before the last save (the previous generation)

Why this shape: each data file is written atomically under a name derived from
its content, so writing a new generation never touches a file the current
manifest names. The manifest is replaced atomically *last*, so at every
instant the manifest on disk names a complete, consistent set. A kill at any
moment leaves either the old generation or the new one, never a mix. Files
no manifest (current or previous) names are removed after a save; data that
did not change keeps its name and is not rewritten.

Reading checks every named file against its hash; if the current generation
is damaged (disk trouble, someone edited a file) the previous one is used, with
a warning. Nothing is ever deleted on a failed read.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import re
from collections.abc import Callable
from pathlib import Path

from volanim_core.errors import FormatError

from .atomic import atomic_write_text, clean_stale, fsync_folder, pending_name

PREVIOUS = "previous.json"
_CONTENT_NAME = re.compile(r"^[a-z]+-[0-9a-f]{12}\.[A-Za-z0-9]+$")
MAX_MANIFEST_BYTES = 16 * 2**20  # a manifest is a few kB; refuse to parse anything huge


def store_folder(manifest: str | Path) -> Path:
    manifest = Path(manifest)
    return manifest.with_name(manifest.name + ".d")


def file_sha256(path: str | Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def store_file(manifest: str | Path, kind: str, suffix: str, write: Callable[[Path], None]) -> tuple[str, str]:
    """Write one data file of the next generation; returns ``(path relative to the manifest, sha256)``.

    ``write(path)`` writes the content to ``path`` (any atomic writer of ours);
    the result is then renamed to a name made of ``kind`` and its hash.
    """
    folder = store_folder(manifest)
    folder.mkdir(parents=True, exist_ok=True)
    clean_stale(folder, kind, ".tmp" + suffix)
    tmp = folder / pending_name(kind, ".tmp" + suffix)
    try:
        write(tmp)
        digest = file_sha256(tmp)
        final = folder / f"{kind}-{digest[:12]}{suffix}"
        if final.is_file() and file_sha256(final) == digest:
            tmp.unlink()
        else:
            os.replace(tmp, final)
    finally:
        with contextlib.suppress(FileNotFoundError):
            tmp.unlink()
    return f"{folder.name}/{final.name}", digest


def commit(manifest: str | Path, data: dict) -> None:
    """Make ``data`` (whose ``"sha256"`` maps keys to the stored files) the current generation."""
    manifest = Path(manifest)
    folder = store_folder(manifest)
    folder.mkdir(parents=True, exist_ok=True)
    fsync_folder(folder)  # the data files' names are durable before a manifest names them
    if manifest.is_file():
        with contextlib.suppress(OSError, ValueError):
            old = manifest.read_text(encoding="utf-8-sig")
            json.loads(old)  # only a readable manifest becomes "previous"
            atomic_write_text(folder / PREVIOUS, old)
    atomic_write_text(manifest, json.dumps(data, indent=2) + "\n")
    fsync_folder(manifest.parent)
    collect_garbage(manifest)


def _named_files(manifest_text: str, folder_name: str) -> set[str]:
    with contextlib.suppress(ValueError, RecursionError):
        data = json.loads(manifest_text)
        if isinstance(data, dict):
            return {v.split("/", 1)[1] for v in data.values()
                    if isinstance(v, str) and v.startswith(folder_name + "/")}
    return set()


def collect_garbage(manifest: str | Path) -> int:
    """Remove content-named files neither the current nor the previous manifest names; returns how many."""
    manifest = Path(manifest)
    folder = store_folder(manifest)
    keep: set[str] = set()
    for m in (manifest, folder / PREVIOUS):
        with contextlib.suppress(OSError, UnicodeDecodeError):
            keep |= _named_files(m.read_text(encoding="utf-8-sig"), folder.name)
    removed = 0
    for f in folder.iterdir() if folder.is_dir() else []:
        if _CONTENT_NAME.match(f.name) and f.name not in keep:
            with contextlib.suppress(OSError):
                f.unlink()
                removed += 1
    return removed


def verify(manifest: str | Path, data: dict) -> None:
    """Raise FormatError naming the first file that is missing or not the one the manifest saved."""
    manifest = Path(manifest)
    hashes = data.get("sha256") or {}
    if not isinstance(hashes, dict):
        raise FormatError(manifest, "\"sha256\" must be an object")
    for key, digest in hashes.items():
        rel = data.get(key)
        if not isinstance(rel, str) or not isinstance(digest, str):
            raise FormatError(manifest, f"\"sha256\" names \"{key}\", which is not a saved file")
        path = manifest.parent / rel
        if not path.is_file():  # a device (/dev/zero) would be hashed forever
            raise FormatError(manifest, f"its {key} file {path} is missing or not a regular file")
        try:
            actual = file_sha256(path)
        except OSError as exc:
            raise FormatError(manifest, f"its {key} file {path} cannot be read: {exc.strerror or exc}") from exc
        if actual != digest:
            raise FormatError(manifest, f"its {key} file {path} was changed or damaged after the save "
                                        "(its SHA-256 does not match)")


def load(manifest: str | Path, parse: Callable[[Path, str], dict]) -> tuple[dict, list[str]]:
    """Read and verify the current generation, or the previous one if the current is damaged.

    ``parse(path, text)`` turns manifest text into checked data (raising FormatError).
    Returns ``(data, warnings)``; raises the current generation's FormatError when neither is usable.
    """
    manifest = Path(manifest)
    try:
        data = parse(manifest, read_manifest_text(manifest))
        verify(manifest, data)
        return data, []
    except FormatError as current_error:
        previous = store_folder(manifest) / PREVIOUS
        if not previous.is_file():
            raise
        try:
            data = parse(manifest, read_manifest_text(previous))
            verify(manifest, data)
        except FormatError:
            raise current_error from None
        return data, [f"{current_error}; opened the previous save instead"]


def read_manifest_text(path: Path) -> str:
    """A manifest's text: a regular file of at most MAX_MANIFEST_BYTES (``/dev/zero`` read forever)."""
    from .files import regular_file_bytes

    try:
        return regular_file_bytes(path, MAX_MANIFEST_BYTES, "project file").decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise FormatError(path, f"cannot read: {exc}") from exc
