"""Propose bones (auto-rig) with a preview the user accepts or discards.

    Bones -> Propose bones... --compute (worker: volanim_core.autorig on the points on screen)-->
    Proposal --preview--> doc.bone_edits.set_bones: the bones show like any bones, one undo step
        --accept--> kept (editable like any bones; Undo takes it back)
        --discard / another template--> that undo step is undone first

Qt-free: the dialog in ``qt/propose_dialog.py`` only calls these.
"""

from __future__ import annotations

from volanim_core.rig.autorig import Proposal, autorig


class BoneProposal:
    def __init__(self, doc):
        self.doc = doc
        self.previewing: str | None = None  # the undo label of the proposal on screen, if any

    def compute(self, template: str = "auto", bones: int | None = None, progress=None, cancel=None) -> Proposal:
        """The proposal for the skeleton at the slider's thinness (no document change: safe in a worker);
        ``progress``/``cancel`` as autorig takes them (the runner's dialog)."""
        if self.doc.skeleton is None:
            raise ValueError("open a skeleton (.mskel) or a volume first: bones are proposed from its points")
        return autorig(self.doc.skeleton.at(self.doc.thinness), template=template, bones=bones, progress=progress,
                       cancel=cancel)

    def preview(self, proposal: Proposal) -> None:
        """Show ``proposal`` as the document's bones (one undo step), replacing a previous preview."""
        self.discard()
        label = f"Propose bones ({proposal.template}, {len(proposal.bones)} bones)"
        self.doc.bone_edits.set_bones(proposal.bones, label)
        self.previewing = label

    def accept(self) -> str:
        """Keep the preview. Auto-connect then attaches by pieces, the method proposals are proven with
        (each piece's points to its own bones; as nearest on a body in one piece): returns what to say."""
        self.previewing = None
        settings = self.doc.settings
        if settings.auto_method == "pieces":
            return ""
        was, settings.auto_method = settings.auto_method, "pieces"
        return (f" Auto-connect (Ctrl+A) now attaches by pieces, as autorig --connect does (it was {was}; "
                "the Connect tab changes it).")

    def discard(self) -> None:
        """Take the preview back, if it is still the last edit (later edits are the user's: kept)."""
        top = self.doc.undo.undo_label
        if self.previewing is not None and top == self.previewing:
            self.doc.undo.undo()
        self.previewing = None
