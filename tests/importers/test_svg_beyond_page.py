"""A shape that reaches beyond the SVG page is cut whole, with a warning.

The root ``<svg>`` clips its content to the page (SVG 1.1 §14.3.3): a viewer shows only the
part of such a shape on the page, while camtool cuts whole contours. Fritzing's breadboard
parts draw their bendable legs so, from the page's bottom edge outward
(``powertransistor_npn.svg``: three ``<line>``\\ s 10 user units long below a viewBox
``0 0 36.998 62.317`` of a 0.36998 × 0.62317 in page, 2.54 mm beyond it).
"""

from __future__ import annotations

from pathlib import Path

from camtool.importers.svg import read_svg
from tests.importers.svgutil import svg

LEGS = (
    '<svg xmlns="http://www.w3.org/2000/svg" width="0.36998in" height="0.62317in" '
    'viewBox="0 0 36.998 62.317">'
    '<rect id="body" x="4" y="0.5" width="30" height="45" fill="#808080"/>'
    '<line id="leg0" x1="9.001" y1="62.317" x2="9.001" y2="72.317" stroke="#8C8C8C" '
    'stroke-width="3"/>'
    '<line id="leg1" x1="18.999" y1="62.317" x2="18.999" y2="72.317" stroke="#8C8C8C" '
    'stroke-width="3"/>'
    "</svg>"
)


def test_legs_below_the_page_are_cut_and_named(tmp_path: Path) -> None:
    path = tmp_path / "legs.svg"
    path.write_text(LEGS, encoding="utf-8")
    drawing = read_svg(path)
    assert [c.source for c in drawing.contours] == ["rect#body", "line#leg0", "line#leg1"]
    # 10 user units at 0.0254 mm each (0.36998 in over 36.998): 2.54 mm below Y 0
    leg = drawing.contours[1]
    assert abs(leg.bbox()[1] + 2.54) < 1e-9
    assert [w for w in drawing.warnings if "page" in w] == [
        f"{path}: 2 contours reach beyond the 9.397 × 15.83 mm page, where a viewer shows "
        "only the part on the page (farthest: line#leg0 at (2.2863, -2.5400) mm, 2.54 mm "
        "beyond); camtool cuts them whole: trim them to the page in the drawing program if "
        "the rest is not to be cut"
    ]


def test_a_sliver_beyond_the_page_is_not_named(tmp_path: Path) -> None:
    """0.1 mm or less beyond the page (a stroke's half-width over the edge, a page size
    rounded in the file) shows nothing worth a warning; 0.11 mm does."""
    body = '<rect id="edge" x="10" y="10" width="{w}" height="20"/>'
    quiet = read_svg(svg(tmp_path, body.format(w=90.1), name="quiet.svg"))
    assert [c.source for c in quiet.contours] == ["rect#edge"]
    assert not any("page" in w for w in quiet.warnings)
    named = read_svg(svg(tmp_path, body.format(w=90.11), name="named.svg"))
    assert any("1 contour reaches beyond the 100 × 100 mm page" in w for w in named.warnings)
    assert any("rect#edge at (10.0000, 70.0000) mm, 0.11 mm beyond" in w for w in named.warnings)


def test_no_page_no_warning(tmp_path: Path) -> None:
    """Without a width, height or viewBox there is no page to reach beyond."""
    body = '<line id="long" x1="-50" y1="0" x2="500" y2="0" stroke="black"/>'
    drawing = read_svg(svg(tmp_path, body, root=""))
    assert [c.source for c in drawing.contours] == ["line#long"]
    assert not any("beyond the" in w or "outside the" in w for w in drawing.warnings)
