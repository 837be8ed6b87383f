"""``arc_length``: an arc's length without making the Arc, the float Arc.length gives."""

from __future__ import annotations

import math
import random

import pytest

from camtool.model.shapes import Arc, arc_length


@pytest.mark.parametrize(
    ("start", "end", "centre", "clockwise", "expected"),
    [
        ((2.0, 0.0), (0.0, 2.0), (0.0, 0.0), False, math.pi),  # a quarter of R 2, CCW
        ((2.0, 0.0), (0.0, 2.0), (0.0, 0.0), True, 3.0 * math.pi),  # the other three
        ((1.0, 5.0), (1.0, 5.0), (0.0, 5.0), True, 2.0 * math.pi),  # start = end: full circle
        ((3.0, 0.0), (-3.0, 0.0), (0.0, 0.0), False, 3.0 * math.pi),  # a half of R 3
    ],
)
def test_lengths_by_analysis(
    start: tuple[float, float],
    end: tuple[float, float],
    centre: tuple[float, float],
    clockwise: bool,
    expected: float,
) -> None:
    assert arc_length(start, end, centre, clockwise) == pytest.approx(expected, rel=1e-12)


def test_the_same_float_as_arc_length() -> None:
    rng = random.Random(44)
    for _ in range(2000):
        cx, cy, r = rng.uniform(-500, 500), rng.uniform(-500, 500), rng.uniform(1e-3, 300)
        a0 = rng.uniform(-math.pi, math.pi)
        a1 = a0 + rng.choice([0.0, 1e-13, rng.uniform(-7, 7)])  # full circles among them
        start = (cx + r * math.cos(a0), cy + r * math.sin(a0))
        end = (cx + r * math.cos(a1), cy + r * math.sin(a1))
        for clockwise in (False, True):
            arc = Arc(start, end, (cx, cy), clockwise)
            assert arc_length(start, end, (cx, cy), clockwise) == arc.length
