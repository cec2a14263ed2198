"""A real studio process making random edits until it is killed (run by test_gui_killed.py).

    python studio_under_edits.py LOG SEED

It opens the mannequin demo with its bones and attachments, then every few milliseconds makes one
random user action through the real widgets: pose slider drags (pressed, moved over many steps of the
event loop, released: a kill often lands mid-drag), typed angles, thinness slider moves, bone
selection, pose keys, mode and display changes, joint renames. Each autosave is logged as two JSON
lines, ``{"saving": N, "t": ..., "state": ...}`` as its snapshot is taken and ``{"saved": N}`` once it
is on disk, so the test knows what the autosave on disk must hold whenever the kill lands; each
action is logged as ``{"act": K, "t": ..., "held": ...}`` (``time.monotonic``, for the lag table).
"""

from __future__ import annotations

import json
import random
import sys
import time

from PySide6.QtCore import QTimer
from PySide6.QtWidgets import QApplication


def session_state(window) -> dict:
    """What a recovered session must give back (the window's model, read directly)."""
    doc = window.doc
    bones = doc.bones.bones
    return {"bones": [[b.proximal, b.distal] for b in bones], "attachments": doc.attachments.bone.tolist(),
            "pose": doc.pose.to_json(), "keys": doc.timeline.to_json()["keys"], "thinness": doc.thinness,
            "settings": doc.settings.as_dict(),
            "selected": [[bones[i].proximal, bones[i].distal] for i in doc.selected_bones]}


def main(log_path: str, seed: int) -> None:
    from paths import ASSETS
    from volanim_studio.model.settings import Mode
    from volanim_studio.qt.main_window import MainWindow

    app = QApplication.instance() or QApplication([])
    rng = random.Random(seed)
    w = MainWindow()
    w.resize(900, 650)
    w.show()
    log = open(log_path, "a", buffering=1)
    saver = w.session.autosaver
    saver.on_taken = lambda n: log.write(json.dumps({"saving": n, "t": time.monotonic(),
                                                     "state": session_state(w)}) + "\n")
    saver.on_written = lambda n: log.write(json.dumps({"saved": n}) + "\n")
    held = {"slider": None, "steps": 0}
    acts = [0]

    def act():
        doc = w.doc
        acts[0] += 1
        log.write(json.dumps({"act": acts[0], "t": time.monotonic(), "held": held["slider"] is not None}) + "\n")
        slider = held["slider"]
        if slider is not None:  # a drag goes on over many timer steps, as a hand's does
            slider.setValue(rng.randrange(-90, 91))
            held["steps"] -= 1
            if held["steps"] <= 0:
                slider.setSliderDown(False)
                held["slider"] = None
            return
        choice = rng.random()
        bone = rng.randrange(len(doc.bones))
        if choice < 0.35:  # a pose slider pressed on a bone: moved by the next steps, then released
            doc.select_bones([bone])
            w.set_mode(Mode.POSE)
            held["slider"] = w.pose_panel.sliders[rng.randrange(3)]
            held["slider"].setSliderDown(True)
            held["steps"] = rng.randrange(5, 200)
        elif choice < 0.5:  # a typed angle
            doc.select_bones([bone])
            spin = w.pose_panel.spins[rng.randrange(3)]
            spin.setValue(rng.randrange(-90, 91))
            spin.editingFinished.emit()
        elif choice < 0.6:
            w.display_panel.thinness_slider.setValue(rng.randrange(w.display_panel.thinness_slider.maximum() + 1))
        elif choice < 0.63:  # rarely: a key holds the pose only until the next edit
            doc.settings.current_frame = rng.randrange(48)
            w.timeline.set_key()
        elif choice < 0.66:  # a joint renamed (an edit of the bones)
            joint = rng.choice(sorted(doc.bones.joints))
            doc.bone_edits.rename_joint(joint, f"J{acts[0]}")
        elif choice < 0.78:
            doc.settings.colour_by = rng.choice(["thinness", "dt", "bone"])
        elif choice < 0.88:
            w.bone_panel.tree.clearSelection()
            w.bone_panel.tree.topLevelItem(bone).setSelected(True)
        else:
            w.set_mode(rng.choice([Mode.VIEW, Mode.POSE, Mode.BONES]))

    def rigged(_=None):
        w.files.open_bones(ASSETS / "mannequin.bones")
        w.files.open_connect(ASSETS / "mannequin.0.50.connect")
        w.doc.settings.live_preview = False  # edits, not pictures, are what this process is for
        log.write(json.dumps({"ready": True}) + "\n")
        timer = QTimer(w)
        timer.timeout.connect(act)
        timer.start(5)

    worker = w.files.load_demo("mannequin")
    worker.succeeded.connect(rigged)
    app.exec()


if __name__ == "__main__":
    main(sys.argv[1], int(sys.argv[2]))
