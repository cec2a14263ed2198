"""Entry point of ``volanim-studio``."""

from __future__ import annotations

import sys


def main(argv: list[str] | None = None) -> int:
    print("volanim-studio: the studio window is not built yet; use the 'volanim' command line.",
          file=sys.stderr)
    return 1


if __name__ == "__main__":
    raise SystemExit(main())
