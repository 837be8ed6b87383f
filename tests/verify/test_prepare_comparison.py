"""prepare_comparison: the drawing's points and the compiled search made before workers fork.

Only the time depends on it (the figures are the same): the budget's forked workers inherit
the sampled drawing and the loaded kernels instead of making them each.
"""

from __future__ import annotations

from typing import Any

import pytest

from camtool.model.shapes import Contour, Drawing, Line
from camtool.verify import drawing_compare, nearest_search


def _square(side: float) -> Drawing:
    c = [(0.0, 0.0), (side, 0.0), (side, side), (0.0, side)]
    lines = tuple(Line(c[i], c[(i + 1) % 4]) for i in range(4))
    return Drawing((Contour(lines, True),))


@pytest.mark.usefixtures("accel_on")
@pytest.mark.parametrize(("side", "loads"), [(10.0, False), (110.0, True)])
def test_a_drawing_is_sampled_and_the_kernels_loaded_when_it_is_large(
    monkeypatch: pytest.MonkeyPatch, side: float, loads: bool
) -> None:
    """A 10 mm square: 8 001 points at 5 µm, under 20 000: the k-d tree stays; 110 mm: 88 001."""
    asked: list[Any] = []
    monkeypatch.setattr(nearest_search, "near_kernels", lambda *a: asked.append(a))
    drawing = _square(side)
    drawing_compare.prepare_comparison(drawing)
    kept = drawing_compare._SAMPLED.get(drawing, drawing_compare.AGAINST_SPACING_MM)
    assert kept is not None
    samples, sizes = kept
    assert len(samples) == round(4 * side / 0.005) + 1 == sum(sizes)
    assert asked == ([()] if loads else [])
    again, _ = drawing_compare._sample_drawing(drawing, drawing_compare.AGAINST_SPACING_MM)
    assert again is samples  # what the comparison then takes: the same points, not resampled
