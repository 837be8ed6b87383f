"""G70/G71, DIN 66025's units codes, as Vectric's Mach2/3 posts write them after G20/G21.

Vectric's Mach2/3 posts head a program ``G00G21G17G90G40G49G80`` / ``G71G91.1`` (in
inches ``G20`` / ``G70``): G71 is millimetres and G70 inches in DIN 66025 (Beckhoff's and
Siemens' manuals), while LinuxCNC and Fanuc lathes read G70/G71 with ``P``, ``Q``... as
lathe cycles. The judge of the moves is LinuxCNC's ``rs274`` on the same program with the
DIN code given as the G20/G21 it means: camtool's re-post must make its moves.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from camtool.cli.main import main
from camtool.importers.gcode import read_gcode
from camtool.model.errors import InputError
from tests.corpus.test_rs274 import ROUND_MM, canon_moves, needs_rs274, rs274

BODY = (
    "T1M06\nG00Z0.2000\nG00X0.0000Y0.0000S18000M03\nG94\nX0.5000Y0.5000F100.0\n"
    "G1Z-0.0400F40.0\nG1X2.0000\nG2X2.5000Y1.0000I0.0000J0.5000\nG1Y2.0000\n"
    "G3X2.0000Y2.5000I-0.5000J0.0000\nG00Z0.2000\nG00X0.0000Y0.0000\nM02\n"
)


def _cuts_mm(stdout: str) -> list[tuple[str, tuple[float, ...]]]:
    """rs274's feed moves in mm (it states them in the program's units)."""
    scale = 25.4 if "USE_LENGTH_UNITS(CANON_UNITS_INCHES)" in stdout else 1.0
    return [
        (kind, tuple(v * scale if i != 4 or kind != "arc" else v for i, v in enumerate(values)))
        for kind, values in canon_moves(stdout)
        if kind != "rapid"
    ]


def _vectric(units: str, din: str) -> str:
    return f"( Profile 1 )\nG00{units}G17G90G40G49G80\n{din}G91.1\n{BODY}"


@needs_rs274
@pytest.mark.parametrize(
    ("header", "meant"),
    [
        # as a Vectric Mach2/3 inch file begins (its N words too)
        ("N100G00G20G17G90G40G49G80\nN110G70G91.1\n", "N100G00G20G17G90G40G49G80\nN110G20G91.1\n"),
        ("G00G21G17G90G40G49G80\nG71G91.1\n", "G00G21G17G90G40G49G80\nG21G91.1\n"),
        ("G00G17G90G40G49G80\nG70G91.1\n", "G00G17G90G40G49G80\nG20G91.1\n"),
    ],
    ids=["vectric-inch", "vectric-mm", "g70-alone"],
)
def test_a_din_units_code_posts_the_moves_of_its_g20_g21(
    tmp_path: Path, header: str, meant: str
) -> None:
    source = tmp_path / "vectric.tap"
    source.write_text(f"( Profile 1 )\n{header}{BODY}")
    plain = tmp_path / "meant.ngc"
    plain.write_text(f"( Profile 1 )\n{meant}{BODY}")
    out = tmp_path / "out.ngc"
    assert main(["post", str(source), "-t", "linuxcnc", "-o", str(out)]) == 0
    want, got = rs274(plain), rs274(out)
    assert want.returncode == 0 and got.returncode == 0, (want.stderr, got.stderr)
    expected, written = _cuts_mm(want.stdout), _cuts_mm(got.stdout)
    assert len(written) == len(expected) == 5
    for (kind, a), (other, b) in zip(written, expected, strict=True):
        assert kind == other and a == pytest.approx(b, abs=ROUND_MM)


def test_vectrics_inch_program_is_read_in_inches_with_one_warning(tmp_path: Path) -> None:
    source = tmp_path / "vectric.tap"
    source.write_text(_vectric("G20", "G70"))
    program = read_gcode(str(source))
    # G1X2.0000 in inches: 50.8 mm
    assert max(m.x for m in program.moves) == pytest.approx(2.5 * 25.4)
    notes = [w for w in program.warnings if "G70" in w]
    assert len(notes) == 1 and "G20 (inches)" in notes[0]


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("G21\nG71 P1 Q2\nG1 X1 F100\n", "G71 with P1 is a lathe cycle"),
        ("G20\nG70 P10 Q20\nG1 X1 F100\n", "G70 with P10 is a lathe cycle"),
        ("G21\nG70\nG1 X1 F100\n", "G70 after the program stated millimetres (G21)"),
        ("G20\nG71\nG1 X1 F100\n", "G71 after the program stated inches (G20)"),
    ],
)
def test_a_lathe_cycle_or_units_against_the_stated_ones_are_refused(
    tmp_path: Path, text: str, message: str
) -> None:
    source = tmp_path / "p.nc"
    source.write_text(text)
    with pytest.raises(InputError, match=message.replace("(", r"\(").replace(")", r"\)")):
        read_gcode(str(source))
