"""``display: contents`` in an SVG: content shown without its box, or nothing at all.

Expected values: Chromium 156 on these documents (``getComputedStyle`` and a rendered
picture): on ``<g>``, nested ``<svg>`` and ``<use>`` the content shows as without them; on a
shape, ``<a>`` and ``<switch>`` it computes to ``none`` and nothing of them shows (CSS
Display 3 §2.8 leaves SVG elements to SVG).
"""

from __future__ import annotations

from pathlib import Path

from camtool.importers.svg import read_svg
from tests.importers.svgutil import svg

LINE = 'd="M 1 1 L 9 9" stroke="#000"'


def test_contents_shows_a_group_s_children_and_hides_a_shape(tmp_path: Path) -> None:
    body = (
        f'<g style="DISPLAY: Contents"><path id="g" {LINE}/></g>'
        f'<svg style="display: contents"><path id="s" {LINE}/></svg>'
        f'<defs><path id="p" {LINE}/></defs><use id="u" xlink:href="#p" x="20" '
        'style="display: contents"/>'
        f'<a style="display: contents"><path id="a" {LINE}/></a>'
        f'<switch style="display: contents"><path id="w" {LINE}/></switch>'
        f'<path id="x" {LINE} style="display: contents"/>'
        f'<rect id="r" x="1" y="1" width="5" height="5" stroke="#000" display="contents"/>'
    )
    sources = {c.source.split(" ")[0] for c in read_svg(svg(tmp_path, body)).contours}
    assert {s.rsplit("#", 1)[-1] for s in sources} == {"g", "s", "u"}  # the clone: its use
