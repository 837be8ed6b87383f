"""The CLI as a user runs it: exit codes, stdout/stderr separation, files."""

from __future__ import annotations

import os
import re
import shlex
import stat
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from camtool.cli.main import main
from tests.shapes import golden_arc_dxf, rectangle_dxf, write_dxf

SAMPLES = Path(__file__).parents[2] / "samples"


def run(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    code = main(args)
    out, err = capsys.readouterr()
    return code, out, err


def test_post_to_stdout_carries_only_code(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _err = run(["post", str(SAMPLES / "logo.dxf"), "--target", "pic-mmh"], capsys)
    assert code == 0
    assert out.startswith("G54;\nG90;\n") and out.endswith("M30;\n")
    assert "camtool" not in out


def test_post_to_file_says_where(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    dest = tmp_path / "logo.pic"
    code, out, err = run(
        ["post", str(SAMPLES / "logo.dxf"), "-t", "pic-mmh", "-o", str(dest)], capsys
    )
    assert code == 0 and out == ""
    assert str(dest) in err
    assert dest.read_text().startswith("G54;")


def test_feed_option(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = golden_arc_dxf(tmp_path / "g.dxf")
    code, out, _ = run(["post", str(path), "-t", "pic-mmh", "--feed", "0.8"], capsys)
    assert code == 0 and "G02X02969.00Y03400.00I03012.00J03040.00F08;" in out


@pytest.mark.parametrize(
    ("make", "args", "exit_code", "message"),
    [
        (None, [], 3, "no such file"),
        ("text", [], 3, "not a readable DXF"),
        ("empty", [], 3, "no usable entity"),
        ("rect", ["--target", "nope"], 2, "unknown target 'nope'; choose one of: "),
        ("big", [], 1, "larger than the 10 × 7 mm travel"),
        ("rect", ["--feed", "20"], 1, "outside F01–F99"),
        ("rect", ["--offset", "outside"], 2, "needs --tool-diameter"),
        ("rect", ["--offset", "sideways"], 2, "Invalid value for '--offset'"),
    ],
)
def test_exit_code_matrix(
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    make: str | None,
    args: list[str],
    exit_code: int,
    message: str,
) -> None:
    path = tmp_path / "in.dxf"
    if make == "text":
        path.write_text("hello\n")
    elif make == "empty":
        write_dxf(path, lambda msp: msp.add_text("x"))
    elif make == "rect":
        rectangle_dxf(path, 2, 1)
    elif make == "big":
        rectangle_dxf(path, 20, 1)
    dest = tmp_path / "out.pic"
    argv = [
        "post",
        str(path),
        "-o",
        str(dest),
        *(args if "--target" in args else ["--target", "pic-mmh", *args]),
    ]
    code, out, err = run(argv, capsys)
    assert code == exit_code
    assert message in err
    assert "Traceback" not in err and out == ""
    assert not dest.exists()  # nothing half-written
    assert list(tmp_path.glob(".out.pic.*")) == []


def test_failed_run_keeps_the_previous_output(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    dest = tmp_path / "out.pic"
    dest.write_text("previous\n")
    code, _, _ = run(
        ["post", str(rectangle_dxf(tmp_path / "b.dxf", 20, 1)), "-t", "pic-mmh", "-o", str(dest)],
        capsys,
    )
    assert code == 1 and dest.read_text() == "previous\n"


def test_drawing_from_stdin(tmp_path: Path) -> None:
    data = golden_arc_dxf(tmp_path / "g.dxf").read_bytes()
    proc = subprocess.run(
        [sys.executable, "-m", "camtool", "post", "-", "-t", "pic-mmh"],
        input=data,
        capture_output=True,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr
    assert b"G02X02969.00Y03400.00I03012.00J03040.00F08;" in proc.stdout


def test_garbage_on_stdin_is_named(capsys: pytest.CaptureFixture[str]) -> None:
    proc = subprocess.run(
        [sys.executable, "-m", "camtool", "post", "-", "-t", "pic-mmh"],
        input=b"not a drawing",
        capture_output=True,
        check=False,
    )
    assert proc.returncode == 3
    assert b"<stdin>: cannot tell what it holds" in proc.stderr and b"Traceback" not in proc.stderr


def test_fit_brings_a_large_drawing_into_the_work_area(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    big = str(rectangle_dxf(tmp_path / "big.dxf", 20, 1))
    assert run(["post", big, "-t", "pic-mmh"], capsys)[0] == 1
    code, out, _ = run(["post", big, "-t", "pic-mmh", "--fit", "8", "5"], capsys)
    assert code == 0 and "G01X09000.00Y01000.00F08;" in out  # 1 + 8 mm


def test_help_explains_units(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(["post", "--help"], capsys)
    assert code == 0
    for text in (
        "--tool-diameter MM",
        "--feed MM_PER_MIN",
        "--tolerance MM",
        "mm/min",
        "--fit W H",
        "--scale K",
    ):
        assert text in out


def test_targets_json(capsys: pytest.CaptureFixture[str]) -> None:
    import json

    code, out, _ = run(["targets", "--json"], capsys)
    assert code == 0
    assert {"pic-mmh"} <= {t["name"] for t in json.loads(out)}


def test_console_script_runs_as_a_process(tmp_path: Path) -> None:
    proc = subprocess.run(
        [sys.executable, "-m", "camtool", "post", str(tmp_path / "missing.dxf"), "-t", "pic-mmh"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert proc.returncode == 3
    assert proc.stdout == "" and "no such file" in proc.stderr and "Traceback" not in proc.stderr


def test_version_does_not_load_opencascade() -> None:
    code = (
        "import sys; from camtool.cli.main import main; main(['--version']); "
        "main(['targets']); print('build123d' in sys.modules, 'OCP' in sys.modules)"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert proc.stdout.strip().endswith("False False")


def test_a_re_post_without_a_picture_loads_no_numpy(tmp_path: Path) -> None:
    """A re-post of straight moves needs neither numpy nor the preview (issue 17's start-up):
    the picture's child and its imports come only with a PNG ``--preview``."""
    program = tmp_path / "lines.ngc"
    program.write_text("G21 G90\nG0 X0 Y0\nG1 X10 Y0 F100\nG1 X10 Y10\nM2\n")
    code = (
        "import sys; from camtool.cli.main import cli\n"
        "try:\n"
        f"    cli.main(['post', {str(program)!r}, '-t', 'linuxcnc', '-o', "
        f"{str(tmp_path / 'out.ngc')!r}], standalone_mode=False)\n"
        "finally:\n"
        "    print('numpy' in sys.modules, 'camtool.preview' in sys.modules)"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert proc.stdout.strip() == "False False"
    assert "G1 X10.000 Y10.000" in (tmp_path / "out.ngc").read_text()


BIG_MACHINE = """
[machine]
name = "MMH on a big table"
steps_per_mm = [7142.857, 7142.857, 7142.857]
work_area_mm = [0.0, 0.0, 200.0, 200.0]
has_z = false
"""


def test_value_over_its_field_names_contour_and_block(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # 151 mm = 151000.00 µm needs 6 integer digits; the pic-mmh field has 5 (S000-07).
    machine = tmp_path / "big.toml"
    machine.write_text(BIG_MACHINE)
    drawing = str(rectangle_dxf(tmp_path / "r.dxf", 150, 1))
    dest = tmp_path / "out.pic"
    code, out, err = run(
        ["post", drawing, "-t", "pic-mmh", "--machine", str(machine), "-o", str(dest)], capsys
    )
    assert code == 1 and out == "" and not dest.exists()
    assert "contour 1, block 4: X = 151000.00 does not fit 5 integer digits" in err


@pytest.mark.parametrize(
    ("width", "origin", "advice"),
    [
        (150, "lower-left", "put work zero at its centre with --origin center"),
        (190, "drawing", "put work zero at its centre with --origin center"),
        (250, "lower-left", "scale it down (--fit W H or --scale) or cut it in parts"),
        (250, "center", "scale it down (--fit W H or --scale) or cut it in parts"),
    ],
)
def test_a_part_wider_than_its_word_is_told_what_fits(
    width: int, origin: str, advice: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A table larger than pic-mmh's numbers: ``--origin lower-left`` is not the advice.

    5 integer digits of µm hold ±99.99999 mm from work zero. A part up to 200 mm wide
    fits them from its centre (and is posted so); a wider one fits no work zero.
    """
    machine = tmp_path / "big.toml"
    machine.write_text(BIG_MACHINE.replace("200.0, 200.0", "600.0, 600.0"))
    drawing = str(rectangle_dxf(tmp_path / "r.dxf", width, 1))
    dest = tmp_path / "out.pic"
    args = ["post", drawing, "-t", "pic-mmh", "--machine", str(machine), "-o", str(dest)]
    code, out, err = run([*args, "--origin", origin], capsys)
    assert code == 1 and out == "" and not dest.exists()
    assert "does not fit 5 integer digits" in err and advice in err
    assert "--origin lower-left" not in err
    if width < 200:
        code, _, err = run([*args, "--origin", "center"], capsys)
        assert code == 0, err
        xs = [float(x) for x in re.findall(r"X(-?\d+\.\d+)", dest.read_text())]
        assert max(abs(x) for x in xs) <= 99999.99
        assert max(xs) - min(xs) >= width * 1000.0


def test_machine_file_with_an_unknown_key(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    machine = tmp_path / "bad.toml"
    machine.write_text(BIG_MACHINE + "backlash_typo = 3\n")
    drawing = str(rectangle_dxf(tmp_path / "r.dxf", 2, 1))
    code, _, err = run(["post", drawing, "-t", "pic-mmh", "--machine", str(machine)], capsys)
    assert code == 3 and "unknown key(s) ['backlash_typo'] in [machine]" in err


DATA = Path(__file__).parents[1] / "data"


def test_post_existing_gcode_reposts_it(capsys: pytest.CaptureFixture[str]) -> None:
    """Yanez-07 §3.3: the FlashCut examples, re-posted for pic-mmh (I/J become absolute)."""
    code, out, err = run(["post", str(DATA / "flashcut-seed001.nc"), "-t", "pic-mmh"], capsys)
    assert code == 0
    assert "G02X03000.00Y03000.00I02000.00J02000.00F30;" in out.splitlines()
    assert "no G20/G21" in err


def test_a_freecad_program_without_f_reposts_with_feed_and_no_guessed_move(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The opening of FreeCAD 0.20's LinuxCNC post (PathTests/test_linuxcnc_00.ngc).

    Its tool controller has no feed, so no F word: ``--feed`` gives it. Its ``G0 Z15.00``
    comes twice before the first XY: the program must not gain a rapid to X0 Y0.
    """
    ngc = tmp_path / "freecad.ngc"
    ngc.write_text(
        "G17 G90\nG21\n(Default_Tool)\nM6 T2\nM3 S0.00\n(Contour)\nG0 Z15.00\nG90\nG17\n"
        "G0 Z15.00\nG0 X10.00 Y10.00\nG0 Z10.00\nG1 X10.00 Y10.00 Z9.00\n"
        "G1 X10.00 Y0.00 Z9.00\nG1 X0.00 Y0.00 Z9.00\nG0 Z15.00\nM2\n"
    )
    code, out, err = run(["post", str(ngc), "-t", "linuxcnc"], capsys)
    assert code == 3 and out == "" and "--feed" in err
    code, out, err = run(["post", str(ngc), "-t", "linuxcnc", "--feed", "300"], capsys)
    assert code == 0, err
    blocks = out.splitlines()
    first_xy = next(k for k, b in enumerate(blocks) if "X" in b and not b.startswith("("))
    assert blocks[first_xy] == "G0 X10.000 Y10.000"
    assert "G1 Z9.000 F300" in blocks


def test_a_relative_program_is_not_reposted_from_a_guessed_start(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A GRBL user's hand-written square in G91: it runs from wherever the tool stands.

    Written again in absolute words it would first rapid to the work zero, at whatever
    height the tool is: refused, naming the line, with the one-line remedy; nothing is
    written. With the start given, the same square posts.
    """
    square = "G21 G91\nG1 X10 F300\nY10\nX-10\nY-10\nM2\n"
    ngc = tmp_path / "square.ngc"
    ngc.write_text(square)
    out_file = tmp_path / "square.gcode"
    code, out, err = run(["post", str(ngc), "-t", "grbl", "-o", str(out_file)], capsys)
    assert code == 3 and out == "" and not out_file.exists()
    assert "square.ngc:2: incremental X10 (G91) before the program gives" in err
    assert "G90 G0 X0 Y0" in err and "Traceback" not in err
    ngc.write_text("G21 G90 G0 X0 Y0\n" + square)
    code, out, err = run(["post", str(ngc), "-t", "grbl", "-o", str(out_file)], capsys)
    assert code == 0, err
    blocks = out_file.read_text().splitlines()
    assert [b for b in blocks if b.startswith("G1")] == [
        "G1 X10.000 Y0.000 F300",
        "G1 X10.000 Y10.000",
        "G1 X0.000 Y10.000",
        "G1 X0.000 Y0.000",
    ]


def test_gcode_with_z_on_a_2d_target_drops_z_with_a_warning(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    ngc = tmp_path / "part.ngc"
    ngc.write_text("G21\nG0 Z5\nG0 X1 Y1\nG1 Z-1 F0.5\nG1 X3 Y1 F0.8\nG2 X3 Y3 I0 J1\nG0 Z5\nM2\n")
    code, out, err = run(["post", str(ngc), "-t", "pic-mmh"], capsys)
    assert code == 0
    assert "Z" not in out.replace("G", "")
    assert "3 Z-only move(s) dropped" in err and "2 Z level(s)" in err


@pytest.mark.parametrize("bed_zero", [False, True])
def test_a_cut_above_the_stock_is_travel_on_a_2d_target(
    bed_zero: bool, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # a program that lifts with G1 and crosses to its next cut at the feed, 1 mm above the
    # stock: with Z dropped, the crossing X1 Y0 -> X2 Y1 was a cut through the part. It is
    # travel (a rapid: a job boundary on the router, a G00 on the scriber); the two cuts
    # stay cuts. A program whose cuts are all above 0 (its zero on the bed) is left as it is
    lift = 10 if bed_zero else 0
    ngc = tmp_path / "lift.ngc"
    ngc.write_text(
        f"G21 G90\nG0 X0 Y0 Z{2 + lift}\nG1 Z{-1 + lift} F100\nG1 X1\nG1 Z{1 + lift}\n"
        f"G1 X2 Y1\nG1 Z{-1 + lift}\nG1 X3\nG0 Z{5 + lift}\nM2\n"
    )
    out_file = tmp_path / "lift.m"
    code, _, err = run(["post", str(ngc), "-t", "matlab-router", "-o", str(out_file)], capsys)
    assert code == 0, err
    from camtool.model.program import Linear, Rapid
    from camtool.post.registry import load_target

    moves = load_target("matlab-router").parse(out_file.read_text()).moves
    cuts = [(m.x, m.y) for m in moves if isinstance(m, Linear)]
    if bed_zero:
        assert cuts == [(1, 0), (2, 1), (3, 1)]
        assert "above the stock" not in err
    else:
        assert cuts == [(1, 0), (3, 1)]  # the crossing is not cut
        assert [(m.x, m.y) for m in moves if isinstance(m, Rapid)] == [(0, 0), (2, 1)]
        assert "1 cut(s) above the stock (Z > 0 all along" in err


def test_drawing_options_on_gcode_are_refused(capsys: pytest.CaptureFixture[str]) -> None:
    args = ["post", str(DATA / "flashcut-seed001.nc"), "-t", "pic-mmh", "--offset", "outside"]
    code, out, err = run(args, capsys)
    assert code == 2 and out == ""
    assert "already a toolpath" in err and "--offset" in err


def test_inspect_lists_layers_and_problems(capsys: pytest.CaptureFixture[str]) -> None:
    import json

    code, out, _ = run(["inspect", str(SAMPLES / "logo.dxf")], capsys)
    assert code == 0 and "open contours: 2" in out and "LWPOLYLINE" in out
    code, out, _ = run(["inspect", str(SAMPLES / "logo.dxf"), "--json"], capsys)
    assert code == 0 and json.loads(out)["source"].endswith("logo.dxf")
    code, out, err = run(["inspect", "missing.dxf"], capsys)
    assert code == 3 and out == "" and "missing.dxf" in err


def _square_with_a_gap(path: Path) -> Path:
    """A 10 mm square of four LINEs whose corner at (10, 0) has a 0.005 mm gap."""
    sides = [((0, 0), (10, 0)), ((10, 0.005), (10, 10)), ((10, 10), (0, 10)), ((0, 10), (0, 0))]
    return write_dxf(path, lambda msp: [msp.add_line(a, b) for a, b in sides])


def test_inspect_of_a_program_says_which_command_reads_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    program = tmp_path / "part.nc"
    program.write_text("G21 G90\nG0 Z5\nG0 X1 Y1\nG1 Z-1 F100\nG1 X5\nG0 Z5\nM2\n")
    code, out, err = run(["inspect", str(program)], capsys)
    assert code == 3 and out == ""  # not a drawing: invalid input, as another file type is
    assert f"{program}: a G-code program; inspect reads drawings" in err
    assert f"camtool verify {program} -t TARGET" in err and "Traceback" not in err


def test_inspect_joins_the_gaps_post_joins(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # 0.005 mm: within the default --chain-tolerance (0.01 mm), above 0.001 mm
    import json

    path = str(_square_with_a_gap(tmp_path / "gap.dxf"))
    code, out, _ = run(["inspect", path], capsys)
    assert code == 0 and "contours: 1 (1 closed, 0 open)" in out and "no problems found" in out
    assert "chaining tolerance 0.01 mm" in out
    code, out, _ = run(["inspect", path, "--json"], capsys)
    data = json.loads(out)
    assert data["contours"]["closed"] == 1 and data["finding_counts"] == {}
    assert data["tolerance_mm"] == 0.001 and data["chain_tolerance_mm"] == 0.01
    code, _, err = run(["post", path, "-t", "grbl", "-o", str(tmp_path / "a.nc")], capsys)
    assert code == 0 and "mm gap" not in err and "stays open" not in err
    # at --chain-tolerance 0.001 both call it open: the chain's own ends stay 0.005 mm apart
    code, out, _ = run(["inspect", path, "--chain-tolerance", "0.001"], capsys)
    assert code == 0 and "contours: 1 (0 closed, 1 open)" in out and "open contours: 1" in out
    assert "gap of 0.005 mm at (10.0000, 0.0025): above the chaining tolerance 0.001 mm" in out
    post = ["post", path, "-t", "grbl", "-o", str(tmp_path / "b.nc"), "--chain-tolerance", "0.001"]
    code, _, err = run(post, capsys)
    assert code == 0 and "closed a 0.005 mm gap between its ends at (10.0000, 0.0025)" in err
    code, _, err = run([*post, "--close-gap", "0"], capsys)
    assert code == 0 and "stays open: its ends are 0.0050 mm apart" in err


def test_layers_and_units_reach_the_importers(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    svg = str(DATA / "inkscape-layers.svg")
    code, out, err = run(["post", svg, "-t", "pic-mmh", "--layers", "nope"], capsys)
    assert code == 3 and "no layer named 'nope'" in err
    points = tmp_path / "p.csv"
    points.write_text("x,y\n100,100\n300,100\n300,200\n100,100\n")
    code, out, _ = run(["post", str(points), "-t", "pic-mmh", "--units", "um"], capsys)
    assert code == 0 and "G01X00300.00Y00100.00F08;" in out.splitlines()


# -- nothing lost: outputs that are inputs, devices, FIFOs, symlinks, a full disk ---------------


@pytest.fixture
def part(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """tmp_path as the working directory: part.dxf, its program part.pic, sub/, link.dxf."""
    monkeypatch.chdir(tmp_path)
    rectangle_dxf(tmp_path / "part.dxf", 2, 1)
    assert main(["post", "part.dxf", "-t", "pic-mmh", "-o", "part.pic"]) == 0
    (tmp_path / "sub").mkdir()
    (tmp_path / "link.dxf").symlink_to("part.dxf")
    (tmp_path / "m.toml").write_text(BIG_MACHINE)
    return tmp_path


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["post", "part.dxf", "-o", "part.dxf"], "-o part.dxf would overwrite the input"),
        (["post", "part.dxf", "-o", "./sub/../part.dxf"], "would overwrite the input part.dxf"),
        (["post", "part.dxf", "-o", "link.dxf"], "-o link.dxf would overwrite the input"),
        (["post", "link.dxf", "-o", "part.dxf"], "-o part.dxf would overwrite the input"),
        (["post", "part.dxf", "--preview", "part.dxf"], "--preview part.dxf would overwrite"),
        (["post", "part.dxf", "-o", "a.pic", "--report", "part.dxf"], "--report part.dxf would"),
        (["post", "part.dxf", "-o", "m.toml", "--machine", "m.toml"], "the --machine file m.toml"),
        (["post", "part.dxf", "-o", "r.json", "--report", "r.json"], "are the same file"),
        (["post", "part.dxf", "--report", "-"], "-o - and --report - both write to stdout"),
        (["verify", "part.pic", "--report", "part.pic"], "overwrite the program part.pic"),
        (["verify", "part.pic", "--preview", "./part.pic"], "overwrite the program part.pic"),
        (["verify", "part.pic", "--against", "part.dxf", "--report", "link.dxf"], "--against"),
        (["preview", "part.pic", "-o", "a.svg", "--program", "a.svg"], "overwrite the --program"),
    ],
)
def test_an_output_naming_an_input_or_another_output_is_refused(
    part: Path, capsys: pytest.CaptureFixture[str], args: list[str], message: str
) -> None:
    before = {p.name: p.read_bytes() for p in part.iterdir() if p.is_file()}
    code, out, err = run([*args, "-t", "pic-mmh"], capsys)
    assert code == 2, err
    assert message in err and out == "" and "Traceback" not in err
    assert {p.name: p.read_bytes() for p in part.iterdir() if p.is_file()} == before


def test_preview_of_a_drawing_onto_itself_is_refused(
    part: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    drawing = part / "d.svg"
    drawing.write_text(
        '<svg xmlns="http://www.w3.org/2000/svg" width="10mm" height="10mm" '
        'viewBox="0 0 10 10"><path d="M1 1 H4 V3 H1 Z"/></svg>'
    )
    before = drawing.read_bytes()
    code, _, err = run(["preview", "d.svg", "-o", "./sub/../d.svg"], capsys)
    assert code == 2 and "-o ./sub/../d.svg would overwrite the input d.svg" in err
    assert drawing.read_bytes() == before


def test_post_to_a_full_stdout_is_an_error_not_a_crash(part: Path) -> None:
    with open("/dev/full", "wb") as full:
        proc = subprocess.run(
            [sys.executable, "-m", "camtool", "post", "part.dxf", "-t", "pic-mmh"],
            stdout=full,
            stderr=subprocess.PIPE,
            text=True,
            check=False,
        )
    assert proc.returncode == 1
    assert "camtool: error: stdout: no space left on device" in proc.stderr
    assert "internal error" not in proc.stderr and "Exception ignored" not in proc.stderr


def test_post_to_a_full_device_names_it(part: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run(["post", "part.dxf", "-t", "pic-mmh", "-o", "/dev/full"], capsys)
    assert code == 1 and "/dev/full: cannot write (no space left on device)" in err
    assert stat.S_ISCHR(os.stat("/dev/full").st_mode)


def test_post_to_dev_null_leaves_it_a_device(
    part: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, _, err = run(["post", "part.dxf", "-t", "pic-mmh", "-o", "/dev/null"], capsys)
    assert code == 0, err
    assert stat.S_ISCHR(os.stat("/dev/null").st_mode)
    assert os.stat("/dev/null").st_rdev == os.makedev(1, 3)  # Linux: mem major 1, minor 3


def test_post_into_a_fifo_writes_through(part: Path, capsys: pytest.CaptureFixture[str]) -> None:
    os.mkfifo("fifo.pic")
    got: list[bytes] = []
    reader = threading.Thread(target=lambda: got.append(Path("fifo.pic").read_bytes()))
    reader.start()
    code, _, err = run(["post", "part.dxf", "-t", "pic-mmh", "-o", "fifo.pic"], capsys)
    reader.join(timeout=20)
    assert code == 0, err
    assert got == [Path("part.pic").read_bytes()]
    assert stat.S_ISFIFO(os.lstat("fifo.pic").st_mode)


def test_post_through_a_symlink_replaces_its_target(
    part: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    Path("sub/prog.pic").write_text("previous\n")
    Path("prog.pic").symlink_to("sub/prog.pic")
    code, _, err = run(["post", "part.dxf", "-t", "pic-mmh", "-o", "prog.pic"], capsys)
    assert code == 0, err
    assert Path("prog.pic").is_symlink() and os.readlink("prog.pic") == "sub/prog.pic"
    assert Path("sub/prog.pic").read_bytes() == Path("part.pic").read_bytes()


@pytest.mark.parametrize("raised", ["plain", "from a compiled kernel"])
def test_ctrl_c_is_aborted_not_an_internal_error(
    raised: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Ctrl-C while numba's kernel runs came out as 'internal error: SystemError ... returned a
    result with an exception set'; it is the user stopping the job: 'aborted', exit 130."""
    import camtool.jobs.pipeline as pipeline

    def interrupted(*args: object, **kwargs: object) -> None:
        if raised == "plain":
            raise KeyboardInterrupt
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt as exc:  # what CPython raises for a C call that left it set
            raise SystemError("CPUDispatcher(<function near_segments>) returned a result "
                              "with an exception set") from exc  # fmt: skip

    monkeypatch.setattr(pipeline, "verify_job", interrupted)
    src = rectangle_dxf(tmp_path / "r.dxf")
    code = main(["post", str(src), "-t", "grbl", "-o", str(tmp_path / "r.gcode"), "--verify"])
    err = capsys.readouterr().err
    assert code == 130
    assert "camtool: aborted" in err and "internal error" not in err


@pytest.mark.parametrize("command", ["post", "verify"])
def test_an_output_in_a_missing_directory_is_refused_before_any_work(
    part: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], command: str
) -> None:
    """Found only when written, the preview's missing directory failed the run after the
    program had been written and verified; now nothing is written and the exit is 2."""
    code, _, err = run(["post", "part.dxf", "-t", "grbl", "-o", "part.gcode"], capsys)
    assert code == 0
    program = Path("part.gcode").read_bytes()
    out = tmp_path / "new.gcode"
    missing = tmp_path / "no" / "such" / "dir" / "p.png"
    args = {
        "post": ["post", "part.dxf", "-t", "grbl", "-o", str(out), "--preview", str(missing)],
        "verify": ["verify", "part.gcode", "-t", "grbl", "--preview", str(missing)],
    }[command]
    code, _, err = run(args, capsys)
    assert code == 2
    assert f"--preview {missing}: {missing.parent} does not exist" in err
    assert not out.exists() and not missing.parent.exists()
    assert Path("part.gcode").read_bytes() == program
    a_file = tmp_path / "a-file"
    a_file.write_text("x")
    code, _, err = run(["post", "part.dxf", "-t", "grbl", "-o", str(a_file / "p.gcode")], capsys)
    assert code == 2 and f"{a_file} is not a directory" in err


@pytest.mark.parametrize("drawing", ["logo.dxf", "LOGO.SVG", "my logo.dxf"])
def test_verify_of_a_drawing_says_to_post_it_first(
    drawing: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A drawing given as verify's program is refused with what to do, not a parse error."""
    path = tmp_path / drawing
    path.write_bytes((SAMPLES / "logo.dxf").read_bytes())
    code, out, err = run(["verify", str(path), "-t", "grbl"], capsys)
    assert code == 3 and out == ""
    assert f"{path}: a drawing, not a program" in err
    assert f"camtool post {shlex.quote(str(path))} -t grbl -o PROGRAM" in err
    assert f"--against {shlex.quote(str(path))}" in err
    assert "unexpected character" not in err and "Traceback" not in err
    code, _out, err = run(["verify", str(tmp_path / "missing.dxf"), "-t", "grbl"], capsys)
    assert code == 3 and "missing.dxf: no such file" in err


def test_send_of_a_drawing_says_to_post_it_first(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``send`` refuses a drawing before it opens any port, saying what to do."""
    missing_port = tmp_path / "no-such-port"
    args = ["send", str(SAMPLES / "logo.dxf"), "-t", "grbl", "--port", str(missing_port)]
    code, out, err = run(args, capsys)
    assert code == 3 and out == ""
    assert "logo.dxf: a drawing, not a program" in err and "then send PROGRAM" in err
    assert str(missing_port) not in err


@pytest.mark.parametrize("ending", [".dxf", ".svg", ".csv"])
def test_a_drawing_path_that_is_not_a_file_is_named_for_what_it_is(
    ending: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # not "no such file" for each: a FIFO (not opened: it could block), a folder, a link
    # to nothing or round a loop
    fifo, folder = tmp_path / f"fifo{ending}", tmp_path / f"folder{ending}"
    os.mkfifo(fifo)
    folder.mkdir()
    (tmp_path / f"dangling{ending}").symlink_to("nowhere")
    (tmp_path / f"loop{ending}").symlink_to(f"loop{ending}")
    said = {
        fifo: "not a regular file (a FIFO, a socket or a device)",
        folder: "a folder, not a file",
        tmp_path / f"dangling{ending}": "a symbolic link that leads to no file",
        tmp_path / f"loop{ending}": "a symbolic link that leads to no file (or round a loop)",
        tmp_path / f"missing{ending}": "no such file",
    }
    for path, what in said.items():
        code, out, err = run(
            ["post", str(path), "-t", "grbl", "-o", str(tmp_path / "o.nc")], capsys
        )
        assert code == 3 and out == "", err
        assert err.startswith(f"camtool: error: {path}: {what}")
    assert not (tmp_path / "o.nc").exists()


def test_verify_names_a_program_path_that_is_a_link_to_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    link = tmp_path / "gone.nc"
    link.symlink_to("nowhere.nc")
    code, out, err = run(["verify", str(link), "-t", "grbl"], capsys)
    assert code == 3 and out == ""
    assert (
        err == f"camtool: error: {link}: a symbolic link that leads to no file (or round a loop)\n"
    )


def test_memory_running_out_is_said_so_and_writes_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """numpy's MemoryError (a trace of 50 million rows on a machine without the memory for
    it) is a job too large for the machine, not "internal error: MemoryError"; the output
    file is left as it was (here: not there)."""
    from camtool.jobs import pipeline

    def too_large(*args: object, **kwargs: object) -> None:
        raise MemoryError(
            "Unable to allocate 763. MiB for an array with shape (50000000, 2) and data type "
            "float64"
        )

    monkeypatch.setattr(pipeline, "run_job", too_large)
    out = tmp_path / "logo.nc"
    code, stdout, err = run(
        ["post", str(SAMPLES / "logo.dxf"), "-t", "grbl", "-o", str(out)], capsys
    )
    assert code == 1 and stdout == ""
    assert err.startswith("camtool: error: out of memory (Unable to allocate 763. MiB")
    assert "steps_per_mm" in err and "internal error" not in err
    assert not out.exists()
    monkeypatch.setattr(pipeline, "run_job", lambda *a, **k: (_ for _ in ()).throw(MemoryError()))
    code, _, err = run(["post", str(SAMPLES / "logo.dxf"), "-t", "grbl", "-o", str(out)], capsys)
    assert code == 1 and err.startswith("camtool: error: out of memory: the job needs")
