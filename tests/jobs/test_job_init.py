"""``camtool job init``: the first job's guesses, on the sample plate and on real drawings."""

from __future__ import annotations

import math
import re
import tomllib
from pathlib import Path
from typing import Any

import pytest

from camtool.importers import read_drawing
from camtool.jobs.init import initial_job
from camtool.jobs.jobfile import job_from_dict
from camtool.jobs.run import run_job
from camtool.model.errors import InputError
from camtool.model.program import ArcMove, Linear
from camtool.post.registry import load_target
from tests.corpus.conftest import CORPUS
from tests.shapes import write_dxf

ROOT = Path(__file__).resolve().parents[2]
KIN42 = CORPUS / "pkg/librecad-data/usr/share/librecad/library/kinetics/kin42.dxf"


def _ops(text: str) -> list[dict[str, object]]:
    return list(tomllib.loads(text)["operations"])


def test_the_sample_plate_gets_drill_pocket_and_outline_in_that_order() -> None:
    text = initial_job(read_drawing(ROOT / "samples" / "part.dxf"), thickness_mm=6.0)
    ops = _ops(text)
    assert [(op["type"], op.get("side")) for op in ops] == [
        ("drill", None),
        ("pocket", None),
        ("profile", "outside"),
    ]
    drill, _pocket, outline = ops
    assert drill["layers"] == ["HOLES"] and drill["diameter"] == 3.2 and drill["depth"] == 6.5
    assert outline["layers"] == ["OUTLINE"] and outline["tabs"] == 3
    tools = {t["id"]: t for t in tomllib.loads(text)["tools"]}
    assert tools[drill["tool"]]["type"] == "drill" and tools[drill["tool"]]["diameter"] == 3.2
    assert tools[outline["tool"]]["type"] == "end-mill"
    # every guess says why; the open line and the centre lines are left out, said so
    assert "# 4 circle(s) of ø3.2 mm on layer 'HOLES'" in text
    assert '# [[operations]]\n# type = "engrave"' in text
    assert "layer 'CENTER': linetype CENTER: 10 contour(s)" in text


def test_a_layer_of_holes_only_is_cut_on_their_inside(tmp_path: Path) -> None:
    def build(msp: object) -> None:
        msp.add_lwpolyline(  # type: ignore[attr-defined]
            [(0, 0), (100, 0), (100, 50), (0, 50)], close=True, dxfattribs={"layer": "EDGE"}
        )
        msp.add_circle((30, 25), 10, dxfattribs={"layer": "CUTOUTS"})  # type: ignore[attr-defined]
        msp.add_circle((70, 25), 2, dxfattribs={"layer": "CUTOUTS"})  # type: ignore[attr-defined]

    text = initial_job(read_drawing(write_dxf(tmp_path / "p.dxf", build)))
    kinds = [(op["type"], op.get("side"), tuple(op["layers"])) for op in _ops(text)]  # type: ignore[arg-type]
    assert kinds == [
        ("drill", None, ("CUTOUTS",)),  # the ø4 mm circle
        ("profile", "inside", ("CUTOUTS",)),  # the ø20 mm hole, too large to drill
        ("profile", "outside", ("EDGE",)),
    ]


def test_circles_of_one_size_either_side_of_a_rounding_are_one_drill(tmp_path: Path) -> None:
    # Fritzing's gEDA footprints (CAPPR-508P-450D): two pins of ø1.3335 mm whose floats fall
    # either side of 1.3335, rounded to 1 µm as 1.333 and 1.334: one hole size, drilled once
    def build(msp: object) -> None:
        msp.add_circle((10, 10), 1.33349 / 2, dxfattribs={"layer": "PINS"})  # type: ignore[attr-defined]
        msp.add_circle((15.08, 10), 1.33351 / 2, dxfattribs={"layer": "PINS"})  # type: ignore[attr-defined]
        msp.add_circle((20, 10), 0.8, dxfattribs={"layer": "PINS"})  # type: ignore[attr-defined]

    drawing = read_drawing(write_dxf(tmp_path / "pins.dxf", build))
    text = initial_job(drawing, thickness_mm=1.6)
    drills = [op for op in _ops(text) if op["type"] == "drill"]
    assert len(drills) == 2 and len(tomllib.loads(text)["tools"]) == 2
    job = job_from_dict(tomllib.loads(text), source="pins.toml")
    done = run_job(drawing, load_target("linuxcnc"), job)
    assert not [w for w in done.warnings if "again" in w]
    bottoms = [(m.x, m.y) for m in done.program.moves if isinstance(m, Linear) and m.z == -2.1]
    # each hole once (work zero at the lower-left hole's centre: the job's origin)
    assert [x for x, _ in sorted(bottoms)] == pytest.approx([0.0, 5.08, 10.0])
    assert [y for _, y in bottoms] == [0.0, 0.0, 0.0]


def test_pockets_no_common_end_mill_fits_are_named_not_called_no_contour(tmp_path: Path) -> None:
    # pads 0.3 mm wide (a footprint's, Fritzing's SparkFun-QFN20) on a layer whose name says
    # pocket: the smallest end mill job init knows is 0.5 mm, so its guess stays commented
    # and no job is written; the refusal says why, not that the drawing has no contour
    def build(msp: object) -> None:
        for x in (0.0, 1.2):
            msp.add_lwpolyline(  # type: ignore[attr-defined]
                [(x, 0), (x + 0.3, 0), (x + 0.3, 0.65), (x, 0.65)],
                close=True,
                dxfattribs={"layer": "POCKETS"},
            )

    with pytest.raises(InputError) as caught:
        initial_job(read_drawing(write_dxf(tmp_path / "pads.dxf", build)))
    message = str(caught.value)
    assert "has no contour" not in message
    assert "nothing to cut with a common end mill (the smallest 0.5 mm)" in message
    assert 'layers = ["POCKETS"]: all 2 pockets are narrower than the 3 mm end mill' in message


def test_a_part_on_a_drawing_sheet_is_cut_outside_not_inside_the_sheets_border(
    tmp_path: Path,
) -> None:
    # An Autodesk Inventor drawing exported to DXF (the Voron build plate's): the part on
    # 'Visible (ISO)', the sheet's frame on 'Border - Kova (ANSI)' around it. Taken for a
    # part, the frame would make the part's outline a hole of it, cut on its inside: the
    # part a tool's diameter small.
    def build(msp: object) -> None:
        visible = {"layer": "Visible (ISO)"}
        msp.add_lwpolyline(  # type: ignore[attr-defined]
            [(0, 0), (840, 0), (840, 530), (0, 530)], close=True,
            dxfattribs={"layer": "Border - Kova (ANSI)"},
        )  # fmt: skip
        msp.add_lwpolyline(  # type: ignore[attr-defined]
            [(100, 100), (300, 100), (300, 250), (100, 250)], close=True, dxfattribs=visible
        )
        msp.add_circle((200, 175), 20, dxfattribs=visible)  # type: ignore[attr-defined]

    text = initial_job(read_drawing(write_dxf(tmp_path / "sheet.dxf", build)))
    kinds = [(op["type"], op.get("side"), tuple(op["layers"])) for op in _ops(text)]  # type: ignore[arg-type]
    assert kinds == [("profile", "outside", ("Visible (ISO)",))]  # the hole inside, by nesting
    assert "layer 'Border - Kova (ANSI)': construction layer" in text


def test_a_drawing_of_lines_only_is_engraved(tmp_path: Path) -> None:
    def build(msp: object) -> None:
        msp.add_line((0, 0), (10, 0))  # type: ignore[attr-defined]
        msp.add_line((10, 0), (10, 5))  # type: ignore[attr-defined]

    text = initial_job(read_drawing(write_dxf(tmp_path / "sign.dxf", build)))
    assert [op["type"] for op in _ops(text)] == ["engrave"]


def test_an_outline_drawn_as_lines_is_a_part_cut_outside(tmp_path: Path) -> None:
    """A closed outline of LINEs (LibreCAD's ``algoritm/alg11.dxf``: a pentagon) is a part.

    job init chains a layer's entities as the operations' ``closed`` selects them (as the
    planner chains them): the five LINEs are one closed contour, not "lines only" to
    engrave with ``closed = false`` (which would select nothing). The pentagon is cut
    outside, and the job posts.
    """
    corners = [(0, 0), (20, 0), (26, 18), (10, 30), (-6, 18)]

    def build(msp: object) -> None:
        for a, b in zip(corners, corners[1:] + corners[:1], strict=True):
            msp.add_line(a, b)  # type: ignore[attr-defined]
        msp.add_line((20, 0), (30, -5))  # type: ignore[attr-defined]  # a tail: engraved

    drawing = read_drawing(write_dxf(tmp_path / "pentagon.dxf", build))
    text = initial_job(drawing)
    ops = _ops(text)
    assert [(op["type"], op.get("side")) for op in ops] == [("profile", "outside")]
    assert '# type = "engrave"  # 1 open contour(s)' in text
    job = job_from_dict(tomllib.loads(text), source="pentagon.toml")
    done = run_job(drawing, load_target("grbl"), job)
    xs = [m.x for m in done.program.moves if isinstance(m, Linear)]
    # the 1.5 mm tool radius out on both sides of the 32 mm wide pentagon (lower-left zero)
    assert max(xs) - min(xs) > 33.0


def test_a_drawing_with_an_uncoloured_shape_is_not_split_by_colour(tmp_path: Path) -> None:
    """Inkscape's ``blend_modes.svg``: 17 coloured shapes and 200 filled by a gradient.

    A job selects no contour by "no colour", so a layer is split by colour only when every
    shape has one: here one layer, one operation, by layer.
    """
    svg = tmp_path / "blend.svg"
    svg.write_text(
        '<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="60mm" '
        'viewBox="0 0 100 60"><defs><linearGradient id="g"><stop offset="0" '
        'stop-color="red"/><stop offset="1" stop-color="blue"/></linearGradient></defs>'
        '<rect x="5" y="5" width="20" height="20" fill="none" stroke="#ff0000"/>'
        '<rect x="35" y="5" width="20" height="20" fill="none" stroke="#0000ff"/>'
        '<rect x="65" y="5" width="20" height="20" fill="url(#g)"/></svg>'
    )
    drawing = read_drawing(svg)
    assert sorted(c.colour for c in drawing.contours) == ["", "#0000ff", "#ff0000"]
    ops = _ops(initial_job(drawing))
    assert [(op["type"], op.get("layers"), op.get("colours")) for op in ops] == [
        ("profile", ["0"], None)
    ]


def test_a_drawing_of_construction_only_has_nothing_to_cut(tmp_path: Path) -> None:
    def build(msp: object) -> None:
        msp.add_line((0, 0), (10, 0), dxfattribs={"layer": "DIMENSIONS"})  # type: ignore[attr-defined]

    with pytest.raises(InputError, match="nothing to cut: every contour is construction"):
        initial_job(read_drawing(write_dxf(tmp_path / "dims.dxf", build)))


def test_the_points_drill_says_when_the_tool_it_names_is_no_drill(tmp_path: Path) -> None:
    # a plate with two POINTs: the commented drill of the points names tool 1, the plate's
    # end mill, the only tool listed; the line says so. With a hole drilled too, tool 1 is
    # that drill and nothing needs saying.
    def points_drill(name: str, with_hole: bool) -> tuple[str, str]:
        """The tool line of the points' commented drill, and the whole job."""

        def build(msp: Any) -> None:
            msp.add_lwpolyline([(0, 0), (40, 0), (40, 30), (0, 30)], close=True)
            for at in ((10.0, 10.0), (30.0, 20.0)):
                msp.add_point(at)
            if with_hole:
                msp.add_circle((20.0, 15.0), 1.5)

        text = initial_job(read_drawing(write_dxf(tmp_path / name, build)))
        return text.split('# type = "drill"  # 2 point(s)', 1)[1].splitlines()[1], text

    line, _ = points_drill("a.dxf", with_hole=False)
    assert line == "# tool = 1  # the 3 mm end-mill: add a [[tools]] drill, give its id"
    line, text = points_drill("b.dxf", with_hole=True)
    assert line == "# tool = 1" and 'type = "drill"\ndiameter = 3' in text


def test_a_drawing_of_points_only_says_so_and_names_the_drill_operation(tmp_path: Path) -> None:
    """ezdxf's MODEL.dxf and Leica_Disto_S910.dxf: points, no contour; not "construction"."""

    def build(msp: object) -> None:
        for x in (0.0, 10.0, 20.0):
            msp.add_point((x, 5.0), dxfattribs={"layer": "PTS"})  # type: ignore[attr-defined]

    with pytest.raises(InputError) as err:
        initial_job(read_drawing(write_dxf(tmp_path / "points.dxf", build)))
    assert str(err.value) == (
        f"{tmp_path / 'points.dxf'}: nothing to cut: the drawing has no contour, only 3 points "
        "(on layer 'PTS'); a drill operation of a job written by hand drills points "
        "(docs/jobs.md)"
    )


@pytest.mark.skipif(not KIN42.exists(), reason="the LibreCAD corpus is not fetched")
def test_kin42_job_cuts_the_disc_and_not_its_diameter_lines() -> None:
    drawing = read_drawing(KIN42)
    text = initial_job(drawing)
    job = job_from_dict(tomllib.loads(text), source="kin42.toml")
    done = run_job(drawing, load_target("grbl"), job)
    # the two diameter lines of the ø22 mm disc run along X and Y through its centre; cut,
    # the tool would run the whole 22 mm across the part on one of those lines
    cuts = [m for m in done.program.moves if isinstance(m, Linear) and m.z is None]
    starts = [done.program.moves[i - 1] for i, m in enumerate(done.program.moves) if m in cuts]
    for start, move in zip(starts, cuts, strict=True):
        across = abs(move.x - start.x) >= 22 - 1e-6 or abs(move.y - start.y) >= 22 - 1e-6
        assert not across, (start, move)
    assert "LINE" in "\n".join(done.warnings)


def test_a_drawing_larger_than_the_machine_is_fitted_and_said_so(tmp_path: Path) -> None:
    def build(msp: object) -> None:
        msp.add_lwpolyline(  # type: ignore[attr-defined]
            [(0, 0), (388, 0), (388, 100), (0, 100)], close=True, dxfattribs={"layer": "EDGE"}
        )
        msp.add_circle((20, 20), 3, dxfattribs={"layer": "EDGE"})  # type: ignore[attr-defined]

    drawing = read_drawing(write_dxf(tmp_path / "long.dxf", build))
    text = initial_job(drawing, travel_mm=(200.0, 200.0))
    # the outside profile's tool centre runs 1.5 mm outside the part on each side: the part
    # may take 200 - 3 mm of travel, less the 0.01 mm post leaves (its --fit proposal)
    assert "fit = [196.99, 196.99]  # the drawing is 388 × 100 mm; with the 3 mm tool" in text
    assert f"SCALED DOWN to {196.99 / 388:.3g}×" in text
    data = tomllib.loads(text)
    drill = data["operations"][0]
    assert drill["diameter"] == 6.0  # as drawn: a selection is in the drawing's own mm
    tool = {t["id"]: t for t in data["tools"]}[drill["tool"]]
    assert tool["diameter"] == round(6.0 * 196.99 / 388, 3)  # as cut: the ø6 circle scaled
    done = run_job(drawing, load_target("grbl"), job_from_dict(data, source="j.toml"))
    assert done.operations[0].holes == 1


def test_a_machine_without_z_gets_no_heights_depths_tabs_or_drilling(tmp_path: Path) -> None:
    """pic-mmh moves X and Y only (its depth is set by hand): a job of depths it refuses.

    A 6 × 4 mm plate with a ø1.5 mm hole and a 0.5 mm end mill: the hole is profiled on
    its inside (no plunge to drill with), nothing says a depth, a height or a tab, and the
    job posts for pic-mmh.
    """

    def build(msp: object) -> None:
        msp.add_lwpolyline(  # type: ignore[attr-defined]
            [(0, 0), (6, 0), (6, 4), (0, 4)], close=True, dxfattribs={"layer": "EDGE"}
        )
        msp.add_circle((2, 2), 0.75, dxfattribs={"layer": "EDGE"})  # type: ignore[attr-defined]

    drawing = read_drawing(write_dxf(tmp_path / "small.dxf", build))
    target = load_target("pic-mmh")
    assert not target.machine.has_z
    text = initial_job(drawing, tool_diameter=0.5, travel_mm=target.machine.travel_mm, no_z="x")
    for key in ("depth", "step_down", "tabs", "tab_height", "clearance_z", "safe_z", "fit"):
        assert f"{key} =" not in text
    assert "# x has no programmable Z" in text
    data = tomllib.loads(text)
    assert [(op["type"], op.get("side")) for op in data["operations"]] == [("profile", "outside")]
    done = run_job(drawing, target, job_from_dict(data, source="j.toml"))
    cuts = [m for m in done.program.moves if isinstance(m, Linear | ArcMove)]
    # the plate's outside cut runs 0.25 mm outside it: its lower-left is the plate's less that
    x0, y0 = min(m.x for m in cuts) + 0.25, min(m.y for m in cuts) + 0.25
    # the hole's inside cut: the tool centre 0.75 - 0.25 mm from the hole's centre
    around = [m for m in cuts if abs(math.dist((m.x, m.y), (x0 + 2, y0 + 2)) - 0.5) < 0.01]
    assert len(around) >= 2
    assert all(m.z is None for m in cuts)


@pytest.mark.parametrize(("width", "fitted"), [(9.0, False), (9.02, True)])
def test_a_drawing_is_fitted_only_when_its_toolpath_passes_the_travel(
    tmp_path: Path, width: float, fitted: bool
) -> None:
    """With a 1 mm tool the outside profile's toolpath is the drawing plus 1 mm: a 9 × 6 mm
    plate's is the 10 × 7 mm travel itself and fits; 9.02 mm wide, it does not."""

    def build(msp: object) -> None:
        msp.add_lwpolyline(  # type: ignore[attr-defined]
            [(0, 0), (width, 0), (width, 6), (0, 6)], close=True, dxfattribs={"layer": "EDGE"}
        )

    drawing = read_drawing(write_dxf(tmp_path / "plate.dxf", build))
    text = initial_job(drawing, tool_diameter=1.0, travel_mm=(10.0, 7.0))
    assert ("fit = [8.99, 5.99]" in text) == fitted


def test_a_tool_as_wide_as_the_travel_is_refused(tmp_path: Path) -> None:
    def build(msp: object) -> None:
        msp.add_circle((0, 0), 20.0)  # type: ignore[attr-defined]

    drawing = read_drawing(write_dxf(tmp_path / "disc.dxf", build))
    with pytest.raises(InputError, match=r"the 7 mm tool is as wide as the machine's 10 × 7 mm"):
        initial_job(drawing, tool_diameter=7.0, travel_mm=(10.0, 7.0))


def _plate_with_slots(tmp_path: Path, widths: list[float]) -> Path:
    """A 100 × 50 mm plate (layer EDGE) and 10 mm long rectangular slots (layer SLOTS)."""

    def build(msp: object) -> None:
        msp.add_lwpolyline(  # type: ignore[attr-defined]
            [(0, 0), (100, 0), (100, 50), (0, 50)], close=True, dxfattribs={"layer": "EDGE"}
        )
        for k, w in enumerate(widths):
            x = 10.0 + 15.0 * k
            msp.add_lwpolyline(  # type: ignore[attr-defined]
                [(x, 20), (x + w, 20), (x + w, 30), (x, 30)],
                close=True,
                dxfattribs={"layer": "SLOTS"},
            )

    return write_dxf(tmp_path / "slots.dxf", build)


def test_holes_narrower_than_the_end_mill_get_one_that_fits(tmp_path: Path) -> None:
    """Slots 2.8 and 6 mm wide under the default 3 mm end mill (boxes.py's finger slots).

    A slot's width is its largest inscribed circle's diameter, 2.8 mm (analysis); the
    largest common end mill within 95 % of it (2.66 mm) is 2.5 mm. With the 3 mm one the
    slots operation would stop the post ("nothing left to cut" when every slot is too
    narrow); with 2.5 mm every slot is cut on its inside.
    """
    drawing = read_drawing(_plate_with_slots(tmp_path, [2.8, 2.8, 6.0]))
    text = initial_job(drawing)
    data = tomllib.loads(text)
    slots, edge = data["operations"]
    tools = {t["id"]: t for t in data["tools"]}
    assert (slots["side"], tools[slots["tool"]]["diameter"]) == ("inside", 2.5)
    assert (edge["side"], tools[edge["tool"]]["diameter"]) == ("outside", 3)
    assert slots["step_down"] == 2.5
    assert "2 of the 3 holes are narrower than the 3 mm end mill" in text
    assert "(the narrowest about 2.8 mm wide): a 2.5 mm one cuts them" in text
    done = run_job(drawing, load_target("grbl"), job_from_dict(data, source="j.toml"))
    placed_slots = [(10.0 + 15.0 * k, 10.0 + 15.0 * k + w) for k, w in enumerate([2.8, 2.8, 6])]
    assert done.placed is not None  # the job's lower-left origin moves the plate:
    dx = done.placed.bbox()[0] - drawing.bbox()[0]
    cut_x = [m.x - dx for m in done.program.moves if isinstance(m, Linear) and m.z is None]
    for x0, x1 in placed_slots:  # the 2.5 mm tool's centre runs 1.25 mm inside each slot
        assert any(abs(x - (x0 + 1.25)) < 1e-6 for x in cut_x), (x0, x1)


def test_holes_no_common_end_mill_fits_leave_their_operation_commented(tmp_path: Path) -> None:
    """0.4 mm slots: 95 % of that is under the smallest common end mill (0.5 mm)."""
    drawing = read_drawing(_plate_with_slots(tmp_path, [0.4, 0.4]))
    text = initial_job(drawing)
    assert [op["layers"] for op in _ops(text)] == [["EDGE"]]
    assert "# tool = 1  # all 2 holes are narrower than the 3 mm end mill" in text
    assert "no common end mill fits; give this operation a tool that does" in text


def test_a_pocket_narrower_than_the_end_mill_gets_one_that_fits(tmp_path: Path) -> None:
    """A 2 mm wide pocket under the default 3 mm end mill.

    Its width (largest inscribed circle) is 2 mm; the largest common end mill within 95 %
    of it (1.9 mm) is 1.5 mm (analysis). ``post`` clears nothing narrower than its tool
    ("every pocket is narrower than the 3 mm tool"); with 1.5 mm the pocket is cleared, the tool's
    centre on the slot's centre line (y = 11, within 1 mm of either side less 0.75 mm).
    """

    def build(msp: object) -> None:
        msp.add_lwpolyline(  # type: ignore[attr-defined]
            [(0, 0), (60, 0), (60, 30), (0, 30)], close=True, dxfattribs={"layer": "EDGE"}
        )
        msp.add_lwpolyline(  # type: ignore[attr-defined]
            [(10, 10), (40, 10), (40, 12), (10, 12)], close=True, dxfattribs={"layer": "POCKET"}
        )

    drawing = read_drawing(write_dxf(tmp_path / "slot.dxf", build))
    text = initial_job(drawing)
    data = tomllib.loads(text)
    pocket = next(op for op in data["operations"] if op["type"] == "pocket")
    tools = {t["id"]: t["diameter"] for t in data["tools"]}
    assert tools[pocket["tool"]] == 1.5
    assert "the pocket is narrower than the 3 mm end mill (about 2 mm wide): a 1.5 mm one" in text
    edge = next(op for op in data["operations"] if op["type"] == "profile")
    assert tools[edge["tool"]] == 3
    done = run_job(drawing, load_target("grbl"), job_from_dict(data, source="j.toml"))
    run = next(r for r in done.operations if r.operation.type == "pocket")
    assert done.placed is not None
    dx, dy = (a - b for a, b in zip(done.placed.bbox()[:2], drawing.bbox()[:2], strict=True))
    cut = [m for m in done.program.moves[run.moves[0] : run.moves[1]] if isinstance(m, Linear)]
    assert cut
    assert all(abs((m.y - dy) - 11.0) <= 1.0 - 0.75 + 1e-6 for m in cut)
    assert min(m.x - dx for m in cut) >= 10.75 - 1e-6 and max(m.x - dx for m in cut) <= 39.25 + 1e-6


SHAPER = """<svg xmlns="http://www.w3.org/2000/svg"
  xmlns:shaper="http://www.shapertools.com/namespaces/shaper"
  viewBox="0 0 200 100" width="200mm" height="100mm">
  <rect x="0" y="0" width="200" height="100" fill="none" stroke="blue" shaper:cutType="guide"/>
  <rect x="20" y="20" width="60" height="40" fill="black" stroke="black" shaper:cutType="outside"/>
  <circle cx="40" cy="40" r="1.5" fill="white" stroke="black" shaper:cutType="inside"/>
  <rect x="100" y="20" width="60" height="40" fill="black" stroke="black" shaper:cutType="inside"/>
  <rect x="50" y="45" width="20" height="10" fill="#7F7F7F" shaper:cutType="pocket"/>
  <path d="M 120 30 L 140 30 L 140 50 Z" fill="none" stroke="#7F7F7F" shaper:cutType="online"/>
</svg>"""


def test_shaper_s_cut_types_make_the_operations(tmp_path: Path) -> None:
    """An SVG in Shaper Origin's format says how each shape is cut (``shaper:cutType``):
    each cut type is a layer, and its operation follows it: the 60 x 40 mm rectangle
    marked inside is cut inside although nothing surrounds it, the pocket is pocketed, the
    ø3 hole drilled, the on-line triangle engraved (commented out, closed as it is). The
    sheet's 200 x 100 mm border is a guide: not cut, and not counted against the 200 x
    200 mm travel, which the part alone fits (no fit, no scaling down)."""
    path = tmp_path / "sheet.svg"
    path.write_text(SHAPER, encoding="utf-8")
    drawing = read_drawing(path)
    assert {c.layer for c in drawing.contours} == {
        "0", "shaper outside", "shaper inside", "shaper pocket", "shaper online"
    }  # fmt: skip
    text = initial_job(drawing, travel_mm=(200.0, 200.0))
    assert "fit =" not in text and "SCALED" not in text
    kinds = [(op["type"], op.get("side"), tuple(op["layers"])) for op in _ops(text)]  # type: ignore[arg-type]
    assert kinds == [
        ("drill", None, ("shaper inside",)),
        ("pocket", None, ("shaper pocket",)),
        ("profile", "inside", ("shaper inside",)),
        ("profile", "outside", ("shaper outside",)),
    ]
    engrave = text.split('# type = "engrave"')[1].split("[[operations]]")[0]
    assert "shaper online" in engrave and "closed" not in engrave


def test_shaper_s_cut_depths_are_the_operations_depths(tmp_path: Path) -> None:
    """Shaper's ``cutDepth`` per shape (a stepped tray: an outline through 15 mm stock,
    pockets 4 and 10 mm deep) gives an operation per cut type and depth, at that depth,
    where job init otherwise guesses (through the stock, pockets at half of it)."""
    ns = 'xmlns:shaper="http://www.shapertools.com/namespaces/shaper"'
    path = tmp_path / "tray.svg"
    path.write_text(
        f'<svg xmlns="http://www.w3.org/2000/svg" {ns} width="220mm" height="140mm" '
        'viewBox="0 0 220 140">'
        '<rect x="10" y="10" width="200" height="120" rx="10" fill="#fff" stroke="#000" '
        'shaper:pathType="exterior" shaper:cutDepth="15.0mm"/>'
        '<rect x="25" y="25" width="60" height="90" rx="5" fill="#a0a0a0" stroke="#000" '
        'shaper:pathType="pocket" shaper:cutDepth="4.0mm"/>'
        '<rect x="115" y="25" width="80" height="90" rx="5" fill="#404040" stroke="#000" '
        'shaper:pathType="pocket" shaper:cutDepth="10.0mm"/></svg>',
        encoding="utf-8",
    )
    text = initial_job(read_drawing(path), thickness_mm=6.0)
    got = {op["layers"][0]: (op["type"], op["depth"]) for op in _ops(text)}  # type: ignore[index]
    assert got == {
        "shaper outside 15mm": ("profile", 15),
        "shaper pocket 4mm": ("pocket", 4),
        "shaper pocket 10mm": ("pocket", 10),
    }
    assert text.count("# Shaper's cut depth") == 3


def test_a_site_plan_in_metres_far_from_zero_is_drilled_where_its_circles_are(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A drawing in metres, millions of mm from 0 (map coordinates), with circles over 1 m.

    ``job init`` names the circles as drawn (ø1.5 m = 1500 mm) and fits the plan into the
    travel; ``post --job`` must take the job it wrote: the diameter selects the circles, and
    the tool's place between operations is a point of the drawing, however far from 0.
    The holes' positions, by analysis: the same direction as drawn, at most the travel apart.
    """
    import ezdxf

    from camtool.cli.main import main

    doc = ezdxf.new(units=6)  # $INSUNITS 6: metres
    msp = doc.modelspace()
    x0, y0 = 3438.0, 1725.0  # m: 3.4e6 mm from 0
    msp.add_lwpolyline(
        [(x0, y0), (x0 + 200, y0), (x0 + 200, y0 + 150), (x0, y0 + 150)],
        close=True,
        dxfattribs={"layer": "SITE"},
    )
    for cx, cy in ((x0 + 50, y0 + 40), (x0 + 150, y0 + 100)):
        msp.add_circle((cx, cy), 0.75, dxfattribs={"layer": "WELLS"})
    drawing = tmp_path / "site.dxf"
    doc.saveas(drawing)
    job = tmp_path / "site.toml"
    assert main(["job", "init", str(drawing), "-t", "grbl", "-o", str(job)]) == 0
    assert "diameter = 1500" in job.read_text()
    out = tmp_path / "site.nc"
    code = main(["post", str(drawing), "--job", str(job), "-t", "grbl", "-o", str(out)])
    assert code == 0, capsys.readouterr().err
    loads = re.compile(r"\(program \d+ of \d+: load T\d+ drill ")
    (drill,) = [p for p in tmp_path.glob("site.T*.nc") if loads.search(p.read_text())]
    lines = drill.read_text().splitlines()
    holes = []  # a rapid to XY, down to safe Z, then feed down: a hole's first peck
    for k, line in enumerate(lines[:-2]):
        xy = re.fullmatch(r"G0 X(-?[\d.]+) Y(-?[\d.]+)", line)
        if xy and lines[k + 1].startswith("G0 Z") and lines[k + 2].startswith("G1 Z"):
            holes.append((float(xy[1]), float(xy[2])))
    holes = sorted(set(holes))
    assert len(holes) == 2, holes
    (ax, ay), (bx, by) = holes
    assert all(0.0 <= v <= 200.0 for v in (ax, ay, bx, by))  # GRBL's 200 × 200 mm travel
    assert math.atan2(by - ay, bx - ax) == pytest.approx(math.atan2(60.0, 100.0), abs=1e-4)


def test_a_drill_pecks_a_diameter_deep_and_never_less_than_1_mm(tmp_path: Path) -> None:
    """Pecks of a diameter; a micro drill's are 1 mm, and its comment says so, not "a diameter"."""

    def build(msp: object) -> None:
        msp.add_circle((10, 10), 0.25, dxfattribs={"layer": "SMALL"})  # type: ignore[attr-defined]
        msp.add_circle((30, 10), 2.5, dxfattribs={"layer": "BIG"})  # type: ignore[attr-defined]

    text = initial_job(read_drawing(write_dxf(tmp_path / "h.dxf", build)), thickness_mm=4.0)
    pecks = {op["diameter"]: op["step_down"] for op in _ops(text) if op["type"] == "drill"}
    assert pecks == {0.5: 1.0, 5.0: 5.0}
    lines = [ln for ln in text.splitlines() if ln.startswith("step_down")]
    assert lines == ["step_down = 1  # peck 1 mm at a time (G83)",
                     "step_down = 5  # peck about a diameter deep (G83)"]  # fmt: skip


def test_a_first_job_that_would_hold_more_tools_than_a_job_may_is_refused(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # The sample plate's first job has two tools (the 3.2 mm drill, the 3 mm end mill):
    # under a limit of one, the job post --job would refuse is not written.
    import camtool.jobs.init as init_module

    drawing = read_drawing(ROOT / "samples" / "part.dxf")
    assert len(tomllib.loads(initial_job(drawing, source="part.dxf"))["tools"]) == 2
    monkeypatch.setattr(init_module, "MAX_TOOLS", 1)
    with pytest.raises(InputError, match=r"^part.dxf: its first job would need 2 tools"):
        initial_job(drawing, source="part.dxf")


def test_a_circle_drawn_around_a_smaller_one_is_named_a_possible_counterbore(
    tmp_path: Path,
) -> None:
    """A counterbore in plan is two circles about one centre: the larger is cut through,
    as drawn, and the job file says which circles those are (not the inner holes, not a
    circle drawn twice)."""

    def build(msp: object) -> None:
        add = msp.add_circle  # type: ignore[attr-defined]
        msp.add_lwpolyline([(0, 0), (60, 0), (60, 40), (0, 40)], close=True)  # type: ignore[attr-defined]
        add((10, 10), 1.6)  # ø3.2 through, in a ø6 counterbore: both drilled
        add((10, 10), 3.0)
        add((50, 10), 1.6)  # a plain ø3.2 hole, drawn twice
        add((50, 10), 1.6)
        add((30, 20), 3.3)  # ø6.6 in a ø11 counterbore: both larger than a drill, profiled
        add((30, 20), 5.5)

    text = initial_job(read_drawing(write_dxf(tmp_path / "cb.dxf", build)), thickness_mm=5.0)
    lines = text.splitlines()
    small = next(line for line in lines if "circle(s) of ø3.2 mm" in line)
    large = next(line for line in lines if "circle(s) of ø6 mm" in line)
    assert "around" not in small
    assert large.endswith(
        "small, drilled; 1 of them around a smaller circle at their centre (a counterbore, or "
        "a thread's outer diameter, drawn in plan?): drilled through the stock here; if so, give "
        "them an operation of their own with its depth"
    )
    assert "# 1 of its circles around a smaller circle at their centre" in text
    assert [(op["type"], op.get("diameter")) for op in _ops(text)] == [
        ("drill", 3.2),
        ("drill", 6.0),
        ("profile", None),
    ]
