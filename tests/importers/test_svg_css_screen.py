"""Style sheet rules and values camtool does not apply, where a viewer would hide a shape.

Each expectation is what Chromium shows (its ``getComputedStyle`` on a screen, checked by
hand on these documents): ``@media screen`` rules apply, ``@media print`` ones do not; a
rule after an ``@import`` statement applies. camtool does not evaluate media queries, so
where one may hide a shape it refuses the drawing (a hidden shape cut is a wrong part),
naming the rule (custom properties: tests/importers/test_svg_css_variables.py).
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from camtool.importers.svg import read_svg
from camtool.model.errors import InputError
from tests.importers.svgutil import svg

SHAPES = '<path id="x" class="x" d="M 0 0 L 1 0"/><path id="y" d="M 0 2 L 1 2"/>'


@pytest.mark.parametrize(
    "media", ["screen", "all", "(min-width: 10px)", "not print", "print, screen"]
)
def test_a_media_rule_that_may_hide_on_a_screen_is_refused(tmp_path: Path, media: str) -> None:
    body = f"<style>@media {media} {{ .x {{ display: none }} }}</style>{SHAPES}"
    rule = re.escape(f"'@media {media}' hides what it selects on a screen")
    with pytest.raises(InputError, match=rule):
        read_svg(svg(tmp_path, body))


@pytest.mark.parametrize("media", ["print", "only print", "speech"])
def test_a_print_rule_hides_nothing_on_a_screen(tmp_path: Path, media: str) -> None:
    body = f"<style>@media {media} {{ .x {{ display: none }} }}</style>{SHAPES}"
    drawing = read_svg(svg(tmp_path, body))
    assert [c.source for c in drawing.contours] == ["path#x", "path#y"]
    assert f"'@media {media}'" in drawing.warnings[0]


@pytest.mark.parametrize("rule", ["@keyframes fade", "@-webkit-keyframes fade"])
def test_an_animations_frames_hide_nothing_in_a_still_picture(tmp_path: Path, rule: str) -> None:
    # a frame at opacity 0 is a moment of an animation, not a rule that selects elements
    body = f"<style>{rule} {{ 0% {{ opacity: 0 }} 100% {{ opacity: 1 }} }}</style>{SHAPES}"
    assert [c.source for c in read_svg(svg(tmp_path, body)).contours] == ["path#x", "path#y"]


def test_a_rule_after_an_import_statement_applies(tmp_path: Path) -> None:
    # The sheet the @import names is not read (said in the warning); the rule after the
    # statement is a rule of its own, which hides path#x.
    body = "<style>@import url(other.css); .x { display: none }</style>" + SHAPES
    drawing = read_svg(svg(tmp_path, body))
    assert [c.source for c in drawing.contours] == ["path#y"]
    assert "'@import url(other.css)'" in drawing.warnings[0]
