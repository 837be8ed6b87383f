"""A job's end position when its last operation plans no end move of its own.

The planner ends an operation's moves with the ``end_position`` rapid; a drill operation's
cycles and an operation left with nothing to cut (each contour cut by an earlier one) end
without it. The program must still end there, at clearance, and the placement must not
take the last move for that rapid: it keeps the end rapid where it was asked (work
coordinates) while it shifts every other move, so a cycle's retract kept unshifted would
be a rapid out of the hole, sideways from the bottom. Expected values are the job's: the
bundled plate (samples/part.dxf, 80 × 60 mm) with work zero at the toolpath's lower-left
corner, clearance 5 mm, end position X0 Y0; the code is read back with a reader of the
test's own (G0/G1/G2/G3 and their X, Y, Z words).
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from camtool.importers import read_drawing
from camtool.jobs.jobfile import load_job
from camtool.jobs.run import run_job
from camtool.post.registry import load_target

ROOT = Path(__file__).resolve().parents[2]

_JOB = """
[job]
end_position = [0, 0]
origin = "lower-left"

[[tools]]
id = 1
type = "end-mill"
diameter = 3

[[tools]]
id = 2
type = "drill"
diameter = 3.2

"""

_PROFILE = """
[[operations]]
type = "profile"
tool = 1
side = "outside"
layers = ["OUTLINE"]
depth = 2
"""

_DRILL_LAST = """
[[operations]]
type = "drill"
tool = 2
layers = ["HOLES"]
depth = 4
"""

_WORD = re.compile(r"([GXYZ])(-?[0-9.]+)")


def _rapids(code: str) -> list[tuple[tuple[float, float, float], tuple[float, float, float]]]:
    """Each G0 of ``code`` as (from, to) positions, modal G and axes followed."""
    here = [0.0, 0.0, 0.0]
    mode = None
    out = []
    for line in code.splitlines():
        line = re.sub(r"\([^)]*\)|;.*", "", line)
        words = _WORD.findall(line)
        axes = {k: float(v) for k, v in words if k in "XYZ"}
        codes = [float(v) for k, v in words if k == "G"]
        motion = [g for g in codes if g in (0, 1, 2, 3)]
        mode = motion[-1] if motion else mode
        if not axes or any(g in (10, 28, 30, 53, 92) for g in codes):
            continue
        start = tuple(here)
        for axis, value in axes.items():
            here["XYZ".index(axis)] = value
        if mode == 0:
            out.append((start, tuple(here)))
    return out  # type: ignore[return-value]


@pytest.mark.parametrize("target", ["grbl", "linuxcnc"])
@pytest.mark.parametrize("last", [_DRILL_LAST, _PROFILE], ids=["drill", "cut-before"])
def test_the_program_ends_at_the_end_position_and_no_rapid_leaves_the_cut_sideways(
    tmp_path: Path, target: str, last: str
) -> None:
    path = tmp_path / "job.toml"
    path.write_text(_JOB + _PROFILE + last)  # the profile again: each contour cut before
    drawing = read_drawing(ROOT / "samples" / "part.dxf")
    post = run_job(drawing, load_target(target), load_job(path))
    pieces = [p.result.code for p in post.pieces] or [post.result.code]  # per tool on grbl
    for code in pieces[:-1]:
        for start, end in _rapids(code):
            assert start[:2] == end[:2] or (start[2] >= 0 and end[2] >= 0), (start, end)
    rapids = _rapids(pieces[-1])  # the last tool's program ends the job
    for start, end in rapids:
        if start[:2] != end[:2]:  # across: above the top from start to end
            assert start[2] >= 0 and end[2] >= 0, f"a rapid across from {start} to {end}"
    assert rapids[-1][1] == (0.0, 0.0, 5.0)  # the end position, at clearance
