"""DXF import: entities, bulges, OCS, units, warnings and bad input."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest

from camtool.importers import read_drawing
from camtool.importers.dxf import read_dxf
from camtool.model.errors import InputError
from camtool.model.shapes import Arc, Line
from tests.shapes import rectangle_dxf, write_dxf


def test_line_arc_circle(tmp_path: Path) -> None:
    def build(msp: Any) -> None:
        msp.add_line((0, 0), (1, 0))
        msp.add_arc((0, 0), 2.0, 0, 90)
        msp.add_circle((5, 5), 1.5)

    d = read_dxf(write_dxf(tmp_path / "a.dxf", build))
    line, arc, circle = (c.segments[0] for c in d.contours)
    assert line == Line((0.0, 0.0), (1.0, 0.0))
    assert isinstance(arc, Arc) and not arc.clockwise
    assert arc.start == pytest.approx((2.0, 0.0)) and arc.end == pytest.approx((0.0, 2.0))
    assert arc.sweep == pytest.approx(math.pi / 2)
    assert isinstance(circle, Arc) and circle.is_full_circle and circle.radius == 1.5
    assert d.contours[2].closed and not d.contours[0].closed


def test_bulge_sign_gives_direction(tmp_path: Path) -> None:
    # bulge = tan(sweep/4); +1 is a CCW half circle, -1 a CW one (DXF reference).
    def build(msp: Any) -> None:
        msp.add_lwpolyline([(0, 0, 1.0), (2, 0, 0)], format="xyb")
        msp.add_lwpolyline([(0, 0, -1.0), (2, 0, 0)], format="xyb")

    ccw, cw = (c.segments[0] for c in read_dxf(write_dxf(tmp_path / "b.dxf", build)).contours)
    assert isinstance(ccw, Arc) and isinstance(cw, Arc)
    assert not ccw.clockwise and cw.clockwise
    assert type(ccw.clockwise) is bool and type(cw.clockwise) is bool  # not numpy's bool_
    assert ccw.centre == pytest.approx((1.0, 0.0)) and ccw.radius == pytest.approx(1.0)
    # CCW from (0,0) to (2,0) about (1,0) passes below the chord: y_min = -1
    assert ccw.bbox()[1] == pytest.approx(-1.0) and cw.bbox()[3] == pytest.approx(1.0)


def test_polyline2d_with_bulge_and_closed_flag(tmp_path: Path) -> None:
    def build(msp: Any) -> None:
        p = msp.add_polyline2d([(0, 0), (4, 0), (4, 2)], close=True)
        p.vertices[1].dxf.bulge = 0.5

    (contour,) = read_dxf(write_dxf(tmp_path / "p.dxf", build)).contours
    assert contour.closed and len(contour.segments) == 3
    assert isinstance(contour.segments[1], Arc)


def test_mirrored_ocs_arc_runs_clockwise(tmp_path: Path) -> None:
    # An ARC with extrusion (0,0,-1) is seen mirrored from +Z: OCS x → WCS -x.
    def build(msp: Any) -> None:
        msp.add_arc((1, 0), 1.0, 0, 90, dxfattribs={"extrusion": (0, 0, -1)})

    (contour,) = read_dxf(write_dxf(tmp_path / "m.dxf", build)).contours
    arc = contour.segments[0]
    assert isinstance(arc, Arc) and arc.clockwise
    assert arc.centre == pytest.approx((-1.0, 0.0))
    assert arc.start == pytest.approx((-2.0, 0.0)) and arc.end == pytest.approx((-1.0, 1.0))


def test_mirrored_lwpolyline_bulge_flips(tmp_path: Path) -> None:
    # OCS (0,0,-1): x → -x. A CCW half circle below the chord (0,0)→(2,0) becomes a
    # half circle from (0,0) to (-2,0), still below, now run clockwise.
    def build(msp: Any) -> None:
        msp.add_lwpolyline(
            [(0, 0, 1.0), (2, 0, 0)], format="xyb", dxfattribs={"extrusion": (0, 0, -1)}
        )

    (contour,) = read_dxf(write_dxf(tmp_path / "ml.dxf", build)).contours
    arc = contour.segments[0]
    assert isinstance(arc, Arc) and arc.clockwise
    assert arc.end == pytest.approx((-2.0, 0.0)) and arc.centre == pytest.approx((-1.0, 0.0))
    assert arc.bbox()[1] == pytest.approx(-1.0)


def test_inches_are_scaled_by_25_4(tmp_path: Path) -> None:
    d = read_dxf(rectangle_dxf(tmp_path / "in.dxf", 1.0, 0.5, insunits=1))
    x0, y0, x1, y1 = d.bbox()
    assert (x0, y0) == (25.4, 25.4)
    assert x1 - x0 == pytest.approx(25.4) and y1 - y0 == pytest.approx(12.7)


def test_unitless_drawing_is_taken_as_mm_with_a_warning(tmp_path: Path) -> None:
    d = read_dxf(rectangle_dxf(tmp_path / "u.dxf", insunits=0))
    assert d.bbox() == (1.0, 1.0, 11.0, 6.0)
    assert any("assuming mm" in w for w in d.warnings)


@pytest.mark.parametrize("measurement", [0, 1])
def test_a_unitless_drawing_with_imperial_settings_hints_at_inches(
    tmp_path: Path, measurement: int
) -> None:
    """``$MEASUREMENT = 0`` (imperial) is named in the warning; the coordinates stay mm."""
    import ezdxf

    path = rectangle_dxf(tmp_path / "u.dxf", insunits=0)
    doc = ezdxf.readfile(path)
    doc.header["$MEASUREMENT"] = measurement
    doc.saveas(path)
    d = read_dxf(path)
    assert d.bbox() == (1.0, 1.0, 11.0, 6.0)
    (warning,) = [w for w in d.warnings if "assuming mm" in w]
    assert ("$MEASUREMENT = 0" in warning and "--units in" in warning) == (measurement == 0)


def test_other_entities_skipped_with_one_warning_per_type(tmp_path: Path) -> None:
    def build(msp: Any) -> None:
        msp.add_line((0, 0), (1, 0))
        for k in range(3):
            msp.add_text(f"t{k}")
        msp.add_point((1, 1))

    d = read_dxf(write_dxf(tmp_path / "s.dxf", build))
    assert len(d.contours) == 1
    assert sum("3 TEXT entities" in w for w in d.warnings) == 1
    assert sum("1 POINT entity" in w for w in d.warnings) == 1


def test_missing_file(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="no such file"):
        read_drawing(tmp_path / "nope.dxf")


def test_not_a_dxf(tmp_path: Path) -> None:
    bad = tmp_path / "bad.dxf"
    bad.write_text("this is not a drawing\n")
    with pytest.raises(InputError, match=r"bad\.dxf"):
        read_drawing(bad)


def test_no_usable_entity(tmp_path: Path) -> None:
    path = write_dxf(tmp_path / "empty.dxf", lambda msp: msp.add_text("only text"))
    with pytest.raises(InputError, match="no usable entity"):
        read_drawing(path)


def test_unknown_suffix(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"cannot read '\.stl' files"):
        read_drawing(tmp_path / "part.stl")


def _hidden_drawing(path: Path) -> Path:
    """Layers switched off and frozen, an invisible CIRCLE and an invisible block reference.

    Written with ezdxf, whose ``Layer.off()``/``freeze()`` set the LAYER table's colour sign
    and flag bit 1 as AutoCAD does, and ``invisible`` is group code 60 (DXF reference).
    """

    def build(msp: Any) -> None:
        doc = msp.doc
        doc.layers.add("OFF").off()
        doc.layers.add("Frozen").freeze()
        doc.blocks.new("B").add_circle((0, 0), 1.0)
        msp.add_circle((0, 0), 5.0, dxfattribs={"layer": "OFF"})
        msp.add_spline([(0, 0), (5, 5), (10, 0), (15, 5)], dxfattribs={"layer": "OFF"})
        msp.add_line((0, 0), (9, 0), dxfattribs={"layer": "Frozen"})
        msp.add_circle((20, 0), 5.0, dxfattribs={"invisible": 1})
        msp.add_line((0, 20), (9, 20), dxfattribs={"invisible": 1})
        msp.add_blockref("B", (30, 0), dxfattribs={"invisible": 1})
        msp.add_circle((40, 0), 5.0, dxfattribs={"layer": "PART"})

    return write_dxf(path, build)


def test_hidden_layers_and_invisible_entities_are_not_cut(tmp_path: Path) -> None:
    """What the CAD program does not show is not cut; the warning says how to cut it."""
    path = _hidden_drawing(tmp_path / "h.dxf")
    drawing = read_dxf(path)
    assert [c.layer for c in drawing.contours] == ["PART"]
    assert drawing.warnings == (
        f"{path}: skipped 3 entities on layer(s) 'Frozen', 'OFF', off or frozen in the drawing "
        "(hidden, so not cut); name the layer in --layers or in a job operation to cut it",
        f"{path}: skipped 3 invisible entities (the entity's invisible flag is set: not shown, "
        "so not cut)",
    )


def test_a_hidden_layer_named_is_read(tmp_path: Path) -> None:
    from camtool.importers.options import ImportOptions

    path = _hidden_drawing(tmp_path / "h.dxf")
    named = read_dxf(path, ImportOptions(layers=("off", "PART")))
    assert sorted(c.layer for c in named.contours) == ["OFF", "OFF", "PART"]
    assert not any("hidden" in w for w in named.warnings)
    by_job = read_dxf(path, ImportOptions(shown=("FROZEN",)))  # a job's operation names it
    assert sorted(c.layer for c in by_job.contours) == ["Frozen", "PART"]
    assert "'OFF', off or frozen" in by_job.warnings[0]


def _blocks_on_hidden_layers(path: Path) -> Path:
    """Block references on an off and on a frozen layer, one nested, content on own layers.

    The rule the expected values come from is AutoCAD's (its help, "Layers: About block
    references"; QCAD's Teigha visibility test drawings show the same): an entity on layer 0
    in a block takes the layer of the reference that places it; a reference on a layer that
    is only off still shows its entities on other layers; a reference on a frozen layer shows
    nothing it places, at any depth.
    """

    def build(msp: Any) -> None:
        doc = msp.doc
        doc.layers.add("REF_OFF").off()
        doc.layers.add("REF_FROZEN").freeze()
        doc.layers.add("NEST_FROZEN").freeze()
        for name in ("CONTENT", "INNER"):
            doc.layers.add(name)
        inner = doc.blocks.new("INNER")
        inner.add_circle((0, 0), 1.0, dxfattribs={"layer": "INNER"})
        outer = doc.blocks.new("OUTER")
        outer.add_line((0, 0), (10, 0), dxfattribs={"layer": "CONTENT"})
        outer.add_line((0, 5), (10, 5), dxfattribs={"layer": "0"})  # takes the reference's
        outer.add_blockref("INNER", (5, 10), dxfattribs={"layer": "NEST_FROZEN"})
        outer.add_blockref("INNER", (5, 20), dxfattribs={"layer": "INNER", "invisible": 1})
        outer.add_blockref("INNER", (5, 30), dxfattribs={"layer": "0"})
        msp.add_blockref("OUTER", (0, 0), dxfattribs={"layer": "REF_OFF"})
        msp.add_blockref("OUTER", (100, 0), dxfattribs={"layer": "REF_FROZEN"})
        msp.add_blockref("OUTER", (200, 0), dxfattribs={"layer": "PART"})

    return write_dxf(path, build)


def test_a_block_reference_on_a_frozen_layer_hides_all_it_places(tmp_path: Path) -> None:
    from camtool.importers.options import ImportOptions

    path = _blocks_on_hidden_layers(tmp_path / "refs.dxf")
    drawing = read_dxf(path)
    placed = sorted((c.layer, round(c.bbox()[0])) for c in drawing.contours)
    # REF_OFF at x 0: only its CONTENT line and the INNER circle of the layer-0 reference
    # (its layer-0 line and the layer-0 reference take REF_OFF, which is off: the circle is
    # on INNER, so it shows). REF_FROZEN at x 100: nothing. PART at x 200: all but the
    # reference on NEST_FROZEN and the invisible one.
    assert placed == [
        ("CONTENT", 0),
        ("CONTENT", 200),
        ("INNER", 4),
        ("INNER", 204),
        ("PART", 200),
    ]
    assert any(
        "skipped 3 block reference(s) (INSERT) on frozen layer(s) 'NEST_FROZEN', "
        "'REF_FROZEN' with everything they place" in w
        for w in drawing.warnings
    )
    named = read_dxf(path, ImportOptions(shown=("REF_FROZEN",)))
    assert sorted(round(c.bbox()[0]) for c in named.contours if 100 <= c.bbox()[0] < 200) == [
        100,
        100,
        104,
    ]


def test_an_mline_is_cut_as_ezdxf_draws_its_elements(tmp_path: Path) -> None:
    """AutoCAD's MLINE (parallel lines, walls): its element lines, in model space and in a
    block placed scaled and turned. Expected: ezdxf's own drawing of it
    (``MLine.virtual_entities``); in the block, those lines moved by the block reference's
    matrix (``Insert.matrix44``), so the lines' separation scales with the block as AutoCAD
    draws it (ezdxf's ``MLine.transform`` keeps the separation: 1 here, not 2)."""
    import ezdxf

    def build(msp: Any) -> None:
        msp.add_mline([(0, 10), (50, 10), (50, 40)], dxfattribs={"layer": "WALLS"})
        block = msp.doc.blocks.new("ROOM")
        block.add_mline([(0, 0), (10, 0), (10, 5)], close=True)
        msp.add_blockref("ROOM", (100, 0), dxfattribs={"xscale": 2, "yscale": 2, "rotation": 90})
        msp.add_xline((0, 0), (1, 1))

    path = write_dxf(tmp_path / "walls.dxf", build)
    doc = ezdxf.readfile(path)
    expected = []
    for entity in doc.modelspace().query("MLINE INSERT"):
        if entity.dxftype() == "MLINE":
            lines = list(entity.virtual_entities())
        else:
            (mline,) = doc.blocks["ROOM"]
            lines = [line.transform(entity.matrix44()) for line in mline.virtual_entities()]
        for line in lines:
            start, end = line.dxf.start, line.dxf.end
            expected.append(((start.x, start.y), (end.x, end.y)))
    drawing = read_dxf(path)
    got = [(s.start, s.end) for c in drawing.contours for s in c.segments]

    def key(pair: tuple[tuple[float, float], tuple[float, float]]) -> tuple[float, ...]:
        a, b = sorted(pair)
        return tuple(round(v, 6) + 0.0 for v in (*a, *b))

    assert sorted(map(key, got)) == sorted(map(key, expected))
    assert len(expected) == 4 + 6  # two elements: 2 segments open, 3 closed
    assert {c.layer for c in drawing.contours} == {"WALLS", "0"}
    assert any("XLINE entity (an infinite construction line" in w for w in drawing.warnings)


def test_polylines_drawn_with_a_width_are_cut_on_their_centre_line_and_named(
    tmp_path: Path,
) -> None:
    """A width draws a band (QCAD's entities.dxf, centroid symbols); its centre line is cut."""

    def build(msp: Any) -> None:
        msp.add_lwpolyline([(0, 0), (10, 0)], dxfattribs={"const_width": 2.5})
        msp.add_lwpolyline([(0, 5, 2.0, 5.0), (10, 5, 0.0, 0.0)], format="xyse")
        wide = msp.add_polyline2d([(0, 10), (10, 10)])
        wide.vertices[0].dxf.end_width = 1.0
        msp.add_lwpolyline([(0, 15), (10, 15)])  # no width: not named

    drawing = read_dxf(write_dxf(tmp_path / "w.dxf", build, insunits=1))  # inches
    ends = sorted((c.segments[0].start, c.segments[-1].end) for c in drawing.contours)
    assert ends == [((0.0, y * 25.4), (254.0, y * 25.4)) for y in (0, 5, 10, 15)]
    (warning,) = [w for w in drawing.warnings if "width" in w]
    assert "3 polyline(s) drawn with a width (first LWPOLYLINE #" in warning
    assert "63.5 mm wide" in warning  # 2.5 in
