"""Undo lives in the model: a bounded stack of command atoms.

A command is a pair of callables, ``redo`` and ``undo``, plus a label shown
in the Edit menu. ``push`` runs ``redo`` once; the GUI only calls
:meth:`UndoStack.undo` and :meth:`UndoStack.redo`.
"""

from __future__ import annotations

from collections.abc import Callable
from contextlib import contextmanager
from dataclasses import dataclass

from .events import EventEmitter


@dataclass
class Command:
    label: str
    redo: Callable[[], None]
    undo: Callable[[], None]
    merge_key: str | None = None  # consecutive commands with this key become one step (a slider drag)


_UNREACHABLE = object()  # a clean marker no stack top can ever be


class UndoStack:
    """Bounded history; pushing after undos drops the redo branch."""

    def __init__(self, limit: int = 500):
        self.limit = limit
        self._done: list[Command] = []
        self._undone: list[Command] = []
        self.events = EventEmitter("changed")
        self.edits = 0  # monotonically counts pushes, undos and redos (autosave watches it)
        self._clean_top: object = None  # the command on top when the document was last saved or opened
        self._group: list[Command] | None = None  # commands pushed inside group(), one step at its end

    # The document is unmodified when the command on top is the one that was on top when it was
    # saved (None: an empty stack). Undoing back to the saved state makes it unmodified again,
    # like QUndoStack's clean index; an edit merged into the top command replaces it, so it counts.
    def mark_clean(self, state=_UNREACHABLE) -> None:
        """The document was saved or opened: this state (or ``state``, a :attr:`state` taken earlier: a save
        written on a thread while the user went on editing) is unmodified."""
        self._clean_top = self._top if state is _UNREACHABLE else state
        self.events.changed.emit()

    @property
    def state(self) -> object:
        """A token of the history as it is now, for :meth:`mark_clean` once what was taken of it is saved."""
        return self._top

    def mark_modified(self) -> None:
        """This state is saved nowhere (a restored autosave): modified until saved."""
        self._clean_top = _UNREACHABLE
        self.events.changed.emit()

    @property
    def is_clean(self) -> bool:
        return self._top is self._clean_top

    @property
    def _top(self) -> Command | None:
        return self._done[-1] if self._done else None

    @contextmanager
    def group(self, label: str):
        """Every command pushed inside the ``with`` becomes one step labelled ``label`` (QUndoStack's macro): a
        lasso that connects points and repaints the flesh they stand for is undone by one Ctrl+Z."""
        outer, self._group = self._group, []
        try:
            yield
        finally:
            done, self._group = self._group, outer
            if len(done) == 1:
                self._record(Command(label, done[0].redo, done[0].undo))
            elif done:
                self._record(Command(label, lambda: [c.redo() for c in done],
                                     lambda: [c.undo() for c in reversed(done)]))

    def push(self, command: Command) -> None:
        if self._group is not None:  # inside group(): run now, recorded as one step at its end
            command.redo()
            self._group.append(command)
            return
        top = self._top
        if command.merge_key and top is not None and top.merge_key == command.merge_key and not self._undone:
            command.redo()
            self._done[-1] = Command(command.label, command.redo, top.undo, command.merge_key)
            self._changed()
            return
        command.redo()
        self._record(command)

    def _record(self, command: Command) -> None:
        """``command`` (already run) on top of the history."""
        self._done.append(command)
        if len(self._done) > self.limit:
            if self._clean_top is None or self._clean_top is self._done[0]:
                self._clean_top = _UNREACHABLE  # the saved state fell off the bottom
            del self._done[: -self.limit]
        self._undone.clear()
        self._changed()

    def undo(self) -> str | None:
        if not self._done:
            return None
        cmd = self._done.pop()
        cmd.undo()
        self._undone.append(cmd)
        self._changed()
        return cmd.label

    def redo(self) -> str | None:
        if not self._undone:
            return None
        cmd = self._undone.pop()
        cmd.redo()
        self._done.append(cmd)
        self._changed()
        return cmd.label

    def seal(self) -> None:
        """End merging: the next command starts a new step (a slider was released)."""
        if self._done and self._done[-1].merge_key:
            top = self._done[-1]
            self._done[-1] = Command(top.label, top.redo, top.undo, None)
            if self._clean_top is top:
                self._clean_top = self._done[-1]

    def clear(self) -> None:
        """Forget the history; the state it leaves is modified unless :meth:`mark_clean` follows."""
        self._done.clear()
        self._undone.clear()
        self._clean_top = _UNREACHABLE
        self._changed()

    @property
    def can_undo(self) -> bool:
        return bool(self._done)

    @property
    def can_redo(self) -> bool:
        return bool(self._undone)

    @property
    def undo_label(self) -> str:
        return self._done[-1].label if self._done else ""

    @property
    def redo_label(self) -> str:
        return self._undone[-1].label if self._undone else ""

    def _changed(self) -> None:
        self.edits += 1
        self.events.changed.emit()
