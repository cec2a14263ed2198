"""The mapping dialog (#39): per-bone confidence, detected axes and units, checks, and a posed preview."""

from __future__ import annotations

import numpy as np

from real_clips import clip
from volanim_core.io.bvh_files import read_bvh
from volanim_core.samples import mannequin_bones
from volanim_studio.qt.mapping_dialog import UNMAPPED, MappingDialog


def lit_extent(dialog, half: int) -> tuple[int, int]:
    """(width, height) in pixels of the drawn figure in one half of the preview (0: front, 1: side)."""
    img = dialog.figure.grab().toImage()
    w, h = img.width(), img.height()
    arr = np.frombuffer(img.constBits(), np.uint8).reshape(h, img.bytesPerLine() // 4, 4)[:, :w, :3]
    lit = (arr[..., 2] > 150) & (arr[..., 1] > 120) & (arr[..., 0] < 180)  # BGRA: the figure's warm yellow
    lit = lit[:, half * w // 2:(half + 1) * w // 2]
    ys, xs = np.nonzero(lit)
    assert len(ys), "nothing drawn"
    return int(np.ptp(xs)), int(np.ptp(ys))


def test_a_biovision_clip_shows_its_scheme_confidence_units_and_an_upright_figure(qtbot, tmp_path):
    bones = mannequin_bones()
    dialog = MappingDialog(bones, read_bvh(clip("mocapbank")), "test_mocapbank.bvh")
    qtbot.addWidget(dialog)
    dialog.show()
    qtbot.waitExposed(dialog)
    assert dialog.mapping()["L_UPPERARM"] == "LeftShoulder" and dialog.mapping()["L_CLAVICLE"] == "LeftCollar"
    assert dialog.how["L_UPPERARM"].text() == "name and shape"
    text = dialog.detected.text()
    assert "up y, facing z" in text and "centimetres" in text and "FAILS" not in text
    width, height = lit_extent(dialog, 0)
    assert height > 1.5 * width  # standing: taller than wide, seen from the front
    dialog.figure.grab().save(str(tmp_path / "upright.png"))

    dialog.up.setCurrentText("x")  # the user tries another axis: the checks and the figure say it is wrong
    assert "FAILS" in dialog.detected.text() and "suspect the up axis" in dialog.detected.text()
    side_w, side_h = lit_extent(dialog, 1)
    front_w, front_h = lit_extent(dialog, 0)
    assert max(side_w, front_w) > min(side_h, front_h)  # lying down in at least one view

    dialog.up.setCurrentText("auto")
    dialog.combos["L_UPPERARM"].setCurrentText("LeftElbow")  # an edit is the user's, and shown as such
    assert dialog.how["L_UPPERARM"].text() == "your choice" and dialog.mapping()["L_UPPERARM"] == "LeftElbow"
    dialog.frame.setValue(200)  # another frame: the preview follows (this clip crouches there)
    assert dialog.frame_label.text().startswith("200 /")
    w200, h200 = lit_extent(dialog, 0)
    assert h200 < height


def test_a_one_arm_clip_is_refused_as_found_and_taken_once_the_user_maps_it(qtbot, tmp_path):
    """#86 item 3 in the studio: the arm clip's suggested mapping is checked as a whole figure (other: not
    the rig's kind, said); a row the user changes makes the mapping theirs, and only what it drives is
    checked."""
    from core.motion.test_clip_kind import arm_bvh

    arm_bvh(tmp_path / "arm.bvh")
    bones = mannequin_bones()
    dialog = MappingDialog(bones, read_bvh(tmp_path / "arm.bvh"), "arm.bvh")
    qtbot.addWidget(dialog)
    assert "the clip's figure is a biped, as the rig: no" in dialog.detected.text()
    arm = {"L_CLAVICLE": "LeftShoulder", "L_UPPERARM": "LeftArm", "L_FOREARM": "LeftForeArm", "L_HAND": "LeftHand"}
    for b in bones.bones:  # the user maps the arm, and nothing else
        dialog.combos[b.label].setCurrentText(arm.get(b.label, UNMAPPED))
    assert dialog.mapping() == arm
    text = dialog.detected.text()
    assert "as the rig" not in text and "FAILS" not in text, text
    assert "L elbow bends" in text  # the mapped arm is still checked
