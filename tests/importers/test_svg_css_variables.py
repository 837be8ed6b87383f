"""CSS custom properties in an SVG's styles: what a shape's ``var()`` stands for is read.

Expected values by analysis of CSS Custom Properties for Cascading Variables Level 1: a
custom property is inherited (§2) and may be set by a style sheet rule, ``:root``
included; ``var(--x, fallback)`` is the property's value, else the fallback (§3); with
neither, or in a cycle, the declaration is invalid at computed-value time and acts as
``unset`` (§3.1, §2.3): ``fill`` and ``stroke`` then inherit (the element's own
presentation attribute, which the style declaration outranks, does not count),
``display`` takes its initial ``inline``. A browser paints by that; a shape it does not
show is not cut. Each expectation was checked against Chromium 156's ``getComputedStyle`` on
these documents (stroke, fill, display, visibility, opacity).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from camtool.importers.svg import read_svg
from camtool.model.errors import InputError
from tests.importers.svgutil import svg

SQUARE = 'd="M 10 10 L 20 10 L 20 20 L 10 20 Z"'
OTHER = '<path id="y" d="M 40 40 L 60 40" stroke="#000"/>'


def _cut(tmp_path: Path, body: str) -> dict[str, str | None]:
    """``{source: colour}`` of the drawing's contours."""
    return {c.source: c.colour for c in read_svg(svg(tmp_path, body + OTHER)).contours}


def test_a_root_rule_s_none_leaves_the_shape_unpainted(tmp_path: Path) -> None:
    body = (
        "<style>:root { --ink: none } .a { fill: var(--ink); stroke: var(--ink) }</style>"
        f'<path id="x" class="a" {SQUARE}/>'
    )
    assert set(_cut(tmp_path, body)) == {"path#y"}


def test_a_custom_property_is_inherited_and_its_colour_is_the_shape_s(tmp_path: Path) -> None:
    body = (
        f'<g style="--ink: none"><path id="x" {SQUARE} style="fill: var(--ink); '
        'stroke: var(--ink)"/></g>'
        f'<g style="--ink: #FF0000"><path id="z" {SQUARE} fill="none" '
        'style="stroke: var(--ink)"/></g>'
    )
    assert _cut(tmp_path, body) == {"path#z": "#ff0000", "path#y": "#000000"}


def test_a_fallback_is_taken_when_the_property_is_not_set(tmp_path: Path) -> None:
    body = f'<path id="x" {SQUARE} fill="none" style="stroke: var(--nope, #00ff00)"/>'
    assert _cut(tmp_path, body)["path#x"] == "#00ff00"


def test_no_value_nor_fallback_is_unset_the_parent_s_none(tmp_path: Path) -> None:
    # stroke: unset inherits the group's none; the path's own stroke="#000" is outranked
    body = (
        f'<g fill="none" stroke="none"><path id="x" {SQUARE} stroke="#000" '
        'style="stroke: var(--nope)"/></g>'
    )
    assert set(_cut(tmp_path, body)) == {"path#y"}


def test_a_cycle_is_invalid_so_the_fallback_paints(tmp_path: Path) -> None:
    body = (
        f'<path id="x" {SQUARE} fill="none" style="--a: var(--b); --b: var(--a); '
        'stroke: var(--a, #0000ff)"/>'
    )
    assert _cut(tmp_path, body)["path#x"] == "#0000ff"


@pytest.mark.parametrize(
    ("style", "shown"),
    [
        ("display: var(--d)", True),  # unset: display's initial inline
        ("display: var(--off)", False),
        ("visibility: var(--v, hidden)", False),
        ("opacity: VAR(--o, 0)", False),
        ("opacity: var(--o, 1)", True),
    ],
)
def test_a_custom_property_that_decides_whether_a_shape_shows(
    tmp_path: Path, style: str, shown: bool
) -> None:
    sheet = "<style>:root { --off: none }</style>"
    body = f'{sheet}<path id="x" {SQUARE} stroke="#000" style="{style}"/>'
    assert ("path#x" in _cut(tmp_path, body)) is shown


def test_a_property_a_rule_not_applied_sets_is_refused_where_it_decides(tmp_path: Path) -> None:
    sheet = "<style>svg:not(.print) { --off: none }</style>"
    hidden = f'<path id="x" {SQUARE} stroke="#000" style="display: var(--off)"/>'
    with pytest.raises(InputError, match=r"path#x: display: var\(--off\) uses --off, which a"):
        read_svg(svg(tmp_path, sheet + hidden))
    capped = f'<path id="x" {SQUARE} stroke="#000" style="stroke-linecap: var(--off)"/>'
    assert "path#x" in _cut(tmp_path, sheet + capped)  # a cap decides nothing of showing


def test_root_selects_the_svg_element_only(tmp_path: Path) -> None:
    # the path inherits the group's --ink; :root sets the <svg> element's, not the path's own
    body = (
        "<style>:root { --ink: #ff0000 } g { --ink: #00ff00 }</style>"
        f'<g><path id="x" {SQUARE} fill="none" style="stroke: var(--ink)"/></g>'
    )
    assert _cut(tmp_path, body)["path#x"] == "#00ff00"


def test_a_presentation_attribute_s_var_is_resolved_too(tmp_path: Path) -> None:
    # Chromium 156: fill="var(--c)" is none under --c: none (not the group's #123456);
    # display="var(--c)" is none; opacity="var(--o)" with --o not set is unset: 1
    body = (
        '<g style="--c: none" stroke="#123456"><path id="f" d="M 1 1 L 2 2" fill="var(--c)" '
        'stroke="var(--c)"/><path id="v" d="M 1 1 L 2 2" stroke="#000" display="var(--c)"/></g>'
        f'<path id="o" {SQUARE} stroke="#000" opacity="var(--o)"/>'
    )
    assert set(_cut(tmp_path, body)) == {"path#o", "path#y"}


def test_a_value_that_grows_at_each_property_is_invalid_past_a_length(tmp_path: Path) -> None:
    # --v0 would be 3^16 · 3 characters (144 MB): over any length a browser substitutes, so
    # --v0 is invalid, and stroke takes its fallback
    chain = "; ".join(f"--v{i}: var(--v{i + 1}) var(--v{i + 1}) var(--v{i + 1})" for i in range(16))
    body = (
        f'<path id="x" {SQUARE} fill="none" style="{chain}; --v16: abc; stroke: var(--v0, #00f)"/>'
    )
    assert _cut(tmp_path, body)["path#x"] == "#0000ff"


def test_a_clone_s_var_from_where_its_use_stands_is_refused(tmp_path: Path) -> None:
    # a clone inherits from its <use> (CSS Scoping 1 §3.3.1): one <use> paints nothing here,
    # the other red; camtool resolves the copied path once, where it stands
    body = (
        f'<defs><path id="p" {SQUARE} fill="none" style="stroke: var(--ink)"/></defs>'
        '<use xlink:href="#p" style="--ink: none"/>'
        '<use xlink:href="#p" x="30" style="--ink: #ff0000"/>'
    )
    with pytest.raises(InputError, match=r"path#p: stroke: var\(--ink\) is placed by a <use>"):
        read_svg(svg(tmp_path, body))


@pytest.mark.parametrize(
    ("style", "colour"),
    [
        ("--ink: #ff0000; stroke: var(--ink)", "#ff0000"),
        ("stroke: var(--nope, #0000ff)", "#0000ff"),
    ],
)
def test_a_clone_s_var_set_within_or_nowhere_is_resolved(
    tmp_path: Path, style: str, colour: str
) -> None:
    body = (
        f'<defs><path id="p" {SQUARE} fill="none" style="{style}"/></defs>'
        '<use id="u" xlink:href="#p" x="30"/>'
    )
    assert {c.colour for c in read_svg(svg(tmp_path, body + OTHER)).contours} == {colour, "#000000"}
