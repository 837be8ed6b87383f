"""A kind of finding prints at most MAX_LISTED + 1 warning lines; the report keeps them all.

A laser-cut sheet from boxes.py (parts 1.5 mm apart) posted with ``--offset outside
--tool-diameter 3`` printed one "the tool cuts into the part" warning per overlap: 1 786
lines for its Arcade example, in which the other warnings were lost.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import ezdxf

from camtool.toolpath.cuts import MAX_LISTED, Finding, finding_warnings


def _findings(kind: str, n: int) -> list[Finding]:
    return [Finding(kind, f"{kind} number {i}", (float(i), 0.0), 1.0) for i in range(n)]


def test_a_kind_with_many_findings_lists_the_first_and_counts_the_rest_in_place() -> None:
    gouges = _findings("gouge", 25)
    corners = _findings("tight-corner", 3)
    # open contours are capped where they are found: MAX_LISTED and one counting line
    opened = _findings("open-left-out", MAX_LISTED + 1)
    findings = [corners[0], *gouges[:12], corners[1], *gouges[12:], *opened, corners[2]]
    lines = finding_warnings(findings)
    count = "15 more place(s) where the tool cuts into the part, not listed here"
    assert lines == [
        corners[0].message,
        *(g.message for g in gouges[:MAX_LISTED]),
        f"{count} (the report of --report R.json lists each one)",
        corners[1].message,
        *(f.message for f in opened),
        corners[2].message,
    ]


def test_up_to_one_more_than_the_limit_everything_is_listed_in_order() -> None:
    findings = [*_findings("gouge", MAX_LISTED + 1), *_findings("uncut", 2)]
    assert finding_warnings(findings) == [f.message for f in findings]
    twice = [*findings, findings[0]]  # a repeated message is said once
    assert finding_warnings(twice) == [f.message for f in findings]


def test_thirty_squares_closer_than_the_tool_warn_in_eleven_lines(tmp_path: Path) -> None:
    """30 squares of 10 mm in a row, 1 mm apart, cut outside with a 3 mm tool.

    Each path sweeps 3 mm from its square, 2 mm into each neighbour: 2 × 30 − 2 = 58
    overlaps (the two end squares have one neighbour), each 2 × 10 = 20 mm².
    """
    doc = ezdxf.new()
    doc.units = ezdxf.units.MM
    msp = doc.modelspace()
    for k in range(30):
        x = 11.0 * k
        msp.add_lwpolyline([(x, 0), (x + 10, 0), (x + 10, 10), (x, 10)], close=True)
    drawing = tmp_path / "row.dxf"
    doc.saveas(drawing)
    out, report = tmp_path / "row.nc", tmp_path / "row.json"
    done = subprocess.run(
        [sys.executable, "-m", "camtool", "post", str(drawing), "-t", "linuxcnc",
         "--machine", str(_big(tmp_path)), "--offset", "outside", "--tool-diameter", "3",
         "--no-budget", "--report", str(report), "-o", str(out)],
        capture_output=True, text=True, check=False,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    said = [line for line in done.stderr.splitlines() if "cuts into the part" in line]
    assert len(said) == MAX_LISTED + 1
    assert said[-1].startswith(f"camtool: warning: {58 - MAX_LISTED} more place(s) where")
    found = json.loads(report.read_text())["plan"]["findings"]
    gouges = [f for f in found if f["kind"] == "gouge"]
    assert len(gouges) == 58
    assert all(abs(f["value"] - 20.0) < 0.02 for f in gouges)


def _big(folder: Path) -> Path:
    machine = folder / "big.toml"
    machine.write_text("[machine]\nwork_area_mm = [-50.0, -50.0, 400.0, 100.0]\n")
    return machine
