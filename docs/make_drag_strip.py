"""A drag on mannequin-large in the studio, as a strip of the live pictures it drew (#85's proof).

The thesis's half-size Visible Human grid (46 M voxels), rigged as bench_studio rigs it, L_UPPERARM raised by a
pose drag paced as a mouse paces it (a step every 1/60 s); each frame of the strip is the 3-D view as the live
picture was drawn, captioned with what the Pose tab said of it (resolution and each stage's milliseconds).

Run: xvfb-run -a .venv/bin/python docs/make_drag_strip.py   (writes docs/studio-drag-large.png)
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).parent
ANGLES = (0, -30, -60, -90, -120)  # the frames kept: the drag passes each on its way


def main() -> None:
    from PIL import Image, ImageDraw
    from PySide6.QtWidgets import QApplication

    from volanim_core import samples
    from volanim_core.rig.attach import auto_connect
    from volanim_studio.model.interaction import Mode
    from volanim_studio.qt.main_window import MainWindow

    app = QApplication.instance() or QApplication(sys.argv[:1])
    w = MainWindow()
    w.resize(1200, 800)
    w.show()

    def settle():
        while w.busy or not w.previews.live_worker.idle:
            app.processEvents()
            time.sleep(0.005)
        for _ in range(5):
            app.processEvents()

    w.files.load_demo("mannequin-large")
    settle()
    w.doc.bone_edits.set_bones(samples.load("mannequin-large").bones)
    out, _ = auto_connect(w.doc.skeleton.points, w.doc.bones, w.doc.mask, method="nearest")
    w.doc.attachments.assign_many(np.arange(len(out)), out, "auto")
    w.set_mode(Mode.POSE)
    settle()
    bone = w.doc.bones.index("L_UPPERARM")
    w.doc.select_bones([bone])
    w.scene.front_view()
    w.plotter.camera.zoom(0.8)  # room above the head for the hand raised to 120 degrees
    settle()
    frames, shown = [], []
    w.doc.events.preview.connect(lambda **_: shown.append(w.doc.preview) if w.doc.preview.live else None)
    w.doc.settings.dragging = True  # what pressing a pose slider does
    t0 = time.perf_counter()
    for k, a in enumerate(np.linspace(0, -120, 121)):
        w.doc.pose.set_angles(bone, (0, float(a), 0))
        while time.perf_counter() < t0 + (k + 1) / 60:
            time.sleep(0.001)
            app.processEvents()
        if len(frames) < len(ANGLES) and a <= ANGLES[len(frames)]:
            settle()  # the picture of this pose drawn: kept as the window shows it
            caption = f"{abs(a):.0f} deg: {w.pose_panel.verdict.plain.split(' (release')[0]}"
            frames.append((np.ascontiguousarray(w.plotter.screenshot(return_img=True)[:, :, :3]), caption))
    w.doc.settings.dragging = False
    settle()
    w.close()
    # one crop for every frame: the box of what differs from the background in any of them, squared
    body = np.any([np.abs(img.astype(int) - img[0, 0]).sum(2) > 30 for img, _ in frames], axis=0)
    body[-150:, :150] = False  # the orientation axes' corner
    ys, xs = np.nonzero(body)
    side = max(ys.max() - ys.min(), xs.max() - xs.min()) + 40
    cy, cx = (ys.max() + ys.min()) // 2, (xs.max() + xs.min()) // 2
    h, w_ = body.shape
    side = min(side, h, w_)  # within the picture: a crop past its edge came out as a black band
    x0, y0 = min(max(0, cx - side // 2), w_ - side), min(max(0, cy - side // 2), h - side)
    box = (x0, y0, x0 + side, y0 + side)
    tiles = []
    for img, caption in frames:
        tile = Image.fromarray(img).crop(box).resize((400, 400))
        canvas = Image.new("RGB", (400, 440), (30, 31, 36))
        canvas.paste(tile, (0, 0))
        draw = ImageDraw.Draw(canvas)
        draw.text((6, 410), caption, fill=(220, 220, 220))
        tiles.append(canvas)
    strip = Image.new("RGB", (400 * len(tiles) + 6 * (len(tiles) - 1), 440), (60, 60, 60))
    for i, tile in enumerate(tiles):
        strip.paste(tile, (406 * i, 0))
    path = HERE / "studio-drag-large.png"
    strip.save(path)
    print(f"wrote {path}: {len(shown)} live pictures drawn in the drag")
    for _, caption in frames:
        print(" ", caption)


if __name__ == "__main__":
    main()
