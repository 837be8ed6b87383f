"""Two closed contours that cross each other are said to, before the tool cuts through them.

Overlaps are geometry: two squares shifted by half their side share a quarter of each.
"""

from __future__ import annotations

import math

import pytest

from camtool.model.shapes import Arc, Contour, Line
from camtool.toolpath.compensate import crossings


def _square(x0: float, y0: float, side: float) -> Contour:
    c = [(x0, y0), (x0 + side, y0), (x0 + side, y0 + side), (x0, y0 + side)]
    return Contour(tuple(Line(a, b) for a, b in zip(c, c[1:] + c[:1], strict=True)), True)


def _circle(cx: float, cy: float, r: float) -> Contour:
    return Contour((Arc((cx + r, cy), (cx + r, cy), (cx, cy), False),), True)


def test_two_squares_drawn_over_each_other_cross() -> None:
    (found,) = crossings([_square(0, 0, 10), _square(5, 5, 10)], 0.01)
    assert found.kind == "crossing"
    assert found.value == pytest.approx(25.0)  # the 5 × 5 mm they share
    x, y = found.at or (math.nan, math.nan)
    assert 5 < x < 10 and 5 < y < 10
    assert "cross each other" in found.message and "(0.0000, 0.0000)" in found.message


@pytest.mark.parametrize(
    "pair",
    [
        (_square(0, 0, 10), _square(2, 2, 5)),  # one inside the other
        (_square(0, 0, 10), _square(10, 0, 10)),  # sharing an edge
        (_square(0, 0, 10), _square(20, 0, 10)),  # apart
        (_square(0, 0, 2), _circle(1, 1, math.sqrt(2))),  # corners on the circle
        (_circle(0, 0, 5), _circle(10, 0, 5)),  # touching at one point
    ],
)
def test_contours_that_nest_touch_or_stand_apart_do_not(pair: tuple[Contour, Contour]) -> None:
    assert crossings(list(pair), 0.01) == []


def test_a_sliver_thinner_than_the_tolerance_is_not_a_crossing() -> None:
    assert crossings([_square(0, 0, 10), _square(9.995, 0, 10)], 0.01) == []
    assert len(crossings([_square(0, 0, 10), _square(9.9, 0, 10)], 0.01)) == 1
