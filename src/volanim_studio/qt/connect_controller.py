"""The Connect menu's whole-skeleton actions: auto-connect and mirror (the modes do cube and lasso).

    Ctrl+A / the Connect tab's button --> Attachments.auto --> colour by bone; a report, and when
        *path* left most points unattached an offer to use *path-or-nearest*
    Mirror --> Attachments.mirror --> how many points found no partner

Owned by the main window.
"""

from __future__ import annotations

from .controller import Controller


class ConnectController(Controller):
    def fill_menu(self, menu, action) -> None:
        action("Auto-connect", self.auto_connect, "Ctrl+A", menu=menu)
        action("Mirror connectivity of selected bones", self.mirror_connectivity, menu=menu)

    def auto_connect(self) -> None:
        """Measure in a worker with progress and Cancel (the pieces method takes seconds on a big scan),
        then assign on the GUI thread as one undo step."""
        st = self.doc.settings
        if self.jobs.busy:
            self.show_error("Auto-connect", "another job is running; try again when it has finished")
            return
        try:
            task, apply = self.doc.attachments.auto_job(scope=st.auto_scope, overwrite=st.auto_overwrite,
                                                        selection=self.doc.point_selection, method=st.auto_method)
        except ValueError as exc:
            self.show_error("Auto-connect", str(exc))
            return
        self.jobs.run("Auto-connect", task, lambda result: self._connected(apply(result)))

    def _connected(self, report) -> None:
        st = self.doc.settings
        st.colour_by = "bone"  # what was connected to what is the thing to look at now
        self.doc.message(f"Auto-connect: {report}.")
        if not report.unattached:
            return
        text = f"Auto-connect {report}. Connect the rest with the cube or lasso."
        if st.auto_method != "path" or report.unattached <= report.attached:
            self.show_error("Auto-connect", text)
            return
        # most points found no straight path inside the volume to a bone (a crude rig, a curled
        # body): the fallback method attaches those to the nearest bone instead
        text += ("\n\nMost points found no path. The method path-or-nearest connects those to the nearest bone: "
                 "use it now?")
        def fall_back():
            st.auto_method = "path-or-nearest"
            self.auto_connect()

        self.ask("Auto-connect", text, "Use path-or-nearest", fall_back)

    def mirror_connectivity(self) -> None:
        try:
            copied, lonely = self.doc.attachments.mirror()
        except ValueError as exc:
            self.show_error("Mirror connectivity", str(exc))
            return
        text = f"Mirrored {copied} attachments"
        if lonely:
            text += f"; {lonely} points found no partner on the other side (connect them by hand)"
        self.doc.message(text + ".")
