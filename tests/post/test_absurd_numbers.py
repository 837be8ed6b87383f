"""Absurd numbers in code read back by the built-in dialect readers: exit 3, never a crash.

Each case is run as a user runs ``camtool verify``; the message names the file and line
and quotes the number briefly (a 400-digit number is not echoed whole).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from camtool.cli.main import main

BIG = "1" + "0" * 400  # 1e400 written out: float() of it is inf

MATLAB = """xy =
[     0    10    20;
      0    10     0 ]

lxy =
[    10    10;
     10    10 ]

velxy =
[   480   480;
    480  -480 ]
"""
# the arrays camtool writes for the triangle (0,0)-(1,1)-(2,0) mm at the default speed


def verify(tmp_path: Path, capsys: pytest.CaptureFixture[str], name: str, text: str, target: str):
    path = tmp_path / name
    path.write_text(text, encoding="ascii")
    code = main(["verify", str(path), "-t", target])
    return code, capsys.readouterr().err


def test_the_matlab_arrays_above_verify(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, err = verify(tmp_path, capsys, "t.m", MATLAB, "matlab-router")
    assert code == 0, err


@pytest.mark.parametrize("number", [BIG, "99999999999999999999", "-32768"])
def test_matlab_router_value_beyond_int16_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], number: str
) -> None:
    # not: "internal error: OverflowError: Python int too large to convert to C long"
    text = MATLAB.replace("[     0    10    20", f"[     0    {number}    20")
    code, err = verify(tmp_path, capsys, "t.m", text, "matlab-router")
    assert code == 3
    assert "t.m:2: xy:" in err and "does not fit the master's int16 (±32767)" in err
    assert len(err) < 200


@pytest.mark.parametrize("target", ["grbl", "linuxcnc", "flashcut"])
@pytest.mark.parametrize("number", [BIG, BIG + ".000", "1e308", "nan", "inf"])
def test_word_address_reader_refuses_absurd_numbers(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], target: str, number: str
) -> None:
    text = f"G21 G90 G17\nG0 X{number} Y1.000\nG1 X2.000 Y1.000 F300\nM2\n"
    if target == "flashcut":
        text = f"G00 X{number} Y1.0\nG01 X2.0 Y1.0 F300.0\nM30\n"
    code, err = verify(tmp_path, capsys, "t.nc", text, target)
    assert code == 3
    line = 1 if target == "flashcut" else 2
    assert f"t.nc:{line}:" in err
    assert "internal error" not in err and len(err.replace(str(tmp_path), "")) < 200
