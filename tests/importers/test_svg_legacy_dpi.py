"""SVGs saved by Inkscape before 0.92, which drew 90 px to the inch: read at 96, said so.

Expected values by analysis: Inkscape 0.48 stores a square it showed as 100 mm as
100 / 25.4 · 90 = 354.33071 px, which at CSS's 96 px to the inch is 93.75 mm; the warning's
remedy, ``--scale`` 96/90, gives the 100 mm back. Which documents Inkscape's own file update
(``sp_file_convert_dpi``) offers to rescale: a page in px (or without a unit), or in absolute
units without a viewBox.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import pytest

from camtool.importers import read_drawing
from camtool.importers.options import ImportOptions

SQUARE = '<rect x="35.433071" y="35.433071" width="354.33071" height="354.33071"/>'


def _svg(tmp_path: Path, version: str | None, size: str) -> Path:
    ink = 'xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape"'
    stamp = f'inkscape:version="{version}"' if version else ""
    path = tmp_path / "old.svg"
    path.write_text(
        f'<svg xmlns="http://www.w3.org/2000/svg" {ink} {stamp} {size}>{SQUARE}</svg>',
        encoding="utf-8",
    )
    return path


def _read(path: Path, scale: float = 1.0) -> tuple[float, list[str]]:
    drawing = read_drawing(path, ImportOptions())
    x0, _, x1, _ = drawing.bbox()
    return (x1 - x0) * scale, [w for w in drawing.warnings if "90 px to the inch" in w]


@pytest.mark.parametrize(
    "size",
    [
        'width="210mm" height="297mm"',  # absolute, no viewBox: user units are px
        'width="744.09448819" height="1052.3622047"',  # Inkscape 0.48's A4 in px
        'width="744.09448819px" height="1052.3622047px" viewBox="0 0 744.09448819 1052.3622047"',
    ],
)
def test_a_page_in_px_from_inkscape_0_48_is_read_at_96_with_the_remedy(
    tmp_path: Path, size: str
) -> None:
    width, said = _read(_svg(tmp_path, "0.48.4 r9939", size))
    assert width == pytest.approx(93.75, abs=1e-6)
    assert len(said) == 1 and "Inkscape 0.48.4" in said[0] and "--scale 1.066667" in said[0]


def test_the_remedy_cuts_the_size_inkscape_showed(tmp_path: Path, run: Any) -> None:
    path = _svg(tmp_path, "0.48.4 r9939", 'width="210mm" height="297mm"')
    out = tmp_path / "square.ngc"
    code, err = run("post", str(path), "-t", "linuxcnc", "--scale", "1.066667", "-o", str(out))
    assert code == 0 and "--scale 1.066667" in err
    cut = [line for line in out.read_text().splitlines() if line.startswith("G1 X")]
    xs = [float(re.search(r"X(-?[\d.]+)", line)[1]) for line in cut]  # type: ignore[index]
    assert max(xs) - min(xs) == pytest.approx(100.0, abs=0.001)


@pytest.mark.parametrize(
    ("version", "size"),
    [
        ("0.92.4 (5da689c313, 2019-01-14)", 'width="210mm" height="297mm"'),
        ("1.3.2 (091e20e, 2023-11-25)", 'width="744.09448819" height="1052.3622047"'),
        (None, 'width="210mm" height="297mm"'),
        # the viewBox and an absolute size fix the user unit whatever Inkscape drew
        ("0.48.4 r9939", 'width="210mm" height="297mm" viewBox="0 0 744.09448819 1052.3622047"'),
    ],
)
def test_no_word_for_later_inkscape_or_a_page_that_fixes_its_unit(
    tmp_path: Path, version: str | None, size: str
) -> None:
    _, said = _read(_svg(tmp_path, version, size))
    assert said == []
