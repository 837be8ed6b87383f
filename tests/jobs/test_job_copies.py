"""A path two operations of a job select alike is cut once (a fill and its outline).

LibreOffice Draw and Impress export a filled, outlined shape as a fill path (the fill's
colour) and a stroke path (the line's colour) of the same points; ``camtool job init``
makes one operation per colour, so the shape is selected twice. Expected values come from
the geometry: a 40 × 20 mm rectangle cut on its outside by a 3 mm end mill is a path
2·(40 + 20) + 2π·1.5 mm long (straight sides and quarter-circle corners around each
vertex), at the operation's depth.
"""

from __future__ import annotations

import dataclasses
import json
import math
import tomllib
from pathlib import Path
from typing import Any

import pytest

from camtool.cli.main import main
from camtool.importers import read_drawing
from camtool.jobs.init import initial_job
from camtool.jobs.jobfile import job_from_dict, load_job
from camtool.jobs.pipeline import verify_job
from camtool.jobs.run import PostJob, run_job
from camtool.model.program import ArcMove, Move, Rapid, ToolChange, segment_of
from camtool.model.shapes import Contour, Drawing
from camtool.post.registry import load_target
from tests.shapes import kin47_arcs_dxf, write_dxf
from tests.toolpath.contours import circle, rect

PERIMETER = 2 * (40 + 20) + 2 * math.pi * 1.5

_OPERATION = """
[[operations]]
type = "profile"
tool = 1
side = "outside"
colours = ["{colour}"]
depth = {depth}
"""


def _job(tmp_path: Path, *ops: tuple[str, float]) -> Path:
    text = '[[tools]]\nid = 1\ntype = "end-mill"\ndiameter = 3\n'
    text += "".join(_OPERATION.format(colour=c, depth=d) for c, d in ops)
    path = tmp_path / "job.toml"
    path.write_text(text)
    return path


def _painted(contour: Contour, colour: str, source: str) -> Contour:
    return dataclasses.replace(contour, colour=colour, source=source)


def _drawing(*contours: Contour) -> Drawing:
    return Drawing(contours, "shapes.svg")


def _fill_and_outline() -> tuple[Contour, Contour]:
    square = rect(10, 10, 50, 30)
    return _painted(square, "#ffcc00", "path[2]"), _painted(square, "#000000", "path[3]")


def _feed_at(post: PostJob, number: int, z: float) -> float:
    """The XY length operation ``number`` cuts at Z ``z`` (level feeds only), mm."""
    first, end = post.operations[number - 1].moves
    moves: list[Move] = list(post.program.moves)
    height = None  # Z before each move
    for move in moves[:first]:
        height = move.z if move.z is not None else height
    total = 0.0
    for i in range(first, end):
        move = moves[i]
        after = move.z if move.z is not None else height
        if not isinstance(move, Rapid) and height == after == z and i > 0:
            start = (moves[i - 1].x, moves[i - 1].y)
            if isinstance(move, ArcMove):
                total += segment_of(start, move).length
            else:
                total += math.dist(start, (move.x, move.y))
        height = after
    return total


def test_a_fill_and_its_outline_in_two_operations_are_cut_once(tmp_path: Path) -> None:
    fill, outline = _fill_and_outline()
    job = load_job(_job(tmp_path, ("#ffcc00", 1), ("#000000", 1)))
    post = run_job(_drawing(fill, outline), load_target("linuxcnc"), job)
    second = post.operations[1]
    assert math.isclose(_feed_at(post, 1, -1.0), PERIMETER, rel_tol=1e-6)
    assert second.moves[0] == second.moves[1]  # nothing left for the outline
    assert any(
        "path[3]" in w and "repeats contour path[2], which operation 1 cuts" in w
        for w in post.warnings
    )
    assert not any("no operation selects" in w for w in post.warnings)
    header = [n for n in post.program.notes if n.startswith("2. ")]
    assert header == ["2. profile outside T1: nothing left to cut (its paths cut before)"]


def test_only_the_copies_are_left_out_of_an_operation_that_has_more(tmp_path: Path) -> None:
    fill, outline = _fill_and_outline()
    hole = _painted(circle(100, 20, 5), "#000000", "path[4]")  # outlined only
    job = load_job(_job(tmp_path, ("#ffcc00", 1), ("#000000", 1)))
    post = run_job(_drawing(fill, outline, hole), load_target("linuxcnc"), job)
    # the circle alone: 2π(5 + 1.5) on its outside
    assert math.isclose(_feed_at(post, 2, -1.0), 2 * math.pi * 6.5, rel_tol=1e-6)
    # and verified alone against the circle, not the rectangle operation 1 cuts (which
    # would be ~20 mm from its code): a few µm of the controller's own rounding
    second = verify_job(post, budget=False).parts[1].verification
    assert second.against is not None and second.against.max_um < 12.0


def test_a_copy_cut_deeper_by_a_later_operation_is_cut_again(tmp_path: Path) -> None:
    fill, outline = _fill_and_outline()
    job = load_job(_job(tmp_path, ("#ffcc00", 1), ("#000000", 2)))
    post = run_job(_drawing(fill, outline), load_target("linuxcnc"), job)
    assert math.isclose(_feed_at(post, 1, -1.0), PERIMETER, rel_tol=1e-6)
    assert math.isclose(_feed_at(post, 2, -2.0), PERIMETER, rel_tol=1e-6)
    assert not any("repeats" in w for w in post.warnings)


_LIBREOFFICE = """<?xml version="1.0" encoding="UTF-8"?>
<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="50mm" viewBox="0 0 10000 5000">
 <g class="com.sun.star.drawing.CustomShape">
  <path fill="rgb(114,159,207)" stroke="none" d="M 1000,1000 L 5000,1000
   5000,3000 1000,3000 1000,1000 Z"/>
  <path fill="none" stroke="rgb(52,101,164)" d="M 1000,1000 L 5000,1000
   5000,3000 1000,3000 1000,1000 Z"/>
 </g>
</svg>
"""  # the shape of LibreOffice Draw's SVG export: fill path, then its outline


def test_job_init_leaves_a_libreoffice_shapes_fill_to_its_outline(tmp_path: Path) -> None:
    svg = tmp_path / "shape.svg"
    svg.write_text(_LIBREOFFICE)
    drawing = read_drawing(svg)
    text = initial_job(drawing)
    job = job_from_dict(tomllib.loads(text), source="shape.toml")
    # an operation per colour, in their order: the outline's first, the fill's left to it
    assert [op.select.colours for op in job.operations] == [("#3465a4",)]
    assert (
        '# name = "#729fcf"  # each contour of colour #729fcf lies on one of colour #3465a4' in text
    )
    post = run_job(drawing, load_target("linuxcnc"), job)
    # one path round the rectangle on the last pass, less the gaps over its 2 tabs
    assert PERIMETER - 20 < _feed_at(post, 1, -3.5) < PERIMETER
    assert not any("no operation selects" in w for w in post.warnings)


def test_a_contour_two_operations_select_alike_is_cut_by_the_first(tmp_path: Path) -> None:
    outline = _painted(rect(10, 10, 50, 30), "#000000", "LWPOLYLINE #8F")
    job = load_job(_job(tmp_path, ("#000000", 1), ("#000000", 1)))
    post = run_job(_drawing(outline), load_target("linuxcnc"), job)
    assert math.isclose(_feed_at(post, 1, -1.0), PERIMETER, rel_tol=1e-6)
    assert post.operations[1].moves[0] == post.operations[1].moves[1]
    assert (
        "contour LWPOLYLINE #8F at (10.0000, 10.0000) mm: operation 1 cuts it already: cut once"
        in (post.warnings)
    )
    assert any("is one selection too wide?" in w for w in post.warnings)


def test_a_line_drawn_twice_is_an_open_line_to_job_init_and_to_a_selection(
    tmp_path: Path,
) -> None:
    # Two copies of a LINE chain out and back, ending where they began: a closed contour
    # to chaining alone, but an open line to cut. job init offers it to an engrave
    # operation (commented out) and the profile's closed = true does not select it.
    def build(msp: Any) -> None:
        msp.add_lwpolyline([(0, 0), (60, 0), (60, 40), (0, 40)], close=True)
        msp.add_line((10, 20), (50, 20))
        msp.add_line((50, 20), (10, 20))

    drawing = read_drawing(write_dxf(tmp_path / "plate.dxf", build))
    text = initial_job(drawing)
    assert '# type = "engrave"  # 1 open contour(s) on layer' in text
    job = job_from_dict(tomllib.loads(text), source="plate.toml")
    post = run_job(drawing, load_target("linuxcnc"), job)
    (profile,) = post.operations
    assert [c.source for c in profile.placed.contours] == [drawing.contours[0].source]
    assert any(w.startswith("not cut: 1 contour(s) on layer '0' (1 open;") for w in post.warnings)


def test_a_job_with_an_operation_left_with_nothing_is_verified_and_previewed(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # The operation left with nothing has no code to read back: verified, reported and
    # drawn are the operations that cut; the program is written.
    svg = tmp_path / "shape.svg"
    svg.write_text(_LIBREOFFICE)
    job = _job(tmp_path, ("#729fcf", 1), ("#3465a4", 1))
    out, png, report = tmp_path / "shape.ngc", tmp_path / "shape.png", tmp_path / "r.json"
    args = ["post", str(svg), "-t", "grbl", "--job", str(job), "-o", str(out)]
    code = main([*args, "--preview", str(png), "--report", str(report)])
    err = capsys.readouterr().err
    assert code == 0, err
    assert out.is_file() and png.stat().st_size > 0
    operations = json.loads(report.read_text())["operations"]
    assert [o["operation"] for o in operations] == ["operation 1 (profile outside) T1"]


def test_no_tool_change_for_an_operation_left_with_nothing(tmp_path: Path) -> None:
    # The outline, a drill between, the outline again alike: the third has nothing left,
    # so the program asks for no change back to the end mill after drilling.
    job = _job(tmp_path, ("#000000", 1))
    text = job.read_text().replace(
        "[[tools]]", '[[tools]]\nid = 2\ntype = "drill"\ndiameter = 2\n\n[[tools]]', 1
    )
    text += '\n[[operations]]\ntype = "drill"\ntool = 2\ncolours = ["#ff0000"]\ndepth = 1\n'
    text += _OPERATION.format(colour="#000000", depth=1)
    job.write_text(text)
    hole = _painted(circle(70, 20, 1), "#ff0000", "CIRCLE #90")
    outline = _painted(rect(10, 10, 50, 30), "#000000", "LWPOLYLINE #8F")
    post = run_job(_drawing(outline, hole), load_target("grbl"), load_job(job))
    changes = [c.tool for _, c in post.program.commands if isinstance(c, ToolChange)]
    assert changes == [1, 2]
    assert post.operations[2].moves[0] == post.operations[2].moves[1]


def test_a_hole_drawn_twice_as_an_arc_short_of_360_is_drilled_once(tmp_path: Path) -> None:
    """LibreCAD's kinetics/kin47.dxf draws its 5 mm holes as two copies of an ARC from 270°
    to 269.99999427°: chained end to end (the second reversed) they are a path out and
    back, no circle, and the drill operation that ``job init`` proposed for them refused
    it. Expected from the drawing: one hole at the ARC's centre."""
    path = kin47_arcs_dxf(tmp_path / "arcs.dxf", (5.0, 10.0))
    job = tmp_path / "drill.toml"
    job.write_text(
        '[[tools]]\nid = 1\ntype = "drill"\ndiameter = 5\n'
        '[[operations]]\ntype = "drill"\ntool = 1\nlayers = ["0"]\ndepth = 3\n'
    )
    done = run_job(read_drawing(path), load_target("linuxcnc"), load_job(job))
    holes = [(m.x, m.y) for m in done.program.moves if m.z == -3.0]
    assert holes == [(5.0, 10.0)]


def test_many_operations_that_select_one_layer_share_one_warning_past_the_third(
    tmp_path: Path,
) -> None:
    # operations 1-6 and 8-13 engrave the ENGRAVE layer, operation 7 drills the holes:
    # operations 2-4 are named with the contour, the other eight (5, 6, 8-13) counted in
    # one line
    root = Path(__file__).resolve().parents[2]
    engrave = '\n[[operations]]\ntype = "engrave"\ntool = 1\nlayers = ["ENGRAVE"]\ndepth = 0.3\n'
    drill = (
        '\n[[operations]]\ntype = "drill"\ntool = 2\nlayers = ["HOLES"]\ndepth = 6.5\n'
        "step_down = 2.0\n"
    )
    head = (root / "samples" / "part.toml").read_text().split("[[operations]]")[0]
    job_file = tmp_path / "many.toml"
    job_file.write_text(head + engrave * 6 + drill + engrave * 6)
    post = run_job(
        read_drawing(root / "samples" / "part.dxf"), load_target("grbl"), load_job(job_file)
    )
    again = [w for w in post.warnings if "again" in w]
    assert [w.split(" (")[0] for w in again[:3]] == [
        "operation 2",
        "operation 3",
        "operation 4",
    ]
    assert all("LWPOLYLINE #95 on layer 'ENGRAVE'" in w for w in again[:3])
    assert again[3:] == [
        "8 more operations (5, 6, 8-13) cut a contour again that an earlier operation of "
        "their kind cuts: is a selection too wide?"
    ]
