"""Planning a big drawing holds memory in proportion to it, with no large per-entity transients.

A dense drawing of disjoint short LINEs (the kind where every open end has tens of other
ends within the open-gap reach, as in a 200 000-LINE drawing on a 180 mm square) is read
and planned under ``tracemalloc``; the peak for 4N entities must grow at most about 5×
from N, and the bytes per entity stay under a bound with a wide margin over what was
measured (about 2.3 KB an entity at 16 000 LINEs; 4.7 KB when the open-gap search took
every near pair at once and the windowed 2-opt 32 768 positions at a time). Counting
bytes, not time.
"""

from __future__ import annotations

import gc
import math
import tracemalloc
from pathlib import Path

from camtool.importers.dxf import read_dxf
from camtool.toolpath.plan import PlanOptions, plan_drawing

PITCH_MM = 0.4
"""Grid pitch of the LINEs: that of 200 000 LINEs on a 180 mm square."""
BYTES_PER_ENTITY = 3_500
"""Peak bytes per LINE allowed at 16 000 LINEs (measured ~2 300: a 1.5× margin)."""


def _write(path: Path, n: int) -> Path:
    """``n`` LINEs half a pitch long, one per grid cell, at varying angles (mm)."""
    side = math.ceil(math.sqrt(n))
    with path.open("w", encoding="ascii") as f:
        f.write("0\nSECTION\n2\nHEADER\n9\n$ACADVER\n1\nAC1009\n9\n$INSUNITS\n70\n4\n")
        f.write("0\nENDSEC\n0\nSECTION\n2\nENTITIES\n")
        for k in range(n):
            x, y = 5 + PITCH_MM * (k % side), 5 + PITCH_MM * (k // side)
            a = (k * 0.618) % 1.0 * math.pi
            x1, y1 = x + 0.5 * PITCH_MM * math.cos(a), y + 0.5 * PITCH_MM * math.sin(a)
            f.write(f"0\nLINE\n8\n0\n10\n{x:.6f}\n20\n{y:.6f}\n11\n{x1:.6f}\n21\n{y1:.6f}\n")
        f.write("0\nENDSEC\n0\nEOF\n")
    return path


def _peak(path: Path) -> int:
    """Peak traced bytes of reading and planning ``path``."""
    gc.collect()
    tracemalloc.start()
    try:
        plan = plan_drawing(read_dxf(path), PlanOptions(feed_mm_min=500.0))
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert plan.program.moves
    return peak


def test_planning_peak_grows_with_the_drawing_and_stays_lean(tmp_path: Path) -> None:
    small, big = 4_000, 16_000
    _peak(_write(tmp_path / "warm.dxf", 200))  # lazy imports outside the measurement
    p_small = _peak(_write(tmp_path / "small.dxf", small))
    p_big = _peak(_write(tmp_path / "big.dxf", big))
    assert p_big <= 5 * p_small
    assert p_big / big <= BYTES_PER_ENTITY, f"{p_big / big:.0f} bytes per LINE"


KEPT_PER_ENTITY = 600
"""Bytes per LINE a plan may keep beyond its drawing (measured 477-480 at 2 000 to 16 000
LINEs: what is kept grows with the drawing alone; 720 when every contour that joined
nothing was copied by the chaining and the open-gap search kept a length on every contour
and segment)."""


def test_a_plan_keeps_little_beyond_its_drawing(tmp_path: Path) -> None:
    """What planning leaves alive (its program, cuts, caches) once the drawing is read."""
    n = 4_000
    _peak(_write(tmp_path / "warm.dxf", 200))
    drawing = read_dxf(_write(tmp_path / "lines.dxf", n))
    gc.collect()
    tracemalloc.start()
    try:
        plan = plan_drawing(drawing, PlanOptions(feed_mm_min=500.0))
        gc.collect()
        kept = tracemalloc.get_traced_memory()[0]
    finally:
        tracemalloc.stop()
    assert len(plan.program.moves) >= n
    assert kept / n <= KEPT_PER_ENTITY, f"{kept / n:.0f} bytes per LINE kept"
    assert not any("length" in c.__dict__ for c in drawing.contours)
