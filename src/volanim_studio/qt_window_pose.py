"""Posing and previews in the main window: live and full previews, compare, export, the report.

A mixin of :class:`~volanim_studio.qt_main_window.MainWindow` (it uses the
window's document, scene, panels and ``run_task``), kept apart so each file
stays readable.
"""

from __future__ import annotations

import time
from pathlib import Path

from volanim_core import io
from volanim_core.errors import FormatError

from .model.modes import Mode
from .model.preview import make_preview
from .qt_worker import Worker


class PoseWindowMixin:
    def _pose_drag_started(self) -> None:
        self._posing_drag = True
        if self.worker is not None and getattr(self.worker, "is_preview", False):
            self.worker.cancel()  # a newer pose is coming

    def _pose_drag_finished(self) -> None:
        self._posing_drag = False
        if self.mode == Mode.POSE and len(self.doc.attachments.bone) and (self.doc.attachments.bone >= 0).any():
            self.preview()

    def _on_pose_changed(self, **_) -> None:
        if self._posing_drag and self.reconstruct_panel.live.isChecked():
            self._live_timer.start()  # coalesced: one live preview per event-loop pass

    def live_preview(self) -> None:
        """Half-resolution binary or bone preview on the GUI thread (tens of ms on the mannequin)."""
        t0 = time.perf_counter()
        mode = self.reconstruct_panel.mode.currentText()
        mode = mode if mode in ("binary", "bone") else "bone"
        try:
            tskel = self.doc.pose.tskel()
            p = make_preview(tskel, mode=mode, factor=2, padding=2, neighbours=self.doc.pose.neighbours(tskel))
        except ValueError as exc:
            self.doc.message(str(exc))
            return
        self.doc.set_preview(p)  # drawn by the scene's coalesced render: one frame per pose change
        self.live_timings.append(time.perf_counter() - t0)

    def preview(self, *, report: bool = True) -> Worker | None:
        """Full-resolution reconstruction with the breakage report, in the background."""
        settings = self.reconstruct_panel.settings()
        if self.worker is not None:
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
        joints = dict(self.doc.bones.joints)
        posed = self.doc.pose.posed_joints()
        source = self.doc.volume if settings["mode"] == "sampled" else None
        nbrs = self.doc.pose.neighbours(tskel, compute=False)  # None: the worker computes them
        worker = self.run_task("Reconstructing", lambda progress, cancel: make_preview(
            tskel, **settings, source=source, joints=joints, posed_joints=posed, report=report, neighbours=nbrs,
            progress=progress, cancel=cancel), self.doc.set_preview)
        worker.is_preview = True
        return worker

    def _forget_rest(self, **_) -> None:
        self._rest_preview = None

    def _draw_preview(self) -> None:
        p = self.doc.preview
        if self.reconstruct_panel.show_rest.isChecked():
            if self._rest_preview is None and len(self.doc.attachments.bone):
                from volanim_core.tskel import identity_tskel

                try:
                    rest = identity_tskel(self.doc.pose.tskel().connectivity)
                    mode = p.mode if p is not None else "bone"
                    self._rest_preview = make_preview(rest, mode=mode, source=self.doc.volume)
                except ValueError as exc:
                    self.doc.message(str(exc))
                    return
            p = self._rest_preview
        if p is None:
            self.scene.clear_volume()
            return
        if p.factor > 1 and p.mode in ("bone", "binary"):  # a live preview: a surface draws fastest
            self.scene.show_surface(p.reconstruction.volume, p.origin_voxels, p.spacing, p.mode)
        else:
            self.scene.show_volume(p.reconstruction.volume, p.origin_voxels, p.spacing, p.mode)

    def _slices_toggled(self, on: bool) -> None:
        self.scene.slices = on
        self._draw_preview()

    def jump_to_joint(self, name: str) -> None:
        posed = self.doc.pose.posed_joints()
        if name in posed:
            self.scene.jump_to(posed[name])
            self.doc.message(f"Centred on {name}. Fix the points there (Lasso, L), then preview again (F5).")

    def export_preview(self, path) -> bool:
        p = self.doc.preview
        if p is None:
            self.show_error("Export", "nothing to export: preview first (F5)")
            return False
        vol, note = io.saturate_for_raw(path, p.reconstruction.volume)
        try:
            io.write_volume(path, vol, origin=tuple(p.origin_voxels), spacing=p.spacing)
        except (OSError, ValueError) as exc:
            self.show_error("Export", str(exc))
            return False
        self.doc.message(f"Exported {vol.shape[0]}x{vol.shape[1]}x{vol.shape[2]} ({p.mode}) to {path}; "
                         f"origin {tuple(int(v) for v in p.origin_voxels)}." + (f" Note: {note}." if note else ""))
        return True

    def load_trans(self, path) -> bool:
        try:
            self.doc.pose.load_trans(path)
        except (FormatError, ValueError) as exc:
            self.show_error("Load pose", str(exc))
            return False
        self.doc.message(f"Loaded the pose from {Path(path).name}.")
        return True

