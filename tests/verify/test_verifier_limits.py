"""`--max-error-um` judges what was cut, `--strict` the rest; a drawing apart from the program.

Run as a user runs camtool (`camtool.cli.main.main`). samples/plate.dxf cut on its
outside with a 3 mm tool has two 90° inside corners (the notch) and a 2 mm
square hole the tool cannot enter: the planner reports both, the corners keep
r·(√2 − 1) = 621 µm of material and the hole is millimetres from any cut.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from camtool.cli.main import main
from camtool.model.shapes import Contour, Drawing, Line
from camtool.post.registry import load_target
from camtool.verify.verifier import verify_code
from tests.shapes import rectangle_dxf

SAMPLES = Path(__file__).parents[2] / "samples"
PLATE = str(SAMPLES / "plate.dxf")
POST = ["post", PLATE, "-t", "grbl", "--offset", "outside", "--tool-diameter", "3", "--depth", "3"]


def rect_nc(dx: float = 0.0) -> str:
    """GRBL code of a 10 × 5 mm rectangle from (1 + dx, 1), cut on the line."""
    x0, x1 = 1.0 + dx, 11.0 + dx
    return (
        f"G21 G90 G17\nG0 X{x0:.3f} Y1.000\nG1 X{x1:.3f} Y1.000 F300\nG1 X{x1:.3f} Y6.000\n"
        f"G1 X{x0:.3f} Y6.000\nG1 X{x0:.3f} Y1.000\n"
    )


RECT_NC = rect_nc()


def run(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    code = main(args)
    out, err = capsys.readouterr()
    return code, out, err


def test_limit_judges_what_was_cut(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    report = tmp_path / "r.json"
    args = [*POST, "-o", str(tmp_path / "p.nc"), "--report", str(report), "--max-error-um", "50"]
    code, _, err = run(args, capsys)
    assert code == 0, err
    assert "features not cut as drawn" in err
    data = json.loads(report.read_text())
    kinds = sorted(f["kind"] for f in data["not_cut_as_drawn"])
    assert kinds == ["offset-vanished", "tight-corner", "tight-corner"]
    corners = [f for f in data["not_cut_as_drawn"] if f["kind"] == "tight-corner"]
    assert all(f["error_um"] == pytest.approx(621.32, abs=10.0) for f in corners)
    assert data["against"]["max_um"] < 50.0
    assert data["strict_error_um"] > 1000.0


def test_strict_counts_the_rest(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run(
        [*POST, "-o", str(tmp_path / "p.nc"), "--max-error-um", "50", "--strict"], capsys
    )
    assert code == 4
    assert "exceeds --max-error-um 50 with --strict" in err


def test_disjoint_drawing_is_not_compared() -> None:
    far = Drawing(
        (
            Contour(
                (
                    Line((1000.0, 1000.0), (1010.0, 1000.0)),
                    Line((1010.0, 1000.0), (1010.0, 1005.0)),
                    Line((1010.0, 1005.0), (1000.0, 1005.0)),
                    Line((1000.0, 1005.0), (1000.0, 1000.0)),
                ),
                True,
            ),
        )
    )
    v = verify_code(RECT_NC, load_target("grbl"), against=far)
    assert v.against is None
    assert v.against_skipped is not None
    assert "the program (X 1…11 Y 1…6 mm) and the drawing (X 1000…1010 Y 1000…1005 mm)" in (
        v.against_skipped
    )
    assert "do not overlap" in v.against_skipped
    assert v.against_skipped in v.warnings


def test_scaled_drawing_is_not_compared() -> None:
    # the same rectangle drawn in inches read as mm: 25.4 × larger, overlapping 1/645 of it
    inch = Drawing(
        (
            Contour(
                (
                    Line((25.4, 25.4), (279.4, 25.4)),
                    Line((279.4, 25.4), (279.4, 152.4)),
                    Line((279.4, 152.4), (25.4, 152.4)),
                    Line((25.4, 152.4), (25.4, 25.4)),
                ),
                True,
            ),
        )
    )
    v = verify_code(RECT_NC, load_target("grbl"), against=inch)
    assert v.against is None and v.against_skipped is not None


def test_overlapping_drawing_is_compared() -> None:
    same = Drawing(
        (
            Contour(
                (
                    Line((1.0, 1.0), (11.0, 1.0)),
                    Line((11.0, 1.0), (11.0, 6.0)),
                    Line((11.0, 6.0), (1.0, 6.0)),
                    Line((1.0, 6.0), (1.0, 1.0)),
                ),
                True,
            ),
        )
    )
    v = verify_code(RECT_NC, load_target("grbl"), against=same)
    assert v.against_skipped is None and v.against is not None
    assert v.against.max_um < 5.0  # on the line, grbl's 4 µm steps


def test_cli_disjoint_warns_and_the_limit_fails(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code_file = tmp_path / "far.nc"
    code_file.write_text(rect_nc(150.0))
    drawing = rectangle_dxf(tmp_path / "rect.dxf")  # at (1, 1), the program 150 mm away
    base = ["verify", str(code_file), "-t", "grbl", "--against", str(drawing)]
    code, _, err = run(base, capsys)
    assert code == 0, err
    assert "do not overlap: different scale or origin?" in err
    assert "against the drawing: max" not in err
    code, _, err = run([*base, "--max-error-um", "100"], capsys)
    assert code == 4
    assert "--max-error-um 100 cannot be judged" in err
