"""``--tolerance`` governs the chords a dialect without arcs writes for an arc (re-posted or drawn).

A half circle of radius 10 mm in chords of sagitta at most s needs
``ceil(pi / (2 acos(1 - s / 10)))`` chords: 7 for s = 0.3 mm, 16 for 0.05 mm, 36 for 0.01 mm.
A tolerance coarser than the machine's finest chord is honoured; a finer one gives the
machine's (finer chords would only add moves below its grid or step).
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import ezdxf
import pytest

from camtool.jobs.pipeline import post_file
from camtool.toolpath.options import PlanOptions

HALF_CIRCLE = "G21 G90 G17\nG0 X0 Y0\nG1 X0 Y0 F300\nG2 X20 Y0 I10 J0 F300\nM2\n"


def chords_for(sagitta_mm: float, radius_mm: float = 10.0, sweep: float = math.pi) -> int:
    return math.ceil(sweep / (2.0 * math.acos(1.0 - sagitta_mm / radius_mm)))


def _half_circle(tmp_path: Path, kind: str) -> Path:
    if kind == "gcode":
        path = tmp_path / "arc.gcode"
        path.write_text(HALF_CIRCLE)
        return path
    doc = ezdxf.new()
    doc.header["$INSUNITS"] = 4
    doc.modelspace().add_arc((10, 0), 10, 0, 180)
    path = tmp_path / "arc.dxf"
    doc.saveas(path)
    return path


def _chord_warning(warnings: tuple[str, ...]) -> tuple[int, float]:
    found = [re.search(r"written as (\d+) chords", w) for w in warnings]
    counts = [int(m[1]) for m in found if m]
    assert len(counts) == 1, warnings
    errors = [
        re.search(r"(?:largest sagitta|largest chord error) ([\d.]+) mm", w) for w in warnings
    ]
    return counts[0], max(float(m[1]) for m in errors if m)


@pytest.mark.parametrize("kind", ["gcode", "dxf"])
@pytest.mark.parametrize(
    ("target", "tolerance", "finest"),
    [
        ("matlab-router", 0.3, 0.05),
        ("matlab-router", 0.001, 0.05),
        ("i8751", 0.3, 0.01),
        ("i8751", 0.001, 0.01),
    ],
)
def test_chords_follow_the_tolerance(
    tmp_path: Path, kind: str, target: str, tolerance: float, finest: float
) -> None:
    path = _half_circle(tmp_path, kind)
    job = post_file(path, target, PlanOptions(tolerance=tolerance))
    count, error = _chord_warning(job.result.warnings)
    used = max(tolerance, finest)
    assert count == chords_for(used)
    assert error <= used
