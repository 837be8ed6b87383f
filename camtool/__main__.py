"""``python -m camtool`` and the ``camtool`` console script."""

from __future__ import annotations

import sys


def run() -> None:
    """Entry point: run the CLI and exit with its code."""
    from camtool.cli.main import main

    sys.exit(main())


if __name__ == "__main__":
    run()
