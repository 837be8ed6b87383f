"""Arc blocks that GRBL and LinuxCNC accept after rounding (camtool.post.arccheck).

No thesis covers these controllers (DESIGN.md, "what users pick today"); the
limits come from their sources, cited in camtool/post/arccheck.py:
GRBL 1.1 grbl/gcode.c — radii may differ by 0.005 mm, above that by 0.1 % of
the start radius, never by more than 0.5 mm (error 33); LinuxCNC
src/emc/rs274ngc/interp_arc.cc (arc_data_ijk) with interp_internal.hh —
CENTER_ARC_RADIUS_TOLERANCE_MM = 2·0.01·√2 mm, SPIRAL_RELATIVE_TOLERANCE = 0.1 %
of the larger radius, 100 × the tolerance outright, RADIUS_TOLERANCE_MM =
0.00127 mm.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from camtool.model.errors import DialectError, UsageError
from camtool.post.arccheck import GRBL_TOLERANCE_MM, LINUXCNC_TOLERANCE_MM, MARGIN_MM, arc_error
from camtool.post.arcconform import DEVIATION_QUANTA, ArcPiece, conform_arc
from camtool.post.numfmt import NumberFormat

Point = tuple[float, float]


def _printed(p: Point, decimals: int) -> Point:
    """The point as the writer prints it (NumberFormat: halves away from zero)."""
    fmt = NumberFormat(decimals=decimals)
    return (float(fmt.quantize(p[0])), float(fmt.quantize(p[1])))


def _on_circle(centre: Point, radius: float, degrees: float) -> Point:
    a = math.radians(degrees)
    return (centre[0] + radius * math.cos(a), centre[1] + radius * math.sin(a))


# ------------------------------------------------------------------ GRBL 1.1 gcode.c


def test_grbl_accepts_radii_within_0_005_mm() -> None:
    # start (0,0), I1 J0: radius 1 mm from the start; the end sets the radius to the end.
    assert arc_error((0.0, 0.0), (2.0049, 0.0), (1.0, 0.0), rule="grbl") is None
    error = arc_error((0.0, 0.0), (2.0051, 0.0), (1.0, 0.0), rule="grbl")
    assert error is not None
    assert "error 33" in error
    assert "0.0051 mm" in error


def test_grbl_allows_0_1_percent_of_the_start_radius() -> None:
    # radius 10 mm: 0.1 % = 0.01 mm.
    assert arc_error((0.0, 0.0), (20.0099, 0.0), (10.0, 0.0), rule="grbl") is None
    assert arc_error((0.0, 0.0), (20.0101, 0.0), (10.0, 0.0), rule="grbl") is not None
    # The 0.1 % is of the START radius: shrinking to 9.9901 is the same 0.0099 mm.
    assert arc_error((0.0, 0.0), (19.9901, 0.0), (10.0, 0.0), rule="grbl") is None


def test_grbl_never_allows_more_than_0_5_mm() -> None:
    # radius 600 mm: 0.1 % would be 0.6 mm, but 0.5 mm is the ceiling.
    assert arc_error((0.0, 0.0), (1200.49, 0.0), (600.0, 0.0), rule="grbl") is None
    error = arc_error((0.0, 0.0), (1200.51, 0.0), (600.0, 0.0), rule="grbl")
    assert error is not None
    assert "0.5 mm" in error


def test_grbl_full_circle_passes_and_zero_radius_is_refused() -> None:
    # mc_arc: an end equal to the start is a full turn; the radii are equal.
    assert arc_error((3.0, 4.0), (3.0, 4.0), (0.0, 0.0), rule="grbl") is None
    # I0 J0 passes GRBL's own check but its segment count is undefined: refused.
    error = arc_error((3.0, 4.0), (3.0, 4.0), (3.0, 4.0), rule="grbl")
    assert error is not None
    assert "radius 0" in error


# ------------------------------------------------------ LinuxCNC interp_arc.cc


def test_linuxcnc_absolute_tolerance_2x0_01xsqrt2() -> None:
    assert math.isclose(LINUXCNC_TOLERANCE_MM, 0.028284, abs_tol=1e-6)
    # radius 1 mm: 0.0282 mm is 2.8 % but within the absolute tolerance.
    assert arc_error((0.0, 0.0), (2.0282, 0.0), (1.0, 0.0), rule="linuxcnc") is None
    error = arc_error((0.0, 0.0), (2.0284, 0.0), (1.0, 0.0), rule="linuxcnc")
    assert error is not None
    assert "radius to end of arc differs from radius to start" in error


def test_linuxcnc_relative_tolerance_of_the_larger_radius() -> None:
    # radius 100 mm, 0.1001 mm more at the end: 0.1001/100.1001 < 0.1 % (the larger radius).
    assert arc_error((0.0, 0.0), (200.1001, 0.0), (100.0, 0.0), rule="linuxcnc") is None
    assert arc_error((0.0, 0.0), (200.1003, 0.0), (100.0, 0.0), rule="linuxcnc") is not None
    # GRBL measures the 0.1 % on the start radius: the same block fails there.
    assert arc_error((0.0, 0.0), (200.1001, 0.0), (100.0, 0.0), rule="grbl") is not None


def test_linuxcnc_ceiling_and_zero_radius() -> None:
    # radius 5000 mm: 0.1 % = 5 mm, but 100 × 0.0283 = 2.83 mm is refused outright.
    assert arc_error((0.0, 0.0), (10002.8, 0.0), (5000.0, 0.0), rule="linuxcnc") is None
    assert arc_error((0.0, 0.0), (10002.85, 0.0), (5000.0, 0.0), rule="linuxcnc") is not None
    # RADIUS_TOLERANCE_MM = 0.00005 in = 0.00127 mm.
    error = arc_error((0.0, 0.0), (0.0, 0.0), (0.001, 0.0), rule="linuxcnc")
    assert error is not None
    assert "zero-radius" in error
    assert arc_error((0.0, 0.0), (0.0, 0.0), (0.0013, 0.0), rule="linuxcnc") is None


def test_linuxcnc_accepts_what_its_documentation_and_grbl_refuse() -> None:
    # 0.02 mm at radius 1 mm: over the documented 0.005 mm and 0.1 %, under 0.0283 mm.
    assert arc_error((0.0, 0.0), (2.02, 0.0), (1.0, 0.0), rule="linuxcnc") is None
    assert arc_error((0.0, 0.0), (2.02, 0.0), (1.0, 0.0), rule="grbl") is not None


def test_unknown_rule_lists_the_rules() -> None:
    with pytest.raises(UsageError, match="grbl, linuxcnc"):
        arc_error((0.0, 0.0), (1.0, 0.0), (0.5, 0.0), rule="mach3")


# ----------------------------------------------------------------- conform_arc


def test_three_decimals_keep_the_rounded_centre() -> None:
    # At 1 µm the radii of a rounded arc differ by at most ~2.8 µm < 5 µm: plain rounding.
    centre, r = (10.0004, 20.0006), 5.0
    ex_start, ex_end = _on_circle(centre, r, 10.0), _on_circle(centre, r, 100.0)
    start = _printed(ex_start, 3)
    for rule in ("grbl", "linuxcnc"):
        pieces = conform_arc(
            start, ex_end, centre, False, rule=rule, quantum_mm=0.001, exact_start=ex_start
        )
        assert pieces == [ArcPiece(_printed(ex_end, 3), (10.0, 20.001), False)]


def test_one_decimal_grbl_nudges_the_centre() -> None:
    # r 2.345 mm, 10° → 90° CCW around (0.03, -0.02), printed at 0.1 mm: plain rounding
    # gives start (2.3, 0.4), end (0.0, 2.3), centre (0.0, 0.0): radii 2.3345/2.3000 mm.
    centre, r = (0.03, -0.02), 2.345
    ex_start, ex_end = _on_circle(centre, r, 10.0), _on_circle(centre, r, 90.0)
    start, end = _printed(ex_start, 1), _printed(ex_end, 1)
    assert (start, end) == ((2.3, 0.4), (0.0, 2.3))
    assert arc_error(start, end, (0.0, 0.0), rule="grbl") is not None
    pieces = conform_arc(
        start, ex_end, centre, False, rule="grbl", quantum_mm=0.1, exact_start=ex_start
    )
    assert len(pieces) == 1
    assert pieces[0].end == end
    assert pieces[0].centre != (0.0, 0.0)
    assert math.dist(pieces[0].centre, centre) <= 0.3 + 1e-9  # a nearby grid centre
    assert arc_error(start, end, pieces[0].centre, rule="grbl") is None


def test_one_decimal_grbl_splits_when_no_centre_passes() -> None:
    centre, r = (0.03, -0.02), 3.21
    ex_start, ex_end = _on_circle(centre, r, 10.0), _on_circle(centre, r, 90.0)
    start = _printed(ex_start, 1)
    assert arc_error(start, _printed(ex_end, 1), (0.0, 0.0), rule="grbl") is not None
    pieces = conform_arc(
        start, ex_end, centre, False, rule="grbl", quantum_mm=0.1, exact_start=ex_start
    )
    assert len(pieces) >= 2
    previous = start
    for piece in pieces:
        assert arc_error(previous, piece.end, piece.centre, rule="grbl") is None
        previous = piece.end
    assert previous == _printed(ex_end, 1)


def test_full_circle_stays_one_block() -> None:
    centre, r = (0.03, -0.02), 2.345
    ex_start = _on_circle(centre, r, 10.0)
    start = _printed(ex_start, 1)
    for rule in ("grbl", "linuxcnc"):
        pieces = conform_arc(
            start, ex_start, centre, True, rule=rule, quantum_mm=0.1, exact_start=ex_start
        )
        assert pieces == [ArcPiece(start, (0.0, 0.0), True)]
    # Without exact_start the start is the exact start: start == end is a full circle.
    assert len(conform_arc(start, start, (0.0, 0.0), True, rule="grbl", quantum_mm=0.1)) == 1


def test_an_arc_that_rounds_to_nothing_gives_no_block() -> None:
    # 0.03 mm radius, 90°: both ends print as (5.0, 5.0) at 0.1 mm.
    centre = (5.0, 5.0)
    ex_start, ex_end = _on_circle(centre, 0.03, 0.0), _on_circle(centre, 0.03, 90.0)
    start = _printed(ex_start, 1)
    assert (
        conform_arc(start, ex_end, centre, False, rule="grbl", quantum_mm=0.1, exact_start=ex_start)
        == []
    )


def test_a_circle_below_the_resolution_is_an_error_naming_radius_and_rule() -> None:
    centre = (5.0, 5.0)
    ex_start = _on_circle(centre, 0.03, 0.0)
    with pytest.raises(DialectError, match=r"radius 0\.0300 mm.*grbl"):
        conform_arc(
            _printed(ex_start, 1),
            ex_start,
            centre,
            False,
            rule="grbl",
            quantum_mm=0.1,
            exact_start=ex_start,
        )


def test_an_end_printing_as_the_start_needs_the_exact_start() -> None:
    # Full circle from a start off the grid: the end (= exact start) prints as the start.
    ex_start = (5.03, 5.0)
    with pytest.raises(ValueError, match="exact_start"):
        conform_arc((5.0, 5.0), ex_start, (4.0, 5.0), True, rule="grbl", quantum_mm=0.1)
    pieces = conform_arc(
        (5.0, 5.0), ex_start, (4.0, 5.0), True, rule="grbl", quantum_mm=0.1, exact_start=ex_start
    )
    assert pieces == [ArcPiece((5.0, 5.0), (4.0, 5.0), True)]


def test_bad_arguments() -> None:
    with pytest.raises(UsageError):
        conform_arc((0.0, 0.0), (1.0, 0.0), (0.5, 0.0), False, rule="mach3", quantum_mm=0.001)
    with pytest.raises(UsageError):
        conform_arc((0.0, 0.0), (1.0, 0.0), (0.5, 0.0), False, rule="grbl", quantum_mm=0.0)
    with pytest.raises(ValueError, match="not on the"):
        conform_arc((0.0004, 0.0), (1.0, 0.0), (0.5, 0.0), False, rule="grbl", quantum_mm=0.001)


# ----------------------------------------------------------------- properties


def _safe_radius(rule: str, q: float) -> float:
    """Radius above which conform_arc must succeed, mm.

    Two grid radii that differ do so by at least q/(2·√n) quanta (n the squared
    radius in quanta), so below about q²/(2·tol) only exactly equal radii pass
    and the grid may have none near the arc: GRBL at 0.1 mm, tol 0.005 mm, gives
    1.0 mm. A radius of a few quanta cannot be followed within 1.5 quanta.
    """
    tol = GRBL_TOLERANCE_MM if rule == "grbl" else LINUXCNC_TOLERANCE_MM
    return max(3 * q, 1.2 * q * q / (2 * (tol - MARGIN_MM)))


def _path(start: Point, piece: ArcPiece, rule: str) -> np.ndarray:  # type: ignore[type-arg]
    """Points along a block as the controller moves (GRBL mc_arc; LinuxCNC spiral)."""
    c = np.array(piece.centre)
    u0, u1 = np.array(start) - c, np.array(piece.end) - c
    sweep = math.atan2(u0[0] * u1[1] - u0[1] * u1[0], float(u0 @ u1))
    if piece.clockwise and sweep >= -5e-7:
        sweep -= 2 * math.pi
    elif not piece.clockwise and sweep <= 5e-7:
        sweep += 2 * math.pi
    t = np.linspace(0.0, 1.0, 400)
    r0, r1 = float(np.hypot(*u0)), float(np.hypot(*u1))
    radius = r0 + (0.0 if rule == "grbl" else r1 - r0) * t
    angle = math.atan2(u0[1], u0[0]) + sweep * t
    pts = c + np.column_stack((radius * np.cos(angle), radius * np.sin(angle)))
    return np.vstack((pts, [piece.end]))


@pytest.mark.parametrize("rule", ["grbl", "linuxcnc"])
@pytest.mark.parametrize("decimals", [3, 1])
@settings(max_examples=120, deadline=None)
@given(
    cx=st.floats(-200, 200),
    cy=st.floats(-200, 200),
    log_r=st.floats(math.log(0.01), math.log(500)),
    a0=st.floats(0, 360),
    sweep=st.one_of(st.floats(0.5, 360), st.just(360.0)),
    clockwise=st.booleans(),
)
def test_conformed_arcs_pass_stay_on_the_grid_and_near_the_arc(
    rule: str,
    decimals: int,
    cx: float,
    cy: float,
    log_r: float,
    a0: float,
    sweep: float,
    clockwise: bool,
) -> None:
    q = 10.0**-decimals
    centre, r = (cx, cy), math.exp(log_r)
    ex_start = _on_circle(centre, r, a0)
    ex_end = (
        ex_start
        if sweep == 360.0
        else _on_circle(centre, r, a0 - sweep if clockwise else a0 + sweep)
    )
    start = _printed(ex_start, decimals)
    try:
        pieces = conform_arc(
            start, ex_end, centre, clockwise, rule=rule, quantum_mm=q, exact_start=ex_start
        )
    except DialectError:
        assert r < _safe_radius(rule, q)
        return
    if not pieces:  # the arc rounds away: both ends print the same, all of it near the start
        assert sweep < 360.0
        assert _printed(ex_end, decimals) == start
        return
    assert pieces[-1].end == _printed(ex_end, decimals)
    previous = start
    for piece in pieces:
        assert piece.clockwise == clockwise
        assert arc_error(previous, piece.end, piece.centre, rule=rule) is None
        for v in (*piece.end, *piece.centre):
            assert v == round(v, decimals)  # prints back as itself
            assert abs(v / q - round(v / q)) < 1e-6
        path = _path(previous, piece, rule)
        off = np.abs(np.hypot(path[:, 0] - cx, path[:, 1] - cy) - r)
        assert off.max() <= DEVIATION_QUANTA * q * 1.01 + 1e-9
        previous = piece.end
