"""``Contour.signed_area``: exact for lines and arcs, against areas worked out by hand."""

from __future__ import annotations

import math

import pytest

from camtool.model.shapes import Arc, Contour, Line


def test_full_circles_are_pi_r_squared_signed_by_direction() -> None:
    ccw = Contour((Arc((5.0, 2.0), (5.0, 2.0), (2.0, 2.0), False),), True)
    cw = Contour((Arc((5.0, 2.0), (5.0, 2.0), (2.0, 2.0), True),), True)
    assert ccw.signed_area() == pytest.approx(math.pi * 9.0, rel=1e-15)
    assert cw.signed_area() == pytest.approx(-math.pi * 9.0, rel=1e-15)


def test_a_square_with_a_notch_and_a_bulge() -> None:
    """A 4 × 4 square: a half disc of radius 1 cut into its top, one added to its right.

    Area 16 − π/2 + π/2 = 16 by hand; reversed, −16.
    """
    notch = Arc((3.0, 4.0), (1.0, 4.0), (2.0, 4.0), True)  # dips to (2, 3): into the square
    bulge = Arc((4.0, 1.0), (4.0, 3.0), (4.0, 2.0), False)  # out to (5, 2)
    assert notch.point_at(0.5) == pytest.approx((2.0, 3.0))
    assert bulge.point_at(0.5) == pytest.approx((5.0, 2.0))
    segs = (
        Line((0.0, 0.0), (4.0, 0.0)),
        Line((4.0, 0.0), (4.0, 1.0)),
        bulge,
        Line((4.0, 3.0), (4.0, 4.0)),
        Line((4.0, 4.0), (3.0, 4.0)),
        notch,
        Line((1.0, 4.0), (0.0, 4.0)),
        Line((0.0, 4.0), (0.0, 0.0)),
    )
    square = Contour(segs, True)
    assert square.signed_area() == pytest.approx(16.0, abs=1e-12)
    assert square.reversed().signed_area() == pytest.approx(-16.0, abs=1e-12)
    without_bulge = Contour((*segs[:2], Line((4.0, 1.0), (4.0, 3.0)), *segs[3:]), True)
    assert without_bulge.signed_area() == pytest.approx(16.0 - math.pi / 2, abs=1e-12)


def test_a_major_arc_and_a_gap_the_chaining_left() -> None:
    """Three quarters of a unit disc about (5, 5) and its two radii: 3π/4.

    Its last radius stops 1e-3 mm short of the centre: the gap closes as a chord along
    the same line, so the area is still 3π/4 (left out, the shoelace would lose
    (5·5 − 5·4.999) / 2 = 0.0025 mm²).
    """
    arc = Arc((6.0, 5.0), (5.0, 4.0), (5.0, 5.0), False)  # 270° counter-clockwise
    pie = Contour((Line((5.0, 5.0), (6.0, 5.0)), arc, Line((5.0, 4.0), (5.0, 5.0))), True)
    assert pie.signed_area() == pytest.approx(3 * math.pi / 4, abs=1e-12)
    gapped = Contour((Line((5.0, 5.0), (6.0, 5.0)), arc, Line((5.0, 4.0), (5.0, 4.999))), True)
    assert gapped.signed_area() == pytest.approx(3 * math.pi / 4, abs=1e-12)


def test_an_open_contour_has_no_area() -> None:
    assert (
        Contour((Line((0.0, 0.0), (1.0, 0.0)), Line((1.0, 0.0), (1.0, 1.0))), False).signed_area()
        == 0.0
    )
