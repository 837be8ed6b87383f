"""A drawing larger than the machine's travel is refused before its curves are fitted.

Inkscape's filters.svg (3 275 mm wide) posted for GRBL (200 × 200 mm) without --fit took
65 s and 1.29 GB to be refused after planning. With --offset on or outside the toolpath
passes within the chaining and fitting tolerances of every point of the drawing, so the
drawing's extent settles it at once. These tests hold: the refusal comes before any fit
or planning; it is exact at the edge (a drawing that fits, within the tolerances, is
planned and its program judged by the usual check); points that are not drawn (a path of
zero length) do not count; inside offsets and pockets, whose cuts may vanish, are left to
the check after planning.
"""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any

import pytest

import camtool.importers.svg as svg_importer
import camtool.toolpath.plan as plan_module
from camtool.cli.main import main
from camtool.jobs.pipeline import post_bytes, post_path
from camtool.model.errors import DialectError
from camtool.post.registry import load_target
from camtool.toolpath.options import PlanOptions
from tests.importers.svgutil import svg
from tests.shapes import write_dxf

GRBL_TRAVEL = 200.0  # mm, GRBL's default $130/$131 in the built-in profile
BEZ = '<path d="M 0 50 C 20 0, 80 100, {w} 50" fill="none" stroke="black"/>'


def _wide(tmp_path: Path, width_mm: float, extra: str = "") -> Path:
    """An SVG whose one Bézier spans ``width_mm`` (1 user unit = 1 mm)."""
    root = f'width="{width_mm + 10}mm" height="100mm" viewBox="0 0 {width_mm + 10} 100"'
    return svg(tmp_path, BEZ.format(w=width_mm) + extra, root=root, name=f"w{width_mm}.svg")


def _never(*_: Any, **__: Any) -> Any:
    raise AssertionError("called after the drawing was found too large")


def _planned(monkeypatch: pytest.MonkeyPatch) -> list[bool]:
    """A list that gets ``True`` each time an operation is planned."""
    planned: list[bool] = []
    plan_unplaced = plan_module.plan_unplaced

    def noting(*args: Any, **kwargs: Any) -> Any:
        planned.append(True)
        return plan_unplaced(*args, **kwargs)

    monkeypatch.setattr(plan_module, "plan_unplaced", noting)
    return planned


def test_the_travel_is_grbls() -> None:
    assert load_target("grbl").machine.travel_mm == (GRBL_TRAVEL, GRBL_TRAVEL)


def test_a_drawing_wider_than_the_travel_is_refused_before_any_fit(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = _wide(tmp_path, 1000.0)
    monkeypatch.setattr(svg_importer, "_prefitted", _never)
    monkeypatch.setattr(plan_module, "plan_unplaced", _never)
    plan = PlanOptions(offset="on")
    with pytest.raises(DialectError, match=r"at least 1000 × \d+(\.\d+)? mm") as err:
        post_path(path, load_target("grbl"), plan)
    assert "refused before planning" in str(err.value)
    assert "--fit" in str(err.value) and "travel of GRBL" in str(err.value)
    with pytest.raises(DialectError, match="refused before planning"):
        post_bytes(path.read_bytes(), path.name, load_target("grbl"), plan)


_RECT = '<rect x="0" y="0" width="{w}" height="20" fill="none" stroke="black"/>'


def test_an_outside_offset_is_judged_once_read_by_what_it_cuts(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """An outside offset cuts only closed contours: a 1000 mm open path beside a 20 mm
    square is left out (with a warning), so it is no reason to refuse the square; a
    1000 mm rectangle is refused once read, before planning."""
    plan = PlanOptions(offset="outside", tool_diameter=2.0)
    square = _wide(tmp_path, 1000.0, _RECT.format(w=20))
    job = post_path(square, load_target("grbl"), plan)
    xs = [m.x for m in job.program.moves if m.x is not None]
    assert max(xs) - min(xs) == pytest.approx(22.0, abs=1e-6)
    assert any("not cut: open contour" in w for w in job.warnings)
    monkeypatch.setattr(plan_module, "plan_unplaced", _never)
    root = 'width="1010mm" height="100mm" viewBox="0 0 1010 100"'
    wide = svg(tmp_path, _RECT.format(w=1000), root=root, name="rect.svg")
    with pytest.raises(DialectError, match=r"at least 1000 × 20 mm.*refused before planning"):
        post_path(wide, load_target("grbl"), plan)


def test_the_cli_refuses_it_with_exit_code_1_and_writes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out.gcode"
    assert main(["post", str(_wide(tmp_path, 1000.0)), "-t", "grbl", "-o", str(out)]) == 1
    assert "refused before planning" in capsys.readouterr().err
    assert not out.exists()


def test_scale_counts(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path = _wide(tmp_path, 150.0)  # fits as drawn, 300 mm at --scale 2 does not
    monkeypatch.setattr(plan_module, "plan_unplaced", _never)
    with pytest.raises(DialectError, match=r"at least 300 × .* at --scale 2"):
        post_path(path, load_target("grbl"), PlanOptions(scale=2.0))


def test_a_drawing_that_fits_within_the_tolerances_is_planned(tmp_path: Path) -> None:
    # 200.005 mm: over the travel by less than the chaining tolerance (0.01 mm) each side;
    # the check before planning leaves it to planning, which judges the toolpath itself.
    job = post_path(_wide(tmp_path, 199.99), load_target("grbl"), PlanOptions())
    assert job.program.moves
    with pytest.raises(DialectError, match=r"^the toolpath is 200\.005 × "):
        post_path(_wide(tmp_path, 200.005), load_target("grbl"), PlanOptions())


def test_points_that_are_not_drawn_do_not_count(tmp_path: Path) -> None:
    far = '<path d="M 900 90 L 900 90" fill="none" stroke="black"/>'  # zero length
    job = post_path(_wide(tmp_path, 100.0, far), load_target("grbl"), PlanOptions())
    xs = [m.x for m in job.program.moves]
    assert max(xs) - min(xs) == pytest.approx(100.0, abs=1e-6)


@pytest.mark.parametrize("offset", ["inside", "pocket"])
def test_inside_offsets_and_pockets_are_judged_after_planning(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, offset: str
) -> None:
    path = svg(
        tmp_path,
        '<rect x="0" y="0" width="1000" height="50" fill="none" stroke="black"/>',
        root='width="1010mm" height="100mm" viewBox="0 0 1010 100"',
    )
    planned = _planned(monkeypatch)
    with pytest.raises(DialectError, match=r"^the toolpath is 99\d(\.\d+)? × "):
        post_path(path, load_target("grbl"), PlanOptions(offset=offset, tool_diameter=3.0))
    assert planned == [True]


def test_a_dxf_is_checked_once_read(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    def build(msp: Any) -> None:
        msp.add_line((0, 0), (640, 0))
        msp.add_open_spline([(0, 10, 0), (200, 90, 0), (400, -40, 0), (640, 30, 0)], degree=3)

    path = write_dxf(tmp_path / "long.dxf", build)
    monkeypatch.setattr(plan_module, "plan_unplaced", _never)
    with pytest.raises(DialectError, match=r"at least 640 × .*refused before planning"):
        post_path(path, load_target("grbl"), PlanOptions())


def test_a_dxf_is_refused_as_its_contours_are_read_before_the_other_curves_are_fitted(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A drawing of many splines, the first one already larger than the travel: refused after
    fitting that one (the others are not fitted)."""
    import camtool.importers.dxf_entities as entities

    def build(msp: Any) -> None:
        for k in range(30):
            cps = [(0, 5 * k, 0), (200, 90 + 5 * k, 0), (400, -40 + 5 * k, 0), (640, 30, 0)]
            msp.add_open_spline(cps, degree=3)

    path = write_dxf(tmp_path / "splines.dxf", build)
    fitted: list[int] = []
    spline_segments = entities.spline_segments

    def counting(entity: Any, tolerance: float) -> Any:
        fitted.append(1)
        return spline_segments(entity, tolerance)

    monkeypatch.setattr(entities, "spline_segments", counting)
    monkeypatch.setattr(plan_module, "plan_unplaced", _never)
    with pytest.raises(DialectError, match=r"at least 640 × .*refused before planning"):
        post_path(path, load_target("grbl"), PlanOptions())
    assert len(fitted) == 1
    # within the travel (--scale 0.25: 160 mm), every spline is read and the job planned
    fitted.clear()
    monkeypatch.undo()
    monkeypatch.setattr(entities, "spline_segments", counting)
    job = post_path(path, load_target("grbl"), PlanOptions(scale=0.25))
    assert len(fitted) == 30 and job.result.blocks


def test_a_minsert_is_refused_as_its_cells_are_placed_not_after_all_of_them(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """One MINSERT of 300 × 300 cells 11 mm apart (3 299 mm wide): the check runs as the
    cells are placed, so the refusal comes once the cells read so far span more than the
    200 mm travel (19 cells of the first row: the 19th ends at 18 × 11 + 10 = 208 mm), not
    after the 90 000 cells (a hostile file holds 10⁶)."""
    import camtool.importers.dxf as dxf_importer

    def build(msp: Any) -> None:
        block = msp.doc.blocks.new("SQUARE")
        block.add_lwpolyline([(0, 0), (10, 0), (10, 10), (0, 10)], close=True)
        msp.add_blockref("SQUARE", (0, 0)).grid(size=(300, 300), spacing=(11, 11))

    path = write_dxf(tmp_path / "grid.dxf", build)
    read: list[int] = []
    item = dxf_importer._Reader._item

    def counting(self: Any, *args: Any, **kwargs: Any) -> Any:
        read.append(1)
        return item(self, *args, **kwargs)

    monkeypatch.setattr(dxf_importer._Reader, "_item", counting)
    monkeypatch.setattr(plan_module, "plan_unplaced", _never)
    with pytest.raises(DialectError, match=r"at least 20\d × 10 mm, .*refused before planning"):
        post_path(path, load_target("grbl"), PlanOptions())
    assert len(read) == 19  # columns 0..18: the 19th cell ends at 208 mm


def test_standard_input_is_checked_too(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    def build(msp: Any) -> None:
        msp.add_lwpolyline([(0, 0), (640, 0), (640, 30), (0, 30)], close=True)

    data = write_dxf(tmp_path / "long.dxf", build).read_bytes()
    monkeypatch.setattr(plan_module, "plan_unplaced", _never)
    monkeypatch.setattr("sys.stdin", io.TextIOWrapper(io.BytesIO(data)))
    out = tmp_path / "out.gcode"
    assert main(["post", "-", "-t", "grbl", "-o", str(out)]) == 1
    assert "the drawing is at least 640 × 30 mm" in capsys.readouterr().err
    assert not out.exists()


def test_a_number_past_the_coordinate_limit_is_refused_as_such(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # 1e300 is no extent to judge: the importer's own refusal (exit 3) names the path
    huge = '<path d="M 0 0 L 1e300 10" fill="none" stroke="black"/>'
    path = svg(tmp_path, '<path d="M 0 0 L 10 10" stroke="black"/>' + huge)
    assert main(["post", str(path), "-t", "grbl", "-o", str(tmp_path / "h.gcode")]) == 3
    err = capsys.readouterr().err
    assert "path[2]" in err and "far too large" in err
    assert "travel" not in err


# Fritzing's SMD_crystal_HC49.svg: a 12 × 5 mm part whose one rect a stray transform moved
# 272 mm off the page. The drawing is "too large" only because of what a viewer does not
# show, so the refusal's --fit remedy would shrink the part 0.72×: it must name the shape.
_PART = '<rect id="part" x="10" y="10" width="20" height="20"/>'
_AWAY = '<rect id="away" x="10" y="10" width="5" height="5" transform="translate(0,400)"/>'


@pytest.mark.parametrize("offset", ["on", "outside", "inside", "pocket"])
def test_a_refusal_for_size_names_the_shapes_off_the_page(
    tmp_path: Path, offset: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """Before planning (on: as read; outside: once read) and after it (inside, pocket), the
    refusal says which shape lies off the page and that deleting it, not --fit, is the
    remedy when it is no part of the job."""
    path = svg(tmp_path, _PART + _AWAY)  # a 100 × 100 mm page
    out = tmp_path / "o.nc"
    argv = ["post", str(path), "-t", "grbl", "--offset", offset, "--tool-diameter", "1"]
    assert main([*argv, "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert "larger than the 200 × 200 mm travel" in err
    assert ("refused before planning" in err) == (offset in ("on", "outside"))
    noun = "shape" if offset == "on" else "contour"
    assert f"but {path}: 1 {noun} lies wholly outside the 100 × 100 mm page" in err
    assert "first rect#away at (10.0000, -315.0000) mm" in err
    assert "delete it or move it onto the page rather than scale the part down" in err
    assert not out.exists()


def test_a_refusal_for_size_without_shapes_off_the_page_says_nothing_of_the_page(
    tmp_path: Path,
) -> None:
    """A drawing that is large on its own page gets the --fit remedy alone."""
    root = 'width="1000mm" height="100mm" viewBox="0 0 1000 100"'
    path = svg(tmp_path, '<rect x="10" y="10" width="900" height="50"/>', root=root)
    for offset in ("on", "inside"):
        plan = PlanOptions(offset=offset, tool_diameter=2.0)
        with pytest.raises(DialectError) as err:
            post_path(path, load_target("grbl"), plan)
        assert "--fit" in str(err.value) and "page" not in str(err.value)


# A job: the box of what its profiles cut on the line or outside (and its engravings) is
# within the toolpath's extent, so a job larger than the travel is refused before any of
# its operations is planned (ezdxf's edgeminer 1_polylines.dxf, 224 m across, with the job
# `job init` wrote: 51 s of planning to the same refusal).
def _job(tmp_path: Path, operations: str) -> Any:
    from camtool.jobs.jobfile import load_job

    path = tmp_path / "job.toml"
    path.write_text(
        '[job]\norigin = "lower-left"\n\n[[tools]]\nid = 1\ndiameter = 3\n\n'
        '[[tools]]\nid = 2\ntype = "drill"\ndiameter = 2\n\n' + operations
    )
    return load_job(path)


def _layers(tmp_path: Path) -> Path:
    """Layer BIG: a 640 × 30 mm rectangle; A: a 150 mm line at x 0…150; B: a 20 mm square at
    x 300…320; HOLES: two 2 mm circles 600 mm apart."""

    def build(msp: Any) -> None:
        msp.add_lwpolyline(
            [(0, 0), (640, 0), (640, 30), (0, 30)], close=True, dxfattribs={"layer": "BIG"}
        )
        msp.add_line((0, 100), (150, 100), dxfattribs={"layer": "A"})
        msp.add_lwpolyline(
            [(300, 100), (320, 100), (320, 120), (300, 120)], close=True, dxfattribs={"layer": "B"}
        )
        for x in (10.0, 610.0):
            msp.add_circle((x, 60), 1.0, dxfattribs={"layer": "HOLES"})

    return write_dxf(tmp_path / "layers.dxf", build)


def _op(kind: str, layer: str, extra: str = "") -> str:
    tool = 2 if kind == "drill" else 1
    return (
        f'[[operations]]\ntype = "{kind}"\ntool = {tool}\nlayers = ["{layer}"]\n'
        f"depth = 1\n{extra}\n"
    )


@pytest.mark.parametrize(
    ("operations", "size"),
    [
        (_op("profile", "BIG", 'side = "outside"'), r"640 × 30"),
        (_op("profile", "BIG", 'side = "on"'), r"640 × 30"),
        # each fits the travel alone; together they span 320 mm
        (_op("engrave", "A") + _op("profile", "B", 'side = "outside"'), r"320 × 20"),
    ],
    ids=["outside", "on", "two-operations"],
)
def test_a_job_larger_than_the_travel_is_refused_before_planning(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, operations: str, size: str
) -> None:
    from camtool.importers import read_drawing
    from camtool.jobs.run import run_job

    drawing = read_drawing(_layers(tmp_path))
    job = _job(tmp_path, operations)
    monkeypatch.setattr(plan_module, "plan_unplaced", _never)
    with pytest.raises(DialectError, match=rf"at least {size} mm.*refused before planning"):
        run_job(drawing, load_target("grbl"), job)


@pytest.mark.parametrize(
    "operations",
    [
        _op("pocket", "BIG"),
        _op("profile", "BIG", 'side = "inside"'),
        _op("drill", "HOLES"),  # at the holes' centres: 600 mm apart, not their circles'
    ],
    ids=["pocket", "inside", "drill"],
)
def test_a_job_s_pockets_inside_profiles_and_drills_are_judged_after_planning(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, operations: str
) -> None:
    from camtool.importers import read_drawing
    from camtool.jobs.run import run_job

    drawing = read_drawing(_layers(tmp_path))
    planned = _planned(monkeypatch)
    with pytest.raises(DialectError, match=r"^the toolpath is (6\d\d|600)(\.\d+)? × "):
        run_job(drawing, load_target("grbl"), _job(tmp_path, operations))
    assert planned == ([] if "drill" in operations else [True])


def test_a_job_within_the_travel_is_planned(tmp_path: Path) -> None:
    from camtool.importers import read_drawing
    from camtool.jobs.run import run_job

    drawing = read_drawing(_layers(tmp_path))
    job = run_job(drawing, load_target("grbl"), _job(tmp_path, _op("engrave", "A")))
    xs = [m.x for m in job.program.moves if m.x is not None]
    assert max(xs) - min(xs) == pytest.approx(150.0, abs=1e-6)


def test_an_outside_profile_s_open_contours_are_not_counted(tmp_path: Path) -> None:
    """The planner leaves an open chain out of an outside profile: a 400 mm open line beside
    a 20 mm square on one layer is no reason to refuse it. A 400 mm square of four LINEs is
    closed once chained, and is one."""
    from camtool.importers import read_drawing
    from camtool.jobs.run import run_job

    def build(msp: Any) -> None:
        msp.add_lwpolyline(
            [(0, 0), (20, 0), (20, 20), (0, 20)], close=True, dxfattribs={"layer": "P"}
        )
        msp.add_line((0, 50), (400, 50), dxfattribs={"layer": "P"})
        for a, b in [
            ((0, 100), (400, 100)),
            ((400, 100), (400, 120)),
            ((400, 120), (0, 120)),
            ((0, 120), (0, 100)),
        ]:
            msp.add_line(a, b, dxfattribs={"layer": "Q"})

    drawing = read_drawing(write_dxf(tmp_path / "open.dxf", build))
    outside = 'side = "outside"'
    job = run_job(drawing, load_target("grbl"), _job(tmp_path, _op("profile", "P", outside)))
    xs = [m.x for m in job.program.moves if m.x is not None]
    assert max(xs) - min(xs) == pytest.approx(23.0, abs=1e-6)  # the square and the tool
    with pytest.raises(DialectError, match=r"at least 400 × 20 mm.*refused before planning"):
        run_job(drawing, load_target("grbl"), _job(tmp_path, _op("profile", "Q", outside)))
