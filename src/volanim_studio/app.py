"""``volanim-studio``: the desktop application."""

from __future__ import annotations

import argparse
import os
import sys

EPILOG = """examples:
  volanim-studio --demo mannequin                    the demo mannequin, ready for bone building
  volanim-studio --volume frog.VOL                   segment, skeletonize and view a volume
  volanim-studio --demo mannequin-colour             a colour body: posed previews in its colours
  volanim-studio --mskel man.mskel --bones man.bones continue from files
  volanim-studio session.volanim                     reopen a saved project

Press F1 in the window for the keyboard shortcuts."""


def build_parser() -> argparse.ArgumentParser:
    from volanim_core import samples  # light: numpy only

    p = argparse.ArgumentParser(prog="volanim-studio", description="Build bone skeletons for volumes, connect, "
                                "pose and preview reconstructions.", epilog=EPILOG,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("project", nargs="?", help="a .volanim project to open")
    p.add_argument("--demo", choices=samples.NAMES, help="open a demo dataset")
    p.add_argument("--volume", help="a volume to segment and skeletonize")
    p.add_argument("--mskel", help="a multi-resolution skeleton")
    p.add_argument("--bones", help="a .bones file")
    p.add_argument("--connect", help="a .connect file to continue connecting")
    return p


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    import pyvista
    from PySide6.QtWidgets import QApplication

    from .qt.main_window import main_window_for

    # The studio is a window: pyvista's PYVISTA_OFF_SCREEN (set for scripts and `volanim view` in CI)
    # would leave its Qt interactor without an interactor and fail at start.
    pyvista.OFF_SCREEN = False
    app = QApplication.instance() or QApplication(sys.argv[:1])
    app.setApplicationName("volanim studio")
    if os.environ.get("VOLANIM_STUDIO_SMOKE"):
        _quit_when_loaded(app)  # before the window: its threshold dialog may already be waiting
    window = main_window_for(args)
    window.show()
    return app.exec()


def _quit_when_loaded(app, seconds: float = 600.0) -> None:
    """``VOLANIM_STUDIO_SMOKE=1``: a start-up check for scripts and CI (tests/test_documented_commands.py runs the
    README's studio commands this way). Dialogs are answered with their defaults (OK; No to questions),
    and once everything asked for on the command line has loaded the studio quits: status 0, or 1
    if it showed an error."""
    import time

    from PySide6.QtCore import QTimer
    from PySide6.QtWidgets import QDialog, QMessageBox

    from .qt.main_window import MainWindow

    deadline = time.monotonic() + seconds
    state = {"idle": 0, "errors": []}

    def tick():
        modal = app.activeModalWidget()
        if isinstance(modal, QMessageBox):
            if modal.icon() in (QMessageBox.Critical, QMessageBox.Warning):
                state["errors"].append(modal.text())
            modal.reject() if modal.icon() == QMessageBox.Question else modal.accept()
            return
        if isinstance(modal, QDialog):
            modal.accept()
            return
        windows = [w for w in app.topLevelWidgets() if isinstance(w, MainWindow)]
        idle = windows and not windows[0].busy and modal is None
        state["idle"] = state["idle"] + 1 if idle else 0
        if state["idle"] >= 3 or time.monotonic() > deadline:
            window = windows[0] if windows else None
            errors = state["errors"] + ([window.last_error] if window is not None and window.last_error else [])
            errors = list(dict.fromkeys(errors))  # the dialog's text is also the window's last error
            status = window.statusBar().currentMessage() if window is not None else ""
            print(f"volanim-studio smoke check: {'FAILED: ' + '; '.join(errors) if errors else 'loaded'}"
                  + (f" ({status})" if status else ""), flush=True)
            if window is not None:
                window.session.close()  # a start-up check is no session to offer for recovery
            app.exit(1 if errors or time.monotonic() > deadline else 0)

    timer = QTimer(app)
    timer.timeout.connect(tick)
    timer.start(200)


if __name__ == "__main__":
    raise SystemExit(main())
