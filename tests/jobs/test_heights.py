"""Heights a dialect would round into another move are refused, never written.

Expected resolutions come from each dialect's own definition: GRBL and LinuxCNC
write Z with three decimals (0.001 mm), the VALCNC on its 0.04 mm step grid, the
i8751 in whole motor steps (100 steps/mm in its placeholder profile: 0.01 mm).
A value below half a resolution rounds to 0.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import pytest

from camtool.post.registry import load_target

ROOT = Path(__file__).resolve().parents[2]
LOGO = str(ROOT / "samples" / "logo.dxf")
PART = str(ROOT / "samples" / "part.dxf")

RESOLUTION = {"grbl": 0.001, "linuxcnc": 0.001, "flashcut": 0.001, "valcnc": 0.04, "i8751": 0.01}


@pytest.mark.parametrize("name", sorted(RESOLUTION))
def test_written_z_is_the_dialects_rounding(name: str) -> None:
    target = load_target(name)
    step = RESOLUTION[name]
    assert target.post.written_z(-0.4 * step, target.machine) == 0
    assert target.post.written_z(-3 * step, target.machine) == pytest.approx(-3 * step)


@pytest.mark.parametrize(
    ("name", "options", "flag", "remedy"),
    [
        ("grbl", ["--depth", "0.0003"], "--depth", "--depth 0.001 or more"),
        ("linuxcnc", ["--depth", "0.0003"], "--depth", "--depth 0.001 or more"),
        ("i8751", ["--depth", "0.003"], "--depth", "--depth 0.01 or more"),
        ("valcnc", ["--depth", "0.012"], "--depth", "--depth 0.04 or more"),
        ("grbl", ["--depth", "0.5", "--safe-z", "0.0003"], "--safe-z", "--safe-z 0.001"),
        ("flashcut", ["--depth", "0.5", "--safe-z", "0.0003"], "--safe-z", "--safe-z 0.001"),
        (
            "linuxcnc",
            ["--depth", "0.5", "--safe-z", "0.0003", "--clearance-z", "0.0004"],
            "--safe-z",
            "--safe-z 0.001",
        ),
        ("grbl", ["--depth", "1", "--step-down", "0.0004"], "--step-down", "0.001 or more"),
        ("grbl", ["--depth", "3", "--step-down", "0.0007"], "--step-down", "0.001 or more"),
        ("valcnc", ["--depth", "1", "--step-down", "0.03"], "--step-down", "0.04 or more"),
        (
            "grbl",
            ["--depth", "3", "--tabs", "2", "--tab-height", "0.0002"],
            "--tab-height",
            "--tab-height 0.001 or more",
        ),
    ],
)
def test_a_height_rounded_into_another_move_is_refused(
    run: Any, tmp_path: Path, name: str, options: list[str], flag: str, remedy: str
) -> None:
    out = tmp_path / "logo.out"
    args = ["post", LOGO, "-t", name, "--offset", "outside", "--tool-diameter", "1"]
    code, err = run(*args, *options, "-o", str(out))
    assert code == 2, err
    assert re.search(rf"error: {flag} \S+ mm", err), err
    assert f"steps of {RESOLUTION[name]:g} mm" in err
    assert remedy in err
    assert not out.exists()


def test_the_nearest_working_value_is_written(run: Any, tmp_path: Path) -> None:
    out = tmp_path / "logo.ngc"
    options = ["--offset", "outside", "--tool-diameter", "1", "--safe-z", "0.001"]
    code, err = run("post", LOGO, "-t", "grbl", *options, "--depth", "0.001", "-o", str(out))
    assert code == 0, err
    zs = [float(z) for z in re.findall(r"Z(-?[\d.]+)", out.read_text())]
    assert min(zs) == -0.001
    assert min(z for z in zs if z > 0) == 0.001


def test_a_job_operation_is_named_with_its_key(run: Any, tmp_path: Path) -> None:
    job = tmp_path / "job.toml"
    job.write_text(
        "[[tools]]\nid = 1\ndiameter = 3\n"
        '[[operations]]\nname = "outline"\ntype = "profile"\ntool = 1\n'
        'layers = ["OUTLINE"]\nside = "outside"\ndepth = 0.0003\n'
    )
    out = tmp_path / "part.ngc"
    code, err = run("post", PART, "-t", "grbl", "--job", str(job), "-o", str(out))
    assert code == 3, err
    assert "operation 1 ('outline'): depth 0.0003 mm is written as Z0" in err
    assert not out.exists()


@pytest.mark.parametrize("name", ["grbl", "valcnc", "i8751"])
def test_a_re_posted_height_across_the_top_is_refused(run: Any, tmp_path: Path, name: str) -> None:
    program = tmp_path / "noise.ngc"
    program.write_text("G21 G90\nG0 Z0.0003\nG0 X1 Y1\nG1 Z-1 F100\nG1 X2\nG0 Z5\nM2\n")
    out = tmp_path / "noise.out"
    code, err = run("post", str(program), "-t", name, "-o", str(out))
    assert code != 0
    assert "Z0.0003 mm above the stock is written as Z0" in err
    assert not out.exists()
