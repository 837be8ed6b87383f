"""A white rectangle as large as the page, without a stroke: the page's background, not cut.

matplotlib draws its figure's patch so (``<path d="M 0 216 L 288 216 L 288 0 L 0 0 z"
style="fill: #ffffff"/>``), as do Figma's frames and draw.io's pages; on the white page a
viewer shows nothing of it, and cutting it would cut a frame around the whole sheet. The
expected contours come from the drawing itself: the curve matplotlib was given, 2.5 by 1.5
units in a 4 x 3 in figure whose axes fill it.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import pytest

from camtool.importers import read_drawing
from camtool.importers.options import ImportOptions
from tests.importers.svgutil import svg

SAID = "skipped the page's background"


def _matplotlib(tmp_path: Path, transparent: bool) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure = plt.figure(figsize=(4, 3))
    axes = figure.add_axes((0, 0, 1, 1))
    axes.axis("off")
    axes.set_xlim(0, 4)
    axes.set_ylim(0, 3)
    axes.plot([1, 3.5, 3.5, 1, 1], [1, 1, 2.5, 2.5, 1], "k-")
    path = tmp_path / "figure.svg"
    figure.savefig(path, transparent=transparent)
    plt.close(figure)
    return path


@pytest.mark.parametrize("transparent", [False, True])
def test_a_matplotlib_figure_is_cut_without_its_background(
    tmp_path: Path, transparent: bool
) -> None:
    drawing = read_drawing(_matplotlib(tmp_path, transparent), ImportOptions())
    (contour,) = drawing.contours  # the plotted rectangle alone
    x0, y0, x1, y1 = contour.bbox()
    assert (x1 - x0, y1 - y0) == (pytest.approx(63.5, abs=0.01), pytest.approx(38.1, abs=0.01))
    said = [w for w in drawing.warnings if SAID in w]
    assert len(said) == (0 if transparent else 1)


@pytest.mark.parametrize(
    ("shape", "kept"),
    [
        ('<rect width="100" height="100" fill="white"/>', 0),
        ('<rect width="100" height="100" style="fill:#FFF"/>', 0),
        ('<path d="M0 0 H100 V100 H0 Z" fill="rgb(255,255,255)"/>', 0),
        # seen, so cut: a stroke, another colour, not the whole page, rounded corners
        ('<rect width="100" height="100" fill="white" stroke="black"/>', 1),
        ('<rect width="100" height="100" fill="black"/>', 1),
        ('<rect x="10" y="10" width="80" height="80" fill="white"/>', 1),
        ('<rect width="100" height="100" rx="5" fill="white"/>', 1),
    ],
)
def test_only_a_white_page_sized_rectangle_without_a_stroke_is_the_background(
    tmp_path: Path, shape: str, kept: int
) -> None:
    circle = '<circle cx="50" cy="50" r="20" fill="none" stroke="black"/>'
    drawing = read_drawing(svg(tmp_path, shape + circle), ImportOptions())
    assert len(drawing.contours) == 1 + kept
    assert len([w for w in drawing.warnings if SAID in w]) == 1 - kept


def test_the_background_counts_neither_toward_fit_nor_toward_the_travel(
    tmp_path: Path, run: Any
) -> None:
    """--fit scales what is cut, so the curves are fitted for the part's scale, not the
    page's (by analysis: the 20 x 16 mm ellipse scaled to --fit 100 100, k = 5, every
    point of its arcs within --tolerance of it once scaled). A page larger than the
    travel is no refusal when what is cut fits (it was refused before planning)."""
    page = 'width="200mm" height="200mm" viewBox="0 0 200 200"'
    ellipse = '<ellipse cx="100" cy="100" rx="10" ry="8" fill="none" stroke="black"/>'
    path = svg(tmp_path, '<rect width="200" height="200" fill="#fff"/>' + ellipse, page)
    out = tmp_path / "fit.ngc"
    code, err = run("post", str(path), "-t", "linuxcnc", "--fit", "100", "100", "-o", str(out))
    assert code == 0 and SAID in err
    fitted = read_drawing(path, ImportOptions(fit=(100.0, 100.0)))
    (contour,) = fitted.contours
    x0, _, x1, _ = contour.bbox()
    k = 100.0 / (x1 - x0)  # the scale --fit gives (rx 10: 20 mm wide)

    def off(x: float, y: float) -> float:  # to first order: |F| / |grad F| of the ellipse
        u, v = (x - 100.0) / 10.0, (y - 100.0) / 8.0
        return abs(u * u + v * v - 1.0) / math.hypot(2 * u / 10.0, 2 * v / 8.0)

    worst = max(off(x, y) for s in contour.segments for x, y in s.points(1e-5))
    assert worst * k <= 0.001 + 1e-6  # within --tolerance once scaled
    code, err = run("post", str(path), "-t", "pic-mmh", "--scale", "0.3", "-o", str(out))
    assert code == 0, err  # 6 x 4.8 mm in the 10 x 7 mm travel; the 60 mm page is not cut
