"""Posing and previews: live and full previews, compare, slices, export, poses in and out.

    settings.dragging (a pose slider, the timeline held or playing) + doc.events.pose
        --> live_preview (coalesced) --> LiveWorker (its thread, newest pose first: full resolution on a
            small body, else half; the owned body as the full preview's, only the moved bones redone;
            the surface too) --> _live_made --> doc.set_preview
    settings.current_frame (a step) --> live_preview
    dragging back to False in Pose mode, doc.events.pose_settled, F5, Pose mode entered, a clip loaded
        (show_body: unless the picture shown is current)
        --> preview() --> JobRunner(make_preview) --> doc.set_preview (the picture)
                      --> JobRunner(with_report, background) --> doc.set_preview (the same picture, with its report)
    doc.set_preview --> the scene's PoseLayer draws it (this controller draws nothing)

Owned by the main window (composed, not inherited). Preview mode, kernel and
padding are read from ``doc.settings`` at the moment of use, never from widgets.
"""

from __future__ import annotations

import time
from pathlib import Path

from PySide6.QtCore import QTimer
from PySide6.QtWidgets import QFileDialog

from volanim_core import io

from ..model.live_resolution import LiveResolution
from ..model.preview import LivePreviews, make_preview, with_report
from ..model.settings import Mode
from . import ownership_actions
from .controller import FAILED, Controller
from .live_worker import LiveWorker
from .worker import Worker

DRAW_WAIT_MS = 300  # a live picture not drawn by then lets the next be made all the same


class PreviewController(Controller):
    def __init__(self, window):
        super().__init__(window)
        self.live_timings: list[float] = []  # seconds per live update (pose change -> drawn)
        # redoes only what moved, at the resolution that keeps the rate; used by the live thread only
        self.live = LivePreviews(resolution=LiveResolution(self.doc.settings.live_resolution))
        self.clock = time.perf_counter  # times the live pictures (a test's own clock: the resolution it picks)
        self.live_worker = LiveWorker(window)  # makes them off the GUI thread, the newest pose first
        self.live_worker.made.connect(self._live_made)
        self._full_asked = 0  # full previews asked for: a live picture asked for before the last is dropped
        self._live_timer = QTimer(window)
        self._live_timer.setSingleShot(True)
        self._live_timer.setInterval(0)
        self._live_timer.timeout.connect(self.live_preview)
        # a live picture never drawn (the window hidden, the rest pose shown) lets the next be made all the same;
        # one timer, restarted per picture: an earlier picture's never lets a later one's go early
        self._draw_wait = QTimer(window)
        self._draw_wait.setSingleShot(True)
        self._draw_wait.setInterval(DRAW_WAIT_MS)
        self._draw_wait.timeout.connect(self.live_worker.drawn)
        ev, st = self.doc.events, self.doc.settings.events
        ev.pose.connect(self._on_pose_changed)
        ev.pose_settled.connect(lambda **_: self._settled())
        st.dragging.connect(self._on_dragging)
        st.live_resolution.connect(lambda value, **_: setattr(self.live, "resolution", LiveResolution(value)))
        st.current_frame.connect(lambda **_: self.live_preview_soon() if self.doc.timeline.active else None)
        st.mode.connect(self._on_mode)
        # a clip loaded (or keys changed) moves the body to its frame: drawn, not left under the new bones (#83);
        # looked at once the event has been handled, since the timeline sets the frame's pose after telling
        ev.timeline.connect(lambda **_: QTimer.singleShot(0, window, self._after_timeline))
        self._again = QTimer(window)  # a preview asked for while a job runs: made once it has ended
        self._again.setSingleShot(True)
        self._again.setInterval(50)
        self._again.timeout.connect(self._preview_when_idle)
        self._body_again = QTimer(window)  # the same for show_body's preview
        self._body_again.setSingleShot(True)
        self._body_again.setInterval(50)
        self._body_again.timeout.connect(self.show_body)
        self._owners_again = QTimer(window)  # the hull's ownership colours, made once no job runs
        self._owners_again.setSingleShot(True)
        self._owners_again.setInterval(50)
        self._owners_again.timeout.connect(self.colour_hull_by_owners)
        st.hull_owners.connect(lambda **_: self._owners_again.start())
        ev.owners_shown.connect(lambda **_: self._owners_again.start())
        st.joints.connect(lambda **_: self._joints_changed())
        st.blend.connect(lambda **_: self._joints_changed() if self.doc.settings.joints == "smooth" else None)

    def fill_menu(self, menu, action) -> None:
        """The Pose menu; ``action(text, slot, shortcut=None, menu=None)`` makes a window action."""
        action("Preview reconstruction", lambda: self.preview(), "F5", menu=menu)
        action("Reset pose", lambda: self.doc.pose.reset(), menu=menu)
        action("Load pose (.trans)…", lambda: self.load_trans_dialog(), menu=menu)
        action("Save pose (.trans)…", lambda: self.save_dialog("trans"), menu=menu)
        action("Save frame (.tskel)…", lambda: self.save_dialog("tskel"), menu=menu)
        action("Export reconstruction…", lambda: self.save_dialog("volume"), menu=menu)
        action("Give the cube's voxels to the working bone", lambda: self.own_cube(), menu=menu)
        action("Show ownership on slices", lambda: self.show_ownership(), menu=menu)
        action("Hang stray flesh on the limb it rests on", lambda: self.hang_on(), menu=menu)

    def wire(self, pose_panel, reconstruct_panel) -> None:
        """Connect the Pose and Reconstruct tabs' buttons to this controller."""
        pose_panel.load_trans.clicked.connect(lambda: self.load_trans_dialog())
        pose_panel.save_trans.clicked.connect(lambda: self.save_dialog("trans"))
        pose_panel.save_tskel.clicked.connect(lambda: self.save_dialog("tskel"))
        reconstruct_panel.preview_button.clicked.connect(lambda: self.preview())
        reconstruct_panel.export_button.clicked.connect(lambda: self.save_dialog("volume"))
        reconstruct_panel.fix_lump.connect(self.fix_lump)
        reconstruct_panel.joint_clicked.connect(self.jump_to_joint)

    @property
    def _posing(self) -> bool:
        """In Pose mode with something attached: what full previews follow."""
        bone = self.doc.attachments.bone
        return self.doc.settings.mode == Mode.POSE and len(bone) > 0 and bool((bone >= 0).any())

    def _on_mode(self, value) -> None:
        if value != Mode.POSE:
            self._live_timer.stop()
        else:
            self.show_body()

    def _after_timeline(self) -> None:
        st = self.doc.settings
        if not (self.doc.preview_is_current or st.dragging or st.playing):
            self.show_body()

    def show_body(self) -> None:
        """Pose mode entered, or a project or a recovered session opened in it: the body's full preview,
        once no job runs, unless the one shown is current (#61, #83: it showed the bones alone until the
        first pose change or F5). A background job (no dialog): any job the user asks for next goes first."""
        if self.doc.preview_is_current or not self._posing:
            return
        if self.jobs.running:  # any job, a background one too: never preempted from here (a preempt handles
            self._body_again.start()  # events, and this could be called again inside it)
        else:
            self.preview(background=True)

    def _on_dragging(self, value: bool) -> None:
        """Held (a pose slider, the timeline scrubbed or playing): a running full preview is cancelled, a
        newer pose is coming; released in Pose mode: the full preview with its report."""
        if value:
            worker = self.jobs.worker
            if worker is not None and getattr(worker, "is_preview", False):
                worker.cancel()
        elif self._posing:
            self.preview()

    def _settled(self) -> None:
        if self._posing:
            self.preview()

    def _joints_changed(self) -> None:
        """Joints or blend changed: the pose is shown again the new way. A preview running the old way is
        cancelled and the new one made when it has ended (each step of the Blend box, the last one shown)."""
        if not self._posing:
            return
        worker = self.jobs.worker
        if worker is not None and getattr(worker, "is_preview", False):
            worker.cancel()
        self._preview_when_idle()

    def _preview_when_idle(self) -> None:
        if self.jobs.busy:
            self._again.start()
        elif self._posing:
            self.preview()

    def _on_pose_changed(self, **_) -> None:
        if self.doc.settings.dragging and self.doc.settings.live_preview:
            self._request_live()

    def live_preview_soon(self) -> None:
        """A live preview at the next event-loop pass (the timeline's frame changed), if there is anything
        attached to preview and live previews are on."""
        bone = self.doc.attachments.bone
        if self.doc.settings.live_preview and len(bone) and (bone >= 0).any():
            self._request_live()

    def _request_live(self) -> None:
        """Coalesce live previews: one per event-loop pass, drawing the newest pose.

        A pending request is never restarted. Restarting a zero-interval timer pushes its
        deadline past the playback timer's whenever a frame takes longer than the playback
        interval to handle (a busy machine), so it never fired: playing showed no preview at all.
        """
        if not self._live_timer.isActive():
            self._live_timer.start()

    def live_preview(self) -> None:
        """Ask the live thread for a binary or bone preview of the pose now: full resolution on a small
        body, half on a larger one (:func:`live_factor`), only what moved redone, its surface made there
        too; the GUI thread only draws what comes back (:meth:`_live_made`)."""
        mode = self.doc.settings.preview_mode
        mode = mode if mode in ("binary", "bone") else "bone"
        clock = self.clock
        t0 = clock()
        try:
            make_frame = self.doc.pose.frame_maker()  # a snapshot: the frame itself is made in the live thread
        except ValueError as exc:
            self.doc.message(str(exc))
            return
        basis, full = self.doc.picture_basis, self._full_asked
        # what it shows: playing, the scene draws these bones with it, never the newer pose's
        joints = self.doc.pose.posed_joints()
        frame = self.doc.settings.current_frame if self.doc.timeline.active else None
        function, n_bones, live = self.doc.transfer.function, len(self.doc.bones), self.live
        spacing = tuple(self.scene.spacing)  # the view's world units
        owned = self.doc.ownership  # the body the full preview shows (its ownership made here once per rig)

        def make():
            t1 = clock()
            attached = owned.attach(make_frame())
            t2 = clock()
            p = live.make(attached, mode=mode, padding=2)  # only what moved, at the resolution keeping the rate
            t3 = clock()
            p.basis, p.joints, p.frame = basis, joints, frame
            p.surface = live.surface(p, function, n_bones, spacing)  # only the slices that changed made again
            p.stages = {"pose": t2 - t1, "body": t3 - t2, "surface": clock() - t3}
            return p, full, t0

        self.live_worker.ask(make)

    def _live_made(self, result) -> None:
        """A live picture made: drawn, unless a full preview was asked for since (it would hide it)."""
        if isinstance(result, Exception):
            self.live_worker.drawn()  # nothing to draw: the next may be made now
            if not isinstance(result, ValueError):
                raise result  # a bug: seen, as on the GUI thread
            self.doc.message(str(result))
            return
        p, full, t0 = result
        asked = self.clock() - t0  # asked -> made (drawn at the next render): a drag's pace, waits included
        self.live_timings.append(asked)
        if full != self._full_asked or self.doc.settings.mode != Mode.POSE:
            self.live_worker.drawn()  # dropped: the next may be made now
            return
        self.scene.frames.after_next(self.live_worker.drawn)  # the next is made once this one is drawn
        self._draw_wait.start()
        self.doc.set_preview(p)  # drawn by the scene's coalesced render: one frame per pose change
        # its cost picks the next one's resolution: its stages (the scene adds the last draw), or the wait from
        # asking, when longer (the frog's half-size pictures: 59 ms of stages, one drawn every 140 ms)
        self.live.resolution.took(p.factor, max(sum(p.stages.values()), asked))

    def preview(self, *, report: bool = True, background: bool = False) -> Worker | None:
        """Full-resolution reconstruction in the background, shown as soon as it is made; then, as a second
        job, its breakage report (mannequin-large: the picture in 0.2 s, the report 5 s later, #65).
        ``background``: no dialog, and the next job asked for cancels it (the body shown on entering Pose)."""
        st = self.doc.settings
        settings = {"mode": st.preview_mode, "kernel": st.preview_kernel, "padding": st.preview_padding}
        if self.jobs.busy:
            self.doc.message("A job is running; preview again when it ends.")
            return None
        if settings["mode"] == "sampled" and self.doc.volume is None:
            self.show_error("Preview", "sampled mode needs the volume: open it (File → Open volume)")
            return None
        try:
            tskel = self.doc.pose.tskel()
            if not len(tskel):
                raise ValueError("no attached points to reconstruct: connect points to bones first (Connect tab)")
        except ValueError as exc:
            self.show_error("Preview", str(exc))
            return None
        source = self.doc.volume if settings["mode"] == "sampled" else None
        basis = self.doc.picture_basis
        self._full_asked += 1  # a live picture asked for before this one is not drawn over it,
        self._live_timer.stop()  # nor one about to be asked (playback's last frame, stopped just now)
        self.live_worker.forget()

        def done(p) -> None:
            p.basis = basis  # of the document as it was asked for: a change since leaves it marked old
            self.doc.set_preview(p)
            if report and not self.jobs.busy:  # (busy: what the picture set off started a job of its own)
                self._report(p, tskel)

        owned = self.doc.ownership  # the rig's ownership is made in the worker (once per rig), with the repaints

        worker = self.jobs.run("Reconstructing", lambda progress, cancel: make_preview(
            owned.attach(tskel), **settings, source=source, progress=progress, cancel=cancel), done,
            background=background)
        worker.is_preview = True
        return worker

    def _report(self, shown, tskel) -> None:
        """The breakage report of the preview just shown, in a background job of its own (no dialog: the user
        may pose on, which cancels it); applied only while that preview is still the one shown."""
        joints = dict(self.doc.bones.joints)
        posed = self.doc.pose.posed_joints()
        rest, version = self.doc.pose.rest_parts(tskel), self.doc.pose.rest_version  # None: the worker makes them

        def done(p) -> None:
            self.doc.pose.keep_rest_parts(tskel, p.rest_parts, version)
            p.report.body_pieces = self.doc.body_pieces  # a rest pose in more pieces than the volume is said
            if self.doc.preview is shown:
                self.doc.set_preview(p)

        owned = self.doc.ownership
        worker = self.jobs.run("Checking the pose for breakage", lambda progress, cancel: with_report(
            shown, owned.attach(tskel), joints=joints, posed_joints=posed, rest_parts=rest, cancel=cancel), done,
            background=True)
        worker.is_preview = True

    def jump_to_joint(self, name: str) -> None:
        posed = self.doc.pose.posed_joints()
        if name in posed:
            self.scene.jump_to(posed[name])
            self.doc.message(f"Centred on {name}. {self.fix_hint(name)}, then preview again (F5).")

    def fix_lump(self, k: int) -> None:
        """The shown report's lump ``k`` fixed: the rest voxels it was made of given to the bone it belongs to
        (a repaint of the ownership, one undo step), then the preview made again. The ownership is the one the
        preview moved (made in its worker and kept), so this is quick."""
        p = self.doc.preview
        report = p.report if p is not None else None
        if report is None or not 0 <= k < len(report.lumps):
            return
        lump = report.lumps[k]
        names = [b.label for b in self.doc.bones.bones]
        if self.doc.settings.body != "owned" or not self.doc.ownership.available or self.doc.settings.joints != "rigid":
            # smooth joints move the spheres by blends, which ownership does not steer
            self.show_error("Fix lump", "a lump is fixed by repainting ownership: choose Body: owned, rigid joints, "
                                        "and open the volume, or give the points there to another bone (Lasso, L)")
            return
        if lump.belongs_to not in names:
            self.show_error("Fix lump", f"the lump near {lump.near} names no bone to give its flesh to")
            return
        tskel, matrices = self.doc.pose.tskel(), self.doc.pose.matrices()
        owned = self.doc.ownership

        def done(own) -> None:
            if own is None:
                self.show_error("Fix lump", "nothing attached: connect points to bones first")
                return
            n = owned.fix_lump(own, matrices, lump, names.index(lump.belongs_to))
            self.doc.message(f"Gave {n:,} voxels near {lump.near} to {lump.belongs_to}; previewing again.")
            self.preview()

        self.jobs.run("Ownership", lambda progress, cancel: owned.of(tskel.connectivity), done)

    def own_cube(self) -> None:
        """Repaint ownership: the body's voxels inside the cube (Cube mode places it) go to the working bone."""
        ownership_actions.own_cube(self)

    def show_ownership(self) -> Worker | None:
        """The scan's slices tinted by the bone that moves each voxel (:mod:`.ownership_actions`)."""
        return ownership_actions.show_ownership(self)

    def hang_on(self) -> Worker | None:
        """Flesh that touches the body only through another limb's, to that limb (:mod:`.ownership_actions`)."""
        return ownership_actions.hang_on(self)

    def colour_hull_by_owners(self) -> Worker | None:
        """With *Colour by owning bone* on, the ownership of the rig as it is made in the background and handed to
        the hull (``doc.ownership.show``); made again after any change that makes the shown one old. A result
        for a rig edited meanwhile is dropped and made again."""
        doc = self.doc
        if not doc.settings.hull_owners or doc.ownership.shown is not None or not doc.ownership.available \
                or not len(doc.bones):
            return None
        if self.jobs.running:
            self._owners_again.start()
            return None
        conn, edits = doc.pose.tskel().connectivity, (doc.undo.edits, doc.ownership.version)

        def done(own) -> None:
            if (doc.undo.edits, doc.ownership.version) != edits or own is None:
                self._owners_again.start() if own is not None else None
                return
            doc.ownership.show(own)

        return self.jobs.run("Ownership", lambda progress, cancel: doc.ownership.of(conn), done)

    def fix_hint(self, joint: str) -> str:
        """What to do about the finding near ``joint``, naming the bone to give the points to (#83: "Fix the
        points there" named none, and a guess turned a lump into a stump and 13 cracks)."""
        report = self.doc.preview.report if self.doc.preview is not None else None
        for lump in (report.lumps if report is not None else []):
            if lump.near == joint and lump.belongs_to:
                return (f"The flesh there is {lump.belongs_to}'s, carried off by {lump.carrier}: make "
                        f"{lump.belongs_to} the working bone and give it the points there (Lasso, L)")
        for stump in (report.stumps if report is not None else []):
            if stump.joint == joint:
                return (f"The points left behind lie along {stump.lies_along}: make it the working bone and "
                        "give them to it (Lasso, L)")
        return "Fix the points there (Lasso, L)"

    def export_preview(self, path) -> bool:
        p = self.doc.preview
        if p is None:
            self.show_error("Export", "nothing to export: preview first (F5)")
            return False
        shape = p.reconstruction.volume.shape
        return self.attempt(
            "Export", lambda: io.write_output(path, p.reconstruction.volume, p.reconstruction.geometry, p.mode),
            lambda written: f"Exported {shape[0]}x{shape[1]}x{shape[2]} ({p.mode}) to {written[0]}; origin "
            f"{tuple(int(v) for v in p.origin_voxels)}." + (f" Note: {written[1]}." if written[1] else "")
        ) is not FAILED

    def load_trans(self, path) -> bool:
        return self.attempt("Load pose", lambda: self.doc.pose.load_trans(path),
                            f"Loaded the pose from {Path(path).name}.") is not FAILED


    # -------------------------------------------------------------- dialogs
    def load_trans_dialog(self) -> None:
        path, _ = QFileDialog.getOpenFileName(self.window, "Open pose", self.folder(), "Poses (*.trans);;All files (*)")
        if path:
            self.load_trans(path)

    def save_dialog(self, kind: str) -> None:
        """Ask where, then save the pose (``trans``), the frame (``tskel``) or the preview (``volume``)."""
        filters = {"trans": "Poses (*.trans)", "tskel": "Frames (*.tskel)",
                   "volume": "Volumes (*.vti *.nrrd *.VOL *.vol)"}
        default = {"trans": "pose.trans", "tskel": "pose.tskel", "volume": "preview.vti"}[kind]
        path, _ = QFileDialog.getSaveFileName(self.window, f"Save {kind}", self.folder(default), filters[kind])
        if not path:
            return
        if kind == "volume":
            self.export_preview(path)
            return
        save = self.doc.pose.save_trans if kind == "trans" else self.doc.pose.save_tskel
        self.attempt(f"Save {kind}", lambda: save(path), f"Saved {path}.")
