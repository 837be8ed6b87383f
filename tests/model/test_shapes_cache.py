"""Arc's kept derived values and its chord points equal their plain computation (issue 17).

The slow forms are written out here (the formulas of the documented properties); the
arc's cached values and its hoisted :meth:`Arc.points` must give the same floats.
"""

from __future__ import annotations

import math
import pickle

from hypothesis import given, settings
from hypothesis import strategies as st

from camtool.model.shapes import TAU, Arc, chord_count, distance

coord = st.floats(-500.0, 500.0, allow_nan=False, allow_infinity=False)
point = st.tuples(coord, coord)


def _sweep(arc: Arc) -> float:
    start = math.atan2(arc.start[1] - arc.centre[1], arc.start[0] - arc.centre[0])
    end = math.atan2(arc.end[1] - arc.centre[1], arc.end[0] - arc.centre[0])
    radius = distance(arc.centre, arc.start)
    if distance(arc.start, arc.end) <= 1e-12 * max(1.0, radius):
        return -TAU if arc.clockwise else TAU
    ccw = (end - start) % TAU
    if ccw == 0.0:
        ccw = TAU
    return -(TAU - ccw) if arc.clockwise else ccw


@settings(max_examples=300, deadline=None)
@given(point, point, point, st.booleans())
def test_cached_values_are_the_plain_formulas(s: tuple, e: tuple, c: tuple, cw: bool) -> None:
    arc = Arc(s, e, c, cw)
    for _ in range(2):  # computed, then read back
        assert arc.radius == distance(c, s)
        assert arc.start_angle == math.atan2(s[1] - c[1], s[0] - c[0])
        assert arc.end_angle == math.atan2(e[1] - c[1], e[0] - c[0])
        assert arc.sweep == _sweep(arc)


@settings(max_examples=300, deadline=None)
@given(point, point, point, st.booleans(), st.sampled_from([1e-4, 1e-3, 0.01, 0.5]))
def test_points_equal_point_at_chord_by_chord(
    s: tuple, e: tuple, c: tuple, cw: bool, tol: float
) -> None:
    arc = Arc(s, e, c, cw)
    if arc.radius < 1e-6 or arc.radius > 1e3:
        return
    n = chord_count(arc.radius, abs(arc.sweep), tol)
    if n > 20000:
        return
    slow = [arc.start] + [arc.point_at(k / n) for k in range(1, n)] + [arc.end]
    assert arc.points(tol) == slow


def test_cache_is_not_part_of_equality_hash_or_pickle() -> None:
    a = Arc((1.0, 0.0), (0.0, 1.0), (0.0, 0.0), False)
    b = Arc((1.0, 0.0), (0.0, 1.0), (0.0, 0.0), False)
    assert a.sweep == math.pi / 2
    assert a == b and hash(a) == hash(b) and repr(a) == repr(b)
    again = pickle.loads(pickle.dumps(a))
    assert again == a and again.sweep == a.sweep


@settings(max_examples=200, deadline=None)
@given(point, point, point, st.booleans())
def test_made_segments_are_the_dataclass_ones(s: tuple, e: tuple, c: tuple, cw: bool) -> None:
    """make_line/make_arc give the object the checked __init__ gives (dict, eq, hash, pickle)."""
    from camtool.model.shapes import Line, make_arc, make_line

    for fast, slow in ((make_line(s, e), Line(s, e)), (make_arc(s, e, c, cw), Arc(s, e, c, cw))):
        assert type(fast) is type(slow)
        assert list(vars(fast).items()) == list(vars(slow).items())
        assert fast == slow and hash(fast) == hash(slow) and repr(fast) == repr(slow)
        assert pickle.dumps(fast) == pickle.dumps(slow)
    arc = Arc(s, e, c, cw)
    assert arc.reversed() == Arc(e, s, c, not cw)
    assert arc.transformed(2.5, 1.0, -3.0) == Arc(
        (s[0] * 2.5 + 1.0, s[1] * 2.5 - 3.0),
        (e[0] * 2.5 + 1.0, e[1] * 2.5 - 3.0),
        (c[0] * 2.5 + 1.0, c[1] * 2.5 - 3.0),
        cw,
    )
