"""The planner's shortcuts give exactly what the plain forms written out here give.

Each is compared on many random inputs, for exact equality (every float's bits, not
approximately): :meth:`Track.pieces` (which skips the segments before ``s0`` and stops
after ``s1``) with a walk over every segment of every lap; :func:`segment_signs` (kept
on the arc) and :func:`count_reversals` (every arc's signs at once, in arrays) with the
signs computed afresh; :meth:`Arc.bbox` (quadrant cosines computed once) with the
per-call formula; :func:`sub_segment` on a whole segment (the segment itself) with the
piece rebuilt from its ends; a shifted move with ``dataclasses.replace``'s.
"""

from __future__ import annotations

import math
import struct

from hypothesis import given, settings
from hypothesis import strategies as st

from camtool.model.shapes import TAU, Arc, Contour, Line, Segment, arc_axis_signs
from camtool.toolpath.cuts import Cut
from camtool.toolpath.reversals import count_reversals, segment_signs
from camtool.toolpath.split import MIN_PIECE, Track, _piece, sub_segment


def _arc_signs(arc: Arc, phase: float) -> list[int]:
    """Directions of one axis along ``arc``: X for ``phase`` 0, Y for π/2 (computed afresh)."""
    return list(arc_axis_signs(arc, phase))


def count_reversals_afresh(cuts: list[Cut], start: tuple[float, float]) -> tuple[int, int]:
    """:func:`count_reversals` with every rapid a :class:`Line` and every arc's signs afresh."""
    state = [0, 0]
    count = [0, 0]
    here = start
    for cut in cuts:
        for seg in [Line(here, cut.path.start), *cut.path.segments]:
            if isinstance(seg, Arc):
                signs = (_arc_signs(seg, 0.0), _arc_signs(seg, math.pi / 2))
            else:
                xs, ys = segment_signs(seg)
                signs = (list(xs), list(ys))
            for axis, axis_signs in enumerate(signs):
                for v in axis_signs:
                    if state[axis] and v != state[axis]:
                        count[axis] += 1
                    state[axis] = v
        here = cut.path.end
    return count[0], count[1]


def pieces_of_every_segment(track: Track, s0: float, s1: float) -> list[tuple[Segment, float]]:
    """:meth:`Track.pieces` walking every segment of every lap.

    A piece that reaches a segment's end (starts at its start) takes that end (start)
    exactly, as the module promises; any other split point is a fraction of its length.
    """
    span = track._span(s0, s1)
    if span is None:
        return []
    s0, s1 = span
    total, ends = track.length, track.ends
    out: list[tuple[Segment, float]] = []
    lap = math.floor(s0 / total) if track.closed else 0
    while lap * total < s1 - MIN_PIECE:
        base = lap * total
        for i, seg in enumerate(track.segments):
            a, b = base + (ends[i - 1] if i else 0.0), base + ends[i]
            lo, hi = max(a, s0), min(b, s1)
            if hi - lo > MIN_PIECE:
                f0 = 0.0 if lo == a else (lo - a) / seg.length
                f1 = 1.0 if hi == b else (hi - a) / seg.length
                out.append((_piece(seg, f0, f1), hi))
        lap += 1
        if not track.closed:
            break
    return out


coord = st.floats(-500.0, 500.0, allow_nan=False, allow_infinity=False)
point = st.tuples(coord, coord)


def _bits(x: object) -> object:
    """Floats as their bit patterns (so -0.0 differs from 0.0), recursively."""
    if isinstance(x, float):
        return struct.pack("<d", x)
    if isinstance(x, tuple | list):
        return type(x)(_bits(v) for v in x)
    if isinstance(x, Line | Arc):
        return (type(x).__name__, _bits(x.start), _bits(x.end), _bits(getattr(x, "centre", None)),
                getattr(x, "clockwise", None))  # fmt: skip
    return x


def _bbox_slow(arc: Arc) -> tuple[float, float, float, float]:
    """:meth:`Arc.bbox` as it was written before the quadrant table (per-call cos/sin)."""
    xs = [arc.start[0], arc.end[0]]
    ys = [arc.start[1], arc.end[1]]
    cx, cy = arc.centre
    r = math.hypot(arc.start[0] - cx, arc.start[1] - cy)
    a0 = math.atan2(arc.start[1] - cy, arc.start[0] - cx)
    sweep = arc.sweep
    for k in range(4):
        quad = k * math.pi / 2
        delta = (quad - a0) % TAU if sweep > 0 else (a0 - quad) % TAU
        if delta <= abs(sweep):
            xs.append(cx + r * math.cos(quad))
            ys.append(cy + r * math.sin(quad))
    return (min(xs), min(ys), max(xs), max(ys))


@settings(max_examples=400, deadline=None)
@given(point, point, point, st.booleans())
def test_arc_bbox_is_the_per_call_formula(s: tuple, e: tuple, c: tuple, cw: bool) -> None:
    arc = Arc(s, e, c, cw)
    assert _bits(arc.bbox()) == _bits(_bbox_slow(Arc(s, e, c, cw)))


@st.composite
def arcs(draw: st.DrawFn) -> Arc:
    """Arcs of any sweep, including ones starting or ending exactly on a quadrant."""
    cx, cy = draw(coord), draw(coord)
    r = draw(st.floats(1e-6, 300.0))
    quads = [k * math.pi / 2 for k in range(-4, 5)]
    a0 = draw(st.one_of(st.floats(-7.0, 7.0), st.sampled_from(quads)))
    a1 = draw(st.one_of(st.floats(-7.0, 7.0), st.sampled_from(quads)))
    start = (cx + r * math.cos(a0), cy + r * math.sin(a0))
    end = start if draw(st.booleans()) and draw(st.booleans()) else (
        cx + r * math.cos(a1), cy + r * math.sin(a1))  # fmt: skip
    return Arc(start, end, (cx, cy), draw(st.booleans()))


@settings(max_examples=1500, deadline=None)
@given(arcs())
def test_arc_signs_equal_the_signs_afresh(arc: Arc) -> None:
    slow = (_arc_signs(arc, 0.0), _arc_signs(arc, math.pi / 2))
    for _ in range(2):  # computed, then kept
        xs, ys = segment_signs(arc)
        assert (list(xs), list(ys)) == slow


@settings(max_examples=300, deadline=None)
@given(st.lists(st.one_of(arcs(), st.tuples(point, point)), min_size=1, max_size=30), point)
def test_count_reversals_equals_the_count_afresh(items: list, origin: tuple) -> None:
    """Cuts of random arcs and lines (each its own open cut), from a random origin."""
    cuts = []
    for k, item in enumerate(items):
        seg = item if isinstance(item, Arc) else Line(*item)
        cuts.append(Cut(Contour((seg,), False), k, may_rotate=False))
    assert count_reversals(cuts, origin) == count_reversals_afresh(cuts, origin)


@settings(max_examples=300, deadline=None)
@given(arcs(), point, point)
def test_arc_and_line_bbox_of_random_arcs(arc: Arc, p: tuple, q: tuple) -> None:
    assert _bits(arc.bbox()) == _bits(_bbox_slow(arc))
    assert Line(p, q).bbox() == (min(p[0], q[0]), min(p[1], q[1]), max(p[0], q[0]),
                                 max(p[1], q[1]))  # fmt: skip


@st.composite
def tracks(draw: st.DrawFn) -> Track:
    """Closed or open chains of lines and arcs (some very short, some long)."""
    n = draw(st.integers(1, 12))
    x, y = draw(coord), draw(coord)
    segs: list[Segment] = []
    for _ in range(n):
        step = draw(st.sampled_from([1e-9, 3e-9, 1e-6, 0.01, 1.0, 37.5, 200.0]))
        ang = draw(st.floats(-math.pi, math.pi))
        nx, ny = x + step * math.cos(ang), y + step * math.sin(ang)
        if draw(st.booleans()):
            # an arc through (x, y) and (nx, ny): centre on the chord's bisector
            off = draw(st.floats(-3.0, 3.0))
            mx, my = (x + nx) / 2, (y + ny) / 2
            c = (mx - off * (ny - y), my + off * (nx - x))
            segs.append(Arc((x, y), (nx, ny), c, draw(st.booleans())))
        else:
            segs.append(Line((x, y), (nx, ny)))
        x, y = nx, ny
    closed = draw(st.booleans())
    if closed and (x, y) != segs[0].start:
        segs.append(Line((x, y), segs[0].start))
    return Track.from_segments(segs, closed)


@settings(max_examples=800, deadline=None)
@given(tracks(), st.data())
def test_pieces_equal_the_walk_over_every_segment(track: Track, data: st.DataObject) -> None:
    total = track.length
    if not track.segments:
        assert track.pieces(0.0, 1.0) == pieces_of_every_segment(track, 0.0, 1.0) == []
        return
    ends = [0.0, *track.ends]
    # bounds at segment ends (exactly), just off them, inside, and a few laps on
    anchor = st.one_of(
        st.sampled_from(ends),
        st.sampled_from(ends).map(lambda v: v + 1e-9),
        st.sampled_from(ends).map(lambda v: math.nextafter(v, -math.inf)),
        st.floats(-0.5 * total - 1.0, 3.5 * total + 1.0),
    )
    for _ in range(6):
        lap = data.draw(st.integers(0, 3)) * total
        s0 = data.draw(anchor) + lap
        s1 = s0 + data.draw(st.one_of(st.floats(0.0, 3.0 * total), st.sampled_from([total])))
        fast, slow = track.pieces(s0, s1), pieces_of_every_segment(track, s0, s1)
        assert _bits(fast) == _bits(slow)
        assert fast == slow


@settings(max_examples=300, deadline=None)
@given(tracks())
def test_sub_segment_of_a_whole_segment_is_the_segment(track: Track) -> None:
    for seg in track.segments:
        whole = sub_segment(seg, 0.0, seg.length)
        assert whole is seg
        assert _bits(whole) == _bits(_piece(seg, 0.0, 1.0))
        part = sub_segment(seg, 0.0, seg.length * 0.5)
        assert _bits(part) == _bits(_piece(seg, 0.0, (seg.length * 0.5) / seg.length))


def test_cached_lengths_and_boxes_equal_fresh_ones() -> None:
    segs: list[Segment] = [
        Line((0.0, 0.0), (3.0, 4.0)),
        Arc((3.0, 4.0), (3.0, 4.0), (3.0, 3.0), False),
        Line((3.0, 4.0), (0.0, 0.0)),
    ]
    contour = Contour(tuple(segs), True)
    twin = Contour(tuple(segs), True)
    assert contour.bbox() == contour.bbox() == (0.0, 0.0, 4.0, 4.0)  # circle r 1 about (3, 3)
    assert contour.length == contour.length == 10.0 + TAU
    assert contour == twin and hash(contour) == hash(twin)  # the cache is no field
    track = Track.of(contour)
    assert track.length == sum(s.length for s in segs)
    assert track.ends == (5.0, 5.0 + TAU, 10.0 + TAU)


@settings(max_examples=300, deadline=None)
@given(
    st.lists(
        st.tuples(st.integers(0, 2), point, point, st.booleans(), st.one_of(st.none(), coord)),
        min_size=1,
        max_size=20,
    ),
    coord,
    coord,
)
def test_shifted_moves_are_the_replaced_ones(items: list, dx: float, dy: float) -> None:
    """placement._shifted copies plain moves field by field: the object replace() makes."""
    import pickle

    from camtool.model.program import ArcMove, Linear, Rapid
    from camtool.toolpath.placement import _shifted, _shifted_replaced

    for kind, (x, y), (cx, cy), cw, z in items:
        move = (
            Rapid(x, y, z, 3)
            if kind == 0
            else Linear(x, y, 120.0, z, contour=4)
            if kind == 1
            else ArcMove(x, y, cx, cy, cw, 90.0, z, 5)
        )
        fast, slow = _shifted(move, dx, dy), _shifted_replaced(move, dx, dy)
        assert type(fast) is type(slow)
        assert repr(fast) == repr(slow)  # every field, -0.0 included
        assert fast == slow and hash(fast) == hash(slow)
        assert pickle.dumps(fast) == pickle.dumps(slow)
