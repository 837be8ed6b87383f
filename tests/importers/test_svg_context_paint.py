"""``context-fill`` and ``context-stroke``: the paint of a context element, else none.

SVG 2 §13.2: a context paint takes the fill or stroke of the context element (the ``<use>``
that places the content, the shape a marker is on); a shape drawn where it stands has none,
so ``fill="context-fill"`` there paints nothing (resvg's
``painting/context/without-context-element`` shows only the frame).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from camtool.importers.svg import read_svg
from camtool.model.errors import InputError
from tests.importers.svgutil import svg

FRAME = '<rect id="frame" x="1" y="1" width="98" height="98" fill="none" stroke="black"/>'


@pytest.mark.parametrize(
    "shape",
    [
        '<rect x="20" y="20" width="60" height="60" fill="context-fill" stroke="context-stroke"/>',
        '<g fill="context-stroke"><rect x="20" y="20" width="60" height="60"/></g>',
        '<rect x="20" y="20" width="60" height="60" style="fill: Context-Fill"/>',
    ],
)
def test_a_context_paint_without_a_context_element_paints_nothing(
    tmp_path: Path, shape: str
) -> None:
    drawing = read_svg(svg(tmp_path, shape + FRAME))
    assert [c.source for c in drawing.contours] == ["rect#frame"]
    assert any("skipped 1 element with neither fill nor stroke" in w for w in drawing.warnings)


def test_only_such_shapes_is_nothing_to_cut(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="nothing to cut"):
        read_svg(svg(tmp_path, '<circle cx="50" cy="50" r="9" fill="context-fill"/>'))


def test_a_use_gives_its_content_a_context(tmp_path: Path) -> None:
    body = (
        '<defs><rect id="r" x="20" y="20" width="60" height="60" fill="context-fill"/></defs>'
        '<use id="u" href="#r" fill="red"/>'
    )
    assert [c.source for c in read_svg(svg(tmp_path, body)).contours] == ["use#u > rect#r"]
