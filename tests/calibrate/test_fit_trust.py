"""`calibrate fit` never reports what the sheet did not determine, and refuses data that
contradict physics, as a user runs it.

The measured sheets are synthesised by the coupon's own geometry (not by camtool's simulation):
on grbl (250 steps/mm nominal, no compensation) a move of ``d`` mm commands ``250 d`` steps,
which the mechanics turn into ``250 d / T`` mm (``T`` the true steps/mm); a line cut after a
reversal loses the true backlash ``B`` (the U pattern's second line, a square's top and left
edges, Yanez-07 §5), the long moves and the first U line do not (they follow an approach).
"""

from __future__ import annotations

import csv
import io
import re
import tomllib
from collections.abc import Callable
from pathlib import Path

import pytest

from camtool.calibrate import make_coupon
from camtool.cli.main import main
from camtool.post.registry import load_target

NOMINAL = 250.0  # grbl $100-$102


def _measured(row_id: str, nominal_mm: float, true: dict[str, float]) -> float:
    """The value a machinist reads on a machine with ``true`` steps/mm and backlash."""
    feature, _, measure = row_id.partition(".")
    axis = "x" if feature in ("LX", "UX") or measure == "dx" else "y"
    length = nominal_mm * NOMINAL / true[f"t{axis}"]
    after_reversal = measure in ("back", "dx", "dy")
    return length - (true[f"b{axis}"] / 1000.0 if after_reversal else 0.0)


@pytest.fixture(scope="module")
def template() -> list[dict[str, str]]:
    return list(csv.DictReader(io.StringIO(make_coupon(load_target("grbl")).csv)))


def _sheet(
    path: Path,
    rows: list[dict[str, str]],
    keep: tuple[str, ...],
    true: dict[str, float],
    tweak: Callable[[str, float], float] = lambda _, v: v,
) -> Path:
    out = io.StringIO()
    writer = csv.DictWriter(out, fieldnames=list(rows[0]))
    writer.writeheader()
    for row in rows:
        row = dict(row)
        if row["id"].startswith(keep):
            value = _measured(row["id"], float(row["nominal_mm"]), true)
            row["measured_mm"] = f"{tweak(row['id'], value):.4f}"
        writer.writerow(row)
    path.write_text(out.getvalue())
    return path


def _fit(tmp_path: Path, sheet: Path, capsys, *extra: str) -> tuple[int, str, Path]:
    overlay = tmp_path / "m.toml"
    capsys.readouterr()
    code = main(["calibrate", "fit", "-t", "grbl", str(sheet), "-o", str(overlay), *extra])
    return code, capsys.readouterr().err, overlay


TRUE = {"tx": 252.0, "ty": 248.5, "bx": 60.0, "by": 600.0}
EVERY_XY = ("LX.", "LY.", "UX.", "UY.", "SQ")


def test_a_complete_sheet_gives_the_true_values_and_the_grbl_settings(
    tmp_path: Path, template, capsys
) -> None:
    sheet = _sheet(tmp_path / "s.csv", template, EVERY_XY, TRUE)
    code, err, overlay = _fit(tmp_path, sheet, capsys)
    assert code == 0, err
    table = tomllib.loads(overlay.read_text())["machine"]
    assert table["true_steps_per_mm"][:2] == pytest.approx([252.0, 248.5], rel=2e-4)
    assert table["backlash"]["true_um"][:2] == pytest.approx([60.0, 600.0], abs=4.0)  # a step
    # the controller's settings that make the machine cut true sizes: $100/$101 = true steps/mm
    assert "$100=252.0" in err and "$101=248.5" in err and "$102=" not in err


def test_a_misread_row_is_named_before_the_settings_and_in_the_overlay(
    tmp_path: Path, template, capsys
) -> None:
    # LX.p1 (15 mm) read 1 mm long: no steps/mm and backlash of a machine give that row with
    # the others, so about 1 mm of it stays (over 0.25 mm and 2 % of 15 mm); every other row
    # fits within microns
    misread = _sheet(
        tmp_path / "s.csv",
        template,
        EVERY_XY,
        TRUE,
        lambda row, v: v + 1.0 if row == "LX.p1" else v,
    )
    code, err, overlay = _fit(tmp_path, misread, capsys)
    assert code == 0, err
    caution = [line for line in err.splitlines() if "caution:" in line]
    assert len(caution) == 1 and "caution: 1 of 30 row(s)" in caution[0]
    assert re.search(r"LX\.p1 \(0\.9\d\d mm\);", caution[0]), caution[0]
    assert err.index("caution:") < err.index("to cut true sizes")
    assert "# caution: 1 of 30 row(s)" in overlay.read_text()
    whole = _sheet(tmp_path / "t.csv", template, EVERY_XY, TRUE)
    code, err, overlay = _fit(tmp_path, whole, capsys)
    assert code == 0 and "caution" not in err and "caution" not in overlay.read_text()


def test_a_sheet_without_y_lines_is_refused_naming_the_rows_to_measure(
    tmp_path: Path, template, capsys
) -> None:
    """The squares' left edges depend on Y's steps/mm and Y's backlash alike: holding the
    backlash at the profile's 0 would put 600 µm over 25 mm (2.4 %) into Y's steps/mm."""
    sheet = _sheet(tmp_path / "s.csv", template, ("LX.", "UX.", "SQ"), TRUE)
    code, err, overlay = _fit(tmp_path, sheet, capsys)
    assert code == 3 and not overlay.exists()
    assert "cannot tell backlash Y and true steps/mm Y apart" in err
    assert "SQ1.dy" in err and "LY.p1…p10" in err and "UY.out" in err and "UY.back" in err
    # told to hold the backlash, it fits and says so in the overlay
    code, err, overlay = _fit(tmp_path, sheet, capsys, "--hold", "backlash")
    assert code == 0, err
    text = overlay.read_text()
    assert "# not fitted: backlash Y: held at the profile's value" in text
    assert "backlash" not in tomllib.loads(text)["machine"]


def test_an_axis_not_measured_keeps_the_profile_and_says_so(
    tmp_path: Path, template, capsys
) -> None:
    sheet = _sheet(tmp_path / "s.csv", template, ("LX.", "UX."), TRUE)
    code, err, overlay = _fit(tmp_path, sheet, capsys)
    assert code == 0, err
    table = tomllib.loads(overlay.read_text())["machine"]
    assert table["true_steps_per_mm"] == pytest.approx([252.0, NOMINAL, NOMINAL], rel=2e-4)
    assert table["backlash"]["true_um"][:2] == pytest.approx([60.0, 0.0], abs=4.0)
    assert "true steps/mm Y: not measured by this sheet" in err
    assert "$100=252.0" in err and "$101" not in err


def test_a_return_line_longer_than_the_first_is_a_negative_backlash_refused(
    tmp_path: Path, template, capsys
) -> None:
    """Without compensation the line after a reversal can only be shorter; 0.3 mm longer means
    a backlash of −300 µm: refused (clamped at 0, it made X's steps/mm absorb it)."""
    true = {**TRUE, "bx": 0.0}
    sheet = _sheet(
        tmp_path / "s.csv",
        template,
        ("UX.",),
        true,
        lambda i, v: v + 0.3 if i == "UX.back" else v,
    )
    code, err, overlay = _fit(tmp_path, sheet, capsys)
    assert code == 3 and not overlay.exists()
    assert "backlash X comes out negative, -300" in err and "UX.back" in err


@pytest.mark.parametrize(
    ("factor", "words"),
    [
        (1000.0, "look like µm"),
        (1 / 25.4, "look like inches"),
    ],
)
def test_values_in_another_unit_are_refused_before_the_fit(
    tmp_path: Path, template, capsys, factor: float, words: str
) -> None:
    perfect = {"tx": NOMINAL, "ty": NOMINAL, "bx": 0.0, "by": 0.0}
    sheet = _sheet(tmp_path / "s.csv", template, EVERY_XY, perfect, lambda _, v: v * factor)
    code, err, _ = _fit(tmp_path, sheet, capsys)
    assert code == 3 and words in err and "internal error" not in err
    assert "line 2, LX.p1" in err and "in millimetres" in err


def test_a_sheet_doubled_is_an_implausible_correction_refused(
    tmp_path: Path, template, capsys
) -> None:
    perfect = {"tx": NOMINAL, "ty": NOMINAL, "bx": 0.0, "by": 0.0}
    sheet = _sheet(tmp_path / "s.csv", template, ("LX.", "UX."), perfect, lambda _, v: v * 2)
    code, err, _ = _fit(tmp_path, sheet, capsys)
    assert code == 3
    assert "a correction of -50.0 %" in err and "2× too large" in err
    assert "--max-correction 51" in err
    # a machine that really is 2× off (a driver's microstepping): accepted when told
    code, err, _ = _fit(tmp_path, sheet, capsys, "--max-correction", "60")
    assert code == 0, err
    assert "$100=125.0" in err


def test_a_moderate_correction_is_accepted(tmp_path: Path, template, capsys) -> None:
    true = {"tx": NOMINAL / 1.15, "ty": NOMINAL, "bx": 0.0, "by": 0.0}  # 15 % long in X
    sheet = _sheet(tmp_path / "s.csv", template, ("LX.",), true)
    code, err, _ = _fit(tmp_path, sheet, capsys)
    assert code == 0, err
    assert f"$100={NOMINAL / 1.15:.3f}" in err


@pytest.mark.parametrize(
    "settings",
    ['["$100={}", "$101={}"]', '["$100", "$101", "$102"]', '["$100={}{}", "a{}", "b{}"]'],
)
def test_a_bad_settings_template_is_refused(tmp_path: Path, settings: str) -> None:
    from camtool.model.errors import InputError

    overlay = tmp_path / "m.toml"
    overlay.write_text(f"[machine]\nsteps_per_mm_settings = {settings}\n")
    with pytest.raises(InputError, match=r"steps_per_mm_settings must be a list of 3 strings"):
        load_target("grbl", machine_file=overlay)
