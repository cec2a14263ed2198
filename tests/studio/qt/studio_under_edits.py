"""A real studio process making random edits until it is killed (run by test_gui_killed.py).

    python studio_under_edits.py LOG SEED

It opens the mannequin demo with its bones and attachments, then every few milliseconds makes one
random user action through the real widgets: pose slider drags (press, moves, release), typed
angles, thinness slider moves, bone selection, pose keys, mode and display changes. Each autosave
is logged as two JSON lines, ``{"saving": N, "state": ...}`` before it and ``{"saved": N}`` after,
so the test knows what the autosave on disk must hold whenever the kill lands.
"""

from __future__ import annotations

import json
import random
import sys

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
    w = MainWindow(autosave_every_edits=4, autosave_seconds=0.5)
    w.resize(900, 650)
    w.show()
    log = open(log_path, "a", buffering=1)
    saver = w.session.autosaver
    real_save = saver.save

    def logged_save():  # the real save, bracketed by what it is saving
        n = saver.saves + 1
        log.write(json.dumps({"saving": n, "state": session_state(w)}) + "\n")
        done = real_save()
        log.write(json.dumps({"saved": n}) + "\n")
        return done

    saver.save = logged_save

    def act():
        doc = w.doc
        choice = rng.random()
        bone = rng.randrange(len(doc.bones))
        if choice < 0.4:  # a pose slider drag on a bone
            doc.select_bones([bone])
            w.set_mode(Mode.POSE)
            slider = w.pose_panel.sliders[rng.randrange(3)]
            slider.setSliderDown(True)
            for _ in range(rng.randrange(1, 6)):
                slider.setValue(rng.randrange(-90, 91))
            slider.setSliderDown(False)
        elif choice < 0.55:  # a typed angle
            doc.select_bones([bone])
            spin = w.pose_panel.spins[rng.randrange(3)]
            spin.setValue(rng.randrange(-90, 91))
            spin.editingFinished.emit()
        elif choice < 0.65:
            w.display_panel.thinness_slider.setValue(rng.randrange(w.display_panel.thinness_slider.maximum() + 1))
        elif choice < 0.68:  # rarely: a key holds the pose only until the next edit
            doc.settings.current_frame = rng.randrange(48)
            w.timeline.set_key()
        elif choice < 0.8:
            doc.settings.colour_by = rng.choice(["thinness", "dt", "bone"])
        elif choice < 0.9:
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
