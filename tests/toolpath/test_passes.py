"""Emitting moves: splitting, 2D moves, depth passes, safe Z, ramps, tabs and lead arcs.

Expectations are analytic (lengths, slopes, tangents, areas); the one thesis number
is Munoz-22's cut depth of −1 mm (reference/Munoz-22.md, §"Gcodetools" step 14, L446).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from itertools import pairwise

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from shapely.geometry import LineString, Point, Polygon

from camtool.model.errors import ToolpathError
from camtool.model.program import ArcMove, Linear, Move, Rapid, segment_of
from camtool.model.shapes import Arc, Contour, Line, Segment
from camtool.toolpath.cuts import Cut
from camtool.toolpath.leads import lead_arcs
from camtool.toolpath.options import PlanOptions
from camtool.toolpath.passes import emit_moves, pass_depths, tab_spans
from camtool.toolpath.split import Track, end_tangent, start_tangent, sub_segment

FEED = 300.0
PLUNGE = 60.0


def _rect_cw(x0: float, y0: float, x1: float, y1: float) -> Contour:
    """Clockwise rectangle from its lower-left corner (an outer boundary cut climb)."""
    pts = [(x0, y0), (x0, y1), (x1, y1), (x1, y0)]
    return Contour(tuple(Line(pts[i], pts[(i + 1) % 4]) for i in range(4)), True)


def _circle(cx: float, cy: float, r: float, clockwise: bool = False) -> Contour:
    return Contour((Arc((cx + r, cy), (cx + r, cy), (cx, cy), clockwise),), True)


def _rounded_rect() -> Contour:
    """The 10 × 5 rectangle offset outside by 0.5 mm, clockwise, starting mid-edge."""
    r = 0.5
    segs: list[Segment] = [
        Line((-r, 2.5), (-r, 5.0)),
        Arc((-r, 5.0), (0.0, 5.0 + r), (0.0, 5.0), True),
        Line((0.0, 5.0 + r), (10.0, 5.0 + r)),
        Arc((10.0, 5.0 + r), (10.0 + r, 5.0), (10.0, 5.0), True),
        Line((10.0 + r, 5.0), (10.0 + r, 0.0)),
        Arc((10.0 + r, 0.0), (10.0, -r), (10.0, 0.0), True),
        Line((10.0, -r), (0.0, -r)),
        Arc((0.0, -r), (-r, 0.0), (0.0, 0.0), True),
        Line((-r, 0.0), (-r, 2.5)),
    ]
    return Contour(tuple(segs), True)


def _options(**kw: object) -> PlanOptions:
    base: dict[str, object] = {"feed_mm_min": FEED}
    if kw.get("depth") is not None:
        base["plunge_feed_mm_min"] = PLUNGE
    base.update(kw)
    return PlanOptions(**base)  # type: ignore[arg-type]


@dataclass(frozen=True)
class Stroke:
    """A move with the 3D point it starts from and its XY path."""

    move: Move
    z0: float | None
    z1: float | None
    xy: Segment

    @property
    def xy_length(self) -> float:
        return 0.0 if self.xy.start == self.xy.end and isinstance(self.xy, Line) else self.xy.length


def strokes(moves: Sequence[Move], origin: tuple[float, float] = (0.0, 0.0)) -> list[Stroke]:
    here, z = origin, None
    out = []
    for m in moves:
        z1 = z if m.z is None else m.z
        out.append(Stroke(m, z, z1, segment_of(here, m)))
        here, z = (m.x, m.y), z1
    return out


def _xy_moves(ss: Sequence[Stroke]) -> list[Stroke]:
    return [s for s in ss if s.xy_length > 1e-12]


def _samples(seg: Segment, n: int = 32) -> list[tuple[float, float]]:
    if isinstance(seg, Arc):
        return [seg.point_at(k / n) for k in range(n + 1)]
    (x0, y0), (x1, y1) = seg.start, seg.end
    return [(x0 + (x1 - x0) * k / n, y0 + (y1 - y0) * k / n) for k in range(n + 1)]


def _polygon(contour: Contour) -> Polygon:
    return Polygon(contour.points(1e-4))


# --- splitting ---------------------------------------------------------------------------


def test_sub_segment_line_and_arc_exact() -> None:
    line = Line((0.0, 0.0), (4.0, 3.0))  # length 5
    piece = sub_segment(line, 1.0, 5.0)
    assert piece.start == pytest.approx((0.8, 0.6)) and piece.end == (4.0, 3.0)
    arc = Arc((2.0, 0.0), (-2.0, 0.0), (0.0, 0.0), False)  # half circle r = 2, length 2π
    part = sub_segment(arc, 0.0, math.pi)  # a quarter: ends at (0, 2)
    assert isinstance(part, Arc)
    assert part.start == (2.0, 0.0) and part.centre == (0.0, 0.0) and not part.clockwise
    assert part.end == pytest.approx((0.0, 2.0))
    assert part.length == pytest.approx(math.pi)


def test_tangents() -> None:
    ccw = Arc((1.0, 0.0), (0.0, 1.0), (0.0, 0.0), False)
    cw = Arc((1.0, 0.0), (0.0, -1.0), (0.0, 0.0), True)
    assert start_tangent(ccw) == pytest.approx((0.0, 1.0))
    assert end_tangent(ccw) == pytest.approx((-1.0, 0.0))
    assert start_tangent(cw) == pytest.approx((0.0, -1.0))
    assert start_tangent(Line((0.0, 0.0), (0.0, -2.0))) == pytest.approx((0.0, -1.0))


@settings(max_examples=60, deadline=None)
@given(
    s0=st.floats(0.0, 60.0),
    span=st.floats(1e-3, 60.0),
)
def test_track_pieces_cover_the_span(s0: float, span: float) -> None:
    track = Track.of(_rounded_rect())  # length 2·(10 + 5) + π·0.5 ≈ 31.57, wraps round
    pieces = track.pieces(s0, s0 + span)
    assert sum(seg.length for seg, _ in pieces) == pytest.approx(span, abs=1e-7)
    assert pieces[0][0].start == pytest.approx(track.point_at(s0), abs=1e-9)
    assert pieces[-1][1] == pytest.approx(s0 + span)
    for (a, _), (b, _) in pairwise(pieces):
        assert math.dist(a.end, b.start) < 1e-9
    for seg, s_end in pieces:
        assert math.dist(seg.end, track.point_at(s_end)) < 1e-9


def test_track_pieces_keep_the_segments_ends_exactly() -> None:
    """Whole segments come back as they are, and pieces meet exactly where segments did.

    The cumulative lengths (``Track.ends``) carry rounding: ``ends[i] - ends[i - 1]`` is
    not each segment's length to the last bit, which must not turn a whole segment into a
    rebuilt one whose end is an interpolated point a rounding off.
    """
    corners = [(0.1 * k + 0.013 * k * k, 0.7 * math.sin(k)) for k in range(40)]
    segments = tuple(Line(a, b) for a, b in pairwise([*corners, corners[0]]))
    track = Track.from_segments(segments, True)
    whole = track.pieces(0.0, track.length)
    assert [seg for seg, _ in whole] == list(segments)
    assert all(seg is original for (seg, _), original in zip(whole, segments, strict=True))
    mid = 0.5 * segments[0].length  # from the middle of the first, round to it again
    around = track.pieces(mid, mid + track.length)
    assert len(around) == len(segments) + 1
    inner = zip(around[1:-1], segments[1:], strict=True)
    assert all(seg is original for (seg, _), original in inner)
    assert around[0][0].end == segments[0].end and around[-1][0].start == segments[0].start
    for (a, _), (b, _) in pairwise(around):
        assert a.end == b.start


def test_track_reversed_maps_arc_length() -> None:
    track = Track.of(_rounded_rect())
    back = track.reversed()
    for s in (0.3, 7.0, 20.0):
        assert math.dist(back.point_at(track.length - s), track.point_at(s)) < 1e-9


# --- pass depths -------------------------------------------------------------------------


def test_pass_depths() -> None:
    assert pass_depths(3.0, 1.0) == (-1.0, -2.0, -3.0)
    assert pass_depths(2.5, 1.0) == (-1.0, -2.0, -2.5)
    assert pass_depths(2.0, None) == (-2.0,)
    assert pass_depths(2.0, 5.0) == (-2.0,)
    # 0.3 / 0.1 = 2.9999999999999996 in floats: still 3 passes, the last exactly −0.3
    assert pass_depths(0.3, 0.1) == pytest.approx((-0.1, -0.2, -0.3))
    assert len(pass_depths(0.3, 0.1)) == 3 and pass_depths(0.3, 0.1)[-1] == -0.3
    # Munoz-22 (Gcodetools step 14, L446): one pass at the thesis's cut depth Z = −1 mm
    assert pass_depths(1.0, None) == (-1.0,)


@given(depth=st.floats(0.01, 20.0), ratio=st.floats(0.01, 1.5))
def test_pass_depths_property(depth: float, ratio: float) -> None:
    step = depth * ratio
    zs = pass_depths(depth, step)
    assert zs[-1] == -depth
    steps = [a - b for a, b in zip((0.0, *zs), zs, strict=False)]
    assert all(0 < s <= step * (1 + 1e-9) for s in steps)
    assert len(zs) == max(1, math.ceil(depth / step - 1e-9))


# --- 2D ----------------------------------------------------------------------------------


def test_2d_is_a_rapid_then_one_move_per_segment() -> None:
    cuts = [Cut(_rounded_rect(), 0), Cut(_circle(20, 0, 2), 1), Cut(_rect_cw(30, 0, 31, 1), 2)]
    moves = emit_moves(cuts, _options())
    expected: list[Move] = []
    for number, cut in enumerate(cuts, start=1):
        expected.append(Rapid(*cut.path.start, contour=number))
        for seg in cut.path.segments:
            if isinstance(seg, Arc):
                expected.append(ArcMove(*seg.end, *seg.centre, seg.clockwise, FEED, contour=number))
            else:
                expected.append(Linear(*seg.end, FEED, contour=number))
    assert moves == expected


def test_2d_keeps_a_rapid_when_already_there() -> None:
    a = Contour((Line((0.0, 0.0), (1.0, 0.0)),), False)
    b = Contour((Line((1.0, 0.0), (1.0, 1.0)),), False)
    moves = emit_moves(
        [Cut(a, 0, "open", may_rotate=False), Cut(b, 1, "open", may_rotate=False)], _options()
    )
    assert [type(m) for m in moves] == [Rapid, Linear, Rapid, Linear]
    assert [m.contour for m in moves] == [1, 1, 2, 2]


# --- lead arcs ---------------------------------------------------------------------------


def _check_lead(lead_in: Arc, lead_out: Arc, path: Contour, radius: float) -> None:
    assert lead_in.end == path.start and lead_out.start == path.end
    for arc in (lead_in, lead_out):
        assert arc.radius == pytest.approx(radius)
        assert abs(arc.sweep) == pytest.approx(math.pi / 2)
    assert end_tangent(lead_in) == pytest.approx(start_tangent(path.segments[0]))
    assert start_tangent(lead_out) == pytest.approx(end_tangent(path.segments[-1]))


@pytest.mark.parametrize("path", [_rounded_rect(), _rect_cw(0, 0, 10, 5), _circle(0, 0, 5, True)])
def test_lead_arcs_outside_stay_off_the_part(path: Contour) -> None:
    # A clockwise outer path cut climb keeps the part on its right: the leads come from outside.
    cut = Cut(path, 0, outside_profile=True, material_side="right")
    lead_in, lead_out = lead_arcs(cut, 1.5)
    _check_lead(lead_in, lead_out, path, 1.5)
    part = _polygon(path)
    for arc in (lead_in, lead_out):
        assert part.intersection(LineString(_samples(arc))).length < 1e-6
        assert not part.contains(Point(arc.point_at(0.5)))


def test_lead_arcs_in_a_hole_stay_in_the_hole() -> None:
    # A hole of radius 5 cut climb runs counter-clockwise, material (outside it) on the right.
    hole = _circle(0, 0, 5, clockwise=False)
    lead_in, lead_out = lead_arcs(Cut(hole, 0, material_side="right"), 2.0)
    _check_lead(lead_in, lead_out, hole, 2.0)
    waste = _polygon(hole).buffer(1e-6)
    assert waste.contains(LineString(_samples(lead_in)))
    assert waste.contains(LineString(_samples(lead_out)))


def test_lead_arcs_shrink_to_fit_a_small_hole() -> None:
    # The plate sample's ø4 mm holes with a 3 mm tool leave a tool path of radius 0.5 mm: a
    # 2 mm lead arc would swing across the hole into its wall. Halving 2 → 1 → 0.5 mm gives
    # the first quarter circle that stays inside (internally tangent at radius 0.5).
    hole = _circle(0, 0, 0.5, clockwise=False)
    cut = Cut(hole, 0, material_side="right")
    lead_in, lead_out = lead_arcs(cut, 2.0)
    _check_lead(lead_in, lead_out, hole, 0.5)
    for arc in (lead_in, lead_out):
        assert all(math.hypot(x, y) <= 0.5 + 1e-9 for x, y in _samples(arc))


def test_lead_arcs_follow_the_material_side() -> None:
    # Conventional milling of the same outline (counter-clockwise, part on the left).
    path = _rounded_rect().reversed()
    lead_in, lead_out = lead_arcs(Cut(path, 0, material_side="left"), 1.0)
    _check_lead(lead_in, lead_out, path, 1.0)
    assert lead_in.clockwise and lead_out.clockwise
    part = _polygon(path)
    assert not part.contains(Point(lead_in.start)) and not part.contains(Point(lead_out.end))


def test_lead_moves_2d_and_with_depth() -> None:
    path = _rounded_rect()
    cut = Cut(path, 0, outside_profile=True, material_side="right")
    lead_in, lead_out = lead_arcs(cut, 1.0)
    moves = emit_moves([cut], _options(offset="outside", tool_diameter=1.0, lead_in=1.0))
    assert moves[0] == Rapid(*lead_in.start, contour=1)
    assert moves[1] == ArcMove(*lead_in.end, *lead_in.centre, lead_in.clockwise, FEED, contour=1)
    assert moves[-1] == ArcMove(
        *lead_out.end, *lead_out.centre, lead_out.clockwise, FEED, contour=1
    )
    assert len(moves) == len(path.segments) + 3
    deep = emit_moves(
        [cut],
        _options(offset="outside", tool_diameter=1.0, lead_in=1.0, depth=1.0, step_down=0.5),
    )
    plunges = [m for m in deep if isinstance(m, Linear) and m.z is not None]
    assert [m.z for m in plunges] == [-0.5, -1.0]
    part = _polygon(path)
    for m in plunges:  # each pass goes down at the lead-in start, off the part
        assert (m.x, m.y) == lead_in.start and not part.contains(Point(m.x, m.y))
        assert m.feed_mm_min == PLUNGE


# --- depth passes and safe Z -------------------------------------------------------------


def _check_safe(
    moves: Sequence[Move], safe_z: float, clearance: float | None = None, plunge: float = PLUNGE
) -> list[Stroke]:
    """The Z-plan rules every program keeps; returns the strokes.

    It starts with a Z-only rapid up to clearance where the tool stands (X0 Y0),
    every rapid is at safe Z or above (XY travel at safe Z or clearance, never
    diagonal), a Z-only rapid goes down only to safe Z, cutting moves stay at or
    below the top, and the program ends at clearance.
    """
    clear = max(5.0, safe_z) if clearance is None else clearance
    ss = strokes(moves)
    first = moves[0]
    assert isinstance(first, Rapid) and first.z == clear and (first.x, first.y) == (0.0, 0.0)
    for s in ss:
        if isinstance(s.move, Rapid):
            assert s.z1 is not None and s.z1 >= safe_z  # no rapid below safe Z
            if s.xy_length > 0:  # travel: flat, at safe Z or clearance
                assert s.z0 == s.z1 and s.z1 in (safe_z, clear)
            elif s.z0 is not None and s.z1 < s.z0:  # down from clearance: only to safe Z
                assert s.z1 == safe_z
            else:  # a retract: Z only, upwards
                assert s.z1 in (safe_z, clear)
            continue
        assert s.z1 is not None and s.z0 is not None
        if s.xy_length == 0:
            assert s.z1 != s.z0
            feed = plunge if s.z1 < s.z0 else FEED
            assert s.move.feed_mm_min == feed
            assert s.z1 <= 0
        else:
            assert s.move.feed_mm_min == FEED
            assert s.z0 <= 1e-12 and s.z1 <= 1e-12  # no cutting move above the top
            assert s.z1 <= s.z0 + 1e-12  # only Z-only moves go up (onto a tab)
    assert ss[-1].z1 == clear
    return ss


def test_closed_cut_passes_in_a_row() -> None:
    path = _rounded_rect()
    o = _options(depth=1.5, step_down=0.5, safe_z=3.0)
    ss = _check_safe(emit_moves([Cut(path, 0)], o), 3.0)
    rapids = [s for s in ss if isinstance(s.move, Rapid)]
    # up to clearance, travel, down to safe Z, final rise: no retract between passes
    assert len(rapids) == 4
    plunges = [s for s in ss if s.xy_length == 0 and not isinstance(s.move, Rapid)]
    assert [s.z1 for s in plunges] == [-0.5, -1.0, -1.5]
    assert all((s.move.x, s.move.y) == path.start for s in plunges)
    for z in (-0.5, -1.0, -1.5):
        cut = sum(s.xy_length for s in ss if s.z0 == z and s.z1 == z and s.xy_length > 0)
        assert cut == pytest.approx(path.length)


def test_open_cut_retracts_or_cuts_back() -> None:
    line = Contour((Line((1.0, 0.0), (8.0, 0.0)), Line((8.0, 0.0), (8.0, 3.0))), False)
    o = _options(depth=1.0, step_down=0.5)
    fixed = Cut(line, 0, "open", may_reverse=False, may_rotate=False)
    ss = _check_safe(emit_moves([fixed], o), o.safe_z)
    travels = [s for s in ss if isinstance(s.move, Rapid) and s.xy_length > 0]
    assert [(s.move.x, s.move.y) for s in travels] == [line.start, line.start]
    cuts = [s for s in _xy_moves(ss) if not isinstance(s.move, Rapid)]
    assert [(s.move.x, s.move.y) for s in cuts] == [(8.0, 0.0), (8.0, 3.0)] * 2

    free = Cut(line, 0, "open", may_reverse=True, may_rotate=False)
    ss = _check_safe(emit_moves([free], o), o.safe_z)
    assert len([s for s in ss if isinstance(s.move, Rapid) and s.xy_length > 0]) == 1
    ends = [(s.move.x, s.move.y, s.z1) for s in _xy_moves(ss) if not isinstance(s.move, Rapid)]
    assert ends == [(8.0, 0.0, -0.5), (8.0, 3.0, -0.5), (8.0, 0.0, -1.0), (1.0, 0.0, -1.0)]


def test_pocket_rings_level_by_level() -> None:
    rings = [Cut(_rect_cw(1, 1, 4, 4), 7, "pocket"), Cut(_rect_cw(2, 2, 3, 3), 7, "pocket")]
    other = Cut(_rect_cw(10, 0, 12, 2), 8)
    o = _options(depth=1.0, step_down=0.5)
    ss = _check_safe(emit_moves([*rings, other], o), o.safe_z)
    visits = [
        (s.move.contour, s.z1) for s in ss if s.xy_length == 0 and not isinstance(s.move, Rapid)
    ]
    assert visits == [(1, -0.5), (2, -0.5), (1, -1.0), (2, -1.0), (3, -0.5), (3, -1.0)]
    travels = [s.move.contour for s in ss if isinstance(s.move, Rapid) and s.xy_length > 0]
    assert travels == [1, 2, 1, 2, 3]


@settings(max_examples=40, deadline=None)
@given(
    depth=st.floats(0.2, 3.0),
    ratio=st.sampled_from([None, 0.3, 0.5, 1.0]),
    ramp=st.sampled_from([None, 3.0, 15.0, 45.0]),
    tabs=st.integers(0, 3),
    lead=st.sampled_from([0.0, 1.0]),
    reverse=st.booleans(),
)
def test_safe_z_rules_hold_for_any_mix(
    depth: float, ratio: float | None, ramp: float | None, tabs: int, lead: float, reverse: bool
) -> None:
    cuts = [
        Cut(_circle(20, 0, 1.0, clockwise=False), 0, material_side="right"),
        Cut(Contour((Line((0.0, -5.0), (3.0, -5.0)),), False), 1, "open", reverse, False),
        Cut(_rect_cw(0, 0, 1, 1), 2, "pocket"),
        Cut(_rect_cw(0.3, 0.3, 0.7, 0.7), 2, "pocket"),
        Cut(_rounded_rect(), 3, outside_profile=True, material_side="right"),
    ]
    o = _options(
        offset="outside",
        tool_diameter=1.0,
        depth=depth,
        step_down=None if ratio is None else depth * ratio,
        ramp_deg=ramp,
        tabs=tabs,
        tab_height=depth / 2,
        lead_in=lead,
    )
    ss = _check_safe(emit_moves(cuts, o), o.safe_z)
    assert min(s.z1 for s in ss if s.z1 is not None) == -depth
    assert sorted({s.move.contour for s in ss}) == [1, 2, 3, 4, 5]


# --- ramps -------------------------------------------------------------------------------


def _ramp_strokes(ss: Sequence[Stroke]) -> list[Stroke]:
    return [s for s in _xy_moves(ss) if s.z0 is not None and s.z1 is not None and s.z1 < s.z0]


@pytest.mark.parametrize("helix", [True, False])
def test_ramp_round_a_circle_is_a_helix(helix: bool) -> None:
    # r = 1 circle (2π ≈ 6.28 mm) and a 0.8 mm pass at 5°: L = 0.8/tan 5° ≈ 9.14 mm > 2π.
    circle = _circle(0, 0, 1.0)
    o = _options(depth=1.6, step_down=0.8, ramp_deg=5.0, tolerance=0.001)
    ss = _check_safe(emit_moves([Cut(circle, 0)], o, helix=helix), o.safe_z)
    ramps = _ramp_strokes(ss)
    slope = math.tan(math.radians(5.0))
    for s in ramps:
        assert isinstance(s.move, ArcMove if helix else Linear)
        if helix:
            assert s.z0 - s.z1 == pytest.approx(s.xy_length * slope)
        else:  # Z falls evenly per arc length: a chord is steeper by arc/chord ≤ 1 + tol/(3r)
            ratio = (s.z0 - s.z1) / (s.xy_length * slope)
            assert 1.0 <= ratio <= 1.0 + 1.01 * 0.001 / 3
    ramp_len = sum(s.xy_length for s in ramps)
    if helix:  # exact arcs: the descent is exactly L per pass
        assert ramp_len == pytest.approx(2 * 0.8 / slope)
    else:  # chords within 1 µm of the circle, a little shorter than the arc
        assert 0.999 * 2 * 0.8 / slope < ramp_len < 2 * 0.8 / slope
        for s in ramps:
            mid = ((s.xy.start[0] + s.xy.end[0]) / 2, (s.xy.start[1] + s.xy.end[1]) / 2)
            assert 1.0 - math.hypot(*mid) <= 0.001 + 1e-12
    for z in (-0.8, -1.6):  # after each ramp, one whole loop at the pass depth
        flat = sum(s.xy_length for s in _xy_moves(ss) if s.z0 == z and s.z1 == z)
        assert flat == pytest.approx(circle.length)


def test_ramp_on_a_long_loop_then_full_loop() -> None:
    path = _rounded_rect()
    o = _options(depth=1.0, ramp_deg=10.0)  # L = 1/tan 10° ≈ 5.67 mm < 31.6 mm
    ss = _check_safe(emit_moves([Cut(path, 0)], o), o.safe_z)
    down = [s for s in ss if s.xy_length == 0 and not isinstance(s.move, Rapid)]
    assert [s.z1 for s in down] == [0.0]  # only down to the top: the rest is the ramp
    ramps = _ramp_strokes(ss)
    assert sum(s.xy_length for s in ramps) == pytest.approx(1.0 / math.tan(math.radians(10)))
    assert ramps[0].xy.start == path.start
    flat = sum(s.xy_length for s in _xy_moves(ss) if s.z0 == -1.0 and s.z1 == -1.0)
    assert flat == pytest.approx(path.length)
    ramp_end = (ramps[-1].move.x, ramps[-1].move.y)
    assert (ss[-1].move.x, ss[-1].move.y) == pytest.approx(ramp_end)  # the loop closes there


def test_ramp_zigzags_on_a_short_open_path() -> None:
    # 2 mm path, 1 mm deep at 20°: L = 1/tan 20° ≈ 2.75 mm → forward 2 mm, back 0.75 mm.
    line = Contour((Line((0.0, 0.0), (2.0, 0.0)),), False)
    o = _options(depth=1.0, ramp_deg=20.0)
    ss = _check_safe(emit_moves([Cut(line, 0, "open", may_rotate=False)], o), o.safe_z)
    slope = math.tan(math.radians(20.0))
    ramps = _ramp_strokes(ss)
    assert [s.move.x for s in ramps] == pytest.approx([2.0, 2.0 - (1.0 / slope - 2.0)])
    for s in ramps:
        assert s.z0 - s.z1 == pytest.approx(s.xy_length * slope)
    assert ramps[-1].z1 == -1.0
    flat = [s for s in _xy_moves(ss) if s.z0 == -1.0 and s.z1 == -1.0]
    assert [s.move.x for s in flat] == pytest.approx([0.0, 2.0])  # back, then all of it


# --- tabs --------------------------------------------------------------------------------


def test_tab_spans_even_and_clear_of_the_entry() -> None:
    spans = tab_spans(100.0, 4, 3.0)
    assert [(a + b) / 2 for a, b in spans] == pytest.approx([16.25, 38.75, 61.25, 83.75])
    assert all(b - a == pytest.approx(3.0) for a, b in spans)
    with pytest.raises(ToolpathError, match="fewer --tabs"):
        tab_spans(10.0, 4, 3.0, "contour at (0, 0) mm")


@pytest.mark.parametrize("ramp", [None, 10.0])
def test_tabs_raise_the_tool_on_deep_passes(ramp: float | None) -> None:
    # depth 2, passes −0.5 … −2.0, tab top −2 + 0.5 = −1.5: only the −2.0 pass is deeper.
    path = _rect_cw(0, 0, 10, 5)
    o = _options(
        offset="outside",
        tool_diameter=1.0,
        depth=2.0,
        step_down=0.5,
        tabs=3,
        tab_width=2.0,
        tab_height=0.5,
        ramp_deg=ramp,
    )
    cut = Cut(path, 0, outside_profile=True, material_side="right")
    ss = _check_safe(emit_moves([cut], o), o.safe_z)
    ups = [
        s
        for s in ss
        if s.xy_length == 0
        and s.z0 is not None
        and s.z1 is not None
        and s.z1 > s.z0
        and not isinstance(s.move, Rapid)
    ]
    assert len(ups) == 3  # one rise per tab, on the one deep pass
    assert all(s.z0 == -2.0 and s.z1 == -1.5 and s.move.feed_mm_min == FEED for s in ups)
    over = sum(s.xy_length for s in _xy_moves(ss) if s.z0 == -1.5 and s.z1 == -1.5)
    if ramp is None:  # the −1.5 pass is above no tab: only the −2.0 pass rises
        over -= path.length
        assert over == pytest.approx(3 * (2.0 + 1.0))  # tab width + tool diameter each
    track = Track.of(path)
    for a, b in tab_spans(path.length, 3, 3.0):
        x0, y0 = track.point_at(a)
        assert any(math.dist((s.move.x, s.move.y), (x0, y0)) < 1e-9 for s in ups)
        for k in range(1, 10):  # nothing goes below the tab top over the tab
            px, py = track.point_at(a + (b - a) * k / 10)
            for s in _xy_moves(ss):
                if s.xy.start[1] == s.xy.end[1] == py and min(
                    s.xy.start[0], s.xy.end[0]
                ) < px < max(s.xy.start[0], s.xy.end[0]):
                    assert s.z1 >= -1.5 - 1e-12 and s.z0 >= -1.5 - 1e-12


def test_tabs_only_on_outside_profiles() -> None:
    o = _options(offset="outside", tool_diameter=1.0, depth=2.0, tabs=2, tab_height=0.5)
    hole = Cut(_rect_cw(0, 0, 10, 5).reversed(), 0, material_side="right")
    ss = _check_safe(emit_moves([hole], o), o.safe_z)
    assert all(s.z1 == -2.0 for s in _xy_moves(ss) if not isinstance(s.move, Rapid))


# --- start, end, clearance and parts (issue 13 §2) ------------------------------------------


def _travel_heights(ss: Sequence[Stroke]) -> list[tuple[int, float | None]]:
    return [(s.move.contour, s.z1) for s in ss if isinstance(s.move, Rapid) and s.xy_length > 0]


def test_start_is_z_only_to_clearance_then_xy_then_down() -> None:
    # The machine's XY before the program is unknown: the first move may only be vertical.
    path = _rect_cw(3, 4, 8, 6)
    o = _options(depth=1.0, safe_z=2.0, clearance_z=7.0)
    moves = emit_moves([Cut(path, 0)], o)
    assert moves[:4] == [
        Rapid(0.0, 0.0, 7.0, contour=1),  # Z only, where the tool stands
        Rapid(3.0, 4.0, contour=1),  # XY at clearance (Z unchanged)
        Rapid(3.0, 4.0, 2.0, contour=1),  # rapid down to safe Z only
        Linear(3.0, 4.0, PLUNGE, -1.0, contour=1),  # into the material at the plunge feed
    ]
    assert moves[-1] == Rapid(3.0, 4.0, 7.0, contour=1)  # Z only, up to clearance
    _check_safe(moves, 2.0, 7.0)


def test_clearance_between_parts_safe_z_within_a_part() -> None:
    # Two plates side by side, each with a hole: hole, plate, hole, plate (inside first).
    # A part is the outer profile and what lies inside it.
    plate_a, hole_a = _rect_cw(0, 0, 10, 10), _circle(5, 5, 1)
    plate_b, hole_b = _rect_cw(20, 0, 30, 10), _circle(25, 5, 1)
    cuts = [Cut(hole_a, 1), Cut(plate_a, 0), Cut(hole_b, 3), Cut(plate_b, 2)]
    o = _options(depth=1.0, safe_z=1.0)  # clearance: max(5, 1) = 5
    ss = _check_safe(emit_moves(cuts, o), 1.0)
    assert _travel_heights(ss) == [(1, 5.0), (2, 1.0), (3, 5.0), (4, 1.0)]
    # the retract after plate A and the rise to clearance are one move
    lifts = [
        (s.move.contour, s.z0, s.z1)
        for s in ss[1:]
        if isinstance(s.move, Rapid) and s.xy_length == 0 and s.z1 > s.z0
    ]
    # (the merged lift is numbered with the travel it starts: contour 3)
    assert lifts == [(1, -1.0, 1.0), (3, -1.0, 5.0), (3, -1.0, 1.0), (4, -1.0, 5.0)]


def test_a_part_that_starts_where_the_last_one_ended_needs_no_clearance() -> None:
    # two squares touching at a corner, each a part of its own: the second starts where the
    # first ends, so the tool retracts to safe Z and plunges again; a rise to clearance (for
    # the clamps, on a travel there is none of) and back would be two moves for nothing
    a, b = _rect_cw(0, 0, 10, 10), _rect_cw(10, 10, 20, 20)
    a = Contour(a.segments[2:] + a.segments[:2], True)  # from (10, 10), where b starts
    o = _options(depth=1.0, safe_z=2.0, clearance_z=7.0)
    moves = emit_moves([Cut(a, 0), Cut(b, 1)], o)
    _check_safe(moves, 2.0, 7.0)
    k = next(i for i, m in enumerate(moves) if m.contour == 2)
    last_cut = max(i for i, m in enumerate(moves[:k]) if isinstance(m, Linear))
    assert moves[last_cut + 1 : k + 1] == [
        Rapid(10.0, 10.0, 2.0, contour=1),  # up to safe Z only, where the tool stands
        Linear(10.0, 10.0, PLUNGE, -1.0, contour=2),
    ]
    # apart, the second part is reached at clearance, as before
    far = Contour(
        tuple(
            Line((x + 5, y + 5), (u + 5, v + 5))
            for (x, y), (u, v) in ((s.start, s.end) for s in b.segments)
        ),
        True,
    )
    moves = emit_moves([Cut(a, 0), Cut(far, 1)], o)
    assert [m.z for m in moves if m.contour == 2 and isinstance(m, Rapid)][:1] == [7.0]


def test_parts_group_nested_cuts_and_pocket_rings() -> None:
    from camtool.toolpath.passes import parts

    plate, hole, far = _rect_cw(0, 0, 10, 10), _circle(5, 5, 1), _rect_cw(20, 0, 22, 2)
    ring_a = Cut(_rect_cw(21, 21, 22, 22), 7, "pocket")
    ring_b = Cut(_rect_cw(24, 24, 25, 25), 7, "pocket")  # beside ring_a, same contour
    keys = parts([Cut(hole, 1), Cut(plate, 0), Cut(far, 2), ring_a, ring_b])
    assert keys[0] == keys[1] and len({keys[1], keys[2], keys[3]}) == 3 and keys[3] == keys[4]


def test_parts_from_the_contours_nesting_for_cuts_on_the_line() -> None:
    """The planner's nesting of the contours gives each cut on the line its part.

    Cuts reordered, reversed and started elsewhere (as the ordering leaves them) lie
    where their contours lie: the plate's hole and the open line inside it are the
    plate's part, the far square and the line across nothing are parts of their own.
    """
    from camtool.toolpath.order import nesting
    from camtool.toolpath.passes import parts
    from camtool.toolpath.travel import oriented

    plate, hole, far = _rect_cw(0, 0, 10, 10), _circle(5, 5, 1), _rect_cw(20, 0, 22, 2)
    inner = Contour((Line((2.0, 2.0), (3.0, 2.0)),), False)
    alone = Contour((Line((30.0, 0.0), (31.0, 0.0)),), False)
    contours = [plate, hole, far, inner, alone]
    cuts = [
        Cut(inner.reversed(), 3, "open", may_rotate=False),
        Cut(hole.reversed(), 1),
        oriented(Cut(far, 2), 2, False),
        Cut(alone, 4, "open", may_rotate=False),
        Cut(plate.reversed(), 0),
    ]
    keys = parts(cuts, nesting(contours))
    assert keys == parts(cuts)
    assert keys[0] == keys[1] == keys[4] and len({keys[0], keys[2], keys[3]}) == 3


def test_end_position_at_clearance_after_the_rise() -> None:
    o = _options(depth=0.5, end_position=(-3.0, 40.0))
    moves = emit_moves([Cut(_rect_cw(1, 1, 2, 2), 0)], o)
    assert moves[-2:] == [Rapid(1.0, 1.0, 5.0, contour=1), Rapid(-3.0, 40.0, 5.0, contour=0)]
    _check_safe(moves, o.safe_z)
    flat = emit_moves([Cut(_rect_cw(1, 1, 2, 2), 0)], _options(end_position=(0.0, 0.0)))
    assert flat[-1] == Rapid(0.0, 0.0) and all(m.z is None for m in flat)  # 2D: no Z at all


def test_no_depth_on_a_z_machine_cuts_at_the_top_with_rapids_at_safe_z() -> None:
    path = _rounded_rect()
    o = _options(safe_z=2.0)
    moves = emit_moves([Cut(path, 0), Cut(_circle(20, 0, 2), 1)], o, z_axis=True)
    ss = _check_safe(moves, 2.0, plunge=FEED / 2)  # no --plunge-feed without --depth
    cutting = [s for s in _xy_moves(ss) if not isinstance(s.move, Rapid)]
    assert cutting and all(s.z0 == 0.0 and s.z1 == 0.0 for s in cutting)
    plunges = [s for s in ss if s.xy_length == 0 and not isinstance(s.move, Rapid)]
    assert [(s.z0, s.z1, s.move.feed_mm_min) for s in plunges] == [(2.0, 0.0, FEED / 2)] * 2
    # the same cuts for a machine without Z: the 2D program, unchanged
    assert all(m.z is None for m in emit_moves([Cut(path, 0)], o))


def test_a_hostile_ramp_is_refused_before_any_move() -> None:
    # 1 mm down at 0.0001°: L = 1 / tan(0.0001°) = 572 958 mm ≈ 573 m per pass; round a
    # 31.6 mm loop of 9 segments that is 18 000 laps, 163 000 moves a pass, 2000 passes
    # (--step-down 0.001 of 2 mm) → 3.3e8 moves.
    from camtool.model.errors import UsageError

    o = _options(depth=2.0, step_down=1.0, ramp_deg=0.0001)
    with pytest.raises(UsageError, match=r"--ramp 0\.0001° needs 573 m of ramp per pass"):
        emit_moves([Cut(_rounded_rect(), 0)] * 40, o)


def test_the_move_limit_is_named(monkeypatch: pytest.MonkeyPatch) -> None:
    from camtool.model.errors import UsageError
    from camtool.toolpath import passes

    monkeypatch.setattr(passes, "MAX_MOVES", 10)
    with pytest.raises(UsageError, match=r"camtool\.toolpath\.passes\.MAX_MOVES = 10"):
        emit_moves([Cut(_rounded_rect(), 0)], _options(depth=1.0, step_down=0.5))
