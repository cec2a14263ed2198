"""Naming joints from the keyboard: F2 renames the joint clicked last, Ctrl+F2 names a whole chain.

    F2 --> QInputDialog (the joint's name) --> bone_edits.rename_joint
    Ctrl+F2 --> QInputDialog (a line of names, presets) --> bone_edits.rename_chain (L_/R_ by side)

Both dialogs are non-blocking (``open()``); Enter applies, as one undo step. Owned by the main window.
"""

from __future__ import annotations

from PySide6.QtWidgets import QInputDialog

from .controller import Controller

#: What Name chain offers (it keeps as many names as the chain has joints; the side's L_/R_ is added)
CHAIN_PRESETS = {
    "arm": ("SHOULDER", "ELBOW", "WRIST", "FINGERS"),
    "arm from the neck": ("NECK", "SHOULDER", "ELBOW", "WRIST", "FINGERS"),
    "leg": ("HIP", "KNEE", "ANKLE", "TOE"),
    "leg from the pelvis": ("PELVIS", "HIP", "KNEE", "ANKLE", "TOE"),
    "spine": ("PELVIS", "NECK", "HEAD"),
}


class NamingController(Controller):
    box: QInputDialog | None = None  # the dialog while it is open

    def fill_menu(self, menu, action) -> None:
        action("Rename joint…", self.rename_joint_dialog, "F2", menu=menu)
        action("Name chain…", self.name_chain_dialog, "Ctrl+F2", menu=menu)

    def rename_joint_dialog(self) -> QInputDialog | None:
        """F2: rename the joint clicked last."""
        joint = self.doc.picked_joint
        if joint is None:
            self.doc.message("Click a joint first, then press F2 to rename it.")
            return None
        box = self._dialog("Rename joint", f"New name for {joint}:")
        box.setTextValue(joint)
        box.textValueSelected.connect(lambda text: self._apply(
            lambda: self.doc.bone_edits.rename_joint(joint, text), lambda _: f"Renamed {joint} to {text.strip()}."))
        box.open()
        return box

    def name_chain_dialog(self) -> QInputDialog | None:
        """Ctrl+F2: name the chain of the selected bone (the one just built), else the chain that starts
        at the joint clicked last, in one line: "SHOULDER, ELBOW, WRIST"."""
        edits = self.doc.bone_edits
        if self.doc.selected_bones:
            chain = edits.chain_through(self.doc.selected_bones[0])
        elif self.doc.picked_joint is not None:
            chain = edits.chain_from(self.doc.picked_joint)
        else:
            self.doc.message("Select a bone of the chain (or click its first joint), then Ctrl+F2.")
            return None
        side = edits.side_prefix(chain[-1])
        own = edits.joints_named(chain, len(chain) - 1) if edits.is_fork(chain[0]) else chain
        whole = f" (type {len(chain)} to rename {chain[0]} too)" if len(own) < len(chain) else ""
        box = self._dialog("Name chain", f"Names for the {len(own)} joints {' → '.join(own)}, in order{whole}\n"
                           f"(commas or spaces; {side or 'no prefix'} is added on this side when left out):")
        box.setComboBoxEditable(True)
        box.setComboBoxItems([""] + [", ".join(p[:n]) for p in CHAIN_PRESETS.values() for n in {len(own), len(chain)}
                                     if len(p) >= n and (n == len(chain) or p[0] not in ("NECK", "PELVIS"))])
        box.textValueSelected.connect(lambda text: self._apply(
            lambda: edits.rename_chain(chain, text), lambda names: f"Named the chain {', '.join(names)}."))
        box.open()
        return box

    def _dialog(self, title: str, label: str) -> QInputDialog:
        box = self.box = QInputDialog(self.window)
        box.setWindowTitle(title)
        box.setLabelText(label)
        return box

    def _apply(self, action, done) -> None:
        self.attempt("Name", action, done)
