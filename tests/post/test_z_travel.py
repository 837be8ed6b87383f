"""A program whose Z spans more than the machine's Z travel is refused, not written.

``--depth 5000`` wrote ``G1 Z-5000.000`` for GRBL and exited 0: a plunge no machine makes,
5 m below a work zero set on the stock. The Z travel is the profile's ``z_travel_mm``:
GRBL's ``$132`` default, 200 mm (defaults.h, DEFAULTS_GENERIC), and the MMH-LMM's 20 mm
(Yanez-07, L620: "20 mm de desplazamiento en los ejes X y Z"). The span is from the
clearance height (5 mm above the top by default) to the deepest cut.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parents[2]
PLATE = str(ROOT / "samples" / "plate.dxf")
CUT = ["--offset", "outside", "--tool-diameter", "3"]


def test_a_depth_beyond_the_z_travel_is_refused_and_nothing_written(
    run: Any, tmp_path: Path
) -> None:
    out = tmp_path / "deep.gcode"
    code, err = run("post", PLATE, "-t", "grbl", *CUT, "--depth", "5000", "-o", str(out))
    assert code != 0 and not out.exists()
    assert "Z spans 5005 mm" in err and "200 mm Z travel" in err and "--depth" in err
    assert "Traceback" not in err and "internal error" not in err


@pytest.mark.parametrize(("depth", "clearance", "fits"), [(14, 5, True), (16, 5, False)])
def test_the_span_counts_the_clearance_height_too(
    run: Any, tmp_path: Path, depth: float, clearance: float, fits: bool
) -> None:
    # MMH-LMM: 20 mm of Z; 14 + 5 fits, 16 + 5 does not
    out = tmp_path / "part.nc"
    args = ["--fit", "15", "15", "--origin", "lower-left", *CUT[:2], "--tool-diameter", "1"]
    code, err = run(
        "post", PLATE, "-t", "flashcut", *args, "--depth", str(depth),
        "--clearance-z", str(clearance), "-o", str(out),
    )  # fmt: skip
    assert (code == 0) == fits, err
    assert out.exists() == fits


def test_a_re_posted_program_is_checked_too_and_a_machine_file_may_give_more(
    run: Any, tmp_path: Path
) -> None:
    program = tmp_path / "tall.ngc"
    program.write_text("G21 G90\nG0 Z240\nG0 X1 Y1\nG1 Z-20 F100\nG1 X5 F300\nG0 Z240\nM2\n")
    out = tmp_path / "out.gcode"
    code, err = run("post", str(program), "-t", "grbl", "-o", str(out))
    assert code != 0 and "Z spans 260 mm" in err and not out.exists()
    # the heights are changed where the program was written: --depth is refused for G-code
    assert "clearance height in the program that wrote it" in err and "--depth" not in err
    code, err = run("verify", str(program), "-t", "grbl")
    assert code != 0 and "Z spans 260 mm" in err
    machine = tmp_path / "tall.toml"
    machine.write_text("[machine]\nz_travel_mm = 300\n")
    code, err = run("post", str(program), "-t", "grbl", "--machine", str(machine), "-o", str(out))
    assert code == 0, err
    assert "Z-20.000" in out.read_text()


def test_a_job_file_clearance_beyond_the_travel_is_refused(run: Any, tmp_path: Path) -> None:
    job = (ROOT / "samples" / "part.toml").read_text()
    assert "clearance_z = 10.0" in job
    (tmp_path / "part.toml").write_text(job.replace("clearance_z = 10.0", "clearance_z = 1e5"))
    out = tmp_path / "part.gcode"
    code, err = run(
        "post", str(ROOT / "samples" / "part.dxf"), "-t", "grbl",
        "--job", str(tmp_path / "part.toml"), "-o", str(out),
    )  # fmt: skip
    assert code != 0 and "Z travel" in err and not out.exists()
