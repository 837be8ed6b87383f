"""A filled open subpath: cut as drawn, with a warning that a viewer shows it closed.

SVG fills an open subpath as if a line joined its end to its start (SVG 1.1 §11.3, "The fill
operation implicitly closes open subpaths"), so what a viewer shows has an edge the path does
not draw. camtool cuts the path as drawn (it adds no move the drawing does not hold) and says
so, naming the first such subpath.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from camtool.importers.svg import read_svg
from tests.corpus.conftest import CORPUS, load_manifest
from tests.importers.svgutil import one, svg, vertices

WARNING = "filled open subpath"


def _open_fill_warnings(warnings: tuple[str, ...]) -> list[str]:
    return [w for w in warnings if WARNING in w]


@pytest.mark.parametrize(
    "body",
    [
        '<path id="p" d="M 10 10 L 50 10 L 50 50" fill="black"/>',
        '<polyline id="p" points="10,10 50,10 50,50" stroke="black"/>',  # fill black by default
        '<path id="p" d="M 10 50 A 20 20 0 0 1 50 50" fill="red" stroke="blue"/>',
    ],
)
def test_a_filled_open_subpath_is_cut_open_and_named(tmp_path: Path, body: str) -> None:
    drawing = read_svg(svg(tmp_path, body))
    contour = one(drawing)
    assert not contour.closed  # no closing move added
    said = _open_fill_warnings(drawing.warnings)
    assert len(said) == 1
    assert said[0].startswith(f"{tmp_path / 't.svg'}: 1 {WARNING} (first: ")
    assert "#p)" in said[0] and "fill:none" in said[0]


@pytest.mark.parametrize(
    "body",
    [
        '<path d="M 10 10 L 50 10 L 50 50" fill="none" stroke="black"/>',  # not filled
        '<path d="M 10 10 L 50 10 L 50 50 Z" fill="black"/>',  # closed
        '<path d="M 10 10 L 50 10 L 50 50 L 10 10" fill="black"/>',  # ends where it starts
        '<path d="M 10 10 L 50 10" fill="black" stroke="black"/>',  # one line: no area
        '<line x1="10" y1="10" x2="50" y2="50" stroke="black" fill="black"/>',  # no inside
        '<path d="M 10 10 L 50 10 L 50 50" fill="black" fill-opacity="0" stroke="red"/>',
    ],
)
def test_no_warning_where_the_fill_adds_no_edge(tmp_path: Path, body: str) -> None:
    assert _open_fill_warnings(read_svg(svg(tmp_path, body)).warnings) == []


def test_the_count_is_of_subpaths_and_the_first_is_named(tmp_path: Path) -> None:
    body = (
        '<path id="two" d="M 10 10 L 50 10 L 50 50 M 60 60 L 90 60 L 90 90" fill="black"/>'
        '<path id="third" d="M 10 90 L 30 90 L 30 70" fill="green"/>'
    )
    drawing = read_svg(svg(tmp_path, body))
    assert [c.closed for c in drawing.contours] == [False, False, False]
    (said,) = _open_fill_warnings(drawing.warnings)
    assert f"3 {WARNING}s (first: path#two subpath 1) are cut as drawn" in said


TANGO = "pkg/tango-icon-theme/usr/share/icons/Tango/scalable/actions/mail-message-new.svg"


@pytest.mark.skipif(load_manifest() is None, reason="no corpus (make corpus)")
def test_tangos_open_shadows_are_named() -> None:
    """Tango's mail-message-new.svg draws four filled shadows with no closing ``z``.

    path2164 is ``M 19.077530,30.017590 L 11.744526,21.271586 L 36.562951,14.335513
    L 39.592221,20.551966 L 32.175956,29.992298`` with ``fill:#000000`` and no stroke: a
    pentagon to a viewer, four lines to the path.
    """
    drawing = read_svg(CORPUS / TANGO)
    (said,) = _open_fill_warnings(drawing.warnings)
    assert f"4 {WARNING}s (first: path#path2164)" in said
    shadow = next(c for c in drawing.contours if c.source == "path#path2164")
    assert not shadow.closed and len(vertices(shadow)) == 5
