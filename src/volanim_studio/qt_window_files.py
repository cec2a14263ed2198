"""Opening and saving in the main window: volumes (threshold dialog + worker), skeletons,
bones, connectivity, projects, and the background-job runner with progress and Cancel.

A mixin of :class:`~volanim_studio.qt_main_window.MainWindow`.
"""

from __future__ import annotations

from pathlib import Path

from PySide6.QtWidgets import QFileDialog, QProgressDialog

from volanim_core import io
from volanim_core.errors import FormatError

from . import tasks
from .model.project import read_project
from .qt_threshold_dialog import ThresholdDialog
from .qt_worker import Worker


class FilesWindowMixin:
    # -------------------------------------------------------------- loading
    def run_task(self, label: str, task, on_done) -> Worker:
        """Run ``task(progress, cancel)`` in the background (see :class:`JobRunner`)."""
        return self.jobs.run(label, task, on_done)

    @property
    def busy(self) -> bool:
        return self.jobs.busy

    @property
    def worker(self) -> Worker | None:
        return self.jobs.worker

    @property
    def progress(self) -> QProgressDialog | None:
        return self.jobs.dialog

    def _apply_prepared(self, result: dict, path=None, threshold=None, spacing=None, dims=None) -> None:
        self.doc.set_volume(result["volume"], result["mask"], spacing=spacing or result.get("spacing", (1, 1, 1)),
                            path=path, threshold=threshold, dims=dims)
        self.doc.set_skeleton(result["skeleton"])
        self.doc.set_hull(*result["hull"])
        self.doc.message(f"{len(result['skeleton'])} skeleton points; thinness slider shows the prefix ≥ t.")

    def load_demo(self, name: str) -> Worker:
        def done(r):
            self._apply_prepared(r, spacing=r["spacing"])
            self.doc.demo_name = name

        return self.run_task(f"Preparing the {name} demo", lambda progress, cancel: tasks.load_demo(
            name, progress=progress, cancel=cancel), done)

    def open_volume(self, path, *, dims=None, params: dict | None = None) -> Worker | None:
        """Read a volume; ask for the threshold (unless ``params``); segment it in a worker."""
        try:
            loaded = tasks.load_volume_file(str(path), dims)
        except FormatError as exc:
            self.show_error("Open volume", str(exc))
            return None
        if params is None:
            dialog = ThresholdDialog(loaded["volume"], Path(path).name, self)
            if dialog.exec() != ThresholdDialog.Accepted:
                return None
            params = dialog.parameters()
        vol = loaded["volume"]
        return self.run_task(f"Skeletonizing {Path(path).name}", lambda progress, cancel: tasks.prepare_volume(
            vol, progress=progress, cancel=cancel, **params), lambda r: self._apply_prepared(
            r, path=path, threshold=(params["lo"], params["hi"]), spacing=loaded["spacing"], dims=dims))

    def open_volume_dialog(self) -> None:
        path, _ = QFileDialog.getOpenFileName(self, "Open volume", "", "Volumes (*.vol *.VOL *.vti *.nrrd *.nii "
                                              "*.nii.gz *.mha *.mhd);;All files (*)")
        if path:
            self.open_volume(path)

    def open_mskel(self, path) -> bool:
        try:
            skel = io.read_mskel(path)
        except FormatError as exc:
            self.show_error("Open skeleton", str(exc))
            return False
        self.doc.set_skeleton(skel, path)
        self.doc.message(f"Loaded {len(skel)} points from {Path(path).name}.")
        return True

    def open_bones(self, path) -> bool:
        try:
            self.doc.load_bones(path)
        except FormatError as exc:
            self.show_error("Open bones", str(exc))
            return False
        self.doc.message(f"Loaded {len(self.doc.bones)} bones from {Path(path).name}.")
        return True

    def open_connections(self, path) -> bool:
        try:
            self.doc.load_connections(path)
        except (FormatError, ValueError) as exc:
            self.show_error("Open connections", str(exc))
            return False
        self.doc.message(f"{len(self.doc.bones)} bones in the root order of {Path(path).name}.")
        return True

    def open_project(self, path) -> Worker | None:
        try:
            data = read_project(path)
        except FormatError as exc:
            self.show_error("Open project", str(exc))
            return None

        def rest(_=None):
            if data.get("mskel") and (self.doc.skeleton is None or not (data.get("volume") or data.get("demo"))):
                self.open_mskel(data["mskel"])
            elif data.get("mskel"):
                self.doc.mskel_path = data["mskel"]
            if data.get("bones"):
                self.open_bones(data["bones"])
            if data.get("connect"):
                self.open_connect(data["connect"])
            if data.get("symmetry_x") is not None:
                self.doc.symmetry_x = data["symmetry_x"]
            if data.get("thinness") is not None:
                self.doc.thinness = data["thinness"]
            self.doc.project_path = str(path)
            self.doc.events.project.emit(path=str(path))
            if data.get("camera"):
                self.set_camera(data["camera"])

        if data.get("demo") and not data.get("volume"):
            worker = self.load_demo(data["demo"])
            worker.succeeded.connect(rest)
            return worker
        if data.get("volume"):
            lo, hi = data.get("threshold") or (1, None)
            params = {"lo": lo, "hi": hi, "fill": False}
            worker = self.open_volume(data["volume"], dims=data.get("volume_dims"), params=params)
            if worker is not None:
                worker.succeeded.connect(rest)
            return worker
        rest()
        return None

    def open_connect(self, path) -> bool:
        try:
            warnings = self.doc.attachments.load(path)
        except (FormatError, ValueError) as exc:
            self.show_error("Open connectivity", str(exc))
            return False
        if warnings:
            self.show_error("Open connectivity", "\n".join(warnings))
        per_bone, unconnected = self.doc.attachments.counts()
        self.doc.message(f"Loaded {int(per_bone.sum())} attachments from {Path(path).name}.")
        return True

    def save_connect(self, path=None) -> Path | None:
        if path is None:
            stem = Path(self.doc.project_path or "untitled").with_suffix("").name
            path, _ = QFileDialog.getSaveFileName(self, "Save connectivity", self.doc.attachments.default_filename(
                stem), "Connectivity (*.connect)")
            if not path:
                return None
        try:
            n = self.doc.attachments.save(path)
        except (OSError, ValueError) as exc:
            self.show_error("Save connectivity", str(exc))
            return None
        self.doc.message(f"Saved {n} attached points (thinness ≥ {self.doc.thinness:.2f}) to {path}.")
        return Path(path)

    def _open_dialog(self, kind: str) -> None:
        filters = {"mskel": "Skeletons (*.mskel)", "bones": "Bones (*.bones)", "project": "Projects (*.volanim)",
                   "connect": "Connectivity (*.connect)", "trans": "Poses (*.trans)",
                   "connections": "Connections (*.connections)"}
        path, _ = QFileDialog.getOpenFileName(self, f"Open {kind}", "", f"{filters[kind]};;All files (*)")
        if path:
            {"mskel": self.open_mskel, "bones": self.open_bones, "project": self.open_project,
             "connect": self.open_connect, "trans": self.load_trans, "connections": self.open_connections}[kind](path)

    # -------------------------------------------------------------- saving
    def camera(self) -> dict:
        cam = self.plotter.renderer.GetActiveCamera()
        return {"position": list(cam.GetPosition()), "focal_point": list(cam.GetFocalPoint()),
                "view_up": list(cam.GetViewUp())}

    def set_camera(self, data: dict) -> None:
        cam = self.plotter.renderer.GetActiveCamera()
        cam.SetPosition(*data["position"])
        cam.SetFocalPoint(*data["focal_point"])
        cam.SetViewUp(*data["view_up"])
        self.plotter.renderer.ResetCameraClippingRange()
        self.scene.render()

    def save_project(self, ask: bool = False, path=None) -> Path | None:
        if path is None:
            path = self.doc.project_path
            if ask or not path:
                path, _ = QFileDialog.getSaveFileName(self, "Save project", "session.volanim",
                                                      "Projects (*.volanim)")
                if not path:
                    return None
        try:
            saved = self.doc.save_project(path, camera=self.camera())
        except (OSError, ValueError) as exc:
            self.show_error("Save project", str(exc))
            return None
        self.doc.message(f"Saved {saved}.")
        return saved

    def save_bones(self, path) -> bool:
        try:
            self.doc.save_bones(path)
        except (OSError, ValueError) as exc:
            self.show_error("Save bones", str(exc))
            return False
        self.doc.message(f"Saved {len(self.doc.bones)} bones to {path}.")
        return True

    def _save_dialog(self, kind: str) -> None:
        if kind == "connect":
            self.save_connect()
            return
        if kind in ("trans", "tskel", "volume"):
            filters = {"trans": "Poses (*.trans)", "tskel": "Frames (*.tskel)",
                       "volume": "Volumes (*.vti *.nrrd *.VOL *.vol)"}
            default = {"trans": "pose.trans", "tskel": "pose.tskel", "volume": "preview.vti"}[kind]
            path, _ = QFileDialog.getSaveFileName(self, f"Save {kind}", default, filters[kind])
            if not path:
                return
            if kind == "volume":
                self.export_preview(path)
                return
            try:
                if kind == "trans":
                    self.doc.pose.save_trans(path)
                else:
                    self.doc.pose.save_tskel(path)
            except (OSError, ValueError) as exc:
                self.show_error(f"Save {kind}", str(exc))
                return
            self.doc.message(f"Saved {path}.")
            return
        filters = {"bones": "Bones (*.bones)", "connections": "Connections (*.connections)", "png": "PNG (*.png)"}
        path, _ = QFileDialog.getSaveFileName(self, f"Save {kind}", f"untitled.{kind}", filters[kind])
        if not path:
            return
        if kind == "bones":
            self.save_bones(path)
        elif kind == "connections":
            self.doc.save_connections(path)
        else:
            self.plotter.screenshot(path)

