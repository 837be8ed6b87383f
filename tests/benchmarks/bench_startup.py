"""Benchmark of camtool's start-up: ``camtool --help`` and ``camtool targets`` (not collected).

Run as ``python tests/benchmarks/bench_startup.py``. Each command is run as a user runs
it (``python -m camtool ...`` in a fresh subprocess) :data:`RUNS` times and the best wall
time is kept, next to the best of a bare ``python -c pass`` (the interpreter's own start,
a floor no Python program beats). Goals (issue 17): ``--help`` under 0.3 s, ``targets``
under 0.5 s.
"""

from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from table import camtool_env, row  # noqa: E402

RUNS = 7


def best(argv: list[str]) -> float:
    """Best wall seconds of ``RUNS`` runs of ``argv`` (each must exit 0)."""
    env = camtool_env()
    times = []
    for _ in range(RUNS):
        start = time.perf_counter()
        subprocess.run(argv, env=env, check=True, capture_output=True)
        times.append(time.perf_counter() - start)
    return min(times)


def main() -> int:
    """Time the two commands and the bare interpreter; print two table rows."""
    floor = best([sys.executable, "-c", "pass"])
    for args, goal in ((["--help"], 0.3), (["targets"], 0.5)):
        seconds = best([sys.executable, "-m", "camtool", *args])
        print(f"camtool {' '.join(args)}: {seconds:.3f} s (python -c pass {floor:.3f} s)")
        row(
            f"`camtool {' '.join(args)}`",
            f"{seconds:.2f} s",
            "—",
            "—",
            None,
            "absolute",
            f"< {goal} s",
            seconds < goal,
            f"best of {RUNS}; bare `python -c pass` {floor:.2f} s",
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
