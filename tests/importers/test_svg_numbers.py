"""Numbers in SVG path data and point lists, in every spelling the SVG grammar allows.

SVG 1.1's path grammar (section 8.3.9, ``fractional-constant``) and SVG 2's number
syntax read ``300.`` and ``2.e-4`` as numbers; svgelements stopped reading a path or a
point list at such a number and kept what came before, so a closed outline was cut as its
first few sides. The expected points come from the grammar: each number is Python's
``float`` of its text.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from camtool.importers.svg import read_svg
from camtool.model.errors import InputError
from tests.importers.svgutil import DATA, one, svg, vertices

STROKE = 'fill="none" stroke="black"'


def test_scours_triangle_is_read_whole() -> None:
    """scour's unit-test file: ``M 300. 100 h-50-1.5E+2 l100.00000,2000.0E-01 z``."""
    contour = one(read_svg(DATA / "scour-path-simple-triangle.svg"))
    mm = 25.4 / 96  # no width or height: user units are px
    corners = [(300, 100), (250, 100), (100, 100), (200, 300), (300, 100)]
    expected = [(x * mm, (400 - y) * mm) for x, y in corners]
    assert contour.closed
    np.testing.assert_allclose(vertices(contour), expected, rtol=0, atol=1e-9)


@pytest.mark.parametrize(
    ("body", "corners"),
    [
        ('<path d="M 10,10 L 50,10 L 50,50 L 30. 80 L 10 50 Z"/>', 5),
        ('<path d="M 10,10 H 50. V 50 Z"/>', 3),
        ('<path d="M 10. 10. L 5.e1 1.E1 L 50,50 Z"/>', 3),
        ('<polygon points="10,10 50,10 50. 50 10,50"/>', 4),
        ('<polyline points="10.,10 50.,10. 50. 50."/>', 3),
    ],
)
def test_a_number_with_a_bare_point_keeps_the_rest_of_the_outline(
    tmp_path: Path, body: str, corners: int
) -> None:
    drawing = read_svg(svg(tmp_path, body.replace("/>", f" {STROKE}/>")))
    contour = one(drawing)
    assert len(contour.segments) == corners - (0 if contour.closed else 1)


def test_two_points_in_a_row_are_two_numbers(tmp_path: Path) -> None:
    """``50..5`` is ``50.`` then ``.5``: the grammar reads the longest number first."""
    contour = one(read_svg(svg(tmp_path, f'<path d="M 10,10 H 50..5 V 50 Z" {STROKE}/>')))
    expected = [(10, 90), (50, 90), (0.5, 90), (0.5, 50), (10, 90)]
    np.testing.assert_allclose(vertices(contour), expected, rtol=0, atol=1e-12)


@pytest.mark.parametrize("d", ["M 0 0 L 1.5. 2", "M 0 0 L 1 2.5.", "M 0 0 L . 2"])
def test_a_point_with_no_digit_on_either_side_is_still_refused(tmp_path: Path, d: str) -> None:
    with pytest.raises(InputError, match="bad path data"):
        read_svg(svg(tmp_path, f'<path d="{d}" {STROKE}/>'))


def _spellings(value: int) -> st.SearchStrategy[str]:
    """Texts the SVG grammar reads as ``value`` (an integer here, so every form is exact)."""
    n = abs(value)
    forms = [f"{n}", f"{n}.", f"{n}.0", f"{n}.e0", f"{n}.E+0", f"{n * 10}.e-1", f"{n}e0"]
    signs = ["-"] if value < 0 else ["", "+"]
    return st.sampled_from([sign + form for sign in signs for form in forms])


@settings(max_examples=60)
@given(
    st.lists(
        st.tuples(st.integers(-40, 40), st.integers(-40, 40)), min_size=2, max_size=8, unique=True
    ).flatmap(
        lambda pts: st.tuples(
            st.just(pts),
            st.tuples(*(st.tuples(_spellings(x), _spellings(y)) for x, y in pts)),
            st.sampled_from([" ", ",", "\t", "\n", " , "]),
            st.booleans(),
        )
    )
)
def test_any_spelling_reads_the_same_points(
    tmp_path_factory: pytest.TempPathFactory, case: tuple
) -> None:
    points, texts, sep, as_path = case
    words = [f"{x}{sep}{y}" for x, y in texts]
    if as_path:
        body = f'<path d="M {words[0]} L {" ".join(words[1:])}" {STROKE}/>'
    else:
        body = f'<polyline points="{" ".join(words)}" {STROKE}/>'
    contour = one(read_svg(svg(tmp_path_factory.mktemp("n"), body)))
    expected = [(x, 100.0 - y) for x, y in points]  # the test page: 1 unit = 1 mm, y up
    np.testing.assert_allclose(vertices(contour), expected, rtol=0, atol=1e-12)
