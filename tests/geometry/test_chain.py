"""Chaining keeps what it does not join: the same objects, and a chain's first piece's style."""

from __future__ import annotations

from camtool.geometry.chain import chain
from camtool.model.shapes import Contour, Line


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
