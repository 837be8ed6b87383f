"""`camtool calibrate` as a user runs it: coupon → filled sheet → overlay → verify."""

from __future__ import annotations

import csv
import io
from pathlib import Path

from camtool.cli.main import main
from camtool.post.registry import load_target


def test_coupon_fit_verify_round_trip(tmp_path: Path, capsys) -> None:
    out = tmp_path / "coupon.nc"
    assert main(["calibrate", "coupon", "-t", "grbl", "-o", str(out)]) == 0
    assert out.is_file() and (tmp_path / "coupon.md").is_file()
    template = (tmp_path / "coupon.csv").read_text()
    # a machine 1 % long in X: every X length and position measured 1 % over nominal
    rows = list(csv.DictReader(io.StringIO(template)))
    for row in rows:  # the long moves and the U patterns only: the rest left empty
        scale = 1.01 if row["id"].startswith(("LX.", "UX.")) else 1.0
        if row["id"].startswith(("LX.", "UX.", "LY.", "UY.")):
            row["measured_mm"] = f"{float(row['nominal_mm']) * scale:.4f}"
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=list(rows[0]))
    writer.writeheader()
    writer.writerows(rows)
    measured = tmp_path / "measured.csv"
    measured.write_text(buf.getvalue())
    overlay = tmp_path / "my.toml"
    capsys.readouterr()
    assert main(["calibrate", "fit", "-t", "grbl", str(measured), "-o", str(overlay)]) == 0
    err = capsys.readouterr()
    assert err.out == ""  # stdout carries data only
    assert "true steps/mm X" in err.err and "residual" in err.err
    fitted = load_target("grbl", machine_file=overlay).machine
    assert 250.0 / fitted.real_steps_per_mm[0] > 1.005
    assert main(["verify", str(out), "-t", "grbl", "--machine", str(overlay)]) == 0


def test_bad_sheet_exits_3_naming_line_and_column(tmp_path: Path, capsys) -> None:
    bad = tmp_path / "bad.csv"
    bad.write_text("id,measured_mm\nLX.p1,12,5\nLX.p2,x\n")
    code = main(["calibrate", "fit", "-t", "grbl", str(bad), "-o", str(tmp_path / "m.toml")])
    assert code == 3
    assert "bad.csv: line 3, column 'measured_mm': 'x' is not a number" in capsys.readouterr().err
    assert not (tmp_path / "m.toml").exists()


def test_coupon_to_stdout_needs_a_sheet_path(capsys) -> None:
    assert main(["calibrate", "coupon", "-t", "grbl", "-o", "-"]) == 2
    assert "--sheet" in capsys.readouterr().err
