"""Tiny observer events, one per model property (napari style, no Qt).

    doc.events.thinness.connect(view._on_thinness_changed)
    doc.thinness = 0.8          # setter validates, stores, then emits
"""

from __future__ import annotations

from collections.abc import Callable


class Event:
    """A list of callbacks called with keyword arguments."""

    def __init__(self, name: str):
        self.name = name
        self._callbacks: list[Callable] = []
        self.blocked = 0

    def connect(self, callback: Callable) -> Callable:
        self._callbacks.append(callback)
        return callback

    def disconnect(self, callback: Callable) -> bool:
        """Stop calling ``callback``; whether it was connected (a listener that may already have gone --
        a closed window's -- can ask without knowing)."""
        if callback in self._callbacks:
            self._callbacks.remove(callback)
            return True
        return False

    def emit(self, **kwargs) -> None:
        if self.blocked:
            return
        for cb in list(self._callbacks):
            cb(**kwargs)


class EventEmitter:
    """A namespace of named events: ``emitter.NAME.connect(cb)``."""

    def __init__(self, *names: str):
        for n in names:
            setattr(self, n, Event(n))

    def add(self, name: str) -> Event:
        setattr(self, name, Event(name))
        return getattr(self, name)
