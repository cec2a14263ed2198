"""Autosave and crash recovery, Qt-free (the window drives it with a timer).

    ROOT/<pid>-<start>/session.json      who owns this folder (pid)
    ROOT/<pid>-<start>/recovery.volanim  the last autosave (+ .bones, .connect, .mskel)

A save happens after every ``every_edits`` edits and every ``every_seconds``
while there are unsaved edits. A clean exit removes the folder; a folder whose
pid is dead on the next start is a crashed session, offered for restore.
ROOT is ``$VOLANIM_RECOVERY_DIR`` or ``~/.cache/volanim/recovery``.
"""

from __future__ import annotations

import json
import os
import shutil
import time
from pathlib import Path

from volanim_core import io

RECOVERY_FILE = "recovery.volanim"


def recovery_root() -> Path:
    env = os.environ.get("VOLANIM_RECOVERY_DIR")
    return Path(env) if env else Path.home() / ".cache" / "volanim" / "recovery"


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def find_recoveries(root: Path | None = None) -> list[Path]:
    """Recovery projects of sessions that did not exit cleanly, newest first."""
    root = root or recovery_root()
    found = []
    for folder in root.glob("*") if root.is_dir() else []:
        try:
            info = json.loads((folder / "session.json").read_text())
        except (OSError, ValueError):
            continue
        if (folder / RECOVERY_FILE).is_file() and not _alive(int(info.get("pid", -1))):
            found.append(folder / RECOVERY_FILE)
    return sorted(found, key=lambda p: p.stat().st_mtime, reverse=True)


def prune(root: Path | None = None) -> int:
    """Remove folders of dead sessions that never autosaved (nothing to recover); returns how many."""
    root = root or recovery_root()
    removed = 0
    for folder in root.glob("*") if root.is_dir() else []:
        try:
            info = json.loads((folder / "session.json").read_text())
        except (OSError, ValueError):
            continue
        if not (folder / RECOVERY_FILE).exists() and not _alive(int(info.get("pid", -1))):
            shutil.rmtree(folder, ignore_errors=True)
            removed += 1
    return removed


def discard(recovery: Path) -> None:
    shutil.rmtree(Path(recovery).parent, ignore_errors=True)


class Autosaver:
    def __init__(self, doc, root: Path | None = None, *, every_edits: int = 5, every_seconds: float = 60.0,
                 clock=time.monotonic):
        self.doc = doc
        self.every_edits = every_edits
        self.every_seconds = every_seconds
        self.clock = clock
        root = root or recovery_root()
        prune(root)
        self.folder = root / f"{os.getpid()}-{int(time.time() * 1000)}"
        self.folder.mkdir(parents=True, exist_ok=True)
        (self.folder / "session.json").write_text(json.dumps({"pid": os.getpid(), "started": time.time()}))
        self._saved_edits = doc.undo.edits
        self._saved_at = clock()
        self._mskel_for = None
        self.saves = 0

    @property
    def path(self) -> Path:
        return self.folder / RECOVERY_FILE

    @property
    def dirty(self) -> bool:
        return self.doc.undo.edits != self._saved_edits

    def edited(self) -> bool:
        """After an edit: save when ``every_edits`` edits are unsaved."""
        if self.doc.undo.edits - self._saved_edits >= self.every_edits:
            return self.save()
        return False

    def tick(self) -> bool:
        """Periodically: save when there are unsaved edits older than ``every_seconds``."""
        if self.dirty and self.clock() - self._saved_at >= self.every_seconds:
            return self.save()
        return False

    def save(self) -> bool:
        doc = self.doc
        mskel = doc.mskel_path
        if doc.skeleton is not None and not mskel:
            # a skeleton computed in this session: copy it once, not at every autosave
            mskel = str(self.folder / "recovery.mskel")
            if self._mskel_for is not doc.skeleton:
                io.write_mskel(mskel, doc.skeleton)
                self._mskel_for = doc.skeleton
        doc.write_project(self.path, mskel=mskel)
        self._saved_edits = doc.undo.edits
        self._saved_at = self.clock()
        self.saves += 1
        return True

    def close(self) -> None:
        """A clean exit: nothing to recover."""
        shutil.rmtree(self.folder, ignore_errors=True)
