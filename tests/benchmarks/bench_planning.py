"""Benchmark of the planner's stages (not collected by pytest).

Run as ``python tests/benchmarks/bench_planning.py`` (or ``make bench``). A plate with
a grid of 20 × 25 = 500 holes (squares and circles) is planned with each ``--order``
and ``--offset``; every time is printed with its ratio to the baseline of the same
run, the plain ``--offset on --order travel`` plan (chain, nesting, travel ordering,
emission). The first OpenCASCADE call (loading its OCP bindings, about 1.5 s) is
made before timing.

Measurements: docs/performance.md.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from camtool.model.shapes import Arc, Contour, Drawing, Line
from camtool.toolpath.plan import PlanOptions, plan_drawing


def _square(x: float, y: float, a: float) -> Contour:
    pts = [(x, y), (x + a, y), (x + a, y + a), (x, y + a)]
    return Contour(tuple(Line(pts[i], pts[(i + 1) % 4]) for i in range(4)), True)


def plate(columns: int = 20, rows: int = 25, pitch: float = 6.0) -> Drawing:
    """A plate with a grid of holes, alternately ø3 mm circles and 3 mm squares."""
    holes = []
    for i in range(columns):
        for j in range(rows):
            x, y = 5 + i * pitch, 5 + j * pitch
            if (i + j) % 2:
                holes.append(
                    Contour(
                        (Arc((x + 3, y + 1.5), (x + 3, y + 1.5), (x + 1.5, y + 1.5), False),), True
                    )
                )
            else:
                holes.append(_square(x, y, 3.0))
    w, h = 5 + columns * pitch + 2, 5 + rows * pitch + 2
    return Drawing((*holes, _outline(w, h)))


def _outline(w: float, h: float) -> Contour:
    pts = [(0.0, 0.0), (w, 0.0), (w, h), (0.0, h)]
    return Contour(tuple(Line(pts[i], pts[(i + 1) % 4]) for i in range(4)), True)


def timed(drawing: Drawing, **options: Any) -> float:
    """Seconds to plan ``drawing`` with ``options``."""
    start = time.perf_counter()
    plan_drawing(drawing, PlanOptions(feed_mm_min=300.0, **options))
    return time.perf_counter() - start


def main() -> None:
    """Time each case and print it against the baseline."""
    drawing = plate()
    timed(Drawing((_outline(10, 10),)), offset="outside", tool_diameter=1.0)  # load OCCT
    base = timed(drawing)
    print(f"{'case':<34} {'seconds':>9} {'× baseline':>11}")
    print(f"{'on, travel (baseline)':<34} {base:9.3f} {1.0:11.2f}")
    cases = {
        "on, reversals (backlash unknown)": {"order": "reversals"},
        "outside 1 mm, travel": {"offset": "outside", "tool_diameter": 1.0},
        "inside 1 mm, travel": {"offset": "inside", "tool_diameter": 1.0},
        "pocket 1 mm, concentric": {"offset": "pocket", "tool_diameter": 1.0},
    }
    for name, options in cases.items():
        t = timed(drawing, **options)
        print(f"{name:<34} {t:9.3f} {t / base:11.2f}")


if __name__ == "__main__":
    main()
