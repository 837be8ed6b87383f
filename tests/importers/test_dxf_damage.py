"""A DXF number that is not a number is refused where it places a cut, not guessed.

ezdxf's recover mode reads ``"2,5"`` as ``2.0`` (C's ``strtod``: up to the comma). OpenSCAD
keeps a file of such numbers among its importer's test data
(``tests/data/dxf/nothing-decimal-comma-separated.dxf``: "should not crash but produce no
visible result"); camtool cut a 2 mm square from it, with exit 0 and a warning. The
drawings here are written from ezdxf's own output with one value changed, so what is
expected follows from the text: the coordinate is what the file says or the file is
refused.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from camtool.importers.dxf import import_dxf, read_dxf
from camtool.importers.dxf_damage import guesses
from camtool.model.errors import InputError
from camtool.model.shapes import Line
from tests.shapes import write_dxf
from tests.targets import post_cli


def _square(msp: object) -> None:
    msp.add_lwpolyline(  # type: ignore[attr-defined]
        [(0, 0), (2.5, 0), (2.5, 2.5), (0, 2.5)], close=True
    )


def _lines(path: Path) -> list[str]:
    return path.read_text().splitlines()


def _replace_value(path: Path, code: str, old: str, new: str, after: str) -> Path:
    """The file with the first ``code``/``old`` pair after a ``0``/``after`` tag made ``new``."""
    lines = _lines(path)
    start = next(
        i for i in range(0, len(lines), 2) if lines[i].strip() == "0" and lines[i + 1] == after
    )
    for i in range(start, len(lines) - 1, 2):
        if lines[i].strip() == code and float(lines[i + 1]) == float(old):
            lines[i + 1] = new
            break
    else:
        raise AssertionError(f"no {code}/{old} after {after}")
    out = path.with_name("damaged-" + path.name)
    out.write_text("\n".join(lines) + "\n")
    return out


def test_a_decimal_comma_in_an_entity_is_refused_naming_it(tmp_path: Path) -> None:
    good = write_dxf(tmp_path / "square.dxf", _square)
    bad = _replace_value(good, "10", "2.5", "2,5", "LWPOLYLINE")
    with pytest.raises(InputError) as info:
        read_dxf(bad)
    message = str(info.value)
    assert info.value.exit_code == 3
    assert message.startswith(f"{bad}: near line ")
    assert "'2,5' of a LWPOLYLINE in the ENTITIES section is not a number" in message
    assert "decimal comma" in message and "would read it as 2.0" in message
    assert "with decimal points" in message


def test_a_value_with_no_number_in_it_is_refused_too(tmp_path: Path) -> None:
    def circle(msp: object) -> None:
        msp.add_circle((5, 5), 2.0)  # type: ignore[attr-defined]

    good = write_dxf(tmp_path / "circle.dxf", circle)
    bad = _replace_value(good, "40", "2.0", "1.#QNAN", "CIRCLE")
    with pytest.raises(InputError, match=r"'1\.#QNAN' of a CIRCLE .* would read it as 1\.0"):
        read_dxf(bad)


def test_a_decimal_comma_in_the_header_only_changes_nothing_cut(tmp_path: Path) -> None:
    """``$EXTMIN`` guessed: the file is still read in recover mode, the square whole."""
    good = write_dxf(tmp_path / "square.dxf", _square)
    lines = _lines(good)
    k = lines.index("$EXTMIN")
    assert lines[k + 1].strip() == "10"
    lines[k + 2] = "-6,63671875"
    bad = tmp_path / "header.dxf"
    bad.write_text("\n".join(lines) + "\n")
    read = import_dxf(bad)
    assert read.recovered
    assert any('"-6,63671875"' in r for r in read.repairs)
    ends = sorted({p for seg in read.drawing.contours[0].segments for p in (seg.start, seg.end)})
    assert ends == [(0.0, 0.0), (0.0, 2.5), (2.5, 0.0), (2.5, 2.5)]
    assert all(isinstance(seg, Line) for seg in read.drawing.contours[0].segments)


def test_a_whole_number_re_read_beside_a_damaged_one_is_no_guess() -> None:
    repairs = [
        'recovered invalid floating point value "0,1" near line 74 as "0.0"',
        'recovered invalid floating point value "0" near line 74 as "0.0"',
        'recovered invalid floating point value " 12.5 " near line 74 as "12.5"',
        'recovered invalid integer value "1x" near line 90 as "1"',
        'recovered invalid integer value "7" near line 90 as "7"',
        "fixed: DXF structure error: missing ENDSEC tag.",
    ]
    assert [(g.text, g.line, g.value) for g in guesses(repairs)] == [
        ("0,1", 74, "0.0"),
        ("1x", 90, "1"),
    ]


def test_post_writes_nothing_for_such_a_file(tmp_path: Path) -> None:
    good = write_dxf(tmp_path / "square.dxf", _square)
    bad = _replace_value(good, "20", "2.5", "2,5", "LWPOLYLINE")
    out = tmp_path / "square.nc"
    run = post_cli(bad, "grbl", out)
    assert run.returncode == 3, run.stderr
    assert "is not a number" in run.stderr and "Traceback" not in run.stderr
    assert not out.exists()


_STRAY_ENDS = """  0\nSECTION\n  2\nHEADER\n  9\n$ACADVER\n  1\nAC1009\n  0\nENDSEC
  0\nSECTION\n  2\nTABLES\n  0\nTABLE\n  2\nLAYER\n 70\n1\n  0\nLAYER\n  2\n0\n 70\n0
 62\n7\n  6\nCONTINUOUS\n  0\nENDTAB\n  0\nENDTAB\n  0\nENDSEC
  0\nSECTION\n  2\nBLOCKS\n  0\nENDBLK\n  0\nENDBLK\n  0\nENDSEC
  0\nSECTION\n  2\nENTITIES
  0\nCIRCLE\n  8\n0\n 10\n0.0\n 20\n0.0\n 40\n100.0
  0\nCIRCLE\n  8\n0\n 10\n0.0\n 20\n0.0\n 40\n25.0
  0\nENDSEC\n  0\nEOF\n"""
"""A DXF as small hand-written generators write it: an ENDTAB and an ENDBLK too many (a
measuring plate's generator on GitHub writes this header; its circles are the part)."""


def test_a_stray_endtab_is_named_not_taken_for_a_truncated_file(tmp_path: Path) -> None:
    path = tmp_path / "plate.dxf"
    path.write_text(_STRAY_ENDS)
    drawing = import_dxf(path).drawing
    assert sorted(round(c.bbox()[2], 6) for c in drawing.contours) == [25.0, 100.0]
    damaged = [w for w in drawing.warnings if "damaged DXF file" in w]
    assert len(damaged) == 1
    assert "stray ENDTAB or ENDBLK" in damaged[0]
    assert "ends too early" not in damaged[0]
