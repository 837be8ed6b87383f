"""`camtool verify` and `post --verify` as a user runs them: exit codes, report, preview."""

from __future__ import annotations

import json
import math
from pathlib import Path

import ezdxf
import pytest

from camtool.cli.main import main

SAMPLES = Path(__file__).parents[2] / "samples"
LOGO = str(SAMPLES / "logo.dxf")
DESIGN_KEYS = {
    "target",
    "blocks",
    "steps",
    "iterations",
    "reversals",
    "compensations",
    "deviation_um",
    "closure_um",
    "size_error_um",
    "time_s",
    "warnings",
}  # docs/verify.md, "the keys are stable"


def run(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    code = main(args)
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture
def logo_pic(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> Path:
    dest = tmp_path / "logo.pic"
    assert run(["post", LOGO, "-t", "pic-mmh", "-o", str(dest)], capsys)[0] == 0
    return dest


def test_verify_writes_a_report_with_the_design_keys(
    logo_pic: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    report = tmp_path / "r.json"
    code, out, err = run(
        ["verify", str(logo_pic), "-t", "pic-mmh", "--report", str(report)], capsys
    )
    assert code == 0 and out == ""
    data = json.loads(report.read_text())
    assert set(data) >= DESIGN_KEYS
    assert set(data["steps"]) == {"x", "y", "z"} and set(data["reversals"]) == {"x", "y"}
    assert {"max", "rms"} <= set(data["deviation_um"])
    motion = [ln for ln in logo_pic.read_text().splitlines() if ln.startswith("G0")]
    assert data["blocks"] == len(motion) and data["target"] == "pic-mmh"
    # the worst error is the X over-compensation in region H1: 204 - 190 = 14 µm
    # (UNAM-GMM §5.2: final compensation 204 µm; Tabla 13: H1 true backlash 190 µm),
    # at most combined with the Y under-compensation in V2 (180 - 178 = 2 µm) still held
    # from the last Y reversal, plus 0.2 µm of step quantisation (140 nm steps)
    assert 204 - 190 - 0.2 <= data["deviation_um"]["max"] <= math.hypot(14, 2) + 0.2
    # the worst point names the program line it is on
    at = data["deviation_um"]["at"]
    line = logo_pic.read_text().splitlines()[at["line"] - 1]
    assert line.startswith("G0")
    assert "deviation from the path: max" in err and "estimated time" in err


def test_report_to_stdout(logo_pic: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(["verify", str(logo_pic), "-t", "pic-mmh", "--report", "-"], capsys)
    assert code == 0 and json.loads(out)["target"] == "pic-mmh"


def test_over_the_limit_exits_4_after_writing_the_report(
    logo_pic: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    report = tmp_path / "r.json"
    args = ["verify", str(logo_pic), "-t", "pic-mmh", "--report", str(report)]
    code, _, err = run([*args, "--max-error-um", "1"], capsys)
    assert code == 4 and "exceeds --max-error-um 1" in err
    assert json.loads(report.read_text())["deviation_um"]["max"] > 1
    assert run([*args, "--max-error-um", "1000"], capsys)[0] == 0


def test_against_the_drawing(logo_pic: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(
        ["verify", str(logo_pic), "-t", "pic-mmh", "--against", LOGO, "--report", "-"], capsys
    )
    against = json.loads(out)["against"]
    assert code == 0 and against["samples"] > 100
    # a scribed path (no offset) lies on the drawing up to the backlash residuals (<= 20 µm)
    assert 0 < against["max_um"] < 20.0


def test_the_drawing_compared_says_its_warnings(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """--against reads a drawing: what reading it warned of (here: no units, mm assumed)
    is said, as post says it, since the comparison is measured in those units."""
    drawing = tmp_path / "plate.dxf"
    doc = ezdxf.new("R2000")
    doc.header["$INSUNITS"] = 0
    doc.modelspace().add_lwpolyline([(0, 0), (2, 0), (2, 1.5), (0, 1.5)], close=True)
    doc.saveas(drawing)
    program = tmp_path / "plate.nc"
    assert run(["post", str(drawing), "-t", "grbl", "-o", str(program)], capsys)[0] == 0
    code, _, err = run(["verify", str(program), "-t", "grbl", "--against", str(drawing)], capsys)
    assert code == 0 and err.count("--against: ") >= 1 and "assuming mm" in err


def test_post_verify_matches_verify(
    logo_pic: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    a, b = tmp_path / "a.json", tmp_path / "b.json"
    assert run(["post", LOGO, "-t", "pic-mmh", "-o", "-", "--report", str(a)], capsys)[0] == 0
    assert run(["verify", str(logo_pic), "-t", "pic-mmh", "--report", str(b)], capsys)[0] == 0
    ra, rb = json.loads(a.read_text()), json.loads(b.read_text())
    assert ra["deviation_um"]["max"] == rb["deviation_um"]["max"]
    assert ra["against"] is not None and rb["against"] is None


def test_machine_override_changes_the_prediction(
    logo_pic: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Compensation equal to a uniform true backlash: only interpolation error remains."""
    exact = tmp_path / "exact.toml"
    exact.write_text(
        "[machine.backlash]\n"
        "true_um = [204, 178, 0]\ncompensation_um = [204, 178, 0]\nregions = []\n"
    )
    code, out, _ = run(
        ["verify", str(logo_pic), "-t", "pic-mmh", "--machine", str(exact), "--report", "-"],
        capsys,
    )
    assert code == 0
    assert json.loads(out)["deviation_um"]["max"] < 0.5  # under 4 steps of 140 nm


@pytest.mark.parametrize("suffix", [".png", ".svg"])
def test_preview_files(
    logo_pic: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], suffix: str
) -> None:
    first, second = tmp_path / f"a{suffix}", tmp_path / f"b{suffix}"
    for dest in (first, second):
        assert (
            run(["verify", str(logo_pic), "-t", "pic-mmh", "--preview", str(dest)], capsys)[0] == 0
        )
    assert first.read_bytes() == second.read_bytes()  # deterministic, CI can diff
    if suffix == ".svg":
        text = first.read_text()
        assert "deviation from the path" in text
        assert "max 14." in text  # the 204 - 190 µm over-compensation, annotated


@pytest.mark.parametrize(
    ("args", "exit_code", "message"),
    [
        (["verify", "missing.pic", "-t", "pic-mmh"], 3, "missing.pic: no such file"),
        (["verify", "{pic}", "-t", "nope"], 2, "unknown target 'nope'"),
        (["verify", "{bad}", "-t", "pic-mmh"], 3, ":3: not a pic-mmh block"),
        (
            ["verify", "{pic}", "-t", "pic-mmh", "--preview", "x.gif"],
            2,
            "a preview is .png or .svg",
        ),
        (["verify", "{pic}", "-t", "pic-mmh", "--machine", "nope"], 3, "unknown machine profile"),
        (["verify", "{pic}", "-t", "pic-mmh", "--max-error-um", "-1"], 2, "-1"),
    ],
)
def test_exit_codes(
    args: list[str],
    exit_code: int,
    message: str,
    logo_pic: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    bad = tmp_path / "bad.pic"
    bad.write_text("G54;\nG90;\nG01X1Y1;\n")
    args = [a.format(pic=logo_pic, bad=bad) for a in args]
    code, out, err = run(args, capsys)
    assert code == exit_code and out == ""
    assert message in err
    assert "Traceback" not in err


def _squares(count: int) -> str:
    """A GRBL program cutting ``count`` separate 1 mm squares, each its own contour."""
    out = ["G21 G90 G94 G17", "G0 Z5"]
    for k in range(count):
        x = 3.0 * k
        out += [f"G0 X{x:.3f} Y0", "G1 Z-0.5 F100"]
        out += [f"G1 X{x + 1:.3f} Y0", f"G1 X{x + 1:.3f} Y1", f"G1 X{x:.3f} Y1", f"G1 X{x:.3f} Y0"]
        out += ["G0 Z5"]
    return "\n".join([*out, "M2"]) + "\n"


@pytest.mark.parametrize(("count", "more"), [(10, None), (12, 2)])
def test_summary_counts_the_contours_it_leaves_out(
    count: int, more: int | None, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The stderr summary lists 10 contours; the rest are counted, and "0 more" is never said."""
    program = tmp_path / "squares.gcode"
    program.write_text(_squares(count))
    code, _, err = run(["verify", str(program), "-t", "grbl"], capsys)
    assert code == 0
    listed = [line for line in err.splitlines() if line.startswith("camtool:   contour ")]
    tail = [line for line in err.splitlines() if "more contours in the report" in line]
    assert len(listed) == min(count, 10)
    if more is None:
        assert tail == []
    else:
        assert tail == [f"camtool:   ... {more} more contours in the report"]


def test_a_program_too_large_for_the_machine_is_named_by_its_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The placement refusal starts with the file, as a reader's error does (``FILE:LINE:``)."""
    far = tmp_path / "far.ngc"
    far.write_text("G21 G90\nG0 X0 Y0\nG1 X5000 Y0 F100\nM2\n")  # GRBL's default travel: 200 mm
    code, _, err = run(["verify", str(far), "-t", "grbl"], capsys)
    assert code == 1
    assert f"camtool: error: {far}: the toolpath is 5000 × 0 mm, larger than the 200" in err


def test_a_move_outside_a_machine_coordinate_work_area_is_named_by_file_and_line() -> None:
    """On a machine-coordinate machine each move is checked, named by its file and line."""
    from camtool.model.errors import DialectError
    from camtool.post.registry import load_target
    from camtool.verify.report import check_area

    machine = load_target("matlab-router").machine  # machine coordinates, 0…200 mm
    assert machine.coordinates == "machine"
    program = load_target("linuxcnc").post.parse(
        "G21 G90\nG0 X10 Y10\nG1 X-5 Y10 F100\nG1 X10 Y10\nM2\n", source="cut.ngc"
    )
    with pytest.raises(DialectError, match=r"^cut\.ngc: line 3: reaches X -5\.0000…10\.0000, Y 10"):
        check_area(program, machine, "cut.ngc")
    with pytest.raises(DialectError, match=r"^line 3: reaches X -5\.0000…10"):
        check_area(program, machine)
    # larger than the travel: refused before any move is looked at, named by the file too
    big = load_target("linuxcnc").post.parse(
        "G21 G90\nG0 X10 Y10\nG1 X250 Y10 F100\nM2\n", source="big.ngc"
    )
    with pytest.raises(DialectError, match=r"^big\.ngc: the toolpath is 240 × 0 mm, larger than"):
        check_area(big, machine, "big.ngc")


def test_verify_reads_a_comment_in_utf8_as_post_does(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Universal G-code Sender's test_files/ruler.gcode has UTF-8 in a comment."""
    program = tmp_path / "ruler.gcode"
    program.write_text(
        "G21 G90\n(Lin\u00e9al \u2013 \u00c5\u00c4\u00d6)\nG0 X1 Y1\nG1 X5 Y1 F300\nM2\n"
    )
    code, _, err = run(["verify", str(program), "-t", "grbl"], capsys)
    assert code == 0, err
    program.write_bytes(b"G21 G90\n(\xff)\nG0 X1 Y1\nM2\n")
    code, _, err = run(["verify", str(program), "-t", "grbl"], capsys)
    assert code == 3
    assert "ruler.gcode: not a text program (byte 9 is not UTF-8)" in err


def test_verify_and_send_read_a_program_saved_as_utf16_as_post_does(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Notepad's "Unicode" is UTF-16 LE with a byte-order mark: the same program as in UTF-8."""
    text = "G21 G90\r\n(pi\u00e8ce)\r\nG0 X1 Y1\r\nG1 X5 Y1 F300\r\nM2\r\n"
    plain, wide = tmp_path / "plain.nc", tmp_path / "wide.nc"
    plain.write_text(text, encoding="utf-8")
    wide.write_bytes(text.encode("utf-16"))
    outputs = []
    for program in (plain, wide):
        code, out, err = run(["verify", str(program), "-t", "grbl", "--no-budget"], capsys)
        assert code == 0, err
        outputs.append(out)
        code, _, err = run(["send", str(program), "-t", "grbl", "--dry-run"], capsys)
        assert code == 0, err
    assert outputs[0].replace("plain.nc", "") == outputs[1].replace("wide.nc", "")
