"""An SVG element's CSS ``transform`` property, read as a viewer draws it.

Expected boxes from analysis: a 100 × 100 mm page with ``viewBox="0 0 100 100"`` (one user
unit a mm, Y flipped: y_mm = 100 − y) and the rectangle x 10…30, y 10…20 transformed by
CSS Transforms 1's matrices, about ``transform-origin`` (of the viewport for keywords,
``transform-box: view-box``). Chromium draws each of these the same (to 0.011 mm,
sampling its ``getPointAtLength``). A shape turned about (0, 0) instead of its
``transform-origin`` would lie tens of millimetres away.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from camtool.importers import read_drawing
from camtool.model.errors import InputError

PAGE = (
    '<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" '
    'viewBox="0 0 100 100">{style}<rect x="10" y="10" width="20" height="10" fill="red" {attrs}/>'
    "</svg>"
)


def _box(tmp_path: Path, attrs: str, style: str = "") -> tuple[float, ...]:
    path = tmp_path / "t.svg"
    path.write_text(PAGE.format(attrs=attrs, style=style))
    return tuple(round(v, 6) for v in read_drawing(path).bbox())


@pytest.mark.parametrize(
    ("attrs", "box"),
    [
        # 90° about the rectangle's centre (20, 15): x 15…25, y 5…25
        ('style="transform: rotate(90deg); transform-origin: 20px 15px"', (15, 75, 25, 95)),
        ('style="transform: rotate(0.25turn); transform-origin: 20px 15px"', (15, 75, 25, 95)),
        ('style="transform: rotate(100grad); transform-origin: 20px 15px"', (15, 75, 25, 95)),
        # 5 mm = 18.897637… px, 1 in = 96 px
        ('style="transform: translate(5mm, 1in)"', (28.897638, -16, 48.897638, -6)),
        ('style="transform: translateX(5mm) translateY(1in)"', (28.897638, -16, 48.897638, -6)),
        # skew(45deg, atan 0.5): x' = x + y, y' = 0.5x + y (not skewX then skewY)
        ('style="transform: skew(45deg, 26.56505117707799deg)"', (20, 65, 50, 85)),
        ('style="transform: skew(45deg)"', (20, 80, 50, 90)),
        ('style="transform: scale(150%, 50%)"', (15, 90, 45, 95)),
        # the property wins over the attribute; none leaves no transform at all
        ('transform="translate(50 50)" style="transform: scale(2)"', (20, 60, 60, 80)),
        ('transform="translate(50 50)" style="transform: none"', (10, 80, 30, 90)),
    ],
)
def test_a_css_transform_is_drawn_as_a_viewer_draws_it(
    tmp_path: Path, attrs: str, box: tuple[float, ...]
) -> None:
    assert _box(tmp_path, attrs) == pytest.approx(box, abs=1e-6)


def test_a_style_sheets_transform_turns_about_the_viewports_centre(tmp_path: Path) -> None:
    # transform-origin: center of the 100 × 100 viewport, (50, 50): (x, y) → (100 − y, x)
    sheet = "<style>.t{transform:rotate(90deg);transform-origin:center}</style>"
    assert _box(tmp_path, 'class="t"', sheet) == pytest.approx((80, 70, 90, 90), abs=1e-6)


@pytest.mark.parametrize(
    ("attrs", "why"),
    [
        ('style="transform: rotate(30)"', "has no unit, which CSS requires (30deg)"),
        ('style="transform: translate(10, 5)"', "has no unit, which CSS requires (10px, 5mm)"),
        ('style="transform: translate(10px 5px)"', "cannot read '10px 5px'"),
        ('style="transform: rotateX(30deg)"', "is 3D (rotatex)"),
        ('style="transform: translate(10%, 0)"', "(camtool reads no %)"),
        ('style="transform: rotate(30deg); transform-box: fill-box"', "transform-box 'fill-box'"),
        ('transform="rotate(30)" style="transform-box: fill-box"', "transform-box 'fill-box'"),
        ('style="rotate: 30deg"', "the CSS property 'rotate'"),
    ],
)
def test_a_css_transform_camtool_cannot_draw_as_a_viewer_does_is_refused(
    tmp_path: Path, attrs: str, why: str
) -> None:
    with pytest.raises(InputError, match=r"rect\[1\]: .*" + re.escape(why)):
        _box(tmp_path, attrs)


@pytest.mark.parametrize(
    ("root", "refused"),
    [
        ('transform="rotate(90)"', True),
        ('transform="translate(10 0)"', True),
        ('style="transform: scale(2)"', True),
        ('transform="translate(0 0)"', False),
        ('style="transform: none"', False),
    ],
)
def test_a_transform_on_the_svg_element_itself_is_refused(
    tmp_path: Path, root: str, refused: bool
) -> None:
    # Chromium turns the whole page about its centre (the outermost <svg> has a CSS box:
    # transform-origin 50 % 50 %), svgelements the drawing on the page: rotate(90) puts
    # the rectangle at x 70…90 in one and at x −30…−10 in the other. One that moves
    # nothing passes, and the rectangle is where it is drawn.
    path = tmp_path / "t.svg"
    path.write_text(
        '<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" '
        f'viewBox="0 0 100 100" {root}><rect x="10" y="10" width="20" height="10"/></svg>'
    )
    if refused:
        with pytest.raises(InputError, match="the <svg> element itself has transform="):
            read_drawing(path)
    else:
        assert read_drawing(path).bbox() == pytest.approx((10, 80, 30, 90))
