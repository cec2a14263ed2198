"""Bones -> Propose bones...: pick a template, preview the proposal in the scene, accept or discard.

    template combo / Preview --> jobs.run(BoneProposal.compute) --> BoneProposal.preview (one undo step)
    Accept --> kept; Discard or closing the dialog --> BoneProposal.discard

Owned by the main window (``window.proposing``).
"""

from __future__ import annotations

from PySide6.QtWidgets import QComboBox, QDialog, QDialogButtonBox, QFormLayout, QLabel, QPushButton, QVBoxLayout

from volanim_core.rig.autorig import TEMPLATES

from .controller import Controller

HINTS = {"auto": "the template that fits, else chains named by position",
         "humanoid": "PELVIS, SPINE, NECK, HEAD, L_/R_ CLAVICLE ... FOOT: the mannequin's names",
         "quadruped": "PELVIS, CHEST, HEAD, TAIL, four legs",
         "none": "a joint at every fork, end, bend and narrowing; chains named by side and direction"}


class ProposeDialog(QDialog):
    def __init__(self, controller, parent=None):
        super().__init__(parent)
        self.controller = controller
        self.setWindowTitle("Propose bones")
        self.template = QComboBox()
        self.template.addItems(TEMPLATES)
        self.hint = QLabel(HINTS["auto"])
        self.hint.setWordWrap(True)
        self.template.currentTextChanged.connect(lambda t: (self.hint.setText(HINTS[t]), self.adjustSize()))
        self.summary = QLabel("Preview shows the proposal in the scene; nothing is kept until you accept.")
        self.summary.setWordWrap(True)
        self.preview_button = QPushButton("Preview")
        self.preview_button.clicked.connect(self.preview)
        self.buttons = QDialogButtonBox(QDialogButtonBox.Ok | QDialogButtonBox.Discard)
        self.buttons.button(QDialogButtonBox.Ok).setText("Accept")
        self.buttons.button(QDialogButtonBox.Ok).setEnabled(False)
        self.buttons.accepted.connect(self.accept)
        self.buttons.button(QDialogButtonBox.Discard).clicked.connect(self.reject)
        form = QFormLayout()
        form.addRow("Template", self.template)
        layout = QVBoxLayout(self)
        layout.addLayout(form)
        layout.addWidget(self.hint)  # in the box, not a form row: a wrapped label there was clipped
        layout.addWidget(self.preview_button)
        layout.addWidget(self.summary)
        layout.addWidget(self.buttons)
        self.setMinimumWidth(420)

    def preview(self) -> None:
        self.controller.preview(self.template.currentText(), self.shown)

    def shown(self, proposal) -> None:
        self.summary.setText(f"{proposal}\nThe proposal is in the scene: accept to keep it (Undo takes it back), "
                             "or try another template. Its bones are new: connect the points next "
                             "(Connect → Auto-connect, Ctrl+A).")
        self.buttons.button(QDialogButtonBox.Ok).setEnabled(True)
        self.adjustSize()  # the dialog grows with the text (it was clipped at its first size)

    def accept(self) -> None:
        said = self.controller.doc.proposal.accept()
        self.controller.doc.message(f"Kept the proposed bones: {self.controller.doc.undo.undo_label}.{said}")
        super().accept()

    def reject(self) -> None:
        self.controller.doc.proposal.discard()
        super().reject()


class ProposeController(Controller):
    def fill_menu(self, menu, action) -> None:
        action("Propose bones…", self.open_dialog, "Ctrl+Shift+B", menu=menu)

    def open_dialog(self) -> ProposeDialog:
        dialog = ProposeDialog(self, self.window)
        dialog.setModal(False)
        dialog.show()
        self.dialog = dialog
        return dialog

    def preview(self, template: str, shown) -> None:
        if self.jobs.busy:
            self.show_error("Propose bones", "another job is running; try again when it has finished")
            return
        proposal = self.doc.proposal

        def done(result) -> None:
            proposal.preview(result)
            self.doc.message(f"Proposed {result}")
            shown(result)

        self.jobs.run("Proposing bones", lambda progress, cancel: proposal.compute(template, progress=progress,
                                                                             cancel=cancel), done)
