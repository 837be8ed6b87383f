"""A shape drawn through a ``<filter>``: cut along its own outline, with a warning.

A filter changes what a viewer shows (Filter Effects 1): resvg's
``filters/feOffset/complex-transform`` test shows its rect moved by ``feOffset dx="20"
dy="40"``, Tango's icons blur their shadows with ``feGaussianBlur``. camtool cuts the
shape's geometry, so it names the first shape and its filter.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from camtool.importers.svg import read_svg
from tests.corpus.conftest import CORPUS, load_manifest
from tests.importers.svgutil import svg

OFFSET = '<filter id="f"><feOffset dx="20" dy="40"/></filter>'
SAID = "drawn through a filter"


def _said(path: Path) -> list[str]:
    return [w for w in read_svg(path).warnings if SAID in w]


@pytest.mark.parametrize(
    ("body", "first"),
    [
        ('<rect id="r" width="20" height="20" filter="url(#f)"/>', "rect#r"),
        ('<rect id="r" width="20" height="20" style="filter: url(\'#f\')"/>', "rect#r"),
        ('<g filter="url(#f)"><rect id="in" width="20" height="20"/></g>', "rect#in"),
    ],
)
def test_a_filtered_shape_is_named_with_its_filter(tmp_path: Path, body: str, first: str) -> None:
    drawing = read_svg(svg(tmp_path, OFFSET + body))
    assert [(c.source, c.bbox()) for c in drawing.contours] == [(first, (0, 80, 20, 100))]
    (said,) = [w for w in drawing.warnings if SAID in w]
    assert said.startswith(f"{tmp_path / 't.svg'}: 1 shape {SAID} (first: {first}, filter #f)")


def test_shapes_without_a_filter_say_nothing(tmp_path: Path) -> None:
    body = OFFSET + '<rect width="20" height="20" filter="none"/><circle r="5" cx="50" cy="50"/>'
    assert _said(svg(tmp_path, body)) == []


TANGO = "pkg/tango-icon-theme/usr/share/icons/Tango/scalable/actions/exit.svg"


@pytest.mark.skipif(load_manifest() is None, reason="no corpus (make corpus)")
def test_tangos_blurred_shadows_are_counted() -> None:
    """exit.svg blurs two paths through filter6451 (an feGaussianBlur)."""
    (said,) = _said(CORPUS / TANGO)
    assert ": 2 shapes drawn through a filter (first: path#path6425, filter #filter6451)" in said
