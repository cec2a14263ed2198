"""Autosave and crash recovery, Qt-free (the window drives it with a timer).

    ROOT/<pid>-<start>/session.json        who owns this folder (pid)
    ROOT/<pid>-<start>/recovery.volanim    the last autosave, a project saved as one unit
    ROOT/<pid>-<start>/recovery.volanim.d/ its data files (this save's and the one before)

A save happens after every ``every_edits`` edits and every ``every_seconds``
while there are unsaved edits or the session's state (settings, thinness, the
frame, the selection, the camera: ``document_state``) differs from the last save.
A clean exit removes the folder; a folder whose pid is dead on the next start is a crashed session, offered for restore.
Edits the user discards are first set aside (a declined folder, kept a week).
A restored session's folder is removed only once the new session has
autosaved what it restored, and never when the restore failed.
ROOT is ``$VOLANIM_RECOVERY_DIR`` or ``~/.cache/volanim/recovery``.
"""

from __future__ import annotations

import json
import os
import shutil
import time
from pathlib import Path

from volanim_core.io.atomic import atomic_write_text

RECOVERY_FILE = "recovery.volanim"
DECLINED = "declined"
KEEP_DECLINED_SECONDS = 7 * 24 * 3600


def recovery_root() -> Path:
    env = os.environ.get("VOLANIM_RECOVERY_DIR")
    return Path(env) if env else Path.home() / ".cache" / "volanim" / "recovery"


def in_recovery_area(path) -> bool:
    """Whether ``path`` lies in the autosave area, where a declined session is pruned after a week: a
    project opened from there is saved with Save As, never in place."""
    try:
        Path(path).resolve().relative_to(recovery_root().resolve())
    except ValueError:
        return False
    return True


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def _session_pid(folder: Path) -> int | None:
    """The pid that owns a session folder, or None when its ``session.json`` is unreadable."""
    try:
        info = json.loads((folder / "session.json").read_text())
        return int(info["pid"])
    except (OSError, ValueError, KeyError, TypeError, RecursionError):
        return None


def find_recoveries(root: Path | None = None) -> list[Path]:
    """Recovery projects of sessions that did not exit cleanly (and were not declined), newest first."""
    root = root or recovery_root()
    found = []
    for folder in root.glob("*") if root.is_dir() else []:
        pid = _session_pid(folder)
        if (pid is not None and (folder / RECOVERY_FILE).is_file() and not (folder / DECLINED).exists()
                and not _alive(pid)):
            found.append(folder / RECOVERY_FILE)
    return sorted(found, key=lambda p: p.stat().st_mtime, reverse=True)


def prune(root: Path | None = None, *, now: float | None = None) -> int:
    """Remove folders of dead sessions with nothing to recover, and declined ones after a week.

    Returns how many folders went."""
    root = root or recovery_root()
    now = time.time() if now is None else now
    removed = 0
    for folder in root.glob("*") if root.is_dir() else []:
        pid = _session_pid(folder)
        if pid is None or _alive(pid):
            continue
        declined = folder / DECLINED
        if not (folder / RECOVERY_FILE).exists() or (
                declined.exists() and now - declined.stat().st_mtime > KEEP_DECLINED_SECONDS):
            shutil.rmtree(folder, ignore_errors=True)
            removed += 1
    return removed


def decline(recovery: Path) -> None:
    """The user said no: keep the folder a week (it can be opened as a project) but do not ask again."""
    atomic_write_text(Path(recovery).parent / DECLINED, f"{time.time()}\n")


def describe(recovery: Path) -> str:
    """When an autosave was written and what it holds, for the recovery question: "Tue 24 Nov 2026
    10:40: 18 bones, 4,380 attachments, a pose" (its folder's name is a process id and milliseconds)."""
    from volanim_core import io

    from .project import read_project

    recovery = Path(recovery)
    when = time.strftime("%a %d %b %Y %H:%M", time.localtime(recovery.stat().st_mtime))
    parts = []
    try:
        data = read_project(recovery)
        if data.get("bones"):
            parts.append(f"{len(io.read_bones(data['bones']))} bones")
        if data.get("connect"):
            parts.append(f"{len(io.read_connect(data['connect'])):,} attachments")
        angles, shifts = data["state"].get("pose") or ({}, {})
        if angles or shifts:
            parts.append("a pose")
        timeline = data["state"].get("timeline") or {}
        if timeline.get("keys"):
            parts.append(f"{len(timeline['keys'])} keys")
        if timeline.get("clip"):
            parts.append(f"the clip {Path(timeline['clip']['path']).name}")
    except (OSError, ValueError):  # FormatError is a ValueError: the question still names the time
        pass
    return when + (": " + ", ".join(parts) if parts else "")


def discard(recovery: Path) -> None:
    shutil.rmtree(Path(recovery).parent, ignore_errors=True)


class Autosaver:
    def __init__(self, doc, root: Path | None = None, *, every_edits: int = 5, every_seconds: float = 60.0,
                 clock=time.monotonic):
        self.doc = doc
        self.every_edits = every_edits
        self.every_seconds = every_seconds
        self.clock = clock
        self.root = root or recovery_root()
        prune(self.root)
        self._new_folder()
        self._saved_edits = doc.undo.edits
        self._saved_state = self._state()
        self._saved_at = clock()
        self.saves = 0

    def _new_folder(self) -> None:
        self.folder = self.root / f"{os.getpid()}-{int(time.time() * 1000)}"
        self.folder.mkdir(parents=True, exist_ok=True)
        atomic_write_text(self.folder / "session.json", json.dumps({"pid": os.getpid(), "started": time.time()}))

    @property
    def path(self) -> Path:
        return self.folder / RECOVERY_FILE

    def _state(self) -> str:
        """The session's state besides its edits (view state is not undoable, so no edit counts it)."""
        from .document_state import save_all

        return json.dumps(save_all(self.doc, self.path), sort_keys=True, default=str)

    @property
    def dirty(self) -> bool:
        """Edits, or a changed view (a slider, the frame, the camera), not autosaved yet."""
        return self.doc.undo.edits != self._saved_edits or self._state() != self._saved_state

    def edited(self) -> bool:
        """After an edit: save when ``every_edits`` edits are unsaved -- not while a slider or the timeline is
        held: each step of a drag counts as an edit, and writing the project every fifth step cost a pose drag
        45 ms a save (#65); the release's save follows once the window is idle (SessionController)."""
        if self.doc.settings.dragging:
            return False
        if self.doc.undo.edits - self._saved_edits >= self.every_edits:
            return self.save()
        return False

    def tick(self) -> bool:
        """Periodically: save when there are unsaved edits older than ``every_seconds``."""
        if self.dirty and self.clock() - self._saved_at >= self.every_seconds:
            return self.save()
        return False

    def save(self) -> bool:
        """Autosave now (the skeleton's file is written only when the skeleton changed)."""
        state = self._state()
        self.doc.write_project(self.path)
        self._saved_edits, self._saved_state = self.doc.undo.edits, state
        self._saved_at = self.clock()
        self.saves += 1
        return True

    def set_aside(self) -> Path:
        """Keep the document as it is now for a week, out of this session's way, and go on in a new folder.

        For edits the user chose not to save (closing, or opening another volume): a
        wrong answer to "Save changes?" must not lose an afternoon's work. The kept
        folder is a declined recovery (never offered again, pruned after a week) and
        can be opened as a project. Returns the kept project file.
        """
        self.save()
        kept = self.folder.with_name(f"{self.folder.name}-discarded")
        self.folder.rename(kept)
        decline(kept / RECOVERY_FILE)
        self._new_folder()
        return kept / RECOVERY_FILE

    def close(self) -> None:
        """A clean exit: nothing to recover."""
        shutil.rmtree(self.folder, ignore_errors=True)
