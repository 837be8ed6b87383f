"""Shapes placed where SVG draws none are not cut, and a warning counts them.

Expected from SVG 1.1's content models (§5.1 ``svg``, ``g``; §10.4 ``text`` holds text
content elements only; §13.2 gradients hold ``stop`` and animation; §15 filter primitives;
§5.4 ``desc``/``title``, §21 ``metadata``; §5.6 ``use``: its children are not drawn) and SVG
2 §5.9 (an unknown element, or one of another namespace, is not rendered, nor are its
children): a viewer draws a shape only as a child of ``svg``, ``g``, ``a`` or ``switch``.
svgelements drew every one of them, as if it stood in the enclosing group.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from camtool.importers.svg import read_svg
from tests.importers.svgutil import svg

NOT_DRAWN_IN = [
    "text", "title", "desc", "metadata", "filter", "linearGradient", "radialGradient",
    "foreignObject", "foo", "inkscape:foo", "tspan", "textPath", "animate", "stop",
    "feGaussianBlur", "script", "image", "path", "rect",
]  # fmt: skip


@pytest.mark.parametrize("kind", NOT_DRAWN_IN)
def test_a_shape_inside_an_element_that_draws_no_children_is_not_cut(
    tmp_path: Path, kind: str
) -> None:
    body = (
        f'<g><{kind} id="host"><path id="inside" d="M 0 0 L 10 10"/></{kind}>'
        '<path id="beside" d="M 20 0 L 30 10"/></g>'
    )
    drawing = read_svg(svg(tmp_path, body))
    assert [c.source for c in drawing.contours] == ["path#beside"]
    (said,) = [w for w in drawing.warnings if "where SVG draws none" in w]
    assert "skipped 1 shape placed where SVG draws none (first: path#inside inside a" in said
    assert f"inside a <{kind.removeprefix('inkscape:')}>" in said


@pytest.mark.parametrize("kind", ["g", "a", "switch", "svg"])
def test_a_shape_in_a_group_link_switch_or_svg_is_cut(tmp_path: Path, kind: str) -> None:
    body = f'<{kind} id="host"><path id="inside" d="M 0 0 L 10 10"/></{kind}>'
    drawing = read_svg(svg(tmp_path, body))
    assert [c.source for c in drawing.contours] == ["path#inside"]
    assert not [w for w in drawing.warnings if "where SVG draws none" in w]


def test_a_group_in_a_title_goes_whole_and_each_shape_counts(tmp_path: Path) -> None:
    body = (
        '<title><g id="inner"><path id="one" d="M 0 0 L 1 1"/><rect id="two" width="2" '
        'height="2"/></g>A title</title><text><a><circle id="three" r="3"/></a></text>'
        '<path id="kept" d="M 5 5 L 9 9"/>'
    )
    drawing = read_svg(svg(tmp_path, body))
    assert [c.source for c in drawing.contours] == ["path#kept"]
    (said,) = [w for w in drawing.warnings if "where SVG draws none" in w]
    assert "skipped 3 shapes placed where SVG draws none (first: path#one inside a <title>" in said


def test_a_use_draws_its_target_not_its_children(tmp_path: Path) -> None:
    """SVG 1.1 §5.6: what a ``<use>`` holds (other than description and animation) is not
    drawn; the element it references is."""
    body = (
        '<defs><path id="target" d="M 0 0 L 10 0"/></defs>'
        '<use id="clone" href="#target"><path id="child" d="M 0 5 L 10 5"/></use>'
    )
    drawing = read_svg(svg(tmp_path, body))
    assert [c.source for c in drawing.contours] == ["use#clone > path#target"]
    assert any("skipped 1 shape placed where SVG draws none (first: path#child" in w
               for w in drawing.warnings)  # fmt: skip


def test_a_use_of_a_shape_moved_out_of_a_title_still_draws_it(tmp_path: Path) -> None:
    """The hold keeps the shape's id: a ``<use>`` that names it places it (svgelements finds
    it there), as a viewer draws a referenced element wherever it stands."""
    body = '<title><path id="t" d="M 0 0 L 10 0"/></title><use id="u" href="#t" x="5"/>'
    drawing = read_svg(svg(tmp_path, body))
    assert [c.source for c in drawing.contours] == ["use#u > path#t"]


@pytest.mark.parametrize(
    "defs",
    [
        '<linearGradient id="host"><path id="in" d="M 0 0 L 9 9"/></linearGradient>',
        '<title id="host"><path id="in" d="M 0 0 L 9 9"/></title>',
        '<g id="host"><text><path id="in" d="M 0 0 L 9 9"/></text></g>',
    ],
)
def test_a_use_of_an_element_holding_shapes_where_svg_draws_none_draws_none_of_them(
    tmp_path: Path, defs: str
) -> None:
    """SVG 1.1 §5.6: a ``<use>`` draws its target as the target would be drawn: a gradient
    or a title draws nothing, a group not a path inside its text. svgelements cloned the
    target's content whole. No warning: nothing was shown where the shape stands."""
    body = f'<defs>{defs}</defs><use id="u" href="#host"/><path id="kept" d="M 5 5 L 9 0"/>'
    drawing = read_svg(svg(tmp_path, body))
    assert [c.source for c in drawing.contours] == ["path#kept"]
    assert not [w for w in drawing.warnings if "where SVG draws none" in w]


def test_a_symbol_placed_by_a_use_draws_its_shapes_not_one_in_its_desc(tmp_path: Path) -> None:
    """The placed symbol is drawn where the ``<use>`` stands (a nested viewport), so the
    shape in its ``<desc>`` would have been cut there: the warning names it."""
    body = (
        '<symbol id="s"><desc><path id="in" d="M 0 0 L 9 9"/></desc>'
        '<path id="shown" d="M 0 5 L 9 5"/></symbol><use id="u" href="#s"/>'
    )
    drawing = read_svg(svg(tmp_path, body))
    assert [c.source for c in drawing.contours] == ["use#u > path#shown"]
    assert any("skipped 1 shape placed where SVG draws none (first: path#in inside a <desc>"
               in w for w in drawing.warnings)  # fmt: skip
