"""``volanim-studio``: the desktop application."""

from __future__ import annotations

import argparse
import sys

EPILOG = """examples:
  volanim-studio --demo mannequin                    the demo mannequin, ready for bone building
  volanim-studio --volume frog.VOL                   segment, skeletonize and view a volume
  volanim-studio --mskel man.mskel --bones man.bones continue from files
  volanim-studio session.volanim                     reopen a saved project

Press F1 in the window for the keyboard shortcuts."""


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="volanim-studio", description="Build bone skeletons for volumes, connect, "
                                "pose and preview reconstructions.", epilog=EPILOG,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("project", nargs="?", help="a .volanim project to open")
    p.add_argument("--demo", choices=("mannequin", "frog", "aliascube"), help="open a demo dataset")
    p.add_argument("--volume", help="a volume to segment and skeletonize")
    p.add_argument("--mskel", help="a multi-resolution skeleton")
    p.add_argument("--bones", help="a .bones file")
    p.add_argument("--connect", help="a .connect file to continue connecting")
    return p


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    from PySide6.QtWidgets import QApplication

    from .qt.main_window import main_window_for

    app = QApplication.instance() or QApplication(sys.argv[:1])
    app.setApplicationName("volanim studio")
    window = main_window_for(args)
    window.show()
    return app.exec()


if __name__ == "__main__":
    raise SystemExit(main())
