"""Autosave and crash recovery, Qt-free (the window polls it with a timer).

    ROOT/<pid>-<start>/session.json        who owns this folder (pid)
    ROOT/<pid>-<start>/recovery.volanim    the last autosave, a project saved as one unit
    ROOT/<pid>-<start>/recovery.volanim.d/ its data files (this save's and the one before)
    ROOT/<pid>-<start>/summary.json        what that autosave holds, for the recovery question

    GUI thread, every POLL_SECONDS:  poll() --> changed since the last snapshot? --> project.snapshot (cheap)
    the writer thread:                          project.write_snapshot --> summary.json

Every change -- an edit, a step of a held drag, a slider, the frame, the camera --
is on disk within one poll and one write (#83: a held drag used to hold back the
autosave of finished edits, and a kill lost them). Taking a snapshot copies what
a save needs, so the writing, which formats numbers, happens on a thread of its
own while the user goes on; one write at a time, and the next snapshot is of the
newest state, never a queue of old ones. An empty document is never autosaved,
so a session killed before it loaded anything leaves nothing to offer.

A clean exit removes the folder; a folder whose pid is dead on the next start is
a crashed session, offered for restore with what it holds. Only the session the
user restores is removed, once the new session has autosaved what it restored,
and never when the restore failed; the others stay offered. Edits the user
discards are first set aside (a declined folder, kept a week).
ROOT is ``$VOLANIM_RECOVERY_DIR`` or ``~/.cache/volanim/recovery``.
"""

from __future__ import annotations

import json
import os
import shutil
import threading
import time
from pathlib import Path

from volanim_core.io import bundle
from volanim_core.io.atomic import atomic_write_text

RECOVERY_FILE = "recovery.volanim"
DECLINED = "declined"
SUMMARY = "summary.json"
POLL_SECONDS = 0.25  # the window polls this often: a change is on disk within a poll and one write
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
                and not _alive(pid) and holds_work(folder / RECOVERY_FILE)):  # an empty one is never offered
            found.append(folder / RECOVERY_FILE)
    return sorted(found, key=lambda p: p.stat().st_mtime, reverse=True)


def prune(root: Path | None = None, *, now: float | None = None) -> int:
    """Remove folders of dead sessions with nothing to recover (no autosave, or one of an empty document),
    and declined ones after a week.

    Returns how many folders went."""
    root = root or recovery_root()
    now = time.time() if now is None else now
    removed = 0
    for folder in root.glob("*") if root.is_dir() else []:
        pid = _session_pid(folder)
        if pid is None or _alive(pid):
            continue
        declined = folder / DECLINED
        if not (folder / RECOVERY_FILE).exists() or not holds_work(folder / RECOVERY_FILE) or (
                declined.exists() and now - declined.stat().st_mtime > KEEP_DECLINED_SECONDS):
            shutil.rmtree(folder, ignore_errors=True)
            removed += 1
    return removed


def decline(recovery: Path) -> None:
    """The user said no: keep the folder a week (it can be opened as a project) but do not ask again."""
    atomic_write_text(Path(recovery).parent / DECLINED, f"{time.time()}\n")


def summary_of(snap) -> dict:
    """What an autosave holds, in numbers: written beside it, so the recovery question can say it
    without reading the project."""
    state = snap.fields
    angles_shifts = state.get("pose") or {}
    timeline = state.get("timeline") or {}
    clip = timeline.get("clip") or {}
    return {"saved": time.time(), "volume": Path(state["volume"]).name if state.get("volume") else state.get("demo"),
            "points": 0 if snap.skeleton is None else len(snap.skeleton.points),
            "bones": len(snap.bones), "attachments": int((snap.attached >= 0).sum()),
            "pose": bool(angles_shifts.get("angles") or angles_shifts.get("shifts")),
            "keys": len(timeline.get("keys") or []), "clip": Path(clip["path"]).name if clip.get("path") else None}


def _summary(recovery: Path) -> dict | None:
    """``summary.json`` beside an autosave (None: an older studio's autosave, or unreadable)."""
    try:
        data = json.loads((Path(recovery).parent / SUMMARY).read_text())
    except (OSError, ValueError, RecursionError):
        return None
    return data if isinstance(data, dict) else None


def _summary_from_project(recovery: Path) -> dict | None:
    """The same numbers read from the project itself (an autosave without ``summary.json``); None when it
    cannot be read (damaged: it is kept and offered all the same, never taken for empty)."""
    from volanim_core import io

    from .project import read_project

    out = {"saved": Path(recovery).stat().st_mtime, "volume": None, "points": 0, "bones": 0, "attachments": 0,
           "pose": False, "keys": 0, "clip": None}
    try:
        data = read_project(recovery)
    except (OSError, ValueError):  # FormatError is a ValueError
        return None
    out["volume"] = Path(data["volume"]).name if data.get("volume") else data.get("demo")
    out["points"] = int(bool(data.get("mskel")))  # a skeleton is there (its size needs reading it)
    if data.get("bones"):
        out["bones"] = len(io.read_bones(data["bones"]))
    if data.get("connect"):
        out["attachments"] = len(io.read_connect(data["connect"]))
    angles, shifts = data["state"].get("pose") or ({}, {})
    out["pose"] = bool(angles or shifts)
    timeline = data["state"].get("timeline") or {}
    out["keys"] = len(timeline.get("keys") or [])
    out["clip"] = Path(timeline["clip"]["path"]).name if timeline.get("clip") else None
    return out


def holds_work(recovery: Path) -> bool:
    """Whether an autosave holds anything a user made: a volume or demo, a skeleton, bones, attachments, a
    pose, keys."""
    s = _summary(recovery) or _summary_from_project(recovery)
    if s is None:
        return True  # unreadable: what it holds is unknown, so it is kept
    return bool(s.get("volume") or s.get("points") or s.get("bones") or s.get("attachments") or s.get("pose")
                or s.get("keys"))


def describe(recovery: Path) -> str:
    """When an autosave was written and what it holds, for the recovery question: "Tue 24 Nov 2026
    10:40: mannequin, 18 bones, 4,380 attachments, a pose, the clip walk.bvh" (its folder's name is a
    process id and milliseconds)."""
    recovery = Path(recovery)
    s = _summary(recovery) or _summary_from_project(recovery)
    if s is None:  # the question still names the time
        return time.strftime("%a %d %b %Y %H:%M", time.localtime(recovery.stat().st_mtime)) + \
            ": could not be read (restoring it says why)"
    try:
        saved = float(s.get("saved"))
    except (TypeError, ValueError):
        saved = recovery.stat().st_mtime
    when = time.strftime("%a %d %b %Y %H:%M", time.localtime(saved))
    parts = [str(s["volume"])] if s.get("volume") else []
    for key, one in (("bones", "bone"), ("attachments", "attachment"), ("keys", "key")):
        n = s.get(key)
        if n:
            parts.append(f"{n:,} {one if n == 1 else key}")
        if key == "attachments" and s.get("pose"):
            parts.append("a pose")
    if s.get("clip"):
        parts.append(f"the clip {s['clip']}")
    return when + (": " + ", ".join(parts) if parts else ": nothing")


def discard(recovery: Path) -> None:
    shutil.rmtree(Path(recovery).parent, ignore_errors=True)


class Autosaver:
    """One session's autosave (see the module docstring). ``background=False`` writes on the calling
    thread (tests, scripts); ``clock`` is injectable."""

    def __init__(self, doc, root: Path | None = None, *, background: bool = True, clock=time.monotonic):
        self.doc = doc
        self.background = background
        self.clock = clock
        self.root = root or recovery_root()
        prune(self.root)
        self._new_folder()
        self._taken = (doc.undo.edits, self._state_text())  # what the last snapshot was of
        self._writer: threading.Thread | None = None
        self._error: BaseException | None = None
        self.saves = 0  # snapshots written (counted when taken)
        self.written = 0  # writes finished
        self.taken_at: float | None = None  # clock() when the last snapshot was taken
        self.polls = 0
        # a log of saves (the kill test's driver): on_taken(n) on the GUI thread as snapshot n is taken,
        # on_written(n) on the writer thread once it is on disk
        self.on_taken = self.on_written = None

    def _new_folder(self) -> None:
        self.folder = self.root / f"{os.getpid()}-{int(time.time() * 1000)}"
        self.folder.mkdir(parents=True, exist_ok=True)
        atomic_write_text(self.folder / "session.json", json.dumps({"pid": os.getpid(), "started": time.time()}))

    @property
    def path(self) -> Path:
        return self.folder / RECOVERY_FILE

    def _state(self) -> dict:
        from .document_state import save_all

        return save_all(self.doc, self.path)

    def _state_text(self, state: dict | None = None) -> str:
        """The session's state besides its edits (view state is not undoable, so no edit counts it)."""
        return json.dumps(self._state() if state is None else state, sort_keys=True, default=str)

    @property
    def dirty(self) -> bool:
        """Edits, or a changed view (a slider, the frame, the camera), not in the last snapshot."""
        return self.doc.undo.edits != self._taken[0] or self._state_text() != self._taken[1]

    @property
    def caught_up(self) -> bool:
        """The session as it is now is on disk (an empty one: nothing to write): the last snapshot is of
        it, and its write has finished without an error."""
        return not self.writing and self._error is None and not self.dirty

    @property
    def writing(self) -> bool:
        return self._writer is not None and self._writer.is_alive()

    def poll(self) -> bool:
        """From the window's timer: when the session changed since the last snapshot and no write is under
        way, take one and write it (on the writer thread). Raises the last write's error once (the caller
        says it); returns whether a write started."""
        self.polls += 1
        if self.writing:
            return False
        self._raise_error()
        state = self._state()
        text = self._state_text(state)
        if self.doc.undo.edits == self._taken[0] and text == self._taken[1]:
            return False
        return self._start(state, text)

    def _start(self, state: dict, text: str) -> bool:
        from .project import snapshot

        snap = snapshot(self.doc, self.path, state=state)
        self._taken = (self.doc.undo.edits, text)
        if snap.is_empty:  # nothing a user made: never offered after a crash
            return False
        self.saves += 1
        self.taken_at = self.clock()
        if self.on_taken is not None:
            self.on_taken(self.saves)
        if not self.background:
            self._write(snap, self.saves)
            self._raise_error()
            return True
        self._writer = threading.Thread(target=self._write, args=(snap, self.saves), name="volanim autosave",
                                        daemon=True)
        self._writer.start()
        return True

    def _write(self, snap, number: int) -> None:
        from .project import write_snapshot

        try:
            try:
                write_snapshot(snap, self.path)
            except BaseException:  # a full disk: the files this save stored, which no manifest names, go
                bundle.collect_garbage(self.path)
                raise
            atomic_write_text(self.folder / SUMMARY, json.dumps(summary_of(snap)))
            self.written += 1
            if self.on_written is not None:
                self.on_written(number)
        except BaseException as exc:  # said on the GUI thread by the next poll
            self._taken = (-1, "")  # try again at the next poll
            self._error = exc

    def _raise_error(self) -> None:
        error, self._error = self._error, None
        if error is not None:
            raise error

    def wait(self) -> None:
        """Until the write under way (if any) has finished."""
        if self._writer is not None:
            self._writer.join()
            self._writer = None

    def save(self) -> bool:
        """Autosave now, on this thread, after any write under way: the state at this moment is on disk
        when it returns (Discard, a restore). Raises the write's error."""
        self.wait()
        self._error = None
        state = self._state()
        background, self.background = self.background, False
        try:
            return self._start(state, self._state_text(state))
        finally:
            self.background = background

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
        self._taken = (-1, "")  # the new folder holds nothing yet
        return kept / RECOVERY_FILE

    def close(self) -> None:
        """A clean exit: nothing to recover."""
        self.wait()
        shutil.rmtree(self.folder, ignore_errors=True)
