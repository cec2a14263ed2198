"""The studio's Qt-free document model: the single source of truth the views observe."""

from .document import Document
from .events import EventEmitter
from .undo import UndoStack

__all__ = ["Document", "EventEmitter", "UndoStack"]
