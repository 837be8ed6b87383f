"""The machined edge against the drawing: the trace is never joined across a rapid."""

from __future__ import annotations

import numpy as np
import pytest

from camtool.model.shapes import Contour, Drawing, Line
from camtool.verify.drawing_compare import against_drawing


def _line(y: float) -> np.ndarray:
    return np.column_stack([np.linspace(0.0, 10.0, 2001), np.full(2001, y)])


def _square(x: float, y: float, side: float) -> Contour:
    """The closed square of ``side`` mm with its lower-left corner at ``(x, y)``, as four lines."""
    corners = [(x, y), (x + side, y), (x + side, y + side), (x, y + side)]
    ends = corners[1:] + corners[:1]
    return Contour(tuple(Line(p, q) for p, q in zip(corners, ends, strict=True)), True)


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


def test_the_drawing_measured_in_blocks_is_measured_as_one(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # A 20 mm circle (four arcs) and a 30 mm square, cut by a wobbling trace 0.5 mm
    # outside each (tool radius 0.5): thousands of drawing samples, measured a block of
    # 97 at a time (the last block short), must give what one block gives, and the
    # largest error must be the one shapely measures from the same samples to the trace.
    import math

    import shapely

    from camtool.model.shapes import Arc
    from camtool.verify import drawing_compare

    quarter = [(60.0, 50.0), (50.0, 60.0), (40.0, 50.0), (50.0, 40.0), (60.0, 50.0)]
    arcs = tuple(Arc(quarter[k], quarter[k + 1], (50.0, 50.0), False) for k in range(4))
    square = _square(0.0, 0.0, 30.0)
    drawing = Drawing((Contour(arcs, True), square))
    t = np.linspace(0.0, 2.0 * math.pi, 4001)
    wobble = 0.5 + 0.003 * np.sin(37.0 * t)
    circle = np.column_stack(
        [50.0 + (10.0 + wobble) * np.cos(t), 50.0 + (10.0 + wobble) * np.sin(t)]
    )
    s = np.linspace(0.0, 1.0, 1001)
    side = np.column_stack([s * 31.0 - 0.5, np.full_like(s, -0.5 - 0.002 * np.sin(50.0 * s))])
    points = np.vstack([circle, side])
    runs = np.repeat([0, 1], [len(circle), len(side)])

    whole = against_drawing(points, drawing, 0.5, runs=runs)
    monkeypatch.setattr(drawing_compare, "AGAINST_BLOCK", 97)
    blocks = against_drawing(points, drawing, 0.5, runs=runs)
    assert blocks == whole
    assert whole.samples > 97 * 10 and whole.samples % 97  # many blocks, the last short

    samples, _ = drawing_compare._sample_drawing(drawing, drawing_compare.AGAINST_SPACING_MM)
    traces = shapely.multilinestrings([shapely.linestrings(circle), shapely.linestrings(side)])
    off = shapely.distance(shapely.points(samples), traces) - 0.5
    assert whole.max_um == pytest.approx(float(np.max(np.abs(off))) * 1000.0, abs=0.05)


def test_the_worst_point_is_found_among_the_samples_cut_as_drawn() -> None:
    # A 1 mm square the tool could not enter (an offset-vanished finding at its centre,
    # its samples first) and a 10 mm line y = 0 cut with a 0.5 mm radius along y = 0.5,
    # with a 10 µm bump at x = 7 (slopes of 1 in 50). From analysis: the largest error of
    # what was cut as drawn is at the drawing point (7, 0) below the bump, whose nearest
    # trace points lie on the slopes, 0.51 / √(1 + 0.02²) away, less the radius: 9.898 µm.
    # The square is reported apart.
    from types import SimpleNamespace

    square = _square(20.0, 20.0, 1.0)
    drawing = Drawing((square, Contour((Line((0.0, 0.0), (10.0, 0.0)),), False)))
    x = np.linspace(0.0, 10.0, 4001)
    trace = np.column_stack([x, 0.5 + 0.01 * np.clip(1.0 - np.abs(x - 7.0) / 0.5, 0.0, None)])
    nominal = [np.array([[0.0, 0.5], [10.0, 0.5]])]
    vanished = SimpleNamespace(kind="offset-vanished", at=(20.5, 20.5), value=None)
    against = against_drawing(trace, drawing, 0.5, nominal=nominal, findings=[vanished])
    assert [f.kind for f in against.not_cut] == ["offset-vanished"]
    import math

    expected_um = (0.51 / math.sqrt(1.0 + 0.02**2) - 0.5) * 1000.0
    assert against.max_um == pytest.approx(expected_um, abs=0.001)
    assert against.at_mm == pytest.approx((7.0, 0.0), abs=0.005)
