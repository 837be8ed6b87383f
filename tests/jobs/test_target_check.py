"""A misspelt motion name in a target or --machine file is refused before any code is written.

Machine profiles take any interpolator name (targets and plugins bring their own), so the
names are resolved when a job loads its target (``jobs.pipeline.load_target_checked``), not
only when the code is verified: the behaviour of the profile loader before names were opened.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from camtool.cli.main import main
from tests.shapes import rectangle_dxf

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize(
    ("table", "name", "valid"),
    [
        # pic-mmh's profile: the generic pieces and its own; another target's only qualified
        ('line = "ddaa"', "'ddaa'", ["dda", "bresenham", "<target>:<name>"]),
        ('arc = "dssm"', "'dssm'", ["dsm", "staircase", "chords"]),
        ('arc = "chords"\nchords = "sagita"', "'sagita'", ["sagitta", "<target>:<name>"]),
    ],
)
def test_post_refuses_an_unknown_motion_name_in_a_machine_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], table: str, name: str, valid: list[str]
) -> None:
    overlay = tmp_path / "typo.toml"
    overlay.write_text(f'[machine]\nname = "mine"\n[machine.motion]\n{table}\n', "utf-8")
    out = tmp_path / "logo.pic"
    code = main(
        ["post", str(ROOT / "samples" / "logo.dxf"), "-t", "pic-mmh", "--machine", str(overlay),
         "-o", str(out)]
    )  # fmt: skip
    err = capsys.readouterr().err
    assert code == 3
    assert not out.exists()
    assert str(overlay) in err and name in err
    listed = err.split("valid:")[1]
    assert all(v in listed for v in valid)
    assert "timer" not in listed and "grbl," not in listed  # flashcut's line, GRBL's chords


def test_verify_refuses_an_unknown_line_in_a_target_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    target = tmp_path / "mine.toml"
    grbl = (ROOT / "postprocessors" / "grbl" / "grbl.toml").read_text("utf-8")
    target.write_text(grbl.replace('line = "bresenham"', 'line = "bresenhem"'), "utf-8")
    assert 'line = "bresenhem"' in target.read_text("utf-8")
    drawing = tmp_path / "r.dxf"
    rectangle_dxf(drawing, 10.0, 5.0)
    code = main(["post", str(drawing), "-t", str(target), "-o", str(tmp_path / "r.gcode")])
    err = capsys.readouterr().err
    assert code == 3 and str(target) in err and "'bresenhem'" in err
    assert not (tmp_path / "r.gcode").exists()
    # the same file is refused by verify, before the code is read
    (tmp_path / "r.gcode").write_text("G0 X0 Y0\n", "utf-8")
    assert main(["verify", str(tmp_path / "r.gcode"), "-t", str(target)]) == 3
    assert "'bresenhem'" in capsys.readouterr().err
