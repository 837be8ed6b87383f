"""Nothing lost: stdin's file, files the command line never named, half a run's outputs.

Each case failed before: the input read from stdin was overwritten, a coupon replaced
an unrelated sheet beside it, and a run whose report could not be written had already
written its program.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
LOGO = ROOT / "samples" / "logo.dxf"


def camtool(*args: str, cwd: Path, stdin: Path | None = None) -> subprocess.CompletedProcess[str]:
    with open(stdin if stdin is not None else os.devnull, "rb") as feed:
        return subprocess.run(
            [sys.executable, "-m", "camtool", *args],
            cwd=cwd,
            stdin=feed,
            capture_output=True,
            text=True,
            check=False,
            timeout=300,
        )


def test_post_never_overwrites_the_file_stdin_reads(tmp_path: Path) -> None:
    drawing = tmp_path / "logo.dxf"
    drawing.write_bytes(LOGO.read_bytes())
    proc = camtool("post", "-", "-t", "grbl", "-o", "logo.dxf", cwd=tmp_path, stdin=drawing)
    assert proc.returncode == 2, proc.stderr
    assert "standard input" in proc.stderr
    assert drawing.read_bytes() == LOGO.read_bytes()


def test_verify_never_overwrites_the_program_stdin_reads(tmp_path: Path) -> None:
    program = tmp_path / "prog.gcode"
    program.write_text("G21 G90\nG0 X1 Y1\nG1 X5 Y1 F300\nM2\n")
    before = program.read_bytes()
    proc = camtool(
        "verify", "-", "-t", "grbl", "--report", "prog.gcode", cwd=tmp_path, stdin=program
    )
    assert proc.returncode == 2, proc.stderr
    assert program.read_bytes() == before


def test_a_coupon_keeps_an_unrelated_sheet_beside_it(tmp_path: Path) -> None:
    for name in ("star.csv", "star.md"):
        (tmp_path / name).write_text("mine\n")
    proc = camtool("calibrate", "coupon", "-t", "grbl", "-o", "star.gcode", cwd=tmp_path)
    assert proc.returncode == 2, proc.stderr
    assert "--force" in proc.stderr
    assert (tmp_path / "star.csv").read_text() == "mine\n"
    assert not (tmp_path / "star.gcode").exists()
    proc = camtool("calibrate", "coupon", "-t", "grbl", "-o", "star.gcode", "--force", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "star.csv").read_text() != "mine\n"


@pytest.mark.parametrize("report", ["/dev/full", "folder"])
def test_a_report_that_cannot_be_written_publishes_nothing(tmp_path: Path, report: str) -> None:
    if report == "/dev/full" and not os.path.exists("/dev/full"):
        pytest.skip("no /dev/full on this system")
    (tmp_path / "folder").mkdir()
    old = tmp_path / "p.gcode"
    old.write_text("(the program of yesterday)\n")
    proc = camtool(
        "post", str(LOGO), "-t", "grbl", "-o", "p.gcode", "--report", report, cwd=tmp_path
    )
    assert proc.returncode != 0
    assert "cannot write" in proc.stderr
    assert old.read_text() == "(the program of yesterday)\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["folder", "p.gcode"]  # no temporaries
