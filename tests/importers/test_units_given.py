"""``--units`` for a drawing that declares no unit: a DXF without $INSUNITS, an SVG without size.

Expected values by analysis: a 2 × 1 unit rectangle drawn in inches is 50.8 × 25.4 mm.
"""

from __future__ import annotations

from pathlib import Path

import ezdxf
import pytest

from camtool.importers import read_drawing
from camtool.importers.options import ImportOptions
from camtool.model.errors import UsageError


def _box(path: Path, units: str | None) -> tuple[float, float]:
    drawing = read_drawing(path, ImportOptions(units=units))
    x0, y0, x1, y1 = drawing.bbox()
    return (round(x1 - x0, 9), round(y1 - y0, 9))


def _dxf(path: Path, insunits: int) -> Path:
    doc = ezdxf.new()
    doc.header["$INSUNITS"] = insunits
    doc.modelspace().add_lwpolyline([(0, 0), (2, 0), (2, 1), (0, 1)], close=True)
    doc.saveas(path)
    return path


def test_a_dxf_without_units_takes_the_given_unit(tmp_path: Path) -> None:
    path = _dxf(tmp_path / "plain.dxf", 0)
    assert _box(path, None) == (2.0, 1.0)  # assumed mm, with a warning
    assert _box(path, "in") == (50.8, 25.4)


def test_a_dxf_with_units_refuses_another(tmp_path: Path) -> None:
    path = _dxf(tmp_path / "mm.dxf", 4)
    assert _box(path, "mm") == (2.0, 1.0)  # the same unit: nothing to refuse
    with pytest.raises(UsageError, match=r"declares its unit, mm \(\$INSUNITS = 4\)"):
        _box(path, "in")


def test_an_svg_without_size_takes_the_given_unit(tmp_path: Path) -> None:
    path = tmp_path / "plain.svg"
    path.write_text(
        '<svg xmlns="http://www.w3.org/2000/svg">'
        '<rect x="0" y="0" width="2" height="1" fill="none" stroke="black"/></svg>'
    )
    assert _box(path, "in") == (50.8, 25.4)
    sized = tmp_path / "sized.svg"
    sized.write_text(
        '<svg xmlns="http://www.w3.org/2000/svg" width="20mm" height="10mm" viewBox="0 0 2 1">'
        '<rect x="0" y="0" width="2" height="1" fill="none" stroke="black"/></svg>'
    )
    with pytest.raises(UsageError, match="gives its size \\(20mm x 10mm\\)"):
        _box(sized, "in")
