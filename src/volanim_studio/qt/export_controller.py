"""*File → Export animated glTF…*: the body as the studio poses it (the rig's ownership with the animator's
repaints) skinned to the bones, the timeline's clip or keys as its animation, one ``.glb`` any viewer opens
(``volanim export-gltf``'s file; docs/formats.md#gltf-out). Made in the window's worker, with progress and
Cancel; the file appears whole or not at all."""

from __future__ import annotations

from pathlib import Path

from PySide6.QtWidgets import QFileDialog

from .controller import Controller


class ExportController(Controller):
    def fill_menu(self, menu, action) -> None:
        action("Export animated &glTF…", lambda: self.export_gltf_dialog(), menu=menu)

    def export_gltf(self, path):
        """Write ``path`` in the background: the job's worker, or None when refused (said) or a job runs."""
        from volanim_core.render.skinned_body import export_gltf

        tl, doc = self.doc.timeline, self.doc
        if self.jobs.busy:
            doc.message("A job is running; export when it ends.")
            return None
        try:
            if not tl.active:
                raise ValueError("nothing to export: load a clip or set keys first (Timeline menu)")
            conn = doc.pose.tskel().connectivity
            if not len(conn):
                raise ValueError("no attached points: connect points to bones first (Connect tab)")
        except ValueError as exc:
            self.show_error("Export animated glTF", str(exc))
            return None
        mats, fps = tl.matrices(), tl.frame_rate
        name = (tl.clip.animation or tl.clip.name) if tl.clip is not None else "keys"

        def work(progress, cancel):
            own = doc.ownership.of(conn)  # the repaints too: what the preview moves is what the file skins
            rig = conn if own is None else conn.with_ownership(own)
            return export_gltf(rig, mats, fps, path, name, progress=progress, cancel=cancel)

        return self.jobs.run(f"Exporting {len(mats)} frames as glTF", work, lambda held: doc.message(
            f"Exported {Path(path).name}: {held['triangles']:,} triangles skinned to {held['joints']} bones, "
            f"{held['frames']} frames at {fps:g} fps."))

    def export_gltf_dialog(self) -> None:
        tl = self.doc.timeline
        stem = tl.clip.name if tl.clip is not None else "keys"
        path, _ = QFileDialog.getSaveFileName(self.window, "Export animated glTF", self.folder(f"{stem}.glb"),
                                              "glTF binary (*.glb)")
        if path:
            self.export_gltf(path if path.lower().endswith(".glb") else path + ".glb")
