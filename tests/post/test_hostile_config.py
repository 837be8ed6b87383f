"""Hostile machine and target files: a clear error naming the file and key, nothing written.

Each case ended in a traceback, a hang, a MemoryError or a program written from a value
no machine has (``steps_per_mm = 1e300``). The ranges are physical (docs/dialects.md):
no stepper makes a million steps per mm, no controller writes 30 decimals.
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parents[2]
LOGO = str(ROOT / "samples" / "logo.dxf")
GRBL = (ROOT / "postprocessors" / "grbl" / "grbl.toml").read_text()

MACHINE_OVERLAYS = {
    "steps_per_mm = [1e300, 1e300, 1e300]": "steps_per_mm",
    "steps_per_mm = [0, 250, 250]": "steps_per_mm",
    "max_step_rate_hz = -5": "max_step_rate_hz",
    "max_step_rate_hz = nan": "max_step_rate_hz",
    "[machine.motion]\nchord_segments = 0.5": "chord_segments",
    "[machine.motion]\nchord_segments = 1000000000000000": "chord_segments",
    "[machine.motion]\nchord_tolerance_mm = 1e-12": "chord_tolerance_mm",
    "[machine.motion]\nchord_tolerance_mm = 1e-300": "chord_tolerance_mm",
    "[machine.backlash]\ntrue_um = [1e300, 0, 0]": "true_um",
    "work_area_mm = [0, 0, 1e300, 100]": "work_area_mm",
    "z_travel_mm = -5": "z_travel_mm",
    "z_travel_mm = 1e300": "z_travel_mm",
    'z_travel_mm = "200"': "z_travel_mm",
    # a list where a name is chosen: refused, not an internal error (it is not hashable)
    "coordinates = []": "coordinates",
    "[machine.motion]\nrounding = []": "rounding",
    # the timing table times the program's header as well: checked before any code
    '[machine.timing]\nmodel = "grbl"\nmax_rate_mm_min = "x"': "max_rate_mm_min",
    '[machine.timing]\nmodel = "grbl"\nmax_rate_mm_min = 1e-300': "max_rate_mm_min",
    '[machine.timing]\nmodel = "grbl"\nacceleration_mm_s2 = 1e308': "acceleration_mm_s2",
    '[machine.timing]\nmodel = "grbl"\nacceleration_mm_s2 = -10': "acceleration_mm_s2",
}

TARGET_EDITS = {
    ("decimals = 3 ", "decimals = 30 #"): "decimals",
    ("decimals = 3 ", "decimals = 9223372036854775807 #"): "decimals",
    ("decimals = 3 ", "decimals = 3\ngrid_mm = 1e-300 #"): "grid_mm",
    ('end = ["M2", "M30"]', 'end = ["M2\u00e9"]'): "end",
    ('modal = ["F"]', 'modal = ["\uff26"]'): "modal",
    # a spindle below 1 rev/min does not turn: GRBL read "M3 S0" from 1e-300
    ("spindle_rpm = 1000.0", "spindle_rpm = 1e-300 #"): "spindle_rpm",
    # every X written in mm, read by GRBL in inches: 25.4 times the distance, exit 0
    ('preamble = ["G21 G90', 'preamble = ["G20 G90'): "G20 sets inches, but words.X has scale = 1",
    # codes that change how camtool's own blocks are read, written with exit 0: arcs in
    # the XZ plane, F as inverse time or per revolution, every move offset by the tool
    # table's radius, a G92 offset restored, a main program run again from its start
    ('preamble = ["G21 G90 G94 G17"]', 'preamble = ["G21 G90 G17 G18"]'): "G18 is not a setup",
    ('preamble = ["G21 G90 G94 G17"]', 'preamble = ["G21 G90 G17 G93"]'): "G93 is not a setup",
    ('preamble = ["G21 G90 G94 G17"]', 'preamble = ["G21 G90 G17 G95"]'): "G95 is not a setup",
    ('preamble = ["G21 G90 G94 G17"]', 'preamble = ["G21 G90 G17 G41"]'): "G41 is not a setup",
    ('preamble = ["G21 G90 G94 G17"]', 'preamble = ["G21 G92.3"]'): "G92.3 is not a setup",
    ('preamble = ["G21 G90 G94 G17"]', 'preamble = ["G21 G90"]\npostamble = ["M99"]'): "M99",
    # arc centres on a coarser grid than the ends: "internal error: the arc start (1.1,
    # 0.25) is not on the 1.0 mm grid"
    ("[dialect_options.words.IJK]\ndecimals = 3", "[dialect_options.words.IJK]\ndecimals = 0"): (
        "but the words write X 0.001 mm, Y 0.001 mm, I 1 mm, J 1 mm"
    ),
    # every position on a grid of kilometres: the part written as moves to X0 Y0, exit 0
    ("decimals = 3 ", "decimals = 0\nscale = 0.000001 #"): (
        "words.XYZ: scale 1e-06 with decimals = 0 writes a position in steps of 1e+06 mm, "
        "coarser than 10 mm"
    ),
    ("decimals = 3 ", "decimals = 0\ngrid_mm = 20.0 #"): "on grid_mm 20 writes a position",
    # the name was written with str(): "wrote 35 blocks for 1e+308"
    ('name = "grbl"', "name = 1e308"): "name must be one line of printable text",
    # a line break in what the messages name the target by
    ('name = "grbl"', 'name = "grbl\\nM3"'): "name must be one line of printable text",
    ('description = "GRBL 1.1 controller', 'description = ["x"] #'): "description must be one line",
}


def _refused(run: Any, tmp_path: Path, *args: str) -> str:
    out = tmp_path / "out.gcode"
    code, err = run("post", LOGO, *args, "-o", str(out))
    assert code == 3, err
    assert "Traceback" not in err and "internal error" not in err
    assert not out.exists()
    return err


@pytest.mark.parametrize("overlay", sorted(MACHINE_OVERLAYS))
def test_a_machine_value_out_of_its_physical_range_is_refused(
    run: Any, tmp_path: Path, overlay: str
) -> None:
    machine = tmp_path / "m.toml"
    machine.write_text("[machine]\n" + overlay + "\n")
    err = _refused(run, tmp_path, "-t", "grbl", "--machine", str(machine))
    assert MACHINE_OVERLAYS[overlay] in err and "m.toml" in err


def test_a_work_area_corner_is_refused_with_the_range_it_has(run: Any, tmp_path: Path) -> None:
    """A corner may lie below 0 (a machine homed at its centre): the range says so."""
    machine = tmp_path / "m.toml"
    machine.write_text("[machine]\nwork_area_mm = [-2e6, 0, 100, 100]\n")
    err = _refused(run, tmp_path, "-t", "grbl", "--machine", str(machine))
    assert "work_area_mm must be from -1e+06 to 1e+06 mm (a physical machine)" in err


@pytest.mark.parametrize("edit", sorted(TARGET_EDITS))
def test_a_target_value_a_controller_cannot_take_is_refused(
    run: Any, tmp_path: Path, edit: tuple[str, str]
) -> None:
    old, new = edit
    assert old in GRBL
    target = tmp_path / "mine.toml"
    target.write_text(GRBL.replace(old, new, 1), encoding="utf-8")
    err = _refused(run, tmp_path, "-t", str(target))
    assert TARGET_EDITS[edit] in err and "mine.toml" in err


@pytest.mark.parametrize("what", ["fifo", "device", "bad-utf8", "deep-arrays", "deep-tables"])
def test_a_file_that_is_no_toml_file_is_refused_without_reading_forever(
    run: Any, tmp_path: Path, what: str
) -> None:
    machine = tmp_path / "m.toml"
    if what == "fifo":
        os.mkfifo(machine)  # opening it for reading would wait for a writer
    elif what == "device":
        machine = Path("/dev/zero")  # reading it would fill memory
        if not machine.exists():
            pytest.skip("no /dev/zero")
    elif what == "bad-utf8":
        machine.write_bytes(b"[machine]\nname = '\xff\xfe'\n")
    elif what == "deep-arrays":
        machine.write_text("[machine]\nx = " + "[" * 10_000 + "]" * 10_000 + "\n")
    else:
        machine.write_text("[machine]\nx = " + "{a=" * 5_000 + "1" + "}" * 5_000 + "\n")
    if what == "device":
        code, err = run("post", LOGO, "-t", "grbl", "--machine", str(machine), "-o", "-")
        assert code == 3 and "Traceback" not in err
        return
    _refused(run, tmp_path, "-t", "grbl", "--machine", str(machine))


def test_a_byte_order_mark_is_read_as_utf8(run: Any, tmp_path: Path) -> None:
    target = tmp_path / "bom.toml"
    target.write_bytes(b"\xef\xbb\xbf" + GRBL.encode("utf-8"))
    out = tmp_path / "out.gcode"
    code, err = run("post", LOGO, "-t", str(target), "-o", str(out))
    assert code == 0, err
    assert out.exists()


def test_a_spindle_speed_that_rounds_to_s0_is_refused(run: Any, tmp_path: Path) -> None:
    # GRBL writes S with 3 decimals: 0.0003 rev/min would be "M3 S0", a spindle that does
    # not turn under a tool that cuts. Refused, nothing written; 0.0006 rounds to S0.001,
    # with a warning; 0.6 is written as it is (GRBL reads S as a float: a laser's power).
    out = tmp_path / "out.gcode"
    args = ("post", LOGO, "-t", "grbl", "--depth", "1", "-o", str(out))
    code, err = run(*args, "--spindle-rpm", "0.0003")
    assert code != 0 and "rounds to S0" in err and "--spindle-rpm" in err
    assert "internal error" not in err and not out.exists()
    code, err = run(*args, "--spindle-rpm", "0.0006")
    assert code == 0, err
    assert "M3 S0.001\n" in out.read_text()
    assert "spindle speed 0.0006 rev/min written as S0.001" in err
    code, err = run(*args, "--spindle-rpm", "0.6")
    assert code == 0 and "M3 S0.6\n" in out.read_text() and "written as S" not in err


@pytest.mark.parametrize("lift", ["1e308", "1001"])
def test_an_i8751_lift_beyond_any_z_travel_is_refused(run: Any, tmp_path: Path, lift: str) -> None:
    text = (ROOT / "postprocessors" / "i8751" / "i8751.toml").read_text()
    assert "lift_mm = 1.0" in text
    target = tmp_path / "i.toml"
    target.write_text(text.replace("lift_mm = 1.0", f"lift_mm = {lift} #", 1))
    program = tmp_path / "flat.ngc"  # no Z: the writer lifts around the rapids
    program.write_text("G0 X1 Y1\nG1 X5 Y1 F100\nG0 X1 Y3\nG1 X5 Y3\nM2\n")
    out = tmp_path / "out.bin"
    code, err = run("post", str(program), "-t", str(target), "-o", str(out))
    assert code == 3, err
    assert "lift_mm" in err and "i.toml" in err and "internal error" not in err
    assert not out.exists()


def test_an_i8751_lift_of_more_steps_than_a_record_holds_is_refused(
    run: Any, tmp_path: Path
) -> None:
    # 700 mm at the profile's 100 steps/mm: 70 000 Z steps, more than the 65 535 one
    # move record holds (the lift is one record up, one down; Intf8751 §3.7).
    text = (ROOT / "postprocessors" / "i8751" / "i8751.toml").read_text()
    target = tmp_path / "i.toml"
    target.write_text(text.replace("lift_mm = 1.0", "lift_mm = 700 #", 1))
    program = tmp_path / "flat.ngc"
    program.write_text("G0 X1 Y1\nG1 X5 Y1 F100\nM2\n")
    out = tmp_path / "out.bin"
    code, err = run("post", str(program), "-t", str(target), "-o", str(out))
    assert code != 0 and "70000 Z steps" in err and "65535" in err, err
    assert "internal error" not in err and not out.exists()


def test_a_job_tools_speed_that_rounds_to_s0_is_refused(run: Any, tmp_path: Path) -> None:
    # samples/part.toml with its end mill at 0.0003 rev/min: "M3 S0" before its first cut.
    job = (ROOT / "samples" / "part.toml").read_text()
    assert "rpm = 10000" in job
    path = tmp_path / "slow.toml"
    path.write_text(job.replace("rpm = 10000", "rpm = 0.0003", 1))
    out = tmp_path / "out.gcode"
    code, err = run(
        "post", str(ROOT / "samples" / "part.dxf"), "-t", "grbl", "--job", str(path), "-o", str(out)
    )
    assert code != 0 and "rounds to S0" in err and "the tool's rpm in the job file" in err
    assert "internal error" not in err and not out.exists()


def test_a_word_of_whole_centimetres_is_taken(run: Any, tmp_path: Path) -> None:
    """X, Y, I, J, K in whole cm (scale 0.1, 0 decimals): a 10 mm step, the coarsest allowed."""
    text = GRBL.replace('preamble = ["G21 G90 G94 G17"]', 'preamble = ["G90 G94 G17"]', 1)
    for old, new in (
        ("[dialect_options.words.XYZ]\n", "[dialect_options.words.Z]\n"),
        (
            "[dialect_options.words.IJK]\ndecimals = 3",
            "[dialect_options.words.XYIJK]\ndecimals = 0",
        ),
    ):
        assert old in text
        text = text.replace(old, new, 1)
    target = tmp_path / "cm.toml"
    target.write_text(text.replace("decimals = 0", "decimals = 0\nscale = 0.1", 1))
    out = tmp_path / "out.gcode"
    code, err = run("post", LOGO, "-t", str(target), "--origin", "lower-left", "-o", str(out))
    assert code == 0, err
    assert "cm writes X and Y to 10 mm: positions written up to" in err


def test_arc_centres_finer_than_the_ends_are_written(run: Any, tmp_path: Path) -> None:
    """Centres at 0.1 µm, ends at 1 µm: each centre on the ends' grid prints exactly."""
    old = "[dialect_options.words.IJK]\ndecimals = 3"
    target = tmp_path / "fine.toml"
    target.write_text(GRBL.replace(old, "[dialect_options.words.IJK]\ndecimals = 4", 1))
    out = tmp_path / "out.gcode"
    code, err = run("post", LOGO, "-t", str(target), "--origin", "lower-left", "-o", str(out))
    assert code == 0, err
    arcs = re.findall(r"^G[23] .* I-?\d+\.(\d+) J-?\d+\.(\d+)$", out.read_text(), re.M)
    assert arcs and all(len(i) == len(j) == 4 for i, j in arcs)
