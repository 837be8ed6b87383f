"""camtool inspect as a library: counts, findings with their locations, JSON shape."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import pytest

from camtool.importers.lint import check_drawing, inspect_drawing
from camtool.importers.options import ImportOptions
from camtool.model.errors import UsageError
from camtool.model.shapes import Arc, Contour, Drawing, Line
from tests.shapes import write_dxf

TOL = 0.001  # mm, the default --tolerance


def _problem_drawing(msp: Any) -> None:
    msp.doc.layers.add("CUT")
    msp.doc.layers.add("NOTES")
    # a closed square, drawn as four LINEs; the top one is drawn twice (duplicate)
    square = [((0, 0), (10, 0)), ((10, 0), (10, 10)), ((10, 10), (0, 10)), ((0, 10), (0, 0))]
    for a, b in square:
        msp.add_line(a, b, dxfattribs={"layer": "CUT"})
    msp.add_line((0, 10), (10, 10), dxfattribs={"layer": "CUT"})  # reversed duplicate
    # an open L whose corner has a gap of 1.5 tolerances
    msp.add_line((20, 0), (30, 0), dxfattribs={"layer": "CUT"})
    msp.add_line((30, 0.0015), (30, 10), dxfattribs={"layer": "CUT"})
    # a zero-length line and some text
    msp.add_line((40, 5), (40, 5), dxfattribs={"layer": "CUT"})
    msp.add_text("part 7", dxfattribs={"layer": "NOTES"})


@pytest.fixture
def report(tmp_path: Path) -> Any:
    return inspect_drawing(write_dxf(tmp_path / "problems.dxf", _problem_drawing))


def test_counts_by_type_and_layer(report: Any) -> None:
    assert report.entities == (("LINE", "CUT", 8), ("TEXT", "NOTES", 1))
    assert report.units == "mm" and report.tolerance == TOL
    assert report.bbox == (0.0, 0.0, 30.0, 10.0)
    (cut,) = report.layers
    # the square closes; the duplicate line and the two L pieces stay open
    assert (cut.layer, cut.closed, cut.open, cut.lines, cut.arcs) == ("CUT", 1, 3, 7, 0)


def test_each_problem_is_found_with_its_location(report: Any) -> None:
    counts = report.counts()
    assert counts["duplicate"] == 1 and counts["gap"] == 1 and counts["zero-length"] == 1
    (dup,) = [f for f in report.findings if f.kind == "duplicate"]
    assert (
        dup.location in ((10.0, 10.0), (0.0, 10.0))
        and "cut twice" in dup.message
        and dup.message.startswith("duplicate line")
    )
    (gap,) = [f for f in report.findings if f.kind == "gap"]
    assert gap.location == pytest.approx((30.0, 0.00075))
    assert "gap of 0.0015 mm at (30.0000, 0.0008)" in gap.message
    (zero,) = [f for f in report.findings if f.kind == "zero-length"]
    assert zero.location == (40.0, 5.0) and zero.sources[0].startswith("LINE #")
    opened = [f for f in report.findings if f.kind == "open-contour"]
    assert len(opened) == 3
    assert {f.location for f in opened} >= {(20.0, 0.0), (30.0, 0.0015)}
    (text,) = [f for f in report.findings if f.kind == "skipped"]
    assert "TEXT #" in text.message and "text is not cut" in text.message


def test_json_shape(report: Any) -> None:
    data = json.loads(json.dumps(report.to_json()))
    assert set(data) >= {
        "source", "units", "tolerance_mm", "bbox_mm", "size_mm", "entities",
        "block_entities", "contours", "warnings", "findings", "finding_counts",
    }  # fmt: skip
    assert data["entities"][0] == {"type": "LINE", "layer": "CUT", "count": 8}
    assert data["contours"]["closed"] == 1 and data["contours"]["open"] == 3
    assert data["contours"]["by_layer"] == [
        {"layer": "CUT", "closed": 1, "open": 3, "lines": 7, "arcs": 0}
    ]
    gap = next(f for f in data["findings"] if f["kind"] == "gap")
    assert set(gap) == {"kind", "message", "location", "sources"}
    assert gap["location"] == pytest.approx([30.0, 0.00075])
    assert data["finding_counts"]["gap"] == 1
    assert any("skipped 1 TEXT entity" in w for w in data["warnings"])


def test_text_report_for_people(report: Any) -> None:
    text = report.text()
    assert "entities in model space:" in text
    assert re.search(r"^  LINE +CUT +8$", text, re.M) and re.search(
        r"^  TEXT +NOTES +1$", text, re.M
    )
    assert re.search(r"^  CUT +1 +3 +7 +0$", text, re.M)  # layer, closed, open, lines, arcs
    assert "gaps just above the tolerance: 1" in text
    assert "duplicate segments: 1" in text
    assert "contours: 4 (1 closed, 3 open)" in text


def test_gap_just_within_the_tolerance_is_joined_not_reported() -> None:
    drawing = Drawing(
        (
            Contour((Line((0, 0), (10, 0)),), False, "0", "a"),
            Contour((Line((10, 0.0009), (10, 10)),), False, "0", "b"),
            Contour((Line((10, 10.02), (0, 10.02)),), False, "0", "c"),  # 20 tolerances away
        )
    )
    chained, findings = check_drawing(drawing, TOL)
    assert len(chained) == 2
    assert not [f for f in findings if f.kind == "gap"]


def test_a_chain_tolerance_chains_and_judges_gaps_as_the_planner_does() -> None:
    # the 0.0015 mm corner gap of the problem drawing's L, and 0.02 mm to the third line
    drawing = Drawing(
        (
            Contour((Line((0, 0), (10, 0)),), False, "0", "a"),
            Contour((Line((10, 0.0015), (10, 10)),), False, "0", "b"),
            Contour((Line((10, 10.02), (0, 10.02)),), False, "0", "c"),
        )
    )
    chained, findings = check_drawing(drawing, TOL, chain_tolerance=0.01)
    assert len(chained) == 2  # a + b joined (0.0015 ≤ 0.01); c is 0.02 mm away: a gap
    (gap,) = [f for f in findings if f.kind == "gap"]
    assert gap.location == pytest.approx((10.0, 10.01)) and "0.01 mm" in gap.message
    # 0: only coincident ends meet (joint_distance: 1e-9 mm), so nothing is joined
    chained, _ = check_drawing(drawing, TOL, chain_tolerance=0.0)
    assert len(chained) == 3
    with pytest.raises(UsageError, match="--chain-tolerance"):
        check_drawing(drawing, TOL, chain_tolerance=-0.01)


def test_overlapping_collinear_lines_and_arcs() -> None:
    drawing = Drawing(
        (
            Contour((Line((0, 0), (10, 0)),), False, "0", "long"),
            Contour((Line((6, 0), (14, 0)),), False, "0", "shifted"),  # shares 4 mm
            Contour((Line((10, 0), (12, 5)),), False, "0", "touching"),  # only an end in common
            Contour((Arc((25, 0), (15, 0), (20, 0), False),), False, "0", "upper half"),
            Contour((Arc((20, 5), (25, 0), (20, 0), True),), False, "0", "quarter"),
        )
    )
    _, findings = check_drawing(drawing, TOL)
    overlaps = [f for f in findings if f.kind == "overlap"]
    assert len(overlaps) == 2
    line, arc = overlaps
    assert line.sources == ("long", "shifted") and "share 4 mm" in line.message
    assert line.location == pytest.approx((8.0, 0.0))
    # the quarter (90° of radius 5) lies on the upper half: 5π/2 mm shared
    assert arc.sources == ("upper half", "quarter") and "share 7.854 mm" in arc.message


def test_tiny_segments_use_ten_tolerances_by_default() -> None:
    drawing = Drawing(
        (Contour((Line((0, 0), (0.005, 0)), Line((0.005, 0), (5, 0))), False, "0", "p"),)
    )
    _, findings = check_drawing(drawing, TOL)
    (tiny,) = [f for f in findings if f.kind == "tiny-segment"]
    assert tiny.location == (0.0, 0.0) and "0.005 mm" in tiny.message
    _, none = check_drawing(drawing, TOL, tiny_mm=0.001)
    assert not [f for f in none if f.kind == "tiny-segment"]


def test_inspect_follows_the_layer_and_tolerance_options(tmp_path: Path) -> None:
    path = write_dxf(tmp_path / "p.dxf", _problem_drawing)
    wide = inspect_drawing(path, ImportOptions(tolerance=0.002, layers=("CUT",)))
    assert "gap" not in wide.counts()  # 0.0015 mm is within 0.002 mm: joined
    assert "skipped" not in wide.counts()  # NOTES not selected


def test_clean_drawing_says_so(tmp_path: Path) -> None:
    path = write_dxf(tmp_path / "ok.dxf", lambda m: m.add_circle((0, 0), 5))
    report = inspect_drawing(path)
    assert report.findings == () and "no problems found" in report.text()


def test_a_spline_drawn_twice_is_one_duplicate_finding(tmp_path: Path) -> None:
    def build(msp: Any) -> None:
        for _ in range(2):
            msp.add_open_spline([(0, 0, 0), (10, 20, 0), (30, -10, 0), (40, 10, 0)])

    report = inspect_drawing(write_dxf(tmp_path / "twice.dxf", build))
    (dup,) = [f for f in report.findings if f.kind == "duplicate"]
    fitted = len(_fitted_segments(tmp_path / "twice.dxf"))
    assert dup.message.startswith(f"{fitted} duplicate segments at (0.0000, 0.0000)")
    assert len(dup.sources) == 2 and dup.location == (0.0, 0.0)


def _fitted_segments(path: Path) -> tuple[Any, ...]:
    from camtool.importers.dxf import read_dxf

    return read_dxf(path).contours[0].segments


def test_inspect_lists_the_repairs_of_a_damaged_dxf(tmp_path: Path) -> None:
    # the importer's warning is one line with counts; the repairs themselves are findings
    path = tmp_path / "part.dxf"
    path.write_text(  # no EOF: read in recover mode, whose auditor fixes the axis ratio 2
        "  0\nSECTION\n  2\nENTITIES\n  0\nELLIPSE\n  8\n0\n 10\n0.0\n 20\n0.0\n 30\n0.0\n"
        " 11\n10.0\n 21\n0.0\n 31\n0.0\n 40\n2.0\n 41\n0.0\n 42\n6.283185307179586\n"
        "  0\nENDSEC\n"
    )
    report = inspect_drawing(path)
    (warning,) = [w for w in report.warnings if "damaged" in w]
    assert "\n" not in warning and "1 fixes" in warning and "camtool inspect" in warning
    (repaired,) = [f for f in report.findings if f.kind == "repaired"]
    assert repaired.message.startswith("fixed: ") and "axis-ratio" in repaired.message
    assert "repairs made to read a damaged file" in report.text()


def test_what_ezdxf_logs_while_reading_is_a_warning_not_raw_stderr(
    tmp_path: Path, capfd: pytest.CaptureFixture[str]
) -> None:
    """Two LINEs with one handle (as ezdxf's cc_dxflib.dxf has): read, and said in our words."""
    path = tmp_path / "dup.dxf"
    line = "  0\nLINE\n  5\nA1\n  8\n0\n 10\n{x}\n 20\n0\n 30\n0\n 11\n10\n 21\n{y}\n 31\n0\n"
    path.write_text(
        "  0\nSECTION\n  2\nENTITIES\n"
        + line.format(x=0, y=0)
        + line.format(x=10, y=10)
        + "  0\nENDSEC\n  0\nEOF\n"
    )
    report = inspect_drawing(path)
    assert capfd.readouterr().err == ""
    (warning,) = [w for w in report.warnings if "ezdxf noted" in w]
    assert warning == (
        f"{path}: ezdxf noted 1 problem(s) while reading it (Found non-unique entity handle "
        "#A1, data validation is required.); check the result (`camtool inspect` lists them), "
        "or re-save the file from the CAD program"
    )
    assert [f.kind for f in report.findings if f.kind in ("noted", "repaired")] == ["noted"]
    assert "what ezdxf noted while reading the file" in report.text()


def test_a_whole_copy_is_not_said_to_be_cut_twice(tmp_path: Path) -> None:
    """Two polylines on one square: inspect finds the duplicate, post cuts the square once."""
    from camtool.importers import read_drawing
    from camtool.toolpath.copies import drop_copies

    def twice(msp: Any) -> None:
        for _ in range(2):
            msp.add_lwpolyline([(0, 0), (10, 0), (10, 10), (0, 10)], close=True)

    path = write_dxf(tmp_path / "copy.dxf", twice)
    done = inspect_drawing(path, ImportOptions())
    (dup,) = [f for f in done.findings if f.kind == "duplicate"]
    assert "unless a whole contour repeats another" in dup.message
    kept, findings, _ = drop_copies(check_drawing(read_drawing(path), TOL)[0])
    assert len(kept) == 1 and "cut once" in findings[0].message
