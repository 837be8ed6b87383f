"""Benchmark of ``camtool post`` on very large LINE drawings (not collected by pytest).

Run as ``python tests/benchmarks/bench_large.py [N ...] [--kinds a,b] [--order travel]``
(default N: 10 000 and 100 000; 1 000 000 on request). For each N and kind a DXF of
N LINE entities is written once into ``$TMPDIR/camtool-bench-large/`` and posted for
grbl to ``/dev/null`` as a user runs it (a subprocess of ``python -m camtool``); the
wall time of the whole command and the planner's share (``plan_drawing`` alone, in
process, on the imported drawing) are printed.

Kinds (each N LINEs, shuffled, a third of them drawn backwards, so that chaining
has to find every joint):

- ``disjoint``: short lines 0.5 mm long on a 1 mm grid, each an open contour;
- ``squares``: closed 0.6 mm squares of 4 LINEs on a 1 mm grid;
- ``chains``: long polylines of 1000 LINEs each, a dense wave (arc fitting runs
  on them) next to a zigzag (nothing to fit).

Measurements: docs/performance.md (this script's rows, and its earlier notes).
"""

from __future__ import annotations

import argparse
import math
import os
import random
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

ROOT = Path(__file__).resolve().parents[2]
KINDS = ("disjoint", "squares", "chains")
CHAIN_LINES = 1000
"""LINEs per polyline of the ``chains`` kind."""

Seg = tuple[float, float, float, float]


SIZE_MM = 180.0
"""Every drawing fits a square of this side, 5 mm from the origin (grbl's 200 mm travel)."""


def disjoint(n: int) -> list[Seg]:
    """``n`` lines half a grid pitch long, one per grid cell, at varying angles."""
    side = math.ceil(math.sqrt(n))
    pitch = SIZE_MM / side
    out = []
    for k in range(n):
        x, y = 5 + pitch * (k % side), 5 + pitch * (k // side)
        a = (k * 0.618) % 1.0 * math.pi
        out.append((x, y, x + 0.5 * pitch * math.cos(a), y + 0.5 * pitch * math.sin(a)))
    return out


def squares(n: int) -> list[Seg]:
    """``n // 4`` closed squares of 4 lines, 0.6 grid pitch wide, one per grid cell."""
    count = n // 4
    side = math.ceil(math.sqrt(count))
    pitch = SIZE_MM / side
    out = []
    for k in range(count):
        x, y = 5 + pitch * (k % side), 5 + pitch * (k // side)
        a = 0.6 * pitch
        p = [(x, y), (x + a, y), (x + a, y + a), (x, y + a)]
        out += [(*p[i], *p[(i + 1) % 4]) for i in range(4)]
    return out


def chains(n: int) -> list[Seg]:
    """Polylines of :data:`CHAIN_LINES` lines 0.05 mm apart in X, in 3 columns.

    Even ones a wave (fittable arcs), odd ones a zigzag (nothing to fit).
    """
    count = max(1, n // CHAIN_LINES)
    rows = math.ceil(count / 3)
    pitch = SIZE_MM / rows
    out = []
    for c in range(count):
        x0, y0 = 5 + 60.0 * (c % 3), 5 + pitch * (c // 3)
        pts = []
        for k in range(CHAIN_LINES + 1):
            x = 0.05 * k
            bump = 0.5 + 0.5 * math.sin(x) if c % 2 == 0 else k % 2
            pts.append((x0 + x, y0 + 0.4 * min(pitch, 1.0) * bump))
        out += [(*pts[k], *pts[k + 1]) for k in range(CHAIN_LINES)]
    return out


def write_dxf(kind: str, n: int, path: Path) -> None:
    """Write ``n`` LINEs of ``kind``, shuffled, a third reversed, as a minimal DXF in mm.

    Written as text (ezdxf takes minutes for 10⁶ entities): a HEADER with
    ``$INSUNITS`` 4 (mm) and an ENTITIES section of LINEs on layer 0.
    """
    segs = {"disjoint": disjoint, "squares": squares, "chains": chains}[kind](n)
    rng = random.Random(n)
    rng.shuffle(segs)
    tmp = path.with_suffix(".tmp")
    with tmp.open("w", encoding="ascii") as f:
        f.write("0\nSECTION\n2\nHEADER\n9\n$ACADVER\n1\nAC1009\n9\n$INSUNITS\n70\n4\n")
        f.write("0\nENDSEC\n0\nSECTION\n2\nENTITIES\n")
        for k, (x0, y0, x1, y1) in enumerate(segs):
            if k % 3 == 0:
                x0, y0, x1, y1 = x1, y1, x0, y0
            f.write(
                f"0\nLINE\n8\n0\n10\n{x0:.6f}\n20\n{y0:.6f}\n30\n0.0\n"
                f"11\n{x1:.6f}\n21\n{y1:.6f}\n31\n0.0\n"
            )
        f.write("0\nENDSEC\n0\nEOF\n")
    tmp.replace(path)


def drawing_file(kind: str, n: int) -> Path:
    """The cached DXF of ``n`` LINEs of ``kind`` (written on first use)."""
    folder = Path(tempfile.gettempdir()) / "camtool-bench-large"
    folder.mkdir(exist_ok=True)
    path = folder / f"{kind}-{n}.dxf"
    if not path.exists():
        write_dxf(kind, n, path)
    return path


def time_post(path: Path, extra: list[str]) -> tuple[float, int, str]:
    """Wall time, exit code and last stderr line of ``camtool post path -t grbl -o /dev/null``."""
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    cmd = [sys.executable, "-m", "camtool", "post", str(path), "-t", "grbl", "-o", os.devnull]
    t0 = time.perf_counter()
    done = subprocess.run(cmd + extra, env=env, capture_output=True, text=True, check=False)
    lines = done.stderr.strip().splitlines()
    return time.perf_counter() - t0, done.returncode, lines[-1] if lines else ""


def time_plan(path: Path, order: str) -> tuple[float, float]:
    """Seconds to import ``path`` and to plan it (``plan_drawing``), in process."""
    from camtool.importers.dxf import read_dxf
    from camtool.toolpath.plan import PlanOptions, plan_drawing

    t0 = time.perf_counter()
    drawing = read_dxf(path)
    t1 = time.perf_counter()
    plan_drawing(drawing, PlanOptions(order=order, feed_mm_min=500.0))
    return t1 - t0, time.perf_counter() - t1


def main() -> None:
    """Time each N and kind asked for."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("sizes", nargs="*", type=int, default=[10_000, 100_000])
    parser.add_argument("--kinds", default=",".join(KINDS))
    parser.add_argument("--order", default="travel")
    parser.add_argument("--no-cli", action="store_true", help="time import and plan only")
    args = parser.parse_args()
    print(f"{'kind':9} {'N':>9} {'import s':>9} {'plan s':>8} {'post s':>8}  exit")
    for n in args.sizes:
        for kind in args.kinds.split(","):
            path = drawing_file(kind, n)
            imp, pl = time_plan(path, args.order)
            post, code, last = (
                (0.0, 0, "") if args.no_cli else time_post(path, ["--order", args.order])
            )
            print(f"{kind:9} {n:>9} {imp:9.1f} {pl:8.1f} {post:8.1f}  {code} {last[:60]}")
            sys.stdout.flush()


if __name__ == "__main__":
    main()
