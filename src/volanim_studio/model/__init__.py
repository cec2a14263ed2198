"""The studio's Qt-free document model: the single source of truth the views observe.

    document.py ......... Document: everything a session edits, with undo and change events
    document_state.py ... the session as one state: every part a project and an autosave hold
    events.py ........... tiny observer events, one per property (napari style, no Qt)
    undo.py ............. a bounded stack of command atoms
    settings.py ......... view and tool settings: one validated property and one event each
    selection.py ........ cube and lasso selection of skeleton points (pure NumPy)
    interaction.py ...... the cube, lasso, pose and bone modes: pick events in, model calls out
    attachments.py ...... which bone each skeleton point is attached to
    ownership_state.py .. which bone moves each voxel of the body (the default body), and the animator's repaints
    bone_edits.py ....... edits of the bone skeleton, attachments following renumbered bones
    proposal.py ......... auto-rig's proposal, previewed before the user accepts it
    posing.py ........... the pose being previewed: per-bone rotations and shifts driving FK
    preview.py .......... preview reconstructions, full or reduced, with the breakage report
    live_resolution.py .. the live preview's resolution: the one that keeps 10 pictures a second
    timeline.py ......... the clip or pose keys on the timeline; the current frame drives the pose
    transfer.py ......... the user's transfer function, edited with undo
    project.py .......... the .volanim project: written, read and applied
    autosave.py ......... autosave and crash recovery (the window drives the timer)
"""

from .document import Document
from .events import EventEmitter
from .undo import UndoStack

__all__ = ["Document", "EventEmitter", "UndoStack"]
