"""Placement (--origin, --translate) and the work-area rule, run as a user runs camtool.

The expected numbers are hand-checked: a 100 × 60 mm plate drawn from the origin, cut
outside with a 3 mm tool, has a tool-centre path 1.5 mm outside every edge: X −1.5…101.5,
Y −1.5…61.5 (103 × 63 mm).
"""

from __future__ import annotations

import gc
import re
import tracemalloc
from pathlib import Path

import ezdxf
import pytest

from camtool.cli.main import main
from camtool.model.program import ArcMove, Dwell, Linear, Move, Program, Rapid, Spindle
from camtool.model.shapes import Drawing
from camtool.toolpath.options import PlanOptions
from camtool.toolpath.placement import placement_shift, shift_program, toolpath_extent
from camtool.toolpath.plan import place_program

OUTSIDE = ["--offset", "outside", "--tool-diameter", "3"]


def plate(path: Path, x0: float = 0.0, y0: float = 0.0) -> Path:
    """A 100 × 60 mm rectangle from (x0, y0), a DXF in mm ($INSUNITS = 4)."""
    doc = ezdxf.new()
    doc.header["$INSUNITS"] = 4
    corners = [(x0, y0), (x0 + 100, y0), (x0 + 100, y0 + 60), (x0, y0 + 60)]
    doc.modelspace().add_lwpolyline(corners, close=True)
    doc.saveas(path)
    return path


def post(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str]:
    code = main(["post", *args])
    return code, capsys.readouterr().err


def cut_extent(gcode: str) -> tuple[float, float, float, float]:
    """Extent of the X/Y words of the cutting blocks (G1/G2/G3) of GRBL code."""
    xs, ys = [], []
    for line in gcode.splitlines():
        if re.match(r"G[123]\b", line):
            xs += [float(v) for v in re.findall(r"X(-?[\d.]+)", line)]
            ys += [float(v) for v in re.findall(r"Y(-?[\d.]+)", line)]
    return (min(xs), min(ys), max(xs), max(ys))


@pytest.mark.parametrize(
    ("options", "extent"),
    [
        ([], (-1.5, -1.5, 101.5, 61.5)),
        (["--origin", "lower-left"], (0.0, 0.0, 103.0, 63.0)),
        (["--origin", "center"], (-51.5, -31.5, 51.5, 31.5)),
        (["--translate", "10", "5"], (8.5, 3.5, 111.5, 66.5)),
        (["--origin", "lower-left", "--translate", "10", "5"], (10.0, 5.0, 113.0, 68.0)),
    ],
)
def test_plate_at_the_origin_posts_for_grbl_where_asked(
    options: list[str],
    extent: tuple[float, float, float, float],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    out = tmp_path / "p.gcode"
    code, err = post(
        [str(plate(tmp_path / "p.dxf")), "-t", "grbl", *OUTSIDE, *options, "-o", str(out)], capsys
    )
    assert code == 0, err
    assert cut_extent(out.read_text()) == pytest.approx(extent, abs=1e-9)


def test_a_toolpath_across_work_zero_is_warned_about_once(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    dxf = str(plate(tmp_path / "p.dxf"))
    # post warns, and --verify (which applies the same rule to the code) does not repeat it.
    argv = [dxf, "-t", "grbl", *OUTSIDE, "-o", str(tmp_path / "a.gcode"), "--verify"]
    code, err = post(argv, capsys)
    assert code == 0
    warning = "the toolpath spans X -1.5…101.5, Y -1.5…61.5 mm, on both sides of work zero"
    assert err.count(warning) == 1
    assert "use --origin lower-left" in err
    options = ["--origin", "lower-left", "-o", str(tmp_path / "b.gcode")]
    code, err = post([dxf, "-t", "grbl", *OUTSIDE, *options], capsys)
    assert code == 0
    assert "work zero" not in err


def test_a_drawing_far_from_work_zero_is_warned_once_and_told_to_use_origin(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The plate drawn at X 150: its outside profile spans X 148.5…251.5 mm, so work zero
    lies 251.5 mm from its far side, more than GRBL's 200 mm. The planner warns with
    ``--origin``; the writer checks the same rule and must neither repeat it nor give the
    remedy of G-code read back (FreeCAD's A0 templates with ``--fit`` were told both)."""
    dxf = str(plate(tmp_path / "p.dxf", x0=150.0))
    out = ["-o", str(tmp_path / "out.gcode"), "--verify", "--no-budget"]  # verify checks too
    code, err = post([dxf, "-t", "grbl", *OUTSIDE, *out], capsys)
    assert code == 0
    assert err.count("work zero cannot be a point the tool reaches") == 1
    assert "lies 251.5 mm from its far side" in err and "use --origin lower-left" in err
    assert "in the program that wrote it" not in err


def test_a_reposted_program_far_from_work_zero_is_not_told_to_use_origin(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """pcb2gcode's outline at X 116…253 mm: work zero lies 253 mm from its far side, more
    than GRBL's 200 mm. ``--origin`` is refused for G-code, so the warning does not name it."""
    source = tmp_path / "outline.ngc"
    source.write_text("G21 G90\nG0 Z5\nG0 X116 Y10\nG1 Z-1 F100\nG1 X253 Y10\nG0 Z5\nM2\n")
    code, err = post([str(source), "-t", "grbl", "-o", str(tmp_path / "out.gcode")], capsys)
    assert code == 0
    assert "work zero (X0 Y0) lies 253 mm from its far side, more than the 200 mm X" in err
    assert "set it with an offset from a point the tool reaches, or move the program" in err
    assert "--origin" not in err
    # verifying or sending the file as it is: the same advice (neither takes --origin)
    for command in (["verify", "--no-budget"], ["send", "--dry-run"]):
        assert main([command[0], str(source), "-t", "grbl", *command[1:]]) == 0
        err = capsys.readouterr().err
        assert "move the program in the program that wrote it" in err
        assert "--origin" not in err


def test_the_start_position_and_the_lift_there_stay(tmp_path: Path) -> None:
    out = tmp_path / "p.gcode"
    args = [str(plate(tmp_path / "p.dxf")), "-t", "grbl", *OUTSIDE, "--depth", "1"]
    assert main(["post", *args, "--origin", "center", "-o", str(out)]) == 0
    moves = [line for line in out.read_text().splitlines() if line.startswith("G")]
    # The lift at the start position is not dragged sideways (a Z-only rise to clearance);
    # travel follows at that height.
    assert moves[1] == "G0 Z5.000"
    assert moves[2] == "G0 X-51.500 Y-30.000"


def remedies(message: str) -> list[list[str]]:
    """Each option set a message suggests ("--origin lower-left --translate 0 0", …)."""
    value = r" (?:-?[\d.]+|lower-left|center|drawing)"
    found = re.findall(rf"((?:--(?:origin|translate|fit)(?:{value})+ ?)+)", message)
    return [f.split() for f in found]


def replaced(argv: list[str], remedy: list[str]) -> list[str]:
    """``argv`` with the options of ``remedy`` instead of the same options it has."""
    widths = {"--origin": 1, "--translate": 2, "--fit": 2}
    given = {flag for flag in remedy if flag in widths}
    out, i = [], 0
    while i < len(argv):
        if argv[i] in given:
            i += 1 + widths[argv[i]]
            continue
        out.append(argv[i])
        i += 1
    return out + remedy


@pytest.mark.parametrize(
    "placing",
    [[], ["--origin", "center", "--translate", "5", "5"], ["--translate", "-20", "300"]],
)
def test_machine_coordinates_refuse_with_remedies_that_work(
    placing: list[str], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # The Angel-11 router counts from its home: X 0…200, Y 0…200 mm.
    argv = [str(plate(tmp_path / "p.dxf")), "-t", "matlab-router", *OUTSIDE, *placing]
    code, err = post([*argv, "-o", str(tmp_path / "refused.m")], capsys)
    assert code == 1
    assert "outside the work area X 0…200, Y 0…200 mm of Router (Angel-11, 2011)" in err
    assert "machine coordinates" in err
    suggested = remedies(err)
    assert len(suggested) == 2, err
    assert suggested[0][:2] == ["--origin", "lower-left"]
    for n, remedy in enumerate(suggested):
        code, again = post([*replaced(argv, remedy), "-o", str(tmp_path / f"{n}.m")], capsys)
        assert code == 0, (remedy, again)


def test_the_suggested_translation_is_the_one_hand_computed(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = [str(plate(tmp_path / "p.dxf")), "-t", "matlab-router", *OUTSIDE, "-o", "-"]
    code, err = post(argv, capsys)
    assert code == 1
    assert "place it with --origin lower-left, or move it with --translate 1.5 1.5" in err


@pytest.mark.parametrize(
    ("target", "area", "size"),
    [
        ("grbl", "[0.0, 0.0, 100.0, 50.0]", "100 × 50"),
        ("matlab-router", "[0, 0, 80, 40]", "80 × 40"),
    ],
)
def test_a_toolpath_larger_than_the_travel_names_both_sizes_and_a_fit_that_works(
    target: str, area: str, size: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    machine = tmp_path / "small.toml"
    machine.write_text(f"[machine]\nwork_area_mm = {area}\n")
    argv = [str(plate(tmp_path / "p.dxf")), "-t", target, *OUTSIDE, "--machine", str(machine)]
    code, err = post([*argv, "-o", str(tmp_path / "refused")], capsys)
    assert code == 1
    # --offset outside: the toolpath reaches the whole drawing, so it is refused once read
    # (the toolpath's own size, 103 × 63 mm, is known only after planning)
    assert f"the drawing is at least 100 × 60 mm, so its toolpath is larger than the {size}" in err
    assert "(refused before planning)" in err
    assert "use a larger machine (--machine FILE.toml" in err
    (remedy,) = remedies(err)
    assert remedy[0] == "--fit"
    code, again = post([*replaced(argv, remedy), "-o", str(tmp_path / "fits")], capsys)
    assert code == 0, again
    assert "work zero" not in again


def test_verify_runs_negative_work_coordinates(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "p.gcode"
    assert (
        main(["post", str(plate(tmp_path / "p.dxf")), "-t", "grbl", *OUTSIDE, "-o", str(out)]) == 0
    )
    capsys.readouterr()
    assert main(["verify", str(out), "-t", "grbl"]) == 0
    # code read back does not say how its work zero was chosen: nothing to second-guess
    assert "work zero" not in capsys.readouterr().err


def test_verify_refuses_machine_coordinates_outside_with_the_post_remedy(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # Posted for a 400 × 400 mm router at X 148.5…251.5, Y 148.5…211.5: outside 200 × 200.
    wide = tmp_path / "wide.toml"
    wide.write_text("[machine]\nwork_area_mm = [0, 0, 400, 400]\n")
    code = tmp_path / "p.m"
    argv = ["post", str(plate(tmp_path / "p.dxf")), "-t", "matlab-router", *OUTSIDE]
    assert main([*argv, "--translate", "150", "150", "-o", str(code), "--machine", str(wide)]) == 0
    capsys.readouterr()
    assert main(["verify", str(code), "-t", "matlab-router"]) == 1
    err = capsys.readouterr().err
    assert "outside the work area X 0…200, Y 0…200 mm" in err
    assert "post it again with --origin lower-left, or with its --translate moved by " in err
    dx, dy = (float(v) for v in re.findall(r"moved by (\S+) (\S+) mm", err)[0])
    # the code's far corner: 251.5, 211.5 mm on the router's 0.2 mm grid, half away from zero
    assert (dx, dy) == (-51.6, -11.6)
    for remedy in (["--origin", "lower-left"], ["--translate", str(150 + dx), str(150 + dy)]):
        assert main([*argv, *remedy, "-o", str(code)]) == 0
        assert main(["verify", str(code), "-t", "matlab-router"]) == 0


def test_every_target_posts_a_part_drawn_around_the_origin_or_names_a_remedy_that_works(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from camtool.post.registry import target_names

    dxf = str(plate(tmp_path / "p.dxf", -50, -30))
    for target in target_names():
        argv = [dxf, "-t", target, *OUTSIDE, "-o", str(tmp_path / f"{target}.out")]
        code, err = post(argv, capsys)
        if code == 0:
            continue
        suggested = remedies(err)
        assert code == 1 and suggested, (target, err)
        code, again = post(replaced(argv, suggested[0]), capsys)
        assert code == 0, (target, suggested[0], again)


# -- the stage itself ------------------------------------------------------------------


def test_extent_leaves_out_the_travel_from_the_start_position() -> None:
    program = Program(
        (Rapid(0, 0, z=5), Rapid(10, 10), Linear(10, 10, 100, z=-1), Linear(20, 10, 100)),
        origin=(0.0, 0.0),
    )
    assert toolpath_extent(program) == (10, 10, 20, 10)


def test_extent_counts_arcs_by_their_extremes() -> None:
    program = Program((Rapid(1, 0), ArcMove(1, 0, 0, 0, False, 100)))
    assert toolpath_extent(program) == pytest.approx((-1, -1, 1, 1))


def test_shift_moves_ends_and_centres_but_not_the_start() -> None:
    program = Program((Rapid(0, 0, z=5), Rapid(1, 0), ArcMove(1, 0, 0, 0, False, 100, z=None)))
    assert placement_shift(program, "lower-left", (0.0, 0.0)) == (1.0, 1.0)
    moved = shift_program(program, 1.0, 1.0)
    assert moved.moves == (Rapid(0, 0, z=5), Rapid(2, 1), ArcMove(2, 1, 1, 1, False, 100))
    assert moved.origin == (0.0, 0.0)


def test_a_cut_from_the_start_position_is_reached_by_a_rapid_after_the_shift() -> None:
    program = Program(
        (Linear(5, 0, 100), Linear(5, 5, 100)),
        commands=((0, Spindle("cw", 1000)), (1, Dwell(1.0))),
    )
    moved = shift_program(program, 2.0, 3.0)
    assert moved.moves == (Rapid(2, 3), Linear(7, 3, 100), Linear(7, 8, 100))
    # The spindle still starts first; the dwell stays before the second cut.
    assert moved.commands == ((0, Spindle("cw", 1000)), (2, Dwell(1.0)))


def _unplaced(moves: list[Move]) -> Program:
    """A program of ``moves``, the list emptied: the program alone holds them."""
    program = Program(tuple(moves))
    moves.clear()
    return program


def test_placing_a_program_does_not_hold_a_second_set_of_its_moves() -> None:
    """``--origin lower-left`` of 100 000 cuts: each move is let go as its shifted copy is
    made, so the peak grows by the lists of references (~40 bytes a move), not by a second
    set of moves (a ``Linear`` and its two new coordinates are over 100 bytes)."""
    n = 100_000
    tracemalloc.start()
    try:
        moves: list[Move] = [Rapid(10.0, 10.0, z=5.0)]
        moves += [Linear(10.0 + i, 10.0 + i % 7, 300.0, contour=1) for i in range(1, n)]
        gc.collect()
        base = tracemalloc.get_traced_memory()[0]
        tracemalloc.reset_peak()
        options = PlanOptions(placement="lower-left")
        program, _, shift = place_program(_unplaced(moves), Drawing((), "p", ()), options)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert shift == (-10.0, -10.0)
    assert program.moves[1] == Linear(1.0, 1.0, 300.0, contour=1)
    assert (peak - base) / n < 64


def test_a_chosen_work_zero_inside_the_part_is_not_warned_about(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    args = [str(plate(tmp_path / "p.dxf")), "-t", "grbl", *OUTSIDE, "-o", str(tmp_path / "o")]
    assert main(["post", *args]) == 0
    assert "on both sides of work zero" in capsys.readouterr().err  # as drawn: worth a word
    assert main(["post", *args, "--origin", "center"]) == 0
    assert "on both sides of work zero" not in capsys.readouterr().err  # asked for


def test_the_end_position_is_in_work_coordinates(tmp_path: Path) -> None:
    out = tmp_path / "p.gcode"
    args = [str(plate(tmp_path / "p.dxf")), "-t", "grbl", *OUTSIDE, "--depth", "1"]
    place = ["--origin", "lower-left", "--end-position", "0", "0", "-o", str(out)]
    assert main(["post", *args, *place]) == 0
    lines = out.read_text().splitlines()
    # the park move goes to the work zero the user set, not to the drawing's origin shifted
    assert lines[-4:] == ["G0 Z5.000", "G0 X0.000 Y0.000", "M5", "M2"]


@pytest.mark.parametrize("origin", ["drawing", "lower-left"])
def test_features_not_cut_follow_the_placed_program(origin: str, tmp_path: Path) -> None:
    # regression: with --origin lower-left the plan's findings stayed in drawing
    # coordinates, so the 2 mm hole the 3 mm tool cannot cut counted in the main figure
    import json

    sample = Path(__file__).resolve().parents[2] / "samples" / "plate.dxf"
    report = tmp_path / "r.json"
    argv = ["post", str(sample), "-t", "grbl", *OUTSIDE, "--origin", origin]
    assert main([*argv, "-o", str(tmp_path / "p.gcode"), "--report", str(report)]) == 0
    data = json.loads(report.read_text())
    assert len(data["not_cut_as_drawn"]) == 3  # two tight corners and the 2 mm hole
    assert data["max_error_um"] < 50  # what was cut: a few µm of 4 µm steps
