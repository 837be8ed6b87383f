"""`calibrate fit` reads the sheet only from a regular file, and only plain ASCII decimals."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from camtool.calibrate.coupon import build_coupon
from camtool.calibrate.sheet import read_measurements
from camtool.cli.main import main
from camtool.model.errors import InputError
from camtool.post.registry import load_target


def _fit(args: list[str], timeout: float = 60.0) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "camtool", "calibrate", "fit", "-t", "grbl", *args],
        capture_output=True,
        text=True,
        check=False,
        timeout=timeout,
    )


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs here")
def test_a_fifo_is_refused_before_it_is_opened_for_reading(tmp_path: Path) -> None:
    """Nobody ever writes the FIFO: a reader that opened it would block until the timeout."""
    fifo = tmp_path / "sheet.csv"
    os.mkfifo(fifo)
    proc = _fit([str(fifo), "-o", str(tmp_path / "m.toml")])
    assert proc.returncode == 3
    assert f"{fifo}: the measurement sheet is not a regular file" in proc.stderr
    assert "Traceback" not in proc.stderr and not (tmp_path / "m.toml").exists()


@pytest.mark.skipif(not Path("/dev/zero").exists(), reason="no /dev/zero here")
def test_dev_zero_is_refused_not_read_to_the_end(tmp_path: Path) -> None:
    proc = _fit(["/dev/zero", "-o", str(tmp_path / "m.toml")])
    assert proc.returncode == 3
    assert "/dev/zero: the measurement sheet is not a regular file" in proc.stderr


def test_a_huge_sheet_is_refused_by_its_size(tmp_path: Path, capsys) -> None:
    big = tmp_path / "big.csv"
    with big.open("wb") as f:
        f.truncate(64 << 20)  # sparse: 64 MiB of zero bytes, no sheet is that large
    code = main(["calibrate", "fit", "-t", "grbl", str(big), "-o", str(tmp_path / "m.toml")])
    assert code == 3
    assert "the measurement sheet is 67108864 bytes, more than" in capsys.readouterr().err


@pytest.mark.parametrize(
    "text",
    [
        "１５.０",  # full-width digits: float() reads 15.0
        "١٥",  # Arabic-Indic digits: float() reads 15
        "1_5",  # an underscore: float() reads 15
        '"15,0"',  # a decimal comma (quoted)
        "infinity",
        "nan",
        "0x0F",
        "15 mm",
        "+-15",
    ],
)
def test_only_plain_ascii_decimals_are_numbers(text: str) -> None:
    coupon = build_coupon(load_target("grbl"))
    sheet = f"id,nominal_mm,measured_mm\nLX.p2,,\nLX.p1,15,{text}\n"
    where = r"s\.csv: line 3, column 'measured_mm': .* is not a number"
    with pytest.raises(InputError, match=where):
        read_measurements(sheet, coupon, source="s.csv")


@pytest.mark.parametrize(
    ("text", "value"), [("15", 15.0), ("15.", 15.0), (".5e1", 5.0), ("+1.5E+1", 15.0)]
)
def test_plain_decimals_are_read(text: str, value: float) -> None:
    coupon = build_coupon(load_target("grbl"))
    sheet = f"id,measured_mm\nLX.p1,{text}\n"
    (got,) = read_measurements(sheet, coupon, source="s.csv")
    assert got.value_mm == value


def test_a_decimal_comma_is_refused_with_the_number_it_may_be() -> None:
    coupon = build_coupon(load_target("grbl"))
    sheet = 'id,nominal_mm,measured_mm\nLX.p1,15,"15,02"\n'
    with pytest.raises(
        InputError, match=r"'15,02' is not a number .*a decimal comma\? write 15\.02"
    ):
        read_measurements(sheet, coupon, source="s.csv")


@pytest.mark.parametrize("delimiter", [";", "\t"])
def test_a_sheet_saved_with_semicolons_says_how_to_save_it(delimiter: str) -> None:
    # a spreadsheet in a decimal-comma language saves "CSV" with ; between the columns
    coupon = build_coupon(load_target("grbl"))
    sheet = delimiter.join(["id", "nominal_mm", "measured_mm"]) + "\n"
    sheet += delimiter.join(["LX.p1", "15", "15,02"]) + "\n"
    with pytest.raises(InputError, match=r"no 'id' column .*separated by .*commas between"):
        read_measurements(sheet, coupon, source="s.csv")
