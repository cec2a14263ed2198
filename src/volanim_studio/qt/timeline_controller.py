"""The timeline's actions: load clips, play, step, key, scan for breakage, export frames.

    Play --> QTimer --> frame = start + elapsed * fps  (a slow preview drops frames, never lags; the bones
         drawn are the drawn body's frame's: settings.playing, the scene's PoseLayer)
         --> settings.current_frame --> Timeline.show_frame --> pose --> live preview (coalesced)
    Pause / scrub released --> the full preview with its report (in Pose mode)
    Scan --> JobRunner(scan_frames) --> ScanDialog (worst first; double-click jumps to the frame)
    Export --> JobRunner(write_frames) --> NAME.0000.trans (+ .tskel)
    Render movie --> MovieDialog --> JobRunner(tasks.render_movie: sequence + render in worker processes)
    Save view as camera file --> the view's camera in voxel coordinates (for volanim render --camera)
"""

from __future__ import annotations

import copy
import time
from pathlib import Path

import numpy as np
from PySide6.QtCore import QTimer
from PySide6.QtWidgets import QDialog, QFileDialog, QInputDialog

from volanim_core import io
from volanim_core.io.clip_files import CLIP_FILTER, clip_animations, read_clip
from volanim_core.io.frame_files import read_frames, write_frames
from volanim_core.reconstruct.scan import scan_frames, scan_summary, worst_first
from volanim_core.render.views import Camera

from ..model.settings import Mode
from ..model.timeline import retarget_clip
from .controller import FAILED, Controller
from .mapping_dialog import MappingDialog
from .movie_dialog import MovieDialog
from .scan_dialog import ScanDialog
from .worker import Worker


class TimelineController(Controller):
    def __init__(self, window):
        super().__init__(window)
        self.step_actions = []  # arrows: the window disables them in Cube mode (the cube's nudges)
        self.shown_frames: list[int] = []  # frames drawn while playing (tests, benchmarks)
        self.scan_dialog: ScanDialog | None = None
        self.last_scan = None
        self._play = QTimer(window)
        self._play.timeout.connect(self._tick)
        self._start = (0.0, 0)
        self._followed: int | None = None
        self.doc.settings.events.current_frame.connect(lambda **_: self._frame_changed())
        self.doc.events.preview.connect(lambda **_: self._picture_changed())

    # ------------------------------------------------------------ wiring
    def fill_menu(self, menu, action) -> None:
        action("Load clip (BVH, glTF, FBX)…", lambda: self.load_bvh_dialog(), menu=menu)
        action("Load .trans frames…", lambda: self.load_trans_dialog(), menu=menu)
        action("Unload clip", lambda: self.doc.timeline.unload(), menu=menu)
        menu.addSeparator()
        action("Play / pause", lambda: self.toggle_play(), "Space", menu=menu)
        self.step_actions = [action("Previous frame", lambda: self.step(-1), "Left", menu=menu),
                             action("Next frame", lambda: self.step(1), "Right", menu=menu),
                             action("First frame", lambda: self.go(0), "Home", menu=menu),
                             action("Last frame", lambda: self.go(-1), "End", menu=menu)]
        menu.addSeparator()
        action("Set key", lambda: self.set_key(), "S", menu=menu)
        action("Delete key", lambda: self.delete_key(), "Shift+S", menu=menu)
        action("Import keys (.keys)…", lambda: self.keys_dialog(save=False), menu=menu)
        action("Export keys (.keys)…", lambda: self.keys_dialog(save=True), menu=menu)
        menu.addSeparator()
        action("Scan clip for breakage…", lambda: self.scan(), menu=menu)
        action("Export frames (.trans)…", lambda: self.export_dialog(tskel=False), menu=menu)
        action("Export frames (.trans + .tskel)…", lambda: self.export_dialog(tskel=True), menu=menu)
        menu.addSeparator()
        action("Render movie…", lambda: self.render_movie_dialog(), menu=menu)

    def wire(self, panel) -> None:
        self.panel = panel
        panel.load_bvh.clicked.connect(lambda: self.load_bvh_dialog())
        panel.load_trans.clicked.connect(lambda: self.load_trans_dialog())
        panel.play.clicked.connect(lambda: self.toggle_play())
        panel.first.clicked.connect(lambda: self.go(0))
        panel.back.clicked.connect(lambda: self.step(-1))
        panel.forward.clicked.connect(lambda: self.step(1))
        panel.last.clicked.connect(lambda: self.go(-1))
        panel.set_key.clicked.connect(lambda: self.set_key())
        panel.delete_key.clicked.connect(lambda: self.delete_key())
        panel.scan.clicked.connect(lambda: self.scan())
        panel.export.clicked.connect(lambda: self.export_dialog(tskel=False))
        panel.movie.clicked.connect(lambda: self.render_movie_dialog())

    # ------------------------------------------------------------ frames
    def _frame_changed(self) -> None:
        if self.doc.timeline.active and not self.playing:
            if self.doc.settings.follow_body and self.scene.posing:  # the posed body is what the view shows
                self.follow_body()

    def _picture_changed(self) -> None:
        """Playing, the view follows the body drawn -- the frame of the picture, not the newest frame asked
        for (#83: the camera ran ahead of a loaded machine's pictures, and the body left the view's middle)."""
        p = self.doc.preview
        if (self.playing and self.doc.settings.follow_body and self.scene.posing and p is not None
                and p.joints is not None):
            self.follow_body(blend=self._ease(p.frame), joints=p.joints)

    def _ease(self, frame: int) -> float:
        """How far the playing camera moves to the body drawn: by the clip's time since the last picture
        (:func:`camera_moves.follow_blend`), landing on it at the first picture and when the clip went round."""
        from volanim_studio.scene import camera_moves

        last, self._followed = self._followed, frame
        if last is None or frame < last:
            return 1.0
        return camera_moves.follow_blend((frame - last) / self.doc.timeline.frame_rate)

    def follow_body(self, blend: float = 1.0, joints: dict | None = None) -> None:
        """Centre the view on the posed body (the middle of its posed joints' box; ``joints``: those of the
        picture drawn, else the pose's): a walk's figure, which travels metres through the clip, stays in the
        picture instead of walking out of it."""
        joints = self.doc.pose.posed_joints() if joints is None else joints
        if not joints:
            return
        from volanim_studio.scene import camera_moves

        p = np.array(list(joints.values()), np.float64)
        camera_moves.follow(self.scene.plotter.renderer, self.scene.world(((p.min(0) + p.max(0)) / 2)[None])[0], blend)
        self.scene.render()

    def step(self, delta: int) -> None:
        self.doc.timeline.step(delta)

    def go(self, frame: int) -> None:
        n = self.doc.timeline.frame_count
        self.doc.settings.current_frame = frame % n if n else 0

    @property
    def playing(self) -> bool:
        return self._play.isActive()

    def toggle_play(self) -> None:
        self.stop() if self.playing else self.play()

    def play(self) -> None:
        tl = self.doc.timeline
        if not tl.active:
            self.doc.message("Nothing to play: load a BVH clip or .trans frames, or set keys.")
            self._sync_button()
            return
        self.doc.settings.mode = Mode.POSE  # playing shows the posed preview
        self.doc.settings.dragging = True  # held while playing: live previews follow, a full one is cancelled
        self.doc.settings.playing = True  # the bones drawn wait for the body of their frame
        self.shown_frames = []
        self._followed = None  # the frame the camera last moved to (its easing is in clip time)
        self._start = (time.perf_counter(), self.doc.settings.current_frame)
        self._play.start(max(5, int(1000 / tl.frame_rate)))
        self._sync_button()

    def stop(self) -> None:
        if not self.playing:
            return
        self._play.stop()
        self._sync_button()
        self.doc.settings.playing = False  # the bones follow the pose again (the scene draws the frame's)
        self.doc.settings.dragging = False  # the full preview with its report, of the frame stopped on

    def _tick(self) -> None:
        tl = self.doc.timeline
        t0, f0 = self._start
        frame = (f0 + int((time.perf_counter() - t0) * tl.frame_rate)) % max(tl.frame_count, 1)
        if frame != self.doc.settings.current_frame:
            self.doc.settings.current_frame = frame
            self.shown_frames.append(frame)

    def _sync_button(self) -> None:
        panel = getattr(self, "panel", None)
        if panel is not None:
            panel.play.setChecked(self.playing)
            panel.play.setText("❚❚ Pause" if self.playing else "▶ Play")

    # -------------------------------------------------------------- keys
    def set_key(self) -> None:
        self.attempt("Set key", lambda: self.doc.timeline.set_key(), lambda f: f"Keyed the pose at frame {f}.")

    def delete_key(self) -> None:
        self.attempt("Delete key", lambda: self.doc.timeline.delete_key(), "Deleted the key.")

    # ------------------------------------------------------------- clips
    def export_keys(self, path) -> None:
        """The keys as a ``.keys`` file: ``volanim keys`` makes the same frames from it."""
        self.attempt("Export keys", lambda: self.doc.timeline.export_keys(path),
                     f"Saved the keys to {path} (volanim keys {Path(path).name} --bones … makes their frames).")

    def import_keys(self, path) -> None:
        self.stop()
        self.attempt("Import keys", lambda: self.doc.timeline.import_keys(path), f"Loaded the keys of {path}.")

    def keys_dialog(self, *, save: bool) -> None:
        pick = QFileDialog.getSaveFileName if save else QFileDialog.getOpenFileName
        path, _ = pick(self.window, "Export keys" if save else "Import keys", self.folder("animation.keys"),
                       "Keys (*.keys);;All files (*)")
        if path:
            (self.export_keys if save else self.import_keys)(path)

    def load_bvh(self, path, *, ask=None, pick=None) -> Worker | None:
        """Read a clip (BVH; glTF: each of its animations) in the reader thread (#61: no file is read on the
        GUI thread), let the user pick one of a glTF file's animations (``pick(names) -> name or None``; None:
        the first) and confirm the mapping (``ask(dialog) -> bool``; None: the suggestions), then retarget it
        onto the bones. The reader's worker, or None while another file is being read (said)."""
        self.stop()
        return self.read_then(path, lambda progress: [read_clip(path, k) if k else read_clip(path)
                                                      for k in range(len(clip_animations(path)))],
                              lambda motions: self._picked(path, motions, ask, pick))

    def _picked(self, path, motions, ask, pick) -> None:
        motion = motions[0]
        if len(motions) > 1 and pick is not None:
            name = pick([m.animation for m in motions])
            if name is None:
                return
            motion = next(m for m in motions if m.animation == name)
        self._retarget(path, motion, ask)

    def pick_animation(self, path, names: list[str]) -> str | None:
        """The animation of a glTF file to load, asked in a list (None: cancelled)."""
        name, ok = QInputDialog.getItem(self.window, "Pick an animation",
                                        f"{Path(path).name} holds {len(names)} animations:", names, 0, False)
        return name if ok else None

    def _retarget(self, path, motion, ask) -> None:
        """The mapping asked (``ask``), the clip retargeted in the reader thread (#83 item 13: 70 ms of
        mannequin-large's walk on the GUI thread), then put on the timeline."""
        mapping, up, forward = None, "auto", "auto"
        if ask is not None:
            dialog = MappingDialog(self.doc.bones, motion, Path(path).name, self.window)
            if not ask(dialog):
                return
            mapping, (up, forward) = dialog.mapping(), dialog.axes()
        bones = copy.deepcopy(self.doc.bones)  # the load uses it only while the document's bones are these
        self.window.readers.run(f"Retargeting {Path(path).name}",
                                lambda progress, cancel: retarget_clip(path, bones, motion, mapping, up, forward),
                                lambda built: self._put_clip(path, mapping, up, forward, motion, built))

    def _put_clip(self, path, mapping, up, forward, motion, built) -> None:
        r = self.attempt("Load clip", lambda: self.doc.timeline.load_bvh(path, mapping, up, forward, motion, built,
                                                                          motion.animation))
        if r is FAILED:
            return
        absorbed = r.absorbed_degrees()
        worst = max(absorbed, key=absorbed.get) if absorbed else None
        which = f" ({motion.animation})" if motion.animation is not None else ""
        self.doc.message(f"{Path(path).name}{which}: {motion.frames} frames at {motion.fps:.4g} fps on "
                         f"{len(r.mapping)} of {len(self.doc.bones)} bones (up {r.up}, facing {r.forward})"
                         + (f"; largest rest difference {absorbed[worst]:.0f}° at {worst}" if worst else "")
                         + ". Space plays, arrows step.")

    def load_bvh_dialog(self) -> None:
        path, _ = QFileDialog.getOpenFileName(self.window, "Load a motion clip", self.folder(),
                                              f"{CLIP_FILTER};;All files (*)")
        if path:
            self.load_bvh(path, ask=lambda d: d.exec() == QDialog.Accepted,
                          pick=lambda names: self.pick_animation(path, names))

    def load_trans(self, folder) -> Worker | None:
        """Read a folder of ``.trans`` frames in the reader thread (1064 files: about 1.5 s), then put them
        on the timeline. The reader's worker, or None while another file is being read (said)."""
        self.stop()
        bones = self.doc.bones

        def read(progress):
            if not len(bones):
                raise ValueError("build or open the bone skeleton first: the frames move its bones")
            return read_frames(folder, bones, progress=progress)

        def put(frames):
            if self.doc.bones is not bones:  # the bones changed while the files were read: read them again
                frames = None
            clip = self.attempt("Load frames", lambda: self.doc.timeline.load_trans(folder, frames))
            if clip is not FAILED:
                self.doc.message(f"Loaded {len(clip.matrices)} frames from {clip.path}. Space plays, arrows step.")

        return self.read_then(folder, read, put)

    def load_trans_dialog(self) -> None:
        folder = QFileDialog.getExistingDirectory(self.window, "Folder of .trans frames", self.folder())
        if folder:
            self.load_trans(folder)

    # ---------------------------------------------------------- jobs
    def scan(self):
        """Scan every frame for breakage in the background; the report lists the worst first."""
        tl = self.doc.timeline
        if not tl.active or self.jobs.busy:
            self.doc.message("Nothing to scan: load a clip or set keys." if not tl.active else
                             "A job is running; scan when it ends.")
            return None
        self.stop()
        try:
            conn = self.doc.pose.tskel().connectivity
            if not len(conn):
                raise ValueError("no attached points: connect points to bones first (Connect tab)")
        except ValueError as exc:
            self.show_error("Scan for breakage", str(exc))
            return None
        mats, joints, n = tl.matrices(), dict(self.doc.bones.joints), tl.frame_count
        return self.jobs.run(f"Scanning {n} frames for breakage", lambda progress, cancel: scan_frames(
            conn, mats, range(n), joints=joints, progress=progress, cancel=cancel), self._scanned)

    def _scanned(self, verdicts) -> None:
        self.last_scan = worst_first(verdicts)
        if self.scan_dialog is None:
            self.scan_dialog = ScanDialog(self.window)
            self.scan_dialog.jump.connect(lambda f: self.go(f))
        self.scan_dialog.show_verdicts(self.last_scan, self.doc.timeline.frame_number)
        self.scan_dialog.show()
        w = self.last_scan[0]
        self.doc.message(f"{scan_summary(verdicts)}; worst frame "
                         f"{self.doc.timeline.frame_number(w.frame)} ({w.pieces} piece(s), {w.cracks} cracks"
                         + (f" near {w.worst_joint}" if w.worst_joint else "") + ").")

    def export(self, folder, *, tskel: bool = False):
        tl = self.doc.timeline
        if not tl.active:
            self.show_error("Export frames", "nothing to export: load a clip or set keys first")
            return None
        try:
            conn = self.doc.attachments.to_connectivity() if tskel else None
            if conn is not None and not len(conn):
                raise ValueError("no attached points for .tskel frames: connect points to bones first")
        except ValueError as exc:
            self.show_error("Export frames", str(exc))
            return None
        stem = tl.clip.name if tl.clip is not None else "keys"
        numbers = [tl.frame_number(f) for f in range(tl.frame_count)]
        mats, bones = tl.matrices(), self.doc.bones
        return self.jobs.run(f"Writing {len(numbers)} frames", lambda progress, cancel: write_frames(
            folder, stem, bones, mats, numbers, connect=conn, progress=progress, cancel=cancel),
            lambda paths: self.doc.message(f"Wrote {len(paths)} frames to {folder} ({paths[0].name} …)."))

    def export_dialog(self, *, tskel: bool) -> None:
        folder = QFileDialog.getExistingDirectory(self.window, "Folder for the frames", self.folder())
        if folder:
            self.export(folder, tskel=tskel)

    # ---------------------------------------------------------- movies
    def camera(self) -> Camera:
        """The view's camera in world units (voxel x spacing), as the studio draws."""
        return Camera.of(self.scene.plotter.renderer.GetActiveCamera())

    def save_camera(self, path) -> None:
        """The view's camera in voxel coordinates, for ``volanim render --camera``."""
        cam = self.camera().scaled(1.0 / self.scene.spacing)
        self.attempt("Save view as camera file", lambda: io.write_camera(path, cam), f"Saved the view to {path}.")

    def save_camera_dialog(self) -> None:
        path, _ = QFileDialog.getSaveFileName(self.window, "Save view as camera file", self.folder("view.camera"),
                                              "Camera files (*.camera)")
        if path:
            self.save_camera(path)

    def render_movie(self, out, *, first: int = 0, last: int | None = None, step: int = 1, style: str = "surface",
                     size=(640, 480), frame_numbers: bool = False, workers: int | None = None,
                     follow: bool | None = None):
        """Reconstruct frames ``first..last`` (every ``step``) in the preview's mode and render them with
        the view's camera -- moved with the body when ``follow`` (default: the Follow the body setting) --
        and the user's transfer function when there is one, in the background with progress and cancel."""
        from volanim_studio.tasks import MovieSettings, render_movie

        tl, st = self.doc.timeline, self.doc.settings
        if self.jobs.busy:
            self.doc.message("A job is running; render when it ends.")
            return None
        self.stop()
        try:
            if not tl.active:
                raise ValueError("nothing to render: load a clip or set keys first")
            conn = self.doc.pose.tskel().connectivity
            if not len(conn):
                raise ValueError("no attached points: connect points to bones first (Connect tab)")
            if st.preview_mode == "sampled" and self.doc.volume is None:
                raise ValueError("sampled mode needs the volume: open it (File → Open volume)")
            last = tl.frame_count - 1 if last is None else last
            frames = list(range(first, last + 1, step))
            if not frames:
                raise ValueError(f"frames {first}..{last} are empty: the first frame must not come after the last")
        except ValueError as exc:
            self.show_error("Render movie", str(exc))
            return None
        mats, numbers = tl.matrices(frames), [tl.frame_number(f) for f in frames]
        camera, spacing, mode, source = self.camera(), tuple(self.scene.spacing), st.preview_mode, self.doc.volume
        kernel = st.preview_kernel if mode == "sampled" else 1
        if kernel > 1 and source is not None and source.ndim == 4:  # a colour movie's frames hold palette indices
            kernel = 1
            self.doc.message("The colour movie samples the nearest voxel (kernel 1): its frames hold palette "
                             "indices, which cannot be averaged.")
        follow = st.follow_body if follow is None else follow
        fps = tl.frame_rate / step
        transfer = self.doc.transfer.function  # the editor's (None: the mode's colours)
        settings = MovieSettings(mode, camera, source=source, kernel=kernel, spacing=spacing, style=style, size=size,
                                 fps=fps, frame_numbers=frame_numbers, follow=follow, transfer=transfer,
                                 workers=workers)
        return self.jobs.run(f"Rendering {len(frames)} frames", lambda progress, cancel: render_movie(
            conn, mats, numbers, out, settings, progress=progress, cancel=cancel),
            lambda r: self.doc.message(f"Rendered {r['frames']} frames to {r['out']} in {r['seconds']:.1f} s "
                                       f"({r['workers']}){'; ' + r['colours'] if r['colours'] else ''}."))

    def render_movie_dialog(self) -> None:
        tl = self.doc.timeline
        if not tl.active:
            self.show_error("Render movie", "nothing to render: load a clip or set keys first")
            return
        stem = tl.clip.name if tl.clip is not None else "keys"
        tf = self.doc.transfer.function
        dialog = MovieDialog(self.window, tl.frame_count, str(Path.cwd() / f"{stem}.mp4"),
                             self.doc.settings.follow_body,
                             colours=f"your transfer function ({len(tf.values)} points; View → Transfer function)"
                             if tf is not None else f"the {self.doc.settings.preview_mode} mode's own")
        if dialog.exec() != QDialog.Accepted:
            return
        options = dialog.options()
        if not options["out"]:
            self.show_error("Render movie", "choose a file for the movie")
            return
        self.render_movie(options.pop("out"), **options)
