"""Every numeric option refuses NaN, ±inf and absurd magnitudes, naming the option (issue 14)."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from camtool.cli.main import main
from camtool.model.errors import UsageError
from camtool.model.units import fmt_num, fmt_point
from camtool.toolpath.options import MAX_PASSES, PlanOptions

SAMPLES = Path(__file__).resolve().parents[2] / "samples"
TABS = ["--tabs", "2", "--depth", "3", "--offset", "outside", "--tool-diameter", "3"]


@pytest.mark.parametrize(
    ("args", "flag"),
    [
        (["--tab-height", "nan", *TABS], "--tab-height"),
        (["--tab-width", "nan", *TABS], "--tab-width"),
        (["--lead-in", "nan"], "--lead-in"),
        (["--close-gap", "nan"], "--close-gap"),
        (["--fit", "inf", "inf"], "--fit"),
        (["--scale", "inf"], "--scale"),
        (["--tool-diameter", "-inf"], "--tool-diameter"),
        (["--feed", "nan"], "--feed"),
        (["--spindle-rpm", "inf"], "--spindle-rpm"),
        (["--translate", "nan", "0"], "--translate"),
        (["--tolerance", "1_0"], "--tolerance"),
        # Python's float and int read the digits of every script: --fit ١٠٠ 50 was 100 × 50,
        # --depth １ (full-width) 1 mm, --tabs 1_0 ten tabs
        (["--fit", "\u0661\u0660\u0660", "50"], "--fit"),
        (["--depth", "\uff11"], "--depth"),
        (["--tabs", "1_0", *TABS[2:]], "--tabs"),
        (["--tabs", "\u0662", *TABS[2:]], "--tabs"),
        (["--max-entities", "1_000"], "--max-entities"),
    ],
)
def test_non_finite_option_is_a_usage_error_naming_it(
    args: list[str], flag: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "p.gcode"
    code = main(["post", str(SAMPLES / "plate.dxf"), "-t", "grbl", "-o", str(out), *args])
    err = capsys.readouterr().err
    assert code == 2, err
    assert flag in err
    assert not out.exists()


@pytest.mark.parametrize(
    ("args", "said"),
    [
        # not: linuxcnc wrote M3 S1000000000000000000000000000000 (exit 0), pic-mmh stopped
        # with an internal InvalidOperation, grbl a 300-digit block in its message
        (["--spindle-rpm", "1e30"], "--spindle-rpm must be ≥ 0 and ≤ 1e+06 rev/min, got 1e+30"),
        (["--spindle-dwell", "1e300"], "--spindle-dwell must be ≥ 0 and ≤ 3600 s, got 1e+300"),
    ],
)
@pytest.mark.parametrize("target", ["linuxcnc", "pic-mmh", "grbl"])
def test_absurd_spindle_options_are_refused_before_planning(
    args: list[str], said: str, target: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "p.nc"
    code = main(["post", str(SAMPLES / "plate.dxf"), "-t", target, "-o", str(out), *args])
    err = capsys.readouterr().err
    assert code == 2, err
    assert err == f"camtool: error: {said}\n"
    assert not out.exists()


def test_a_spindle_speed_up_to_the_limit_is_written_as_given(tmp_path: Path) -> None:
    out = tmp_path / "p.ngc"
    args = ["post", str(SAMPLES / "plate.dxf"), "-t", "linuxcnc", "-o", str(out)]
    assert main([*args, "--spindle-rpm", "1000000"]) == 0
    assert "M3 S1000000" in out.read_text().splitlines()


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("tab_height", math.nan),
        ("lead_in", math.nan),
        ("close_gap", math.nan),
        ("safe_z", math.inf),
        ("tolerance", math.nan),
        ("stepover", math.nan),
        ("ramp_deg", math.nan),
    ],
)
def test_plan_options_refuse_non_finite(field: str, value: float) -> None:
    extra = {"depth": 3.0} if field == "ramp_deg" else {}
    with pytest.raises(UsageError, match="finite"):
        PlanOptions(feed_mm_min=100.0, **extra, **{field: value})


def test_fit_with_infinite_box_is_refused() -> None:
    with pytest.raises(UsageError, match="--fit"):
        PlanOptions(feed_mm_min=100.0, fit=(math.inf, math.inf))


def test_pass_count_is_bounded() -> None:
    # 3 mm at 1 nm per pass would be 3e9 passes; the limit is MAX_PASSES
    with pytest.raises(UsageError, match="--step-down"):
        PlanOptions(feed_mm_min=100.0, depth=3.0, step_down=1e-9)
    PlanOptions(feed_mm_min=100.0, depth=3.0, step_down=3.0 / MAX_PASSES)
    with pytest.raises(UsageError, match="makes 45000 passes, more than the limit") as small:
        PlanOptions(feed_mm_min=100.0, depth=45.0, step_down=0.001)
    assert "--depth 45 with --step-down 0.001 mm" in str(small.value)
    # a step of 1e-300 mm: the count in a few digits, not 300 of them
    with pytest.raises(UsageError, match=r"makes 3e\+300 passes, more than the limit"):
        PlanOptions(feed_mm_min=100.0, depth=3.0, step_down=1e-300)


def test_clearance_below_safe_z_is_refused() -> None:
    with pytest.raises(UsageError, match="--clearance-z"):
        PlanOptions(feed_mm_min=100.0, safe_z=3.0, clearance_z=2.0)
    assert PlanOptions(feed_mm_min=100.0, safe_z=2.0).clearance == 5.0
    assert PlanOptions(feed_mm_min=100.0, safe_z=8.0).clearance == 8.0


@pytest.mark.parametrize(
    ("value", "text"), [(-0.0, "0.0000"), (-1e-7, "0.0000"), (-0.5, "-0.5000"), (2.25, "2.2500")]
)
def test_fmt_num_never_negative_zero(value: float, text: str) -> None:
    assert fmt_num(value) == text


def test_fmt_point() -> None:
    assert fmt_point((-0.0, 1.5), 2) == "(0.00, 1.50)"


def test_help_shows_no_empty_range(capsys) -> None:
    # a number option without bounds printed "[x<=None]" (click's range text for no bounds)
    assert main(["post", "--help"]) == 0
    out = capsys.readouterr().out
    assert "None]" not in out and "x<=None" not in out
    assert "x>=0" in out  # a bounded option still shows its range


@pytest.mark.parametrize("command", ["post", "verify"])
def test_a_negative_tool_diameter_is_refused_naming_the_option_before_any_reading(
    command: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # verify used to read the code first and then say "tool diameter must be >= 0 mm"
    # without the option (a code with an O-word was refused for that instead)
    code = tmp_path / "p.ngc"
    code.write_text("O100 sub\nG1 X1 F100\nM2\n")  # an O-word: refused if it were read
    source = str(SAMPLES / "plate.dxf") if command == "post" else str(code)
    out = ["-o", str(tmp_path / "p.gcode")] if command == "post" else []
    assert main([command, source, "-t", "grbl", "--tool-diameter", "-1", *out]) == 2
    err = capsys.readouterr().err
    assert "--tool-diameter" in err and "-1" in err
    assert "O100" not in err and "O-word" not in err


@pytest.mark.parametrize("value", ["10", "1.5"])
def test_a_tolerance_past_a_millimetre_is_refused_as_a_slip(
    value: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # --tolerance 10 would let every fitted arc and line lie 10 mm from the drawing (a
    # pocket's rounded ring corners cut square): 10 for 0.010, a slip. 1 mm is the most a
    # toolpath may stray, for post, a re-post and a job's [job] tolerance alike
    out = tmp_path / "p.gcode"
    code = main(
        ["post", str(SAMPLES / "plate.dxf"), "-t", "grbl", "-o", str(out), "--tolerance", value]
    )
    err = capsys.readouterr().err
    assert code == 2, err
    assert "--tolerance must be at most 1 mm" in err and f"got {float(value)!r}" in err
    assert not out.exists()
    job = tmp_path / "j.toml"
    job.write_text(
        (SAMPLES / "part.toml").read_text().replace("[job]", f"[job]\ntolerance = {value}")
    )
    code = main(
        ["post", str(SAMPLES / "part.dxf"), "-t", "grbl", "-o", str(out), "--job", str(job)]
    )
    assert code == 3
    assert "[job]: tolerance must be at most 1 mm" in capsys.readouterr().err
    assert not out.exists() and not list(tmp_path.glob("p*"))
    code = main(
        ["post", str(SAMPLES / "plate.dxf"), "-t", "grbl", "-o", str(out), "--tolerance", "1"]
    )
    assert code == 0, capsys.readouterr().err


@pytest.mark.parametrize(
    "command",
    [
        # not: preview stopped with an internal GEOSException (a sweep 1e300 mm wide), verify
        # printed a numpy overflow warning and distances of 300 digits with exit 0
        ["preview", "-o", "p.png"],
        ["verify"],
    ],
)
def test_a_tool_wider_than_any_cutter_is_refused_by_verify_and_preview(
    command: list[str], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    program = tmp_path / "p.nc"
    assert main(["post", str(SAMPLES / "plate.dxf"), "-t", "grbl", "-o", str(program)]) == 0
    capsys.readouterr()
    args = [command[0], str(program), "-t", "grbl", *command[1:], "--tool-diameter", "1e300"]
    code = main([a if a != "p.png" else str(tmp_path / a) for a in args])
    err = capsys.readouterr().err
    assert code == 2, err
    assert "--tool-diameter" in err and "1000" in err
    assert not (tmp_path / "p.png").exists()


@pytest.mark.parametrize(
    ("diameter", "said"),
    [
        # not: "Tool.diameter must be ≥ 0 and ≤ 1000 mm, got 100000.0" (the job's field)
        ("1e5", "--tool-diameter 100000 mm is more than 1000 mm"),
        # a half-diameter of 5e-301 mm is lost in the offset's float arithmetic: the
        # plate's outline was called "narrower than the tool" and left out, with exit 0
        ("1e-300", "--tool-diameter 1e-300 mm is less than 0.001 mm"),
    ],
)
def test_post_refuses_a_tool_no_cutter_has_naming_the_option(
    diameter: str, said: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "p.nc"
    args = ["--tool-diameter", diameter, "--offset", "outside"]
    assert main(["post", str(SAMPLES / "plate.dxf"), "-t", "grbl", "-o", str(out), *args]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"camtool: error: {said}")
    assert not out.exists()


@pytest.mark.parametrize(
    ("field", "value", "said"),
    [
        ("depth", 1e300, "--depth 1e+300 is beyond ±1e+06 mm: no machine"),
        ("scale", 1e300, "--scale 1e+300 is beyond ±1e+06: no machine"),
        ("tabs", 10**9, "--tabs 1e+09 is beyond ±1e+06: no machine"),  # a count, not mm
    ],
)
def test_an_absurd_magnitude_is_refused_in_the_option_s_unit(
    field: str, value: float, said: str
) -> None:
    with pytest.raises(UsageError) as caught:
        PlanOptions(feed_mm_min=100.0, **{field: value})
    assert str(caught.value).startswith(said)
