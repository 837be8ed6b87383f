"""Chaining keeps what it does not join: the same objects, and a chain's first piece's style."""

from __future__ import annotations

import math

from camtool.geometry.chain import chain, with_end, with_start
from camtool.model.shapes import Arc, Contour, Line


def test_a_contour_that_joins_nothing_is_returned_as_it_was() -> None:
    """No copy of a lone open contour (a 200 000-LINE drawing kept one of each)."""
    lone = Contour((Line((0.0, 0.0), (1.0, 0.0)),), False, "A", "LINE #1", "#ff0000", "CENTER")
    far = Contour((Line((5.0, 5.0), (6.0, 5.0)),), False, "B", "LINE #2")
    out = chain([lone, far], 0.01)
    assert out[0] is lone and out[1] is far


def test_a_chain_keeps_its_first_piece_s_colour_and_linetype() -> None:
    a = Contour((Line((0.0, 0.0), (1.0, 0.0)),), False, "A", "LINE #1", "#ff0000", "DASHED")
    b = Contour((Line((1.0, 0.0), (1.0, 1.0)),), False, "B", "LINE #2", "#00ff00", "")
    (joined,) = chain([a, b], 0.01)
    assert len(joined.segments) == 2
    assert (joined.layer, joined.source, joined.colour, joined.linetype) == (
        "A",
        "LINE #1",
        "#ff0000",
        "DASHED",
    )


# -- an arc shorter than a joint: never turned into its whole circle ----------------------------


def _speck(sweep_deg: float, radius: float = 50.0) -> Arc:
    """A counter-clockwise arc of ``sweep_deg`` on a circle about (100, 100), from angle 0."""
    a = math.radians(sweep_deg)
    end = (100.0 + radius * math.cos(a), 100.0 + radius * math.sin(a))
    return Arc((100.0 + radius, 100.0), end, (100.0, 100.0), False)


def test_a_lone_speck_arc_within_the_joint_stays_open_and_short() -> None:
    # 0.005° of radius 50: 0.0044 mm long, its ends within the 0.01 mm joint. It is no
    # circle: closing it would move its end onto its start, a 100 mm circle (sweep 2π).
    speck = Contour((_speck(0.005),), False, "0", "ARC #1")
    (out,) = chain([speck], 0.01)
    assert not out.closed
    assert out.segments[0].length < 0.01


def test_a_near_full_arc_within_the_joint_is_a_closed_circle() -> None:
    near = Contour((_speck(360.0 - 0.005),), False, "0", "ARC #1")
    (out,) = chain([near], 0.01)
    assert out.closed
    assert out.segments[0].is_full_circle
    assert math.isclose(out.segments[0].length, 2 * math.pi * 50.0)


def test_a_speck_arc_whose_end_is_moved_back_past_its_start_becomes_a_line() -> None:
    # The speck runs from angle 0 to 0.005° (0.0044 mm); the end is moved to a point
    # 0.003 mm before its start on the circle: as an arc, nearly the whole circle.
    speck = _speck(0.005)
    back = (100.0 + 50.0 * math.cos(-6e-5), 100.0 + 50.0 * math.sin(-6e-5))
    moved = with_end(speck, back)
    assert moved == Line(speck.start, back)
    assert with_start(speck.reversed(), back) == Line(back, speck.start)


def test_an_arc_moved_within_its_length_keeps_its_centre() -> None:
    arc = _speck(30.0)
    end = (arc.end[0] + 0.004, arc.end[1])
    moved = with_end(arc, end)
    assert isinstance(moved, Arc) and moved.centre == arc.centre
    assert math.isclose(moved.sweep, arc.sweep, abs_tol=1e-3)


def test_a_speck_chain_closed_by_moving_its_arc_back_cuts_no_circle() -> None:
    # A 0.0026 mm LINE ends where the speck starts; the speck's end is 0.007 mm from the
    # line's start, within the joint: closing the chain moves it back past its own start.
    speck = _speck(0.005)
    a = (
        100.0 + 50.0 * math.cos(math.radians(-0.003)),
        100.0 + 50.0 * math.sin(math.radians(-0.003)),
    )
    out = chain([Contour((Line(a, speck.start),), False), Contour((speck,), False)], 0.01)
    assert len(out) == 1
    assert sum(s.length for s in out[0].segments) < 0.02
