"""Hostile SVG files: NaN and huge numbers, deep nesting, ``<use>`` laughs.

One regression test per class of failure found by trying hostile inputs (issues 13, 14):
a CPU spin in curve fitting (a Bézier control point at 1e20), an internal
ZeroDivisionError (one at 1e12), a RecursionError (2 000 nested groups), a hang (a
``<use>`` "billion laughs"), and a 1e300 coordinate posted into an error message 300
digits long. Each must end quickly with one clear InputError (exit 3).
"""

from __future__ import annotations

from pathlib import Path

import pytest
import svgelements as se

import camtool.importers.options as options_module
from camtool.cli.main import main
from camtool.importers.options import MAX_ENTITIES, ImportOptions
from camtool.importers.svg import read_svg
from camtool.importers.svgdoc import MAX_DEPTH
from camtool.model.errors import InputError
from tests.cpu import cpu_bound
from tests.importers.svgutil import svg

HANG_S = 120


def _refused(path: Path, options: ImportOptions | None = None) -> str:
    # A hang guard, not a speed test: a refusal takes milliseconds, the fitting spin it
    # guards against never ends.
    with pytest.raises(InputError) as info, cpu_bound(HANG_S):
        read_svg(path, options)
    message = str(info.value)
    assert message.startswith(f"{path}: ") and "\n" not in message
    return message


@pytest.mark.parametrize(
    ("d", "shown"),
    [
        ("M 0 0 C 1e20 0 5 5 10 10", "(1e+20, 100)"),  # not: a CPU spin in fitting
        ("M 0 0 C 1e12 0 5 5 10 10", "(1e+12, 100)"),  # not: internal ZeroDivisionError
        ("M 0 0 L 1e300 5", "(1e+300, 95)"),  # not: posted, then a 300-digit message
        ("M 0 0 L 1e400 5", "(inf, nan)"),
    ],
)
def test_huge_path_numbers_are_refused_before_fitting(tmp_path: Path, d: str, shown: str) -> None:
    message = _refused(svg(tmp_path, f'<path d="{d}"/>'))
    assert f"path[1]: a point at {shown} mm" in message
    assert "±1e9 mm" in message


def test_a_huge_transform_is_refused(tmp_path: Path) -> None:
    message = _refused(svg(tmp_path, '<path transform="scale(1e200)" d="M 1 1 L 5 5"/>'))
    assert "path[1]: a point at (1e+200, -1e+200) mm" in message


def test_nan_in_path_data_is_refused(tmp_path: Path) -> None:
    message = _refused(svg(tmp_path, '<path d="M 0 0 L nan 5"/>'))
    assert "path[1]: bad path data" in message


def test_deep_nesting_is_refused_not_a_recursion_error(tmp_path: Path) -> None:
    body = "<g>" * 2000 + '<path d="M 0 0 L 5 5"/>' + "</g>" * 2000
    message = _refused(svg(tmp_path, body))
    assert f"nested deeper than {MAX_DEPTH} levels" in message


def test_nesting_within_the_limit_is_read(tmp_path: Path) -> None:
    levels = MAX_DEPTH - 3  # <svg>, the path and camtool's own <defs> come on top
    body = "<g>" * levels + '<path d="M 0 0 L 5 5"/>' + "</g>" * levels
    assert len(read_svg(svg(tmp_path, body)).contours) == 1


def _use_laugh(levels: int, copies: int) -> str:
    """Group ``a{k}`` clones ``a{k-1}`` ``copies`` times: copies**levels paths drawn."""
    defs = '<defs><path id="a0" d="M 0 0 L 1 1"/>'
    for k in range(1, levels + 1):
        uses = "".join(f'<use xlink:href="#a{k - 1}"/>' for _ in range(copies))
        defs += f'<g id="a{k}">{uses}</g>'
    return defs + f'</defs><use xlink:href="#a{levels}"/>'


@pytest.mark.parametrize(("levels", "copies"), [(30, 10), (30, 2)])
def test_a_use_laugh_is_refused_before_expanding(tmp_path: Path, levels: int, copies: int) -> None:
    message = _refused(svg(tmp_path, _use_laugh(levels, copies)))
    assert f"more than {MAX_ENTITIES:,} entities" in message
    assert "--max-entities" in message


def test_the_use_count_is_exact_and_can_be_raised(tmp_path: Path) -> None:
    # Each element counts once per place it is drawn, a <use> plus what it places:
    # path a0 = 1, a use of it 2, g a1 = 1 + 2·2 = 5, a use of a1 6, a2 = 1 + 2·6 = 13,
    # a3 = 1 + 2·14 = 29, the last use 30, <defs> 1 + 1 + 5 + 13 + 29 = 49, and the root
    # <svg> 1 + 49 + 30 = 80. 2^3 = 8 paths are drawn.
    path = svg(tmp_path, _use_laugh(3, 2))
    assert len(read_svg(path, ImportOptions(max_entities=80)).contours) == 8
    _refused(path, ImportOptions(max_entities=79))


def test_clones_may_add_a_bounded_number_of_elements_unless_the_limit_is_given(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # The same file: 13 elements (<svg>, <defs>, a0, three groups of two <use>, the last
    # <use>) expanding to 80 (above): the clones add 67.
    path = svg(tmp_path, _use_laugh(3, 2))
    monkeypatch.setattr(options_module, "MAX_EXPANSION", 66)
    message = _refused(path)
    assert "its <use> clones expand the 13 entities the file holds to 80, more than the 66 " in (
        message
    )
    assert "allow them with --max-entities 80" in message
    assert len(read_svg(path, ImportOptions(max_entities=80)).contours) == 8
    monkeypatch.setattr(options_module, "MAX_EXPANSION", 67)
    assert len(read_svg(path).contours) == 8


def test_a_small_file_of_many_clones_is_refused_before_it_is_parsed(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # 300 <use> of a row of 1 000 clones of one path: 40 kB of SVG, 1 304 elements (<svg>,
    # <defs>, the path, the row and its 1 000 <use>, the 300 <use>) that expand to
    # 1 + (1 + 1 + 2 001) + 300 · (1 + 2 001) = 602 604 (a clone of the path 2, the row
    # 1 + 1 000 · 2): 600 000 objects of svgelements (gigabytes), under the 5 000 000 of
    # --max-entities.
    row = "".join(f'<use xlink:href="#p" x="{i}"/>' for i in range(1000))
    body = f'<defs><path id="p" d="M 0 0 L 0.5 0"/><g id="row">{row}</g></defs>'
    body += "".join(f'<use xlink:href="#row" y="{j}"/>' for j in range(300))

    def never(*args: object, **kwargs: object) -> None:
        raise AssertionError("parsed")

    monkeypatch.setattr(se.SVG, "parse", never)
    message = _refused(svg(tmp_path, body))
    assert "its <use> clones expand the 1,304 entities the file holds to 602,604" in message
    assert "--max-entities 602604" in message


def test_post_of_a_hostile_svg_exits_3_with_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = svg(tmp_path, '<path d="M 0 0 C 1e20 0 5 5 10 10"/>')
    assert main(["post", str(path), "-t", "grbl", "-o", str(tmp_path / "o.nc")]) == 3
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("camtool: error: ")


def test_an_unknown_xml_encoding_is_an_input_error(tmp_path: Path) -> None:
    # not: an internal LookupError from the XML parser (found by fuzzing)
    path = tmp_path / "enc.svg"
    path.write_text(
        '<?xml version="1.0" encoding="UTF1e-320"?>\n<svg xmlns="http://www.w3.org/2000/svg"/>'
    )
    message = _refused(path)
    assert "unknown encoding" in message and "UTF-8" in message


def test_an_elliptical_arc_too_large_for_the_tolerance_is_refused(tmp_path: Path) -> None:
    # radii 8:4 scaled up to a 1e9 chord: every point is within ±1e9 mm, but fitting it
    # within 0.001 mm took minutes (an ellipse 1e7 mm across already needs 6 400 arcs)
    path = svg(tmp_path, '<path id="oval" d="m 48,20 a 8,4 0 0 1 -8,1e9"/>')
    message = _refused(path)
    assert "path#oval: a curve" in message and "raise --tolerance" in message


def test_a_nearly_straight_arc_of_a_huge_ellipse_is_read(tmp_path: Path) -> None:
    # radius 500 m over an 80 mm chord, stretched 1.5 times in y: an elliptical arc whose
    # ellipse is 10⁹ times the 0.001 mm tolerance, while the part cut is 80 mm long, its
    # sagitta 80² / (8 · 500 000) · 1.5 = 0.0024 mm
    import numpy as np

    from camtool.geometry.arcfit import distances
    from tests.shapes import segment_samples

    d = "M 10 10 A 500000 500000 0 0 1 90 10"
    (contour,) = read_svg(svg(tmp_path, f'<path d="{d}" transform="scale(1 1.5)"/>')).contours
    x = np.linspace(10.0, 90.0, 4001)
    true = np.column_stack([x, 85.0 + 0.0024 * (1.0 - ((x - 50.0) / 40.0) ** 2)])
    # the circle's sagitta is a parabola within (80/2)⁴ / (8 R³) = 2e-12 mm of it
    assert float(np.max(distances(true, contour.segments))) <= 0.001 + 1e-6
    ys = np.array(segment_samples(contour.segments))[:, 1]
    assert float(ys.max()) == pytest.approx(85.0024, abs=0.001)
