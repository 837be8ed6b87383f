"""The box of an elliptical arc: its ends and the turning points between them.

Expected values by analysis (a circle's quarter, a half ellipse) and by dense sampling of
``c + a·cos t + b·sin t`` with numpy: the box never misses a sampled point and is no
larger than the sampled box by more than the sampling can miss.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from camtool.geometry.curves import ellipse_extent


def test_a_quarter_circle_is_its_radius_across() -> None:
    assert ellipse_extent((3.0, 4.0), (2.0, 0.0), (0.0, 2.0), 0.0, math.pi / 2) == pytest.approx(2)


def test_a_half_ellipse_spans_its_major_axis() -> None:
    # from t = -π/2 to π/2 the right half of x = 5 cos t, y = 1 sin t: 5 wide, 2 tall
    got = ellipse_extent((0.0, 0.0), (5.0, 0.0), (0.0, 1.0), -math.pi / 2, math.pi / 2)
    assert got == pytest.approx(5.0)


def test_a_short_arc_of_a_huge_ellipse_is_short() -> None:
    # 1e-5 rad of an ellipse 2e9 across: about 1e4 wide, not 2e9
    got = ellipse_extent((0.0, 0.0), (0.0, 1e9), (-3e8, 0.0), 1.0, 1.0 + 1e-5)
    assert 1e3 < got < 2e4


finite = st.floats(-100.0, 100.0, allow_nan=False)


@settings(max_examples=200, deadline=None)
@given(
    ax=finite, ay=finite, bx=finite, by=finite,
    t0=st.floats(-10.0, 10.0), sweep=st.floats(0.0, 2.0 * math.pi),
)  # fmt: skip
def test_the_box_holds_every_point_and_no_more(
    ax: float, ay: float, bx: float, by: float, t0: float, sweep: float
) -> None:
    t = np.linspace(t0, t0 + sweep, 20001)
    x = ax * np.cos(t) + bx * np.sin(t)
    y = ay * np.cos(t) + by * np.sin(t)
    sampled = max(np.ptp(x), np.ptp(y))
    got = ellipse_extent((0.0, 0.0), (ax, ay), (bx, by), t0, t0 + sweep)
    size = math.hypot(ax, ay) + math.hypot(bx, by)
    step = sweep / 20000
    assert sampled - 1e-9 * (1 + size) <= got <= sampled + size * step * step + 1e-9 * (1 + size)
