"""Arc's kept derived values and its chord points equal their plain computation (issue 17).

The slow forms are written out here (the formulas of the documented properties); the
arc's cached values and its hoisted :meth:`Arc.points` must give the same floats.
"""

from __future__ import annotations

import gc
import math
import pickle
import sys
import tracemalloc
from collections.abc import Callable
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from camtool.model.shapes import TAU, Arc, Contour, chord_count, distance, make_arc, make_line
from camtool.toolpath.reversals import segment_signs

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
    # a spiral (ends at different radii, as code may give) counts chords at its larger radius
    n = chord_count(arc.radius + max(arc.spiral, 0.0), abs(arc.sweep), tol)
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


# -- the kept values fit in the objects' shared-key dicts (camtool.model.plain.share_keys) ----

split_dicts = pytest.mark.skipif(
    sys.implementation.name != "cpython" or sys.version_info < (3, 11),
    reason="CPython 3.11+'s key-sharing instance dicts",
)


def _kept_bytes(objects: list[Any], keep: Callable[[Any], object]) -> float:
    """Bytes allocated per object while ``keep`` computes (and keeps) its values."""
    gc.collect()
    tracemalloc.start()
    try:
        before = tracemalloc.get_traced_memory()[0]
        for obj in objects:
            keep(obj)
        return (tracemalloc.get_traced_memory()[0] - before) / len(objects)
    finally:
        tracemalloc.stop()


@split_dicts
def test_an_arcs_kept_values_cost_only_themselves() -> None:
    # 4 floats (radius, start angle, sweep, length: 24 bytes each; the axis signs are
    # shared tuples) and, for an arc made by the constructor (half of them), the dict
    # object that first holds a kept value (64 bytes; make_arc made it already). An arc
    # whose dict turns ordinary on its 6th key costs ~170 bytes more.
    arcs = [
        (make_arc if k % 2 else Arc)((1.0 + k, 0.0), (0.0, 1.0 + k), (0.0, 0.0), k % 3 == 0)
        for k in range(20_000)
    ]

    def keep(arc: Arc) -> None:
        if arc.end[0] == 0.0 and int(arc.end[1]) % 5 == 0:
            arc.start_angle  # noqa: B018 - some first, as the planner may
        arc.length  # noqa: B018
        segment_signs(arc)

    assert _kept_bytes(arcs, keep) <= 4 * 24 + 64 / 2 + 8


@split_dicts
def test_a_lines_and_a_contours_kept_values_cost_only_themselves() -> None:
    lines = [make_line((0.0, 0.0), (1.0, float(k))) for k in range(20_000)]
    assert _kept_bytes(lines, lambda line: line.length) <= 24 + 8
    contours = [Contour((line, line.reversed()), True) for line in lines]
    # the length (a float) and the box (a 4-tuple of floats: 72 + 16 + 4 × 24 at most)
    assert _kept_bytes(contours, lambda c: (c.length, c.bbox())) <= 24 + 88 + 96 + 8
