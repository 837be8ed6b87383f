"""The machined edge against the drawing: the trace is never joined across a rapid."""

from __future__ import annotations

import numpy as np
import pytest

from camtool.model.shapes import Contour, Drawing, Line
from camtool.verify.drawing_compare import against_drawing


def _line(y: float) -> np.ndarray:
    return np.column_stack([np.linspace(0.0, 10.0, 2001), np.full(2001, y)])


def test_a_rapid_between_two_cuts_is_not_a_cut() -> None:
    # A drawn line y = 5 from x = 0 to 10, cut on the line (tool radius 0) by two passes at
    # y = 4 and y = 6, each 1 mm away. Their trace points, concatenated, would join (10, 4) to
    # (0, 6) across the drawing; that joint is a rapid and must not count: the error is 1 mm
    # everywhere (pocket rings of samples/pocket.dxf showed 838 µm for 5.7 µm before).
    drawing = Drawing((Contour((Line((0.0, 5.0), (10.0, 5.0)),), False),))
    points = np.vstack([_line(4.0), _line(6.0)])
    runs = np.repeat([0, 1], 2001)
    split = against_drawing(points, drawing, 0.0, runs=runs)
    assert split.max_um == pytest.approx(1000.0, abs=1e-6)
    assert split.rms_um == pytest.approx(1000.0, abs=1e-6)
    joined = against_drawing(points, drawing, 0.0)  # one run: the joint crosses the line
    assert joined.rms_um < 1000.0
