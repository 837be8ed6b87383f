"""DXF INSERT/MINSERT: block content placed with the full transform, nested, mirrored.

Expected positions are computed here from the insert's parameters (p' = T + R·S·p, the
DXF reference's definition of INSERT), not with ezdxf's matrices.

The property test runs a few examples; set CAMTOOL_INSERT_EXAMPLES=300 for a deeper search (a
few hundred passed when this was written).
"""

from __future__ import annotations

import io
import itertools
import math
import os
import tempfile
from pathlib import Path
from typing import Any

import ezdxf
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from camtool.geometry.arcfit import distances
from camtool.importers.dxf import read_dxf
from camtool.importers.options import ImportOptions
from camtool.model.errors import InputError
from camtool.model.shapes import Arc, Contour, Line, Point, Segment
from tests.shapes import segment_samples, write_dxf

TOL = 0.001


def _placer(at: Point, rotation_deg: float = 0.0, sx: float = 1.0, sy: float = 1.0) -> Any:
    """The INSERT transform p' = at + R(rotation)·diag(sx, sy)·p, for expected values."""
    c, s = math.cos(math.radians(rotation_deg)), math.sin(math.radians(rotation_deg))

    def place(p: Point) -> Point:
        x, y = p[0] * sx, p[1] * sy
        return (at[0] + c * x - s * y, at[1] + s * x + c * y)

    return place


def _same_segment(a: Segment, b: Segment, tol: float = 1e-9) -> bool:
    """Same line or arc, in either direction."""
    if type(a) is not type(b):
        return False
    if isinstance(a, Arc) and isinstance(b, Arc):
        if math.dist(a.centre, b.centre) > tol:
            return False
        fwd = a.clockwise == b.clockwise and math.dist(a.start, b.start) <= tol
        fwd = fwd and math.dist(a.end, b.end) <= tol
        return fwd or (
            a.clockwise != b.clockwise
            and math.dist(a.start, b.end) <= tol
            and math.dist(a.end, b.start) <= tol
        )
    fwd = math.dist(a.start, b.start) <= tol and math.dist(a.end, b.end) <= tol
    return fwd or (math.dist(a.start, b.end) <= tol and math.dist(a.end, b.start) <= tol)


def _same_contour(a: Contour, b: Contour) -> bool:
    if a.closed != b.closed or len(a.segments) != len(b.segments):
        return False
    for cand in (b, b.reversed()):
        if all(_same_segment(x, y) for x, y in zip(a.segments, cand.segments, strict=True)):
            return True
    return False


def _mirrored(seg: Segment, sx: float, sy: float) -> Segment:
    def m(p: Point) -> Point:
        return (p[0] * sx, p[1] * sy)

    if isinstance(seg, Line):
        return Line(m(seg.start), m(seg.end))
    flips = sx * sy < 0
    return Arc(m(seg.start), m(seg.end), m(seg.centre), seg.clockwise != flips)


_c = st.floats(-40, 40, allow_nan=False).map(lambda v: round(v, 3))
_line = st.tuples(st.just("line"), _c, _c, _c, _c)
_arc = st.tuples(st.just("arc"), _c, _c, st.floats(0.5, 20), st.floats(0, 359), st.floats(1, 359))
_poly = st.tuples(
    st.just("poly"),
    st.lists(
        st.tuples(_c, _c, st.floats(-2, 2).map(lambda v: round(v, 3))), min_size=2, max_size=5
    ),
    st.booleans(),
)


def _draw(layout: Any, items: list[tuple[Any, ...]]) -> None:
    for item in items:
        if item[0] == "line":
            layout.add_line(item[1:3], item[3:5])
        elif item[0] == "arc":
            _, x, y, r, a0, sweep = item
            layout.add_arc((x, y), r, a0, a0 + sweep)
        else:
            layout.add_lwpolyline(item[1], format="xyb", close=item[2])


@settings(max_examples=int(os.environ.get("CAMTOOL_INSERT_EXAMPLES", "30")), deadline=None)
@given(
    items=st.lists(st.one_of(_line, _arc, _poly), min_size=1, max_size=5),
    scales=st.sampled_from([(-1.0, 1.0), (1.0, -1.0), (-1.0, -1.0)]),
)
def test_property_insert_scaled_by_minus_one_is_the_mirrored_drawing(
    items: list[tuple[Any, ...]], scales: tuple[float, float]
) -> None:
    sx, sy = scales
    with tempfile.TemporaryDirectory() as tmp:

        def plain(msp: Any) -> None:
            _draw(msp, items)

        def inserted(msp: Any) -> None:
            _draw(msp.doc.blocks.new("PART"), items)
            msp.add_blockref("PART", (0, 0), dxfattribs={"xscale": sx, "yscale": sy})

        try:
            original = read_dxf(write_dxf(Path(tmp) / "a.dxf", plain)).contours
        except InputError:  # every generated entity has zero length: nothing to compare
            return
        placed = read_dxf(write_dxf(Path(tmp) / "b.dxf", inserted)).contours
    assert len(placed) == len(original)
    for got, want in zip(placed, original, strict=True):
        mirrored = Contour(
            tuple(_mirrored(s, sx, sy) for s in want.segments), want.closed, want.layer
        )
        assert _same_contour(got, mirrored), (got, mirrored)
        assert all(isinstance(s, type(w)) for s, w in zip(got.segments, want.segments, strict=True))


def test_rotation_and_non_uniform_scale(tmp_path: Path) -> None:
    place = _placer((10.0, 5.0), 30.0, 2.0, 0.5)

    def build(msp: Any) -> None:
        block = msp.doc.blocks.new("B")
        block.add_line((0, 0), (4, 0))
        block.add_arc((0, 0), 3.0, 0, 120)  # becomes an elliptical arc
        block.add_lwpolyline([(0, 0, 0.0), (4, 0, 1.0), (4, 4, 0.0)], format="xyb", close=True)
        msp.add_blockref("B", (10, 5), dxfattribs={"rotation": 30, "xscale": 2, "yscale": 0.5})

    line, arc, poly = read_dxf(write_dxf(tmp_path / "r.dxf", build)).contours
    (seg,) = line.segments
    assert isinstance(seg, Line)
    assert seg.start == pytest.approx(place((0, 0))) and seg.end == pytest.approx(place((4, 0)))
    # the elliptical arc: true points p(θ) = place(3 cos θ, 3 sin θ), both ways within TOL
    true = [place((3 * math.cos(t), 3 * math.sin(t))) for t in _range(0, 2 * math.pi / 3)]
    _assert_close(true, arc.segments)
    # the polyline stays one closed contour; its bulge (half circle centre (4, 2),
    # radius 2, from (4, 0) to (4, 4) counter-clockwise) is an elliptical arc now
    assert poly.closed and poly.source.startswith("LWPOLYLINE #")
    half = [
        place((4 + 2 * math.cos(t), 2 + 2 * math.sin(t))) for t in _range(-math.pi / 2, math.pi / 2)
    ]
    edges = [place(p) for p in _polyline_points([(4, 4), (0, 0), (4, 0)])]
    _assert_close(half + edges, poly.segments)


FIT_POINTS = [(0.0, 0.0), (15.0, 7.0), (2.0, 14.0), (0.0, 20.0)]
"""Fit points of a spline drawn in a block: its curve is interpolated where it is drawn."""


def _block_curve(fit: list[Point]) -> list[Point]:
    """The curve through ``fit`` in block coordinates, by ezdxf's own evaluator."""
    spline = ezdxf.new().modelspace().add_spline([(x, y, 0.0) for x, y in fit])
    return [(v.x, v.y) for v in spline.construction_tool().flattening(0.00002)]


@pytest.mark.parametrize("hatch", [False, True], ids=["spline", "hatch-edge"])
def test_a_fit_point_spline_under_non_uniform_scale_is_its_block_curve_placed(
    tmp_path: Path, hatch: bool
) -> None:
    # Placing the fit points and interpolating again gives another curve (chord lengths
    # and end tangents change): a block's curve is placed, not drawn again.
    place = _placer((5.0, -3.0), 30.0, 3.0, 0.5)

    def build(msp: Any) -> None:
        block = msp.doc.blocks.new("B")
        if hatch:
            path = block.add_hatch().paths.add_edge_path()
            path.add_spline(fit_points=FIT_POINTS)
            path.add_line(FIT_POINTS[-1], FIT_POINTS[0])
        else:
            block.add_spline([(x, y, 0.0) for x, y in FIT_POINTS])
        msp.add_blockref("B", (5, -3), dxfattribs={"rotation": 30, "xscale": 3, "yscale": 0.5})

    options = ImportOptions(hatch_boundaries=hatch)
    (contour,) = read_dxf(write_dxf(tmp_path / "f.dxf", build), options).contours
    curve = [place(p) for p in _block_curve(FIT_POINTS)]
    segments = contour.segments
    if hatch:  # the closing line placed, the curve's segments before it
        assert contour.closed and isinstance(segments[-1], Line)
        assert segments[-1].start == pytest.approx(place(FIT_POINTS[-1]))
        assert segments[-1].end == pytest.approx(place(FIT_POINTS[0]))
        segments = segments[:-1]
    _assert_close(curve, segments)


def test_a_hatch_s_ellipse_edge_under_nested_scales_and_a_mirror(tmp_path: Path) -> None:
    # a rotation, then a mirroring non-uniform scale: ezdxf's own HATCH transform
    # misplaces this half ellipse; each boundary piece is placed as the entity it is
    inner = _placer((-48.8, 10.7), 243.0)
    outer = _placer((40.0, -29.0), 296.0, 1.0, -1.826)

    def build(msp: Any) -> None:
        path = msp.doc.blocks.new("IN").add_hatch().paths.add_edge_path()
        path.add_line((-12, -1), (-2, -11))
        path.add_ellipse((-2, -1), (0, 10), 0.31, 180, 360, ccw=True)
        path.add_line((-2, 9), (-12, -1))
        msp.doc.blocks.new("OUT").add_blockref("IN", (-48.8, 10.7), dxfattribs={"rotation": 243})
        msp.add_blockref("OUT", (40, -29), dxfattribs={"yscale": -1.826, "rotation": 296})

    options = ImportOptions(hatch_boundaries=True)
    (contour,) = read_dxf(write_dxf(tmp_path / "h.dxf", build), options).contours
    # the edge c + cos t·M + sin t·ratio·(Z × M), t from π to 2π, then the two lines
    half = [(-2 - 3.1 * math.sin(t), -1 + 10 * math.cos(t)) for t in _range(math.pi, 2 * math.pi)]
    true = half + _polyline_points([(-2, 9), (-12, -1), (-2, -11)])
    assert contour.closed
    _assert_close([outer(inner(p)) for p in true], contour.segments)


def test_a_nearly_straight_bulge_under_non_uniform_scale_is_read(tmp_path: Path) -> None:
    # bulge 0.0002 over 40 in: an arc of 50 000 in radius, an elliptical arc once placed;
    # its whole ellipse is about 10⁹ times the 0.001 mm tolerance, the part cut 40 in long
    # and nearly straight: its size is what is judged
    from ezdxf.math import bulge_to_arc

    place = _placer((0.0, 0.0), 30.0, 2.0, 0.5)

    def build(msp: Any) -> None:
        msp.doc.header["$INSUNITS"] = 1
        msp.doc.blocks.new("B").add_lwpolyline([(0, 0, 0.0002), (40, 0, 0)], format="xyb")
        msp.add_blockref("B", (0, 0), dxfattribs={"rotation": 30, "xscale": 2, "yscale": 0.5})

    (contour,) = read_dxf(write_dxf(tmp_path / "b.dxf", build)).contours
    centre, start, end, radius = bulge_to_arc((0, 0), (40, 0), 0.0002)
    true = [
        place((centre.x + radius * math.cos(t), centre.y + radius * math.sin(t)))
        for t in _range(start, end)
    ]
    _assert_close([(25.4 * x, 25.4 * y) for x, y in true], contour.segments)


def _range(a: float, b: float, n: int = 2000) -> list[float]:
    return [a + (b - a) * k / n for k in range(n + 1)]


def _polyline_points(pts: list[Point], n: int = 200) -> list[Point]:
    out = []
    for (x0, y0), (x1, y1) in itertools.pairwise(pts):
        out += [(x0 + (x1 - x0) * k / n, y0 + (y1 - y0) * k / n) for k in range(n + 1)]
    return out


def _assert_close(true: list[Point], segments: tuple[Segment, ...]) -> None:
    """Every true point within TOL of the segments, every segment point near a true one."""
    import numpy as np

    assert float(np.max(distances(np.array(true), segments))) <= TOL
    fitted = segment_samples(segments)
    true_arr = np.array(true)
    gaps = [float(np.min(np.hypot(*(true_arr - p).T))) for p in fitted]
    spacing = float(np.max(np.hypot(*np.diff(true_arr, axis=0).T)))
    assert max(gaps) <= TOL + spacing


@pytest.mark.parametrize("angle", [45.0, 135.0])
def test_arcs_of_a_block_at_45_degrees_in_a_non_uniformly_scaled_block(
    tmp_path: Path, angle: float
) -> None:
    """A block rotated by 45° (or 135°) inside one scaled (1, -2): arcs become ellipses.

    Under S(1, -2)·R(45°) the block's x and y axes are both √2.5 long but no longer
    perpendicular; ezdxf (1.4) judges such a map by the axes' lengths alone and would keep
    the circle, the arc and the polyline's bulge circular (the circle a 4.74 mm radius
    circle, where the placed curve is an ellipse of semi-axes 3 and 6 mm). Expected
    points: the drawn curves placed by p' = T + R·S·p, inner then outer (analysis).
    """
    inner = _placer((3.0, 3.0), angle, 1.5, 1.5)
    outer = _placer((0.0, 0.0), 0.0, 1.0, -2.0)

    def build(msp: Any) -> None:
        part = msp.doc.blocks.new("B")
        part.add_circle((0, 0), 2)
        part.add_arc((5, 0), 1, 0, 90)
        part.add_lwpolyline([(0, 0, 0), (3, 0, 0.5), (3, 3, 0)], format="xyb")
        rotated = {"rotation": angle, "xscale": 1.5, "yscale": 1.5}
        msp.doc.blocks.new("C").add_blockref("B", (3, 3), dxfattribs=rotated)
        msp.add_blockref("C", (0, 0), dxfattribs={"yscale": -2})

    contours = read_dxf(write_dxf(tmp_path / "nested45.dxf", build)).contours
    arc, circle, polyline = sorted(contours, key=lambda c: c.source)  # ARC, CIRCLE, LWPOLYLINE
    ts = _range(0.0, 2 * math.pi)
    _assert_close([outer(inner((2 * math.cos(t), 2 * math.sin(t)))) for t in ts], circle.segments)
    quarter = [(5 + math.cos(t), math.sin(t)) for t in _range(0.0, math.pi / 2)]
    _assert_close([outer(inner(p)) for p in quarter], arc.segments)
    # bulge 0.5 from (3, 0) to (3, 3): counter-clockwise about (1.875, 1.5), radius 1.875
    half = math.atan2(1.5, 1.125)
    bulge = [(1.875 + 1.875 * math.cos(t), 1.5 + 1.875 * math.sin(t)) for t in _range(-half, half)]
    true = _polyline_points([(0, 0), (3, 0)]) + bulge
    _assert_close([outer(inner(p)) for p in true], polyline.segments)


@settings(max_examples=int(os.environ.get("CAMTOOL_INSERT_EXAMPLES", "30")), deadline=None)
@given(
    angle=st.sampled_from([0.0, 17.5, 45.0, 90.0, 135.0, 225.0, 315.0]),
    k=st.sampled_from([0.5, 1.0, 1.5]),
    scales=st.sampled_from([(1.0, 2.0), (1.0, -2.0), (-3.0, 0.5), (2.0, 2.0), (0.25, 1.0)]),
    outer_angle=st.sampled_from([0.0, 30.0, 45.0]),
    r=st.floats(0.5, 5.0).map(lambda v: round(v, 2)),
    start=st.floats(0.0, 300.0).map(lambda v: round(v, 1)),
)
def test_property_nested_arcs_are_placed_by_both_inserts(
    angle: float,
    k: float,
    scales: tuple[float, float],
    outer_angle: float,
    r: float,
    start: float,
) -> None:
    """A circle and an arc in a block inserted (rotated, scaled) in a block inserted with
    any scale and rotation: every point is the drawn point placed by p' = T + R·S·p, inner
    then outer (the DXF reference's INSERT), whatever shear the two make together."""
    sx, sy = scales
    inner = _placer((3.0, -2.0), angle, k, k)
    outer = _placer((10.0, 20.0), outer_angle, sx, sy)

    def build(msp: Any) -> None:
        part = msp.doc.blocks.new("B")
        part.add_circle((1, 1), r)
        part.add_arc((-4, 2), r, start, start + 100.0)
        placed = {"rotation": angle, "xscale": k, "yscale": k}
        msp.doc.blocks.new("C").add_blockref("B", (3, -2), dxfattribs=placed)
        scaled = {"rotation": outer_angle, "xscale": sx, "yscale": sy}
        msp.add_blockref("C", (10, 20), dxfattribs=scaled)

    with tempfile.TemporaryDirectory() as tmp:
        contours = read_dxf(write_dxf(Path(tmp) / "nested.dxf", build)).contours
    arc, circle = sorted(contours, key=lambda c: c.source)  # ARC, CIRCLE
    ts = _range(0.0, 2 * math.pi, 720)
    drawn = [(1 + r * math.cos(t), 1 + r * math.sin(t)) for t in ts]
    _assert_close([outer(inner(p)) for p in drawn], circle.segments)
    a0 = math.radians(start)
    sweep = [
        (-4 + r * math.cos(t), 2 + r * math.sin(t)) for t in _range(a0, a0 + math.radians(100), 360)
    ]
    _assert_close([outer(inner(p)) for p in sweep], arc.segments)


def test_minsert_rows_and_columns(tmp_path: Path) -> None:
    def build(msp: Any) -> None:
        msp.doc.blocks.new("HOLE").add_circle((0, 0), 1.0)
        msp.add_blockref(
            "HOLE",
            (100, 50),
            dxfattribs={
                "row_count": 3,
                "column_count": 4,
                "row_spacing": 10.0,
                "column_spacing": 5.0,
                "rotation": 90.0,
            },
        )

    contours = read_dxf(write_dxf(tmp_path / "m.dxf", build)).contours
    assert len(contours) == 12
    # the grid turns with the insert: column offset (5 c, 0) → (0, 5 c); row (0, 10 r) → (−10 r, 0)
    want = {(100.0 - 10 * r, 50.0 + 5 * c) for r in range(3) for c in range(4)}
    got = set()
    for contour in contours:
        (arc,) = contour.segments
        assert isinstance(arc, Arc) and arc.is_full_circle and arc.radius == pytest.approx(1.0)
        got.add((round(arc.centre[0], 9), round(arc.centre[1], 9)))
    assert got == want
    assert "row 3 column 4" in contours[-1].source


def test_nested_blocks_two_levels_with_layer_zero_inheritance(tmp_path: Path) -> None:
    def build(msp: Any) -> None:
        nut = msp.doc.blocks.new("NUT")
        nut.add_line((0, 0), (1, 0))  # layer 0: takes the layer of the INSERT chain
        nut.add_circle((0, 0), 0.25, dxfattribs={"layer": "HOLES"})  # keeps its layer
        bolt = msp.doc.blocks.new("BOLT")
        bolt.add_blockref("NUT", (5, 0), dxfattribs={"rotation": 90})  # on layer 0 too
        msp.add_blockref("BOLT", (100, 0), dxfattribs={"xscale": 2, "yscale": 2, "layer": "PARTS"})

    path = write_dxf(tmp_path / "n.dxf", build)
    line, hole = read_dxf(path).contours
    # NUT: (0,0)-(1,0) rotated 90° → (0,0)-(0,1), at (5,0) → (5,0)-(5,1); BOLT ×2 at (100,0)
    (seg,) = line.segments
    assert seg.start == pytest.approx((110.0, 0.0)) and seg.end == pytest.approx((110.0, 2.0))
    assert line.layer == "PARTS" and hole.layer == "HOLES"
    (arc,) = hole.segments
    assert isinstance(arc, Arc) and arc.radius == pytest.approx(0.5)
    doc = ezdxf.readfile(path)
    nut_line = doc.blocks.get("NUT").query("LINE")[0].dxf.handle
    nut_ref = doc.blocks.get("BOLT").query("INSERT")[0].dxf.handle
    bolt_ref = doc.modelspace().query("INSERT")[0].dxf.handle
    assert line.source == (
        f"LINE #{nut_line} in INSERT #{nut_ref} (block 'NUT') in INSERT #{bolt_ref} (block 'BOLT')"
    )
    only_parts = read_dxf(path, ImportOptions(layers=("parts",))).contours
    assert [c.layer for c in only_parts] == ["PARTS"]


def test_mirrored_ocs_entities_inside_a_block(tmp_path: Path) -> None:
    # Block content with extrusion (0,0,-1) is seen mirrored (x → −x) before the insert
    # moves it; a mirrored INSERT mirrors it back to counter-clockwise.
    def build(msp: Any) -> None:
        block = msp.doc.blocks.new("M")
        block.add_arc((1, 0), 1.0, 0, 90, dxfattribs={"extrusion": (0, 0, -1)})
        block.add_lwpolyline(
            [(0, 0, 1.0), (2, 0, 0)], format="xyb", dxfattribs={"extrusion": (0, 0, -1)}
        )
        msp.add_blockref("M", (10, 10))
        msp.add_blockref("M", (20, 10), dxfattribs={"xscale": -1})

    arc, half, arc_back, half_back = read_dxf(write_dxf(tmp_path / "o.dxf", build)).contours
    a = arc.segments[0]
    assert isinstance(a, Arc) and a.clockwise
    assert a.centre == pytest.approx((9.0, 10.0))  # OCS centre (1, 0) → WCS (−1, 0), then +(10, 10)
    assert a.start == pytest.approx((8.0, 10.0)) and a.end == pytest.approx((9.0, 11.0))
    h = half.segments[0]
    assert isinstance(h, Arc) and h.clockwise and h.end == pytest.approx((8.0, 10.0))
    b = arc_back.segments[0]
    assert isinstance(b, Arc) and not b.clockwise and b.centre == pytest.approx((21.0, 10.0))
    assert _same_segment(
        half_back.segments[0], Arc((20.0, 10.0), (22.0, 10.0), (21.0, 10.0), False)
    )


def test_block_base_point_is_the_insertion_point(tmp_path: Path) -> None:
    def build(msp: Any) -> None:
        block = msp.doc.blocks.new("BP", base_point=(5, 5))
        block.add_line((5, 5), (6, 5))
        msp.add_blockref("BP", (0, 0))

    (line,) = read_dxf(write_dxf(tmp_path / "bp.dxf", build)).contours
    assert line.segments[0] == Line((0.0, 0.0), (1.0, 0.0))


def test_ellipse_in_a_rotated_scaled_insert_holds_tolerance(tmp_path: Path) -> None:
    place = _placer((3.0, -2.0), 50.0, 1.5, 0.75)

    def build(msp: Any) -> None:
        block = msp.doc.blocks.new("E")
        block.add_ellipse((1, 1), (8, 2, 0), 0.3, 0.3, 4.0)
        msp.add_blockref("E", (3, -2), dxfattribs={"rotation": 50, "xscale": 1.5, "yscale": 0.75})

    (contour,) = read_dxf(write_dxf(tmp_path / "e.dxf", build)).contours
    # block ellipse: c + M cos t + m sin t with M = (8, 2), m = z × M · 0.3 = (−0.6, 2.4)
    true = [
        place((1 + 8 * math.cos(t) - 0.6 * math.sin(t), 1 + 2 * math.cos(t) + 2.4 * math.sin(t)))
        for t in _range(0.3, 4.0)
    ]
    _assert_close(true, contour.segments)


def test_missing_block_is_skipped_with_a_warning(tmp_path: Path) -> None:
    def build(msp: Any) -> None:
        msp.add_line((0, 0), (1, 0))
        msp.add_blockref("GONE", (0, 0))  # no block of that name

    d = read_dxf(write_dxf(tmp_path / "g.dxf", build))
    assert len(d.contours) == 1
    assert any("INSERT" in w and "is missing" in w for w in d.warnings), d.warnings


def test_an_external_reference_is_named_not_dropped_silently(tmp_path: Path) -> None:
    """An XREF's block is empty here (its content is in the other file): say so."""
    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    doc.add_xref_def("parts/bracket.dxf", "BRACKET")  # as AutoCAD's XATTACH writes it
    doc.modelspace().add_blockref("BRACKET", (10, 10))
    doc.modelspace().add_circle((50, 0), 5)
    path = tmp_path / "x.dxf"
    doc.saveas(path)
    drawing = read_dxf(path)
    assert len(drawing.contours) == 1
    assert drawing.warnings == (
        f"{path}: skipped 1 INSERT entity (block 'BRACKET' is an external reference to "
        "parts/bracket.dxf, which camtool does not read; bind it in the CAD program "
        "(XREF > Bind) to cut it)",
    )


@pytest.mark.parametrize("nested", [False, True])
def test_a_clipped_block_reference_is_refused_not_cut_whole(tmp_path: Path, nested: bool) -> None:
    """An XCLIP boundary shows part of a block; cutting the whole block cuts what it hides."""
    from ezdxf.xclip import XClip

    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    square = doc.blocks.new("SQUARE")
    square.add_lwpolyline([(0, 0), (40, 0), (40, 40), (0, 40)], close=True)
    square.add_circle((30, 30), 5)
    outer = doc.blocks.new("OUTER")
    inner = (outer if nested else doc.modelspace()).add_blockref("SQUARE", (10, 10))
    XClip(inner).set_block_clipping_path([(0, 0), (20, 20)])  # the circle is hidden
    if nested:
        doc.modelspace().add_blockref("OUTER", (0, 0))
    path = tmp_path / "clip.dxf"
    doc.saveas(path)
    with pytest.raises(
        InputError,
        match=r"clip\.dxf: INSERT #\w+ (in INSERT #\w+ \(block 'OUTER'\) )?on layer '0' "
        "shows only part of block 'SQUARE'",
    ):
        read_dxf(path)
    XClip(inner).disable_clipping()  # a clip switched off shows the whole block: it is read
    doc.saveas(path)
    assert len(read_dxf(path).contours) == 2


def _block_with_foreign_data(path: Path) -> Path:
    """A block's LINE (0, 0)-(10, 0) placed at (5, 5) turned 30°, the LINE carrying an
    extension dictionary that owns an object of a class ezdxf does not know (TurboCAD
    writes TCOPTIONALDATA there): ezdxf can read it but not copy it."""
    doc = ezdxf.new("R2010", units=4)
    line = doc.blocks.new("B").add_line((0, 0), (10, 0))
    owner = line.new_extension_dict()
    owner.dictionary.dxf.hard_owned = 1
    owner.add_xrecord("TCOPT").reset([(1, "foreign")])
    doc.modelspace().add_blockref("B", (5, 5), dxfattribs={"rotation": 30})
    text = io.StringIO()
    doc.write(text)
    foreign = text.getvalue().replace("\n  0\nXRECORD\n", "\n  0\nTCOPTIONALDATA\n")
    path.write_text(foreign.replace("AcDbXrecord", "AcDbTCOptionalData"))
    return path


def test_data_other_programs_attach_to_a_block_entity_is_left_behind(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    """Placing a block copies its entities' geometry only: ezdxf, asked to copy the object
    it cannot, logged a line on stderr per placement, outside camtool's messages."""
    drawing = read_dxf(_block_with_foreign_data(tmp_path / "tc.dxf"))
    assert not [w for w in drawing.warnings if "ezdxf" in w], drawing.warnings
    assert not [r for r in caplog.records if r.name.startswith("ezdxf")]
    (contour,) = drawing.contours
    place = _placer((5.0, 5.0), 30.0)
    assert contour.start == pytest.approx(place((0.0, 0.0)), abs=1e-9)
    assert contour.end == pytest.approx(place((10.0, 0.0)), abs=1e-9)


def test_what_ezdxf_logs_while_the_entities_are_read_is_a_warning(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, caplog: pytest.LogCaptureFixture
) -> None:
    """Anything ezdxf logs while the entities are read and placed becomes one warning that
    names the file, not a bare line of ezdxf's on stderr (here: a full copy of the entity)."""
    import camtool.importers.dxf_blocks as blocks

    monkeypatch.setattr(blocks, "geometry_copy", lambda entity: entity.copy())
    path = _block_with_foreign_data(tmp_path / "tc.dxf")
    drawing = read_dxf(path)
    (noted,) = [w for w in drawing.warnings if "ezdxf" in w]
    assert noted.startswith(
        f"{path}: ezdxf logged 1 message(s) while reading the entities (first: copy process "
        "ignored TCOPTIONALDATA(#"
    )
    assert noted.endswith("); check the result in the preview"), noted
    assert not [r for r in caplog.records if r.name.startswith("ezdxf")]
