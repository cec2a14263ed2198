"""Opening and saving for the main window: volumes (threshold dialog + background job),
skeletons, bones, connectivity and projects.

    File menu / buttons --> FilesController --> volanim_core readers / Document
                                   |--> JobRunner (segmenting, skeletonizing) --> Document on the GUI thread
                                   |--> readers, a JobRunner of its own (View, View slices) --> a looking window
    errors --> the window's error dialog naming the file and line; the document stays as it was

Owned by :class:`~volanim_studio.qt.main_window.MainWindow` (composed, not
inherited): it knows the document, the scene (for the camera), the job runner
and the window as the parent of its dialogs.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from PySide6.QtWidgets import QFileDialog

from volanim_core import io

from .. import tasks
from ..model import autosave
from ..model.project import apply_project_files, apply_project_state, read_project, read_project_files, write_save
from .controller import FAILED, Controller
from .look_dialog import LookDialog
from .threshold_dialog import ThresholdDialog
from .worker import Worker

#: What File > Open volume lists: every format ``io.read_scan`` reads as a file.
VOLUME_PATTERNS = " ".join(f"*{s}" for s in (".vol", ".VOL", ".vti", ".nrrd", ".nhdr", ".seg.nrrd", ".nii", ".nii.gz",
                                             ".mha", ".mhd", ".mgh", ".mgz", ".tif", ".tiff", ".dcm"))


class FilesController(Controller):
    def fill_menu(self, menu, action) -> None:
        """The File menu's open and save entries; ``action(text, slot, shortcut=None, menu=None)``."""
        action("Open &volume…", lambda: self.open_volume_dialog(), "Ctrl+O", menu=menu)
        action("Open &DICOM folder…", lambda: self.open_dicom_folder_dialog(), menu=menu)
        action("Open &skeleton (.mskel)…", lambda: self.open_dialog("mskel"), menu=menu)
        action("Open &bones…", lambda: self.open_dialog("bones"), menu=menu)
        action("Open connections…", lambda: self.open_dialog("connections"), menu=menu)
        action("Open &project…", lambda: self.open_dialog("project"), menu=menu)
        action("View volume or &mesh…", lambda: self.view_file_dialog(), menu=menu)
        action("View s&lices…", lambda: self.view_slices_dialog(), menu=menu)
        menu.addSeparator()
        action("&Save project", lambda: self.save_project(), "Ctrl+S", menu=menu)
        action("Save project &as…", lambda: self.save_project(ask=True), "Ctrl+Shift+S", menu=menu)
        action("Save bones…", lambda: self.save_dialog("bones"), menu=menu)
        action("Save connections…", lambda: self.save_dialog("connections"), menu=menu)
        action("Screenshot…", lambda: self.save_dialog("png"), menu=menu)

    # ------------------------------------------------------------ looking
    def view_file(self, path) -> Worker | None:
        """Read a volume, a sequence's first frame or a mesh in the background and show it in a window of
        its own (``viewers[-1]``), coloured by the user's transfer function when there is one; the document
        is untouched. See :meth:`_read_then_view`."""
        from volanim_core.render.quicklook import read_look

        from .quicklook_window import SIZE, QuickLookWindow

        tf = self.doc.transfer.function  # the editor's, as the preview draws with it
        return self._read_then_view(path, "View", lambda: read_look(path, size=SIZE, transfer=tf),
                                    lambda look: QuickLookWindow(path, look, self.window, self.doc),
                                    f"Viewing {Path(path).name}")

    def view_file_dialog(self) -> LookDialog:
        """Ask for a volume, a mesh or a sequence (its ``NAME.zarr`` folder, or the ``zarr.json`` in it), then
        :meth:`view_file` it. Not modal: the dialog (``look_dialog``) is returned and kept while it is open."""
        dialog = LookDialog(self.window, "View volume, mesh or sequence", self.folder(),
                            f"Volumes, meshes and sequences ({VOLUME_PATTERNS} *.ply *.vtp *.obj *.stl *.glb *.gltf "
                            "*.zarr "
                            "zarr.json);;All files (*)")
        dialog.finished.connect(lambda _: dialog.chosen and self.view_file(dialog.chosen))
        self.look_dialog = dialog
        dialog.open()
        return dialog

    def view_slices(self, path) -> Worker | None:
        """Read any volume in the background and show it one slice at a time in a window of its own
        (``viewers[-1]``); the document is untouched. See :meth:`_read_then_view`."""
        from .slice_window import SliceWindow, read_for_slices

        return self._read_then_view(path, "View slices", lambda: read_for_slices(path),
                                    lambda source: SliceWindow(path, source, self.window),
                                    f"Viewing slices of {Path(path).name}")

    def _read_then_view(self, path, title: str, read, make, doing: str) -> Worker | None:
        """``read()`` in the reader thread (:meth:`read_then`), then the looking window ``make(what was read)``
        shown on the GUI thread (a bad file shown under ``title``)."""
        return self.read_then(path, lambda progress: read(),
                              lambda result: self._viewer(title, lambda: make(result), doing))

    def _viewer(self, title: str, make, doing: str):
        """A looking window made by ``make()`` and shown, kept while visible; None (the error shown) on failure."""
        window = self.attempt(title, make, lambda w: f"{doing}: {w.what}.")
        if window is FAILED:
            return None
        self.viewers = self.open_viewers() + [window]
        window.show()
        return window

    def open_viewers(self) -> list:
        """The looking windows still shown (View and View slices), oldest first."""
        return [v for v in getattr(self, "viewers", []) if v.isVisible()]

    def view_slices_dialog(self) -> None:
        path, _ = QFileDialog.getOpenFileName(self.window, "View slices", self.folder(),
                                              f"Volumes ({VOLUME_PATTERNS});;All files (*)")
        if path:
            self.view_slices(path)

    # -------------------------------------------------------------- loading
    def _apply_prepared(self, result: dict, path=None, spacing=None, dims=None) -> None:
        self.doc.reset()  # a new volume is a new document: nothing of the old project stays
        self.doc.set_volume(result["volume"], result["mask"], spacing=spacing or result.get("spacing", (1, 1, 1)),
                            path=path, segmentation=result["segmentation"], dims=dims)
        self.doc.set_skeleton(result["skeleton"], result.get("skeleton_path"))
        self.doc.set_hull(*result["hull"], lod=result.get("hull_lod"))
        regrown, body = result.get("pieces") or (None, None)
        self.doc.body_pieces = body
        if regrown is not None and regrown > body:
            thinness = result["segmentation"].get("min_thinness")
            self.doc.message(f"Thin parts are lost: the skeleton's {len(result['skeleton'])} points re-grow the body "
                             f"in {regrown:,} pieces where the volume is {body:,} (minimum thinness {thinness:g}). "
                             "Open it again with a lower minimum thinness to keep them.")
            return
        self.doc.message(f"{len(result['skeleton'])} skeleton points; thinness slider shows the prefix ≥ t.")

    def load_demo(self, name: str, *, skeleton_path=None, then: Callable[[Any], None] | None = None,
                  also: Callable[[Any], Any] | None = None) -> Worker:
        """Prepare a demo dataset in a worker; ``then(also(grid))`` runs right after it is applied (see
        :meth:`open_project`: ``also`` reads more in the same worker, given the prepared skeleton's grid)."""
        def task(progress, cancel):
            r = tasks.load_demo(name, skeleton_path=skeleton_path, progress=progress, cancel=cancel)
            r["also"] = also(r["skeleton"].geometry) if also is not None else None
            return r

        def done(r):
            self._apply_prepared(r, spacing=r["spacing"])
            self.doc.demo_name = name
            if then is not None:  # the next pass: the window draws the volume in between
                self.jobs.later(lambda: then(r["also"]))

        return self.jobs.run(f"Preparing the {name} demo", task, done)

    def open_volume(self, path, *, dims=None, params: dict | None = None, skeleton_path=None,
                    then: Callable[[Any], None] | None = None, otherwise: Callable[[], None] | None = None,
                    series: str | None = None, also: Callable[[Any], Any] | None = None) -> Worker | None:
        """Read a volume and segment it, both in workers (#61: a large scan's read froze the window): a
        DICOM folder of several series asks which; without ``params`` the threshold dialog asks between
        the read and the segmentation. ``then(also(grid))`` runs right after the result is applied (``also``:
        more to read in the same worker, given the prepared skeleton's grid; None without it); ``otherwise()``
        when the read or the segmentation failed or was cancelled, or the user declined a dialog (the
        error is shown). Returns the first job's worker (None while another job runs: said)."""
        otherwise = otherwise or (lambda: None)
        series = series or (params or {}).get("series")
        name = Path(path).name
        if self.jobs.busy:
            self.doc.message(f"A job is running; open {name} when it ends.")
            otherwise()
            return None

        def task(progress, cancel):
            if series is None:
                choices = tasks.series_choices(path)  # [] unless a DICOM folder of several series
                if len(choices) > 1:
                    return {"choices": choices}
            loaded = tasks.load_volume_file(str(path), dims, series)
            if params is None:
                return {"loaded": loaded}
            return {"loaded": loaded, "prepared": self._prepare(loaded, params, skeleton_path, progress, cancel,
                                                                also)}

        def read(r):
            if "choices" in r:
                chosen = self._ask_series(name, r["choices"])
                if chosen is None:
                    otherwise()
                else:
                    self.open_volume(path, dims=dims, params=params, skeleton_path=skeleton_path, then=then,
                                     otherwise=otherwise, series=chosen, also=also)
            elif "prepared" in r:
                self._apply_volume(r["prepared"], path, dims, self._spacing(r["loaded"], params), series, then)
            else:
                self._ask_threshold(path, r["loaded"], dims, skeleton_path, series, then, otherwise, also)

        return _or_else(self.jobs.run(f"Opening {name}" if params else f"Reading {name}", task, read), otherwise)

    def _ask_threshold(self, path, loaded, dims, skeleton_path, series, then, otherwise, also=None) -> None:
        """The threshold dialog over a volume just read, then its segmentation in a worker."""
        dialog = ThresholdDialog(loaded["grey"], Path(path).name, self.window, spacing=loaded["spacing"],
                                 segments=loaded["segments"], histogram=loaded.get("histogram"))
        if dialog.exec() != ThresholdDialog.Accepted:
            otherwise()
            return
        params = dialog.parameters()
        _or_else(self.jobs.run(f"Skeletonizing {Path(path).name}", lambda progress, cancel: self._prepare(
            loaded, params, skeleton_path, progress, cancel, also),
            lambda r: self._apply_volume(r, path, dims, self._spacing(loaded, params), series, then)), otherwise)

    @staticmethod
    def _spacing(loaded: dict, params: dict) -> tuple:
        """The voxel size the user confirmed (the dialog's, a project's), else the file's."""
        return tuple(float(v) for v in params.get("spacing") or loaded["spacing"])

    def _prepare(self, loaded: dict, params: dict, skeleton_path, progress, cancel, also=None) -> dict:
        """A volume just read, segmented by ``params`` (the dialog's, or a project's) and skeletonized
        (in a worker): :func:`tasks.prepare_volume` on the voxel size the user confirmed; then ``also``."""
        r = tasks.prepare_volume(loaded["volume"], tasks.Segmentation.of(params), skeleton_path=skeleton_path,
                                 grey=loaded["grey"],
                                 geometry=loaded["geometry"].with_spacing(self._spacing(loaded, params)),
                                 progress=progress, cancel=cancel)
        r["also"] = also(r["skeleton"].geometry) if also is not None else None
        return r

    def _apply_volume(self, r: dict, path, dims, spacing, series, then) -> None:
        r["segmentation"]["spacing"] = list(spacing)  # saved with the project: a raw .vol has none
        r["segmentation"]["series"] = series  # and which series of a DICOM folder
        self._apply_prepared(r, path=path, spacing=r["geometry"].spacing, dims=dims)
        if then is not None:  # the next pass: the window draws the volume in between
            self.jobs.later(lambda: then(r["also"]))

    def open_volume_dialog(self) -> None:
        self.window.session.when_saved_or_discarded(self._ask_volume, "opening another volume")

    def _ask_volume(self) -> None:
        path, _ = QFileDialog.getOpenFileName(self.window, "Open volume", self.folder(),
                                              f"Volumes, grey or RGB ({VOLUME_PATTERNS});;"
                                              "Closed meshes, filled (*.ply *.obj *.stl *.vtp *.glb *.gltf);;"
                                              "DICOM files (*.dcm *);;"
                                              "All files (*)")
        if path:
            self.open_volume(self._dicom_series_folder(path))

    def open_dicom_folder_dialog(self) -> None:
        self.window.session.when_saved_or_discarded(self._ask_dicom_folder, "opening another volume")

    def _ask_dicom_folder(self) -> None:
        folder = QFileDialog.getExistingDirectory(self.window, "Open a DICOM series (its folder)", self.folder())
        if folder:
            self.open_volume(folder)

    def _ask_series(self, name: str, choices) -> str | None:
        """The UID of the series the user picks from ``choices`` ``[(uid, text)]``; None when they cancel."""
        from PySide6.QtWidgets import QInputDialog

        line, ok = QInputDialog.getItem(self.window, "Which series?", f"{name} holds {len(choices)} "
                                        "DICOM series:", [text for _, text in choices], 0, False)
        return next(uid for uid, text in choices if text == line) if ok else None

    @staticmethod
    def _dicom_series_folder(path: str) -> str:
        """One file of a DICOM series stands for its series: the folder is read (ordered by position)."""
        from volanim_core.io.dicom_files import is_dicom_file

        p = Path(path)
        return str(p.parent) if p.is_file() and is_dicom_file(p) and len(list(p.parent.iterdir())) > 1 else path

    def open_mskel(self, path) -> bool:
        def load():
            skel = io.read_skeleton(path).one_level()  # a .skel: one level of the slider
            self.doc.loading(lambda: self.doc.set_skeleton(skel, path))
            return skel

        return self.attempt("Open skeleton", load,
                            lambda skel: f"Loaded {len(skel)} points from {Path(path).name}.") is not FAILED

    def open_bones(self, path) -> bool:
        return self.attempt("Open bones", lambda: self.doc.bone_edits.load_bones(path),
                            lambda _: f"Loaded {len(self.doc.bones)} bones from {Path(path).name}.") is not FAILED

    def open_connections(self, path) -> bool:
        return self.attempt("Open connections", lambda: self.doc.bone_edits.load_connections(path),
                            lambda _: f"{len(self.doc.bones)} bones in the root order of {Path(path).name}."
                            ) is not FAILED

    def open_project(self, path, on_opened: Callable[[bool], None] | None = None) -> Worker | None:
        """Open a ``.volanim``: its volume segmented as saved (its ``.mskel`` read, not recomputed), then its files.

        Everything is read in workers (the project and its hashes, then the volume, its skeleton, bones,
        attachments and clip, #83: a ``.trans`` clip read on the GUI thread froze the window 1.4 s); what
        is left for the GUI thread is putting them in the document. ``on_opened(ok)`` is called once it
        is all applied (True) or has failed or been cancelled (False; the error was shown).
        """
        done = on_opened or (lambda ok: None)
        name = Path(path).name
        if self.jobs.busy:
            self.doc.message(f"A job is running; open {name} when it ends.")
            done(False)
            return None

        def read(progress, cancel):
            data = read_project(path)
            if data.get("volume") or data.get("demo"):
                return data, None  # its files are read after the volume, on its skeleton's grid
            return data, read_project_files(data, path, skeleton=True)

        def rest(data, files, reset=False):
            # in two passes of the event loop, the runner busy between them (see apply_project)
            first = self.attempt("Open project", lambda: apply_project_files(self.doc, data, path, reset=reset,
                                                                             files=files))
            if first is FAILED:
                done(False)
                return
            self.jobs.later(lambda: state(*first))

        def state(warnings, saved_state):
            more = self.attempt("Open project", lambda: apply_project_state(self.doc, saved_state, path))
            if more is FAILED:
                done(False)
                return
            if warnings + more:
                self.show_error("Open project", "\n".join(warnings + more))
            self.doc.undo.mark_clean()  # as saved: loading its bones is not an edit to save
            self.doc.message(f"Opened {name}.")
            done(True)
            self.window.previews.show_body()  # opened in Pose mode: its body, not its bones alone

        # the rest is applied by the job's own completion handler, not by a second connection to
        # `succeeded`: that would run as a separate event after the job reads as done ("not busy"),
        # and anything acting in between (a key press, a test) would see a half-opened project
        def opened(r):
            data, files = r
            def also(grid):
                return read_project_files(data, path, skeleton=False, grid=grid)
            if data.get("volume"):
                self.open_volume(data["volume"], dims=data.get("volume_dims"), params=data["segmentation"],
                                 skeleton_path=data.get("mskel"), then=lambda f: rest(data, f), also=also,
                                 otherwise=lambda: done(False))
            elif data.get("demo"):
                _or_else(self.load_demo(data["demo"], skeleton_path=data.get("mskel"),
                                        then=lambda f: rest(data, f), also=also), lambda: done(False))
            else:
                rest(data, files, reset=True)  # a project of bones alone: still a new document

        worker = self.jobs.run(f"Opening {name}", read, opened)
        worker.failed.connect(lambda _: done(False))
        worker.was_cancelled.connect(lambda: done(False))
        return worker

    def open_connect(self, path) -> bool:
        warnings = self.attempt("Open connectivity", lambda: self.doc.attachments.load(path),
                                lambda _: f"Loaded {int(self.doc.attachments.counts()[0].sum())} attachments "
                                          f"from {Path(path).name}.")
        if warnings is FAILED:
            return False
        if warnings:
            self.show_error("Open connectivity", "\n".join(warnings))
        return True

    def save_connect(self, path=None) -> Path | None:
        if path is None:
            stem = Path(self.doc.project_path or "untitled").with_suffix("").name
            default = self.doc.attachments.default_filename(stem)
            path, _ = QFileDialog.getSaveFileName(self.window, "Save connectivity", self.folder(default),
                                                  "Connectivity (*.connect)")
            if not path:
                return None
        n = self.attempt("Save connectivity", lambda: self.doc.attachments.save(path),
                         lambda n: f"Saved {n} attached points (thinness ≥ {self.doc.thinness:.2f}) to {path}.")
        return None if n is FAILED else Path(path)

    def open_dialog(self, kind: str) -> None:
        if kind == "project":
            self.window.session.when_saved_or_discarded(lambda: self._ask_open(kind), "opening another project")
        else:
            self._ask_open(kind)

    def _ask_open(self, kind: str) -> None:
        filters = {"mskel": "Skeletons (*.mskel *.skel)", "bones": "Bones (*.bones)", "project": "Projects (*.volanim)",
                   "connect": "Connectivity (*.connect)", "connections": "Connections (*.connections)"}
        path, _ = QFileDialog.getOpenFileName(self.window, f"Open {kind}", self.folder(),
                                              f"{filters[kind]};;All files (*)")
        if path:
            {"mskel": self.open_mskel, "bones": self.open_bones, "project": self.open_project,
             "connect": self.open_connect, "connections": self.open_connections}[kind](path)

    # -------------------------------------------------------------- saving
    def save_project(self, ask: bool = False, path=None, then=None) -> Path | None:
        """Save the project (asking where when ``ask``, or when it has no name yet): taken from the document
        now, written on the savers' thread, adopted when written, then ``then()``. Returns the path being
        written, or None when nothing was started (the user cancelled the file dialog, nothing to save,
        a save already under way: said in the status bar)."""
        try:
            self.doc.check_savable()
        except ValueError as exc:  # said before asking for a name, not after it (#61)
            self.doc.message(str(exc))
            return None
        if path is None:
            path = self.doc.project_path
            cached = bool(path) and autosave.in_recovery_area(path)  # pruned after a week: never saved there
            if ask or not path or cached:
                where = str(Path.home() / "session.volanim") if cached else self.folder("session.volanim")
                title = "Save project (it was opened from the autosave area)" if cached else "Save project"
                path, _ = QFileDialog.getSaveFileName(self.window, title, where, "Projects (*.volanim)")
                if not path:
                    return None
        savers = self.window.savers
        if savers.busy:
            self.doc.message("Still saving the project: save again when it has been written.")
            return None
        save = self.attempt("Save project", lambda: self.doc.take_save(path))
        if save is FAILED:
            return None

        def written(paths: dict) -> None:
            if self.doc.adopt_save(save, paths):
                self.doc.message(f"Saved {save.path}.")
                if then is not None:
                    then()
            else:  # another project was opened while this one was written
                self.doc.message(f"Saved {save.path} (no longer the open project).")
        # a dialog only after 300 ms, no Cancel (a save stops at no half-way point)
        savers.run(f"Saving {save.path.name}", lambda progress, cancel: write_save(save), written,
                   cancellable=False)
        return save.path

    def save_bones(self, path) -> bool:
        return self.attempt("Save bones", lambda: self.doc.bone_edits.save_bones(path),
                            f"Saved {len(self.doc.bones)} bones to {path}.") is not FAILED

    def save_dialog(self, kind: str) -> None:
        """Ask where, then save: ``connect``, ``bones``, ``connections`` or a ``png`` screenshot."""
        if kind == "connect":
            self.save_connect()
            return
        filters = {"bones": "Bones (*.bones)", "connections": "Connections (*.connections)", "png": "PNG (*.png)"}
        path, _ = QFileDialog.getSaveFileName(self.window, f"Save {kind}", self.folder(f"untitled.{kind}"),
                                              filters[kind])
        if not path:
            return
        if kind == "bones":
            self.save_bones(path)
        elif kind == "connections":
            self.doc.bone_edits.save_connections(path)
        else:
            self.scene.plotter.screenshot(path)


def _or_else(worker: Worker, otherwise: Callable[[], None]) -> Worker:
    """``worker`` with ``otherwise()`` called when it fails (the error is shown) or is cancelled."""
    worker.failed.connect(lambda *_: otherwise())
    worker.was_cancelled.connect(otherwise)
    return worker
