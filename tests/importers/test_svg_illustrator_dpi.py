"""SVGs written by Adobe Illustrator, whose px are its points: read at 96 to the inch, said so.

Expected values by analysis: Illustrator stores a square it showed as 100 mm as
100 / 25.4 · 72 = 283.46457 px (its points), which at CSS's 96 px to the inch is 75 mm;
the warning's remedy, ``--scale`` 96/72 (or ``--units pt`` where the file gives no size),
gives the 100 mm back. The file's prolog comment names the writer (``<!-- Generator:
Adobe Illustrator 27.0.0, SVG Export Plug-In ...``); a file Inkscape saved again carries
``inkscape:version`` and Inkscape's px.
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Any

import pytest

from camtool.importers import read_drawing
from camtool.importers.options import ImportOptions

SIDE_PT = 100 / 25.4 * 72  # 283.46457: the 100 mm side in Illustrator's points
PROLOG = (
    '<?xml version="1.0" encoding="utf-8"?>\n'
    "<!-- Generator: Adobe Illustrator 27.0.0, SVG Export Plug-In . SVG Version: 6.00 "
    "Build 0)  -->\n"
)
CORPUS = Path(os.environ.get("CAMTOOL_CORPUS_DIR", Path(__file__).resolve().parents[2] / ".corpus"))
KMPLOT = CORPUS / "pkg/breeze-icon-theme/usr/share/icons/breeze/apps/48/kmplot.svg"


def _svg(tmp_path: Path, size: str, prolog: str = PROLOG, stamp: str = "") -> Path:
    page = f"{SIDE_PT * 1.2:.3f}"
    square = f'<rect x="{SIDE_PT * 0.1:.5f}" y="{SIDE_PT * 0.1:.5f}" width="{SIDE_PT:.5f}" '
    path = tmp_path / "part.svg"
    path.write_text(
        f'{prolog}<svg version="1.1" id="Layer_1" xmlns="http://www.w3.org/2000/svg" '
        f'xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape" {stamp} x="0px" '
        f'y="0px" {size.format(page=page)} xml:space="preserve">'
        f'{square}height="{SIDE_PT:.5f}" style="fill:none;stroke:#000"/></svg>',
        encoding="utf-8",
    )
    return path


def _read(path: Path, units: str | None = None) -> tuple[float, list[str]]:
    drawing = read_drawing(path, ImportOptions(units=units))
    x0, _, x1, _ = drawing.bbox()
    return x1 - x0, [w for w in drawing.warnings if "Adobe Illustrator" in w]


@pytest.mark.parametrize(
    ("size", "remedy"),
    [
        ('width="{page}px" height="{page}px" viewBox="0 0 {page} {page}"', "--scale 1.333333"),
        ('width="{page}" height="{page}"', "--scale 1.333333"),  # no unit, no viewBox
        ('viewBox="0 0 {page} {page}"', "--units pt"),  # "responsive": no size at all
    ],
)
def test_illustrators_points_are_read_as_css_px_with_the_remedy(
    tmp_path: Path, size: str, remedy: str
) -> None:
    width, said = _read(_svg(tmp_path, size))
    assert width == pytest.approx(75.0, abs=1e-4)
    assert len(said) == 1 and "Illustrator 27.0.0" in said[0] and remedy in said[0]


def test_the_remedies_cut_the_size_illustrator_showed(tmp_path: Path, run: Any) -> None:
    out = tmp_path / "square.ngc"
    sized = _svg(tmp_path, 'width="{page}px" height="{page}px" viewBox="0 0 {page} {page}"')
    code, err = run("post", str(sized), "-t", "linuxcnc", "--scale", "1.333333", "-o", str(out))
    assert code == 0 and "--scale 1.333333" in err
    xs = [float(m[1]) for m in re.finditer(r"^G1 X(-?[\d.]+)", out.read_text(), re.M)]
    assert max(xs) - min(xs) == pytest.approx(100.0, abs=0.001)
    width, said = _read(_svg(tmp_path, 'viewBox="0 0 {page} {page}"'), units="pt")
    assert width == pytest.approx(100.0, abs=1e-4) and said == []


@pytest.mark.parametrize(
    ("size", "prolog", "stamp"),
    [
        # a page in absolute units with a viewBox fixes the user unit whoever wrote it
        ('width="120mm" height="120mm" viewBox="0 0 {page} {page}"', PROLOG, ""),
        # Inkscape saved it again: its px are Inkscape's (96 to the inch since 0.92)
        ('width="{page}px" height="{page}px"', PROLOG, 'inkscape:version="1.3.2"'),
        # not Illustrator's
        ('width="{page}px" height="{page}px"', '<?xml version="1.0"?>\n', ""),
    ],
)
def test_no_word_where_the_unit_is_fixed_or_not_illustrators(
    tmp_path: Path, size: str, prolog: str, stamp: str
) -> None:
    _, said = _read(_svg(tmp_path, size, prolog, stamp))
    assert said == []


@pytest.mark.skipif(not KMPLOT.exists(), reason="corpus not fetched (make corpus)")
def test_an_illustrator_file_inkscape_saved_again_gets_inkscapes_word_only() -> None:
    # Breeze's kmplot icon (Debian's breeze-icon-theme): Illustrator 12's comment, then
    # saved by Inkscape 0.44, which drew 90 px to the inch
    drawing = read_drawing(KMPLOT, ImportOptions())
    assert not [w for w in drawing.warnings if "Adobe Illustrator" in w]
    assert [w for w in drawing.warnings if "Inkscape 0.44" in w]


KIG = CORPUS / "pkg/breeze-icon-theme/usr/share/icons/breeze/apps/48/kig.svg"


@pytest.mark.skipif(not KIG.exists(), reason="corpus not fetched (make corpus)")
def test_a_real_illustrator_10_file_is_said_to_be_in_points() -> None:
    # Breeze's kig icon (Debian's breeze-icon-theme) as Illustrator 10 saved it, its styles
    # in DTD entities: width="128" (Illustrator's points: 45.16 mm) read as 128 px, 33.87 mm
    drawing = read_drawing(KIG, ImportOptions())
    said = [w for w in drawing.warnings if "Adobe Illustrator" in w]
    assert len(said) == 1 and "Illustrator 10.0" in said[0] and "--scale 1.333333" in said[0]
    x0, y0, x1, y1 = drawing.bbox()
    page = 128 * 25.4 / 96
    assert 0 <= x0 < x1 <= page + 1e-6 and 0 <= y0 < y1 <= page + 1e-6
