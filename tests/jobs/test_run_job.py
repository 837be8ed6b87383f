"""Running a job: the bundled test plate as drill, engrave, pocket and outline, one program.

Expected values come from the drawing (samples/make_samples.py: an 80 × 60 mm plate,
four ø3.2 mm holes at 8 mm from the corners, a 30 × 20 mm pocket, centre lines) and the
job (samples/part.toml: a 3.2 mm drill, a 3 mm end mill, work zero at the toolpath's
lower-left corner, i.e. the outline offset by the 1.5 mm tool radius: a shift of +1.5 mm).
"""

from __future__ import annotations

from collections.abc import Callable
from itertools import pairwise
from pathlib import Path
from typing import Any

import pytest

from camtool.importers import read_drawing
from camtool.jobs.job import Job
from camtool.jobs.jobfile import load_job
from camtool.jobs.run import run_job
from camtool.model.errors import InputError
from camtool.model.program import DrillCycle, Linear, Rapid, Spindle, ToolChange
from camtool.model.shapes import Drawing
from camtool.post.registry import load_target

ROOT = Path(__file__).resolve().parents[2]
SHIFT = 1.5  # lower-left work zero: the outline's offset path starts at -1.5 mm
HOLES = {(8.0 + SHIFT, 8.0 + SHIFT), (72 + SHIFT, 8 + SHIFT), (72 + SHIFT, 52 + SHIFT),
         (8 + SHIFT, 52 + SHIFT)}  # fmt: skip


@pytest.fixture(scope="module")
def part() -> object:
    drawing = read_drawing(ROOT / "samples" / "part.dxf")
    return run_job(drawing, load_target("linuxcnc"), load_job(ROOT / "samples" / "part.toml"))


def _xy(x: float, y: float) -> tuple[float, float]:
    return (round(x, 6), round(y, 6))


def _moves(job: object, number: int) -> list[object]:
    run = job.operations[number - 1]  # type: ignore[attr-defined]
    first, end = run.moves
    return list(job.program.moves[first:end])  # type: ignore[attr-defined]


def test_operations_run_in_the_files_order_with_their_tools(part: object) -> None:
    runs = part.operations  # type: ignore[attr-defined]
    assert [(r.operation.kind, r.tool.id) for r in runs] == [
        ("drill", 2),
        ("engrave", 1),
        ("pocket", 1),
        ("profile outside", 1),
    ]
    assert runs[0].holes == 4


def test_holes_are_drilled_at_their_centres_to_depth(part: object) -> None:
    moves = _moves(part, 1)
    feeds = [m for m in moves if isinstance(m, Linear)]
    assert {_xy(m.x, m.y) for m in feeds} == HOLES  # no feed anywhere but at a centre
    assert min(m.z for m in feeds) == -6.5
    bottoms = [m for m in feeds if m.z == -6.5]
    assert len(bottoms) == 4
    # pecks of 2 mm from the R plane (safe Z 2): 0, -2, -4, -6, -6.5 at each hole
    assert sorted({m.z for m in feeds}) == [-6.5, -6.0, -4.0, -2.0, 0.0]
    cycles = [c for _, c in part.program.commands if isinstance(c, DrillCycle)]  # type: ignore[attr-defined]
    assert len(cycles) == 4 and {_xy(c.x, c.y) for c in cycles} == HOLES
    assert all(c.kind == "peck" and c.peck_mm == 2.0 and c.r_z == 2.0 for c in cycles)


def test_every_xy_rapid_of_the_job_is_above_the_top(part: object) -> None:
    z = None
    here = None
    for move in part.program.moves:  # type: ignore[attr-defined]
        if isinstance(move, Rapid) and here is not None and (move.x, move.y) != here:
            assert z is not None and z >= 2.0, f"an XY rapid at Z {z}"
        z = move.z if move.z is not None else z
        here = (move.x, move.y)


def test_the_pocket_goes_to_its_depth_and_stays_inside_it(part: object) -> None:
    cuts = [m for m in _moves(part, 3) if isinstance(m, Linear)]
    assert min(m.z for m in cuts if m.z is not None) == -2.0
    # the tool centre stays 1.5 mm inside the 30 x 20 pocket at (25, 20)-(55, 40)
    xs = [m.x for m in cuts]
    ys = [m.y for m in cuts]
    assert min(xs) >= 25 + 1.5 + SHIFT - 1e-9 and max(xs) <= 55 - 1.5 + SHIFT + 1e-9
    assert min(ys) >= 20 + 1.5 + SHIFT - 1e-9 and max(ys) <= 40 - 1.5 + SHIFT + 1e-9


def test_the_outline_comes_last_with_tabs_at_full_depth(part: object) -> None:
    moves = _moves(part, 4)
    zs = [m.z for m in moves if m.z is not None]
    assert min(zs) == -6.5
    assert -5.5 in zs  # the tab top: depth 6.5 - tab height 1
    xs = [m.x for m in moves if not isinstance(m, Rapid)]
    # the outline (0..80) offset outside by the 1.5 mm radius, moved by the shift
    assert min(xs) == pytest.approx(0.0) and max(xs) == pytest.approx(83.0)


def test_no_centre_line_is_cut(part: object) -> None:
    # the centre lines across the part run at Y 30 and X 40 (+ shift), from outside it
    for move in part.program.moves:  # type: ignore[attr-defined]
        if isinstance(move, Linear) and move.z is None:
            assert not (round(move.y, 6) == 30 + SHIFT and move.x > 80), move
    assert any("layer 'CENTER'" in w for w in part.warnings)  # type: ignore[attr-defined]


def test_a_tool_change_comes_between_drilling_and_milling(part: object) -> None:
    program = part.program  # type: ignore[attr-defined]
    changes = [(i, c) for i, c in program.commands if isinstance(c, ToolChange)]
    assert [c.tool for _, c in changes] == [2, 1]
    assert changes[0][0] == 0
    engrave_first = part.operations[1].moves[0]  # type: ignore[attr-defined]
    assert changes[1][0] == engrave_first
    # the drill is up at clearance when it is changed, and the spindle is off meanwhile
    z_before = [m.z for m in program.moves[:engrave_first] if m.z is not None][-1]
    assert z_before == 10.0
    around = [c for i, c in program.commands if i == engrave_first]
    assert around == [Spindle("off"), ToolChange(1, "end-mill 3 mm")]
    # the new tool's spindle starts after the operation's Z-only rise to clearance
    rise = program.moves[engrave_first]
    assert (rise.x, rise.y) == (
        program.moves[engrave_first - 1].x,
        program.moves[engrave_first - 1].y,
    )
    assert rise.z == 10.0
    after = [c for i, c in program.commands if i == engrave_first + 1]
    assert after == [Spindle("cw", 10000.0)]


def test_the_header_lists_the_tools_and_the_operations_in_order(part: object) -> None:
    notes = part.program.notes  # type: ignore[attr-defined]
    assert "T2: drill 3.2 mm" in notes and "T1: end-mill 3 mm" in notes
    ops = [n for n in notes if n[:2] in ("1.", "2.", "3.", "4.")]
    assert [n.split(":")[0] for n in ops] == [
        "1. drill 'holes' T2",
        "2. engrave 'mark' T1",
        "3. pocket 'pocket' T1",
        "4. profile outside 'outline' T1",
    ]
    assert "4 holes, 6.5 deep, pecks of 2" in ops[0]


def test_a_selection_that_matches_nothing_names_the_drawings_layers(tmp_path: Path) -> None:
    text = (ROOT / "samples" / "part.toml").read_text().replace('["POCKET"]', '["POKET"]')
    path = tmp_path / "job.toml"
    path.write_text(text)
    drawing = read_drawing(ROOT / "samples" / "part.dxf")
    with pytest.raises(InputError) as caught:
        run_job(drawing, load_target("grbl"), load_job(path))
    assert str(caught.value) == (
        "job.toml: operation 3 ('pocket') selects layer 'POKET'; the drawing has CENTER, "
        "ENGRAVE, HOLES, OUTLINE, POCKET"
    )


@pytest.mark.parametrize(
    ("drill", "message"),
    [
        (4.0, r"hole CIRCLE #\w+ on layer 'HOLES' at \(8\.0000, 8\.0000\) mm is 3\.2 mm across, "
         r"smaller than the 4 mm drill"),
        (3.0, r"is 3\.2 mm across, larger than the 3 mm drill .*profile operation"),
    ],
)  # fmt: skip
def test_a_drill_of_another_size_than_its_holes_is_refused(
    tmp_path: Path, drill: float, message: str
) -> None:
    text = (ROOT / "samples" / "part.toml").read_text().replace("3.2", f"{drill:g}")
    path = tmp_path / "job.toml"
    path.write_text(text)
    drawing = read_drawing(ROOT / "samples" / "part.dxf")
    with pytest.raises(InputError, match=message) as caught:
        run_job(drawing, load_target("grbl"), load_job(path))
    assert str(caught.value).startswith("job.toml: operation 1 ('holes'): hole CIRCLE #")


def test_a_drill_operation_refuses_what_is_not_a_hole(tmp_path: Path) -> None:
    text = (ROOT / "samples" / "part.toml").read_text().replace('["HOLES"]', '["OUTLINE"]', 1)
    path = tmp_path / "job.toml"
    path.write_text(text)
    drawing = read_drawing(ROOT / "samples" / "part.dxf")
    with pytest.raises(InputError, match=r"which is not a circle") as caught:
        run_job(drawing, load_target("grbl"), load_job(path))
    # the message names the job file, then its operation
    assert str(caught.value).startswith("job.toml: operation 1 ('holes') drills LWPOLYLINE #")


def test_a_point_is_drilled_where_it_is(tmp_path: Path) -> None:
    from tests.shapes import write_dxf

    def build(msp: object) -> None:
        msp.add_point((12.5, 7.25), dxfattribs={"layer": "DRILL"})  # type: ignore[attr-defined]
        msp.add_lwpolyline(  # type: ignore[attr-defined]
            [(0, 0), (30, 0), (30, 20), (0, 20)], close=True, dxfattribs={"layer": "EDGE"}
        )

    dxf = write_dxf(tmp_path / "points.dxf", build)
    job = tmp_path / "job.toml"
    job.write_text(
        '[[tools]]\nid = 5\ntype = "drill"\ndiameter = 1\n'
        '[[operations]]\ntype = "drill"\ntool = 5\nlayers = ["DRILL"]\ndepth = 2\n'
    )
    done = run_job(read_drawing(dxf), load_target("grbl"), load_job(job))
    feeds = [m for m in done.program.moves if isinstance(m, Linear)]
    assert [(m.x, m.y, m.z) for m in feeds] == [(12.5, 7.25, -2.0)]  # work zero: the drawing's


def test_a_drill_of_one_hole_size_drills_no_point(tmp_path: Path) -> None:
    """A drill selecting circles by diameter keeps only them: a point has no diameter.

    LibreCAD's ``elektro/lamp/sg.dxf`` draws a lamp with a ø1.5 mm circle and two POINTs
    (its connection points). ``camtool job init`` writes a drill for the ø1.5 circles
    and leaves the points' drill commented out: the circle's centre alone is drilled, and
    a warning names the points left; ``points = true`` in the same operation drills them
    as well.
    """
    from camtool.jobs.init import initial_job
    from tests.shapes import write_dxf

    def build(msp: object) -> None:
        msp.add_circle((8.5, -3.0), 0.75)  # type: ignore[attr-defined]
        msp.add_circle((7.5, 0.0), 5.0)  # type: ignore[attr-defined]
        for at in ((0.0, 0.0), (15.0, 0.0)):
            msp.add_point(at)  # type: ignore[attr-defined]

    dxf = write_dxf(tmp_path / "lamp.dxf", build)
    drawing = read_drawing(dxf)
    text = initial_job(drawing).replace('origin = "lower-left"', 'origin = "drawing"')
    assert "diameter = 1.5" in text and '# type = "drill"  # 2 point(s)' in text
    job = tmp_path / "job.toml"
    job.write_text(text)
    done = run_job(drawing, load_target("grbl"), load_job(job))
    drilled = [c for _, c in done.program.commands if isinstance(c, DrillCycle)]
    assert [(c.x, c.y) for c in drilled] == [(8.5, -3.0)]
    (left,) = [w for w in done.program.warnings if w.startswith("not drilled")]
    assert "2 point(s) on layer '0'" in left and "(0.0000, 0.0000) mm" in left
    only = "diameter = 1.5  # only the circles of this size"
    assert only in text
    job.write_text(text.replace(only, f"points = true\n{only}", 1))
    done = run_job(drawing, load_target("grbl"), load_job(job))
    drilled = [c for _, c in done.program.commands if isinstance(c, DrillCycle)]
    assert sorted((c.x, c.y) for c in drilled) == [(0.0, 0.0), (8.5, -3.0), (15.0, 0.0)]
    assert not any(w.startswith("not drilled") for w in done.program.warnings)
    # the points' drill `job init` leaves commented out, uncommented as it stands: the two
    # points alone (the ø10 circle on their layer is the profile's, no hole for this drill)
    lines = text.splitlines()
    start = lines.index('# type = "drill"  # 2 point(s): drilled if you uncomment this') - 1
    block = [line.removeprefix("# ") for line in lines[start : start + 6]]
    assert block[4] == 'points = "only"  # not the contours of these layers'
    job.write_text("\n".join(lines[:start] + block + lines[start + 6 :]) + "\n")
    done = run_job(drawing, load_target("grbl"), load_job(job))
    drilled = [c for _, c in done.program.commands if isinstance(c, DrillCycle)]
    assert sorted((c.x, c.y) for c in drilled) == [(0.0, 0.0), (8.5, -3.0), (15.0, 0.0)]


def test_a_circle_drawn_as_arcs_is_a_hole_to_drill_and_no_profile(tmp_path: Path) -> None:
    """A ø3 hole drawn as two ARCs (as converters and some CAD exports draw circles) is one
    circle once chained: ``job init`` drills it with the CIRCLE of the same size, the
    written drill's ``diameter`` selects it, the profile's ``except_diameter`` leaves it
    (profiled on its inside, a 3 mm mill cuts nothing in it).
    """
    from camtool.jobs.init import initial_job
    from tests.shapes import write_dxf

    def build(msp: object) -> None:
        msp.add_lwpolyline([(0, 0), (60, 0), (60, 40), (0, 40)], close=True)  # type: ignore[attr-defined]
        msp.add_arc((15, 20), 1.5, 0, 180)  # type: ignore[attr-defined]
        msp.add_arc((15, 20), 1.5, 180, 360)  # type: ignore[attr-defined]
        msp.add_circle((45, 20), 1.5)  # type: ignore[attr-defined]
        msp.add_arc((30, 20), 1.5, 90, 0)  # type: ignore[attr-defined]  # 3/4 of a turn, open

    drawing = read_drawing(write_dxf(tmp_path / "arcs.dxf", build))
    text = initial_job(drawing).replace('origin = "lower-left"', 'origin = "drawing"')
    assert "2 circle(s) of ø3 mm on layer '0': small, drilled" in text
    job = tmp_path / "job.toml"
    job.write_text(text)
    done = run_job(drawing, load_target("grbl"), load_job(job))
    drilled = [c for _, c in done.program.commands if isinstance(c, DrillCycle)]
    assert sorted((c.x, c.y) for c in drilled) == [(15.0, 20.0), (45.0, 20.0)]
    profile = done.operations[-1]
    assert profile.operation.kind == "profile outside"
    assert [(c.source or "").split()[0] for c in profile.placed.contours] == ["LWPOLYLINE"]
    assert not any("narrower than the 3 mm tool" in w for w in done.program.warnings)


def test_a_drill_selecting_half_a_circle_refuses_it(tmp_path: Path) -> None:
    from tests.shapes import write_dxf

    def build(msp: object) -> None:
        msp.add_arc((15, 20), 1.5, 0, 180, dxfattribs={"layer": "H"})  # type: ignore[attr-defined]
        msp.add_arc((15, 20), 1.5, 180, 300, dxfattribs={"layer": "H"})  # type: ignore[attr-defined]

    drawing = read_drawing(write_dxf(tmp_path / "half.dxf", build))
    job = tmp_path / "job.toml"
    job.write_text(
        '[[tools]]\nid = 1\ntype = "drill"\ndiameter = 3\n'
        '[[operations]]\ntype = "drill"\ntool = 1\nlayers = ["H"]\ndepth = 2\n'
    )
    with pytest.raises(InputError, match="which is not a circle"):
        run_job(drawing, load_target("grbl"), load_job(job))


def test_closed_selects_a_shape_drawn_as_several_entities(tmp_path: Path) -> None:
    """``closed = true`` (as ``camtool job init`` writes for a profile) keeps a closed chain.

    LibreCAD's ``elektro/dev/dev13.dxf`` draws its outline as four LINEs around a closed
    LWPOLYLINE. Each LINE alone is open; left out, the inner shape would be the outermost
    and be cut on its outside, through the part. As the planner chains them, the LINEs
    are one closed square: cut outside (the 2 mm tool's
    centre 1 mm out), the inner rectangle inside it (1 mm in); a centre line from a corner is
    construction, which the planner leaves out, so it is not chained with the square either.
    """

    def build(msp: object) -> None:
        corners = [(0, 0), (12, 0), (12, 12), (0, 12)]
        for a, b in zip(corners, corners[1:] + corners[:1], strict=True):
            msp.add_line(a, b)  # type: ignore[attr-defined]
        msp.add_lwpolyline([(4, 4), (8, 4), (8, 8), (4, 8)], close=True)  # type: ignore[attr-defined]
        msp.add_line((12, 6), (16, 6))  # type: ignore[attr-defined]  # open: not cut
        # a centre line from a corner: construction, which the planner does not chain
        msp.add_line((0, 0), (-5, -5), dxfattribs={"layer": "CENTER"})  # type: ignore[attr-defined]

    drawing, job = _job_on(
        tmp_path,
        build,
        '[[tools]]\nid = 1\ntype = "end-mill"\ndiameter = 2\n'
        '[[operations]]\ntype = "profile"\ntool = 1\nclosed = true\nside = "outside"\n'
        "depth = 1\n",
    )
    done = run_job(drawing, load_target("grbl"), job)
    z, cuts = 0.0, []  # the moves at the depth (a move that keeps Z has none)
    for m in done.program.moves:
        z = m.z if m.z is not None else z
        if isinstance(m, Linear) and z == -1.0:
            cuts.append(m)
    xs = [m.x for m in cuts]
    assert min(xs) == pytest.approx(-1.0) and max(xs) == pytest.approx(13.0)
    inner = [m for m in cuts if 4.0 < m.x < 8.0 and 4.0 < m.y < 8.0]
    assert inner and all(
        m.x == pytest.approx(5.0)
        or m.x == pytest.approx(7.0)
        or m.y == pytest.approx(5.0)
        or m.y == pytest.approx(7.0)
        for m in inner
    )
    assert any("not cut: 1 contour(s)" in w for w in done.program.warnings)


def test_a_plan_refused_in_a_job_names_the_operation_and_its_keys(tmp_path: Path) -> None:
    """Three tabs on a 1 mm square: refused naming the operation and the job's keys."""
    from camtool.model.errors import ToolpathError

    drawing, job = _square(
        tmp_path,
        1.0,
        '[[tools]]\nid = 1\ntype = "end-mill"\ndiameter = 3\n[[operations]]\nname = "outline"'
        '\ntype = "profile"\ntool = 1\nside = "outside"\ndepth = 3\ntabs = 3\n',
    )
    with pytest.raises(ToolpathError) as caught:
        run_job(drawing, load_target("grbl"), job)
    message = str(caught.value)
    assert message.startswith("job.toml: operation 1 ('outline'): 3 tab(s) do not fit")
    assert "use fewer tabs or a smaller tab_width" in message and "--" not in message


def test_a_drawing_of_points_only_is_drilled_by_a_job_and_refused_by_a_profile(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A DXF of POINTs alone (ezdxf's MODEL.dxf is one): its box is its points."""
    from camtool.cli.main import main
    from tests.shapes import write_dxf

    def build(msp: object) -> None:
        for at in ((4.0, 3.0), (10.0, 8.5)):
            msp.add_point(at)  # type: ignore[attr-defined]

    dxf = write_dxf(tmp_path / "points.dxf", build)
    drawing = read_drawing(dxf)
    assert drawing.contours == () and drawing.bbox() == (4.0, 3.0, 10.0, 8.5)
    job = tmp_path / "job.toml"
    job.write_text(
        '[[tools]]\nid = 5\ntype = "drill"\ndiameter = 1\n'
        '[[operations]]\ntype = "drill"\ntool = 5\ndepth = 2\n'
    )
    done = run_job(drawing, load_target("grbl"), load_job(job))
    feeds = [m for m in done.program.moves if isinstance(m, Linear)]
    assert [(m.x, m.y, m.z) for m in feeds] == [(4.0, 3.0, -2.0), (10.0, 8.5, -2.0)]
    out = tmp_path / "out.nc"
    assert main(["inspect", str(dxf)]) == 0
    capsys.readouterr()
    assert main(["post", str(dxf), "-t", "grbl", "-o", str(out)]) == 3
    assert (
        f"error: {dxf}: the options select nothing: the drawing has no contour, only 2 points"
        in (capsys.readouterr().err)
    )
    assert not out.exists()
    # --fit has nothing to size (no drill drills the points): the same refusal, not a bbox
    # of nothing as an internal error
    assert main(["post", str(dxf), "-t", "grbl", "--fit", "100", "100", "-o", str(out)]) == 3
    assert "the options select nothing" in capsys.readouterr().err
    assert not out.exists()


def test_the_one_operation_shorthand_runs_the_same_path(tmp_path: Path) -> None:
    from camtool.jobs.pipeline import post_drawing
    from camtool.toolpath.options import PlanOptions

    drawing = read_drawing(ROOT / "samples" / "plate.dxf")
    plan = PlanOptions(offset="outside", tool_diameter=3.0, depth=3.0)
    done = post_drawing(drawing, load_target("grbl"), plan)
    assert len(done.operations) == 1 and done.plan is not None
    assert not any(isinstance(c, ToolChange) for _, c in done.program.commands)
    assert done.program.notes[1] == "tool diameter 3 mm, offset outside"


def test_operations_that_cut_the_same_contour_twice_are_warned_about(tmp_path: Path) -> None:
    text = (ROOT / "samples" / "part.toml").read_text()
    text += '[[operations]]\ntype = "profile"\ntool = 1\nlayers = ["OUTLINE"]\ndepth = 1\n'
    path = tmp_path / "job.toml"
    path.write_text(text)
    drawing = read_drawing(ROOT / "samples" / "part.dxf")
    done = run_job(drawing, load_target("grbl"), load_job(path))
    assert any("operation 5 (profile outside) cuts LWPOLYLINE" in w for w in done.warnings)


def test_between_two_holes_the_drill_rises_to_clearance(part: object) -> None:
    moves = _moves(part, 1)
    z = None
    for a, b in pairwise(moves):
        z = a.z if a.z is not None else z
        if isinstance(b, Rapid) and (b.x, b.y) != (a.x, a.y):
            assert z == 10.0


def test_a_hole_selected_alone_for_an_outside_profile_is_warned_about(tmp_path: Path) -> None:
    from tests.shapes import write_dxf

    def build(msp: object) -> None:
        msp.add_lwpolyline(  # type: ignore[attr-defined]
            [(0, 0), (60, 0), (60, 40), (0, 40)], close=True, dxfattribs={"layer": "EDGE"}
        )
        msp.add_circle((30, 20), 8, dxfattribs={"layer": "CUTOUT"})  # type: ignore[attr-defined]

    dxf = write_dxf(tmp_path / "plate.dxf", build)
    job = tmp_path / "job.toml"
    job.write_text(
        "[[tools]]\nid = 1\ndiameter = 3\n"
        '[[operations]]\ntype = "profile"\ntool = 1\nlayers = ["CUTOUT"]\nside = "outside"\n'
        "depth = 2\n"
        '[[operations]]\ntype = "profile"\ntool = 1\nlayers = ["EDGE"]\ndepth = 2\n'
    )
    done = run_job(read_drawing(dxf), load_target("grbl"), load_job(job))
    (warning,) = [w for w in done.warnings if "cuts into the part" in w]
    assert warning.startswith("operation 1 (profile outside) cuts CIRCLE")
    assert 'give that operation side = "inside"' in warning
    fixed = job.read_text().replace('side = "outside"', 'side = "inside"')
    job.write_text(fixed)
    done = run_job(read_drawing(dxf), load_target("grbl"), load_job(job))
    assert not [w for w in done.warnings if "cuts into the part" in w]


def test_the_first_operation_s_moves_are_taken_not_copied() -> None:
    # a job of one operation over 200 000 LINEs holds a million moves: a renumbered copy of
    # each (for an offset of 0) doubled them; later operations are renumbered
    from camtool.jobs import run
    from camtool.model.program import Linear, Move, Rapid

    new: list[Move] = [Rapid(0.0, 0.0, 5.0, 1), Linear(1.0, 0.0, 100.0, -1.0, 1)]
    planned = run._Planned(list(new), [], [], None, None)  # type: ignore[arg-type]
    moves: list[Move] = []
    run._join(moves, [], planned, 0)
    assert all(a is b for a, b in zip(moves, new, strict=True))
    later: list[Move] = []
    run._join(later, [], planned, 3)
    assert [m.contour for m in later] == [4, 4]


def test_each_operation_s_placed_drawing_is_its_share_of_the_job_s(part: object) -> None:
    """Shifted once: an operation's placed contours are the job's (no second copy), in order,
    and each is its contour of the drawing moved by the work-zero shift of +1.5 mm."""
    drawing = read_drawing(ROOT / "samples" / "part.dxf")
    runs = part.operations  # type: ignore[attr-defined]
    joined = [c for r in runs for c in r.placed.contours]
    placed = part.placed.contours  # type: ignore[attr-defined]
    assert len(joined) == len(placed)
    assert all(a is b for a, b in zip(joined, placed, strict=True))
    by_source = {c.source: c for c in drawing.contours}
    for contour in joined:
        drawn = by_source[contour.source]
        assert _xy(*contour.start) == _xy(drawn.start[0] + SHIFT, drawn.start[1] + SHIFT)


def test_what_no_operation_selects_is_counted_as_chained(tmp_path: Path) -> None:
    """An open outline drawn as four LINEs is one open contour not cut, as inspect says."""

    def build(msp: object) -> None:
        msp.add_lwpolyline(  # type: ignore[attr-defined]
            [(0, 0), (20, 0), (20, 20), (0, 20)], close=True, dxfattribs={"layer": "PART"}
        )
        for a, b in [((30, 0), (40, 0)), ((40, 0), (40, 10)), ((40, 10), (30, 10))]:
            msp.add_line(a, b, dxfattribs={"layer": "SKETCH"})  # type: ignore[attr-defined]
        msp.add_line((30, 20), (40, 20), dxfattribs={"layer": "SKETCH"})  # type: ignore[attr-defined]

    drawing, job = _job_on(
        tmp_path,
        build,
        '[[tools]]\nid = 1\ntype = "end-mill"\ndiameter = 2\n'
        '[[operations]]\ntype = "profile"\ntool = 1\nlayers = ["PART"]\nside = "outside"\n'
        "depth = 1\n",
    )
    done = run_job(drawing, load_target("grbl"), job)
    notes = [w for w in done.program.warnings if w.startswith("not cut: ")]
    assert len(notes) == 1
    assert notes[0].startswith("not cut: 2 contour(s) on layer 'SKETCH' (2 open; first LINE")


def test_a_tab_key_with_no_tabs_is_said_in_the_jobs_keys(tmp_path: Path) -> None:
    """``tab_height`` on an outside profile with ``tabs = 0``: named as a key of the operation."""
    drawing, job = _square(
        tmp_path,
        20.0,
        '[[tools]]\nid = 1\ntype = "end-mill"\ndiameter = 2\n'
        '[[operations]]\nname = "outline"\ntype = "profile"\ntool = 1\nside = "outside"\n'
        "depth = 2\ntabs = 0\ntab_height = 1\n",
    )
    done = run_job(drawing, load_target("grbl"), job)
    said = [w for w in done.program.warnings if "no effect" in w]
    assert said == ["operation 1 ('outline'): tab_height has no effect without tabs N"]


def _square(tmp_path: Path, size: float, job_text: str) -> tuple[Drawing, Job]:
    """A ``size`` mm square (layer 0) and the job ``job_text`` for it, read as post reads them."""

    def build(msp: object) -> None:
        corners = [(0, 0), (size, 0), (size, size), (0, size)]
        msp.add_lwpolyline(corners, close=True)  # type: ignore[attr-defined]

    return _job_on(tmp_path, build, job_text)


def _job_on(tmp_path: Path, build: Callable[[Any], None], job_text: str) -> tuple[Drawing, Job]:
    """The drawing ``build(msp)`` fills and the job ``job_text``, read as post reads them."""
    from tests.shapes import write_dxf

    dxf = write_dxf(tmp_path / "drawing.dxf", build)
    job = tmp_path / "job.toml"
    job.write_text(job_text)
    return read_drawing(dxf), load_job(job)


def _outline_open_at_a_corner(msp: object) -> None:
    """A 20 × 20 mm outline whose last corner is not drawn, as boxes.py leaves some parts.

    boxes.py rounds each corner with an arc of its ``burn`` (0.1 mm) and, on some parts,
    ends the outline before the last one: its ends lie 0.1·√2 ≈ 0.1414 mm apart, over
    the default ``close_gap`` (0.02 mm). A 4 × 4 mm hole lies inside.
    """
    msp.add_lwpolyline(  # type: ignore[attr-defined]
        [(0.1, 0), (20, 0), (20, 20), (0, 20), (0, 0.1)], dxfattribs={"layer": "PART"}
    )
    msp.add_lwpolyline(  # type: ignore[attr-defined]
        [(8, 8), (12, 8), (12, 12), (8, 12)], close=True, dxfattribs={"layer": "PART"}
    )


_CLOSED_OUTSIDE = (
    '[[tools]]\nid = 1\ntype = "end-mill"\ndiameter = 2\n'
    '[[operations]]\ntype = "profile"\ntool = 1\nclosed = true\nside = "outside"\n'
    'layers = ["PART"]\ndepth = 1\n'
)


def test_close_gap_closes_an_outline_for_a_closed_selection(tmp_path: Path) -> None:
    """``close_gap`` closes a chain before ``closed = true`` judges it, as the planner does.

    With ``close_gap = 0.2`` the planner would close the outline's 0.1414 mm gap with a
    line; the selection judged the chain as drawn (open), so the part was left out (not
    cut) while the option said it would be closed. Cut outside it, the 2 mm tool's
    centre runs 1 mm out of the 20 mm square: X from -1 to 21; the hole is cut inside
    (X from 9 to 11), not outside as the outermost contour it was while the outline was open.
    """
    drawing, job = _job_on(
        tmp_path, _outline_open_at_a_corner, "[job]\nclose_gap = 0.2\n" + _CLOSED_OUTSIDE
    )
    done = run_job(drawing, load_target("grbl"), job)
    z, xs = 0.0, []
    for m in done.program.moves:
        z = m.z if m.z is not None else z
        if isinstance(m, Linear) and z == -1.0:
            xs.append(m.x)
    assert min(xs) == pytest.approx(-1.0) and max(xs) == pytest.approx(21.0)
    inner = [x for x in xs if 5.0 < x < 15.0]
    assert inner and min(inner) == pytest.approx(9.0) and max(inner) == pytest.approx(11.0)
    assert not [w for w in done.program.warnings if w.startswith("not cut: ")]
    assert [w for w in done.program.warnings if "closed a 0.1414 mm gap" in w]


def test_without_close_gap_the_open_outline_is_not_cut(tmp_path: Path) -> None:
    """At the default ``close_gap`` the outline stays open: not selected, and said so.

    The note says what closes it: its ends are 0.1414 mm apart, so ``close_gap = 0.15``.
    """
    drawing, job = _job_on(tmp_path, _outline_open_at_a_corner, _CLOSED_OUTSIDE)
    done = run_job(drawing, load_target("grbl"), job)
    notes = [w for w in done.program.warnings if w.startswith("not cut: ")]
    assert len(notes) == 1 and "(1 open; first LWPOLYLINE" in notes[0]
    assert notes[0].endswith(
        "; 1 of them end within 0.1414 mm of their start: close_gap = 0.15 in [job] closes them"
    )


def test_a_hole_closed_by_close_gap_and_cut_outside_is_warned_about(tmp_path: Path) -> None:
    """The hole check judges contours as the plan chained them, gaps closed.

    boxes.py's ``Gears.svg`` draws a gear's shaft hole open by 0.1 mm; with ``close_gap``
    the planner closes it and, under an outside profile, cuts it outside itself into the
    gear. Judged as drawn (open) it was no hole, and the program gouged the part unwarned.
    Here a 10 × 10 mm hole open 0.1414 mm at a corner, inside a closed 40 × 40 mm part.
    """

    def build(msp: object) -> None:
        msp.add_lwpolyline(  # type: ignore[attr-defined]
            [(0, 0), (40, 0), (40, 40), (0, 40)], close=True, dxfattribs={"layer": "EDGE"}
        )
        msp.add_lwpolyline(  # type: ignore[attr-defined]
            [(15.1, 15), (25, 15), (25, 25), (15, 25), (15, 15.1)], dxfattribs={"layer": "HOLE"}
        )

    drawing, job = _job_on(
        tmp_path,
        build,
        "[job]\nclose_gap = 0.2\n"
        '[[tools]]\nid = 1\ntype = "end-mill"\ndiameter = 2\n'
        '[[operations]]\ntype = "profile"\ntool = 1\nlayers = ["HOLE"]\nclosed = true\n'
        'side = "outside"\ndepth = 1\n'
        '[[operations]]\ntype = "profile"\ntool = 1\nlayers = ["EDGE"]\nside = "outside"\n'
        "depth = 1\n",
    )
    done = run_job(drawing, load_target("grbl"), job)
    (warning,) = [w for w in done.warnings if "a hole cut outside itself" in w]
    assert warning.startswith("operation 1 (profile outside) cuts LWPOLYLINE")
