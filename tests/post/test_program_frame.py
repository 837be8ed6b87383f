"""Programs a machinist can run, as a user posts them: start, end, clearance, header (issue 13 §2).

Every target with a Z axis (``camtool targets --json``: grbl, linuxcnc, valcnc, flashcut,
i8751) is posted through the CLI and its code read back with the target's own reader:

- the first move is Z only, up to the clearance height, from wherever the machine is
  (the reader starts at X0 Y0, so its XY must not change);
- no rapid moves XY below safe Z, and no Z-only rapid goes below safe Z;
- the spindle starts after that first rise, once the tool is off the stock's top where
  Z zero was set, and before any other move;
- the program ends with a Z-only rise to clearance, then the spindle stops;
- without ``--depth`` the cuts run at Z 0 and a warning says so;
- the header (job notes as comments where the dialect has them) is deterministic.

Re-posted G-code keeps its own moves: nothing is added before its first move.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from camtool.cli.main import main
from camtool.importers.gcode import read_gcode
from camtool.jobs.header import NO_DEPTH_WARNING
from camtool.model.program import Program, Rapid, Spindle
from camtool.post.registry import load_target

ROOT = Path(__file__).parents[2]
LOGO = ROOT / "samples" / "logo.dxf"
SCALE = {"grbl": 20, "linuxcnc": 20, "valcnc": 20, "flashcut": 1, "i8751": 10}
"""Z targets and a scale that puts the logo in their work area."""
SUFFIX = {"grbl": ".gcode", "linuxcnc": ".ngc", "valcnc": ".ngc", "flashcut": ".nc"}


def _run(
    target: str, args: list[str], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> tuple[Program, bytes, str]:
    out = tmp_path / f"out-{target}.{'bin' if target == 'i8751' else 'txt'}"
    argv = ["post", str(LOGO), "-t", target, "--scale", str(SCALE[target]), "-o", str(out), *args]
    code = main(argv)
    _, err = capsys.readouterr()
    assert code == 0, err
    data = out.read_bytes()
    post = load_target(target).post
    return post.parse(data if post.binary else data.decode("ascii")), data, err


def _check_heights(program: Program, safe_z: float, clearance: float) -> None:
    """The rules of the module docstring on the moves read back."""
    first = program.moves[0]
    assert isinstance(first, Rapid) and (first.x, first.y) == (0.0, 0.0)
    assert first.z == pytest.approx(clearance)
    x, y, z = 0.0, 0.0, None
    for move in program.moves:
        moved_xy = (move.x, move.y) != (x, y)
        z_end = z if move.z is None else move.z
        if isinstance(move, Rapid):
            assert z_end is not None and z_end >= safe_z - 1e-9, move
            if moved_xy:
                assert z is not None and z >= safe_z - 1e-9 and z_end == z, move
        x, y, z = move.x, move.y, z_end
    last = program.moves[-1]
    assert isinstance(last, Rapid) and last.z == pytest.approx(clearance)
    assert (last.x, last.y) == (program.moves[-2].x, program.moves[-2].y)  # Z only


@pytest.mark.parametrize("target", sorted(SCALE))
@pytest.mark.parametrize("depth", [None, "1"])
def test_start_is_z_only_to_clearance_and_the_end_rises_before_the_spindle_stops(
    target: str, depth: str | None, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    args = ["--safe-z", "3", "--clearance-z", "8"] + ([] if depth is None else ["--depth", depth])
    program, data, err = _run(target, args, tmp_path, capsys)
    _check_heights(program, 3.0, 8.0)
    cutting_z = {m.z for m in program.moves if not isinstance(m, Rapid) and m.z is not None}
    assert min(cutting_z) == (0.0 if depth is None else -1.0)
    assert (NO_DEPTH_WARNING in err) == (depth is None)
    if target in SUFFIX:  # text: the first motion block has no X and no Y word
        motion = [
            line
            for line in data.decode().splitlines()
            if line.startswith("G0") and not line.startswith(("G04", "G0 P"))
        ]
        assert "Z8" in motion[0] and "X" not in motion[0] and "Y" not in motion[0]
    spindle = [(i, c) for i, c in program.commands if isinstance(c, Spindle)]
    if spindle:  # grbl, linuxcnc, flashcut: on after the first rise, off after the last move
        assert spindle[0][0] == 1 and spindle[-1] == (len(program.moves), Spindle("off"))


def test_no_depth_on_grbl_cuts_at_the_top_and_says_so(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    program, data, err = _run("grbl", [], tmp_path, capsys)
    assert f"camtool: warning: {NO_DEPTH_WARNING}" in err
    _check_heights(program, 2.0, 5.0)  # the defaults: safe Z 2 mm, clearance max(5, 2)
    assert {m.z for m in program.moves if not isinstance(m, Rapid) and m.z is not None} == {0.0}
    lines = data.decode().splitlines()
    assert lines[lines.index("M3 S1000") - 1] == "G0 Z5.000"
    assert lines[-3:] == ["G0 Z5.000", "M5", "M2"]


def test_2d_targets_do_not_change(capsys: pytest.CaptureFixture[str]) -> None:
    # pic-mmh has no Z: no warning, no Z, its thesis frame as before.
    code = main(["post", str(LOGO), "-t", "pic-mmh"])
    out, err = capsys.readouterr()
    assert code == 0 and NO_DEPTH_WARNING not in err
    assert out.startswith("G54;\nG90;\nG00X") and "Z" not in out


@pytest.mark.parametrize("target", ["grbl", "linuxcnc"])
def test_header_names_the_job_and_two_runs_are_byte_identical(
    target: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from camtool import __version__

    args = ["--offset", "outside", "--tool-diameter", "3", "--depth", "2", "--step-down", "1"]
    _, first, _ = _run(target, args, tmp_path, capsys)
    _, second, _ = _run(target, args, tmp_path, capsys)
    assert first == second
    lines = first.decode().splitlines()
    k = SCALE[target]
    assert lines[:8] == [
        f"(camtool {__version__}: logo.dxf for {target})",
        f"(placement: scale {k:g}, shift X0 Y0 mm)",  # --scale, about the drawing's origin
        f"(--scale {k:g}: the drawing at {100 * k:g} % of its size)",
        "(tool diameter 3 mm, offset outside)",
        "(work zero X0 Y0: the drawing's origin)",
        "(depth 2 mm in passes of 1 mm)",
        "(safe Z 2 mm, clearance Z 5 mm above the top)",
        "G21 G90 G94 G17" + (" G40 G49 G80" if target == "linuxcnc" else ""),
    ]
    assert lines[8:10] == ["G0 Z5.000", "M3 S" + ("1000" if target == "grbl" else "12000")]


def test_a_long_file_name_is_cut_to_grbl_line_limit(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    name = tmp_path / ("a-very-long-drawing-name-" * 6 + ".dxf")
    name.write_bytes(LOGO.read_bytes())
    assert main(["post", str(name), "-t", "grbl", "--scale", "20"]) == 0
    out, _ = capsys.readouterr()
    first = out.splitlines()[0]
    assert first.startswith("(camtool") and first.endswith("...)") and len(first) + 1 == 80


def test_spindle_dwell_is_written_after_the_spindle_starts(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["post", str(LOGO), "-t", "grbl", "--scale", "20", "--spindle-dwell", "2.5"]) == 0
    lines = capsys.readouterr().out.splitlines()
    start = lines.index("M3 S1000")
    assert lines[start - 1 : start + 2] == ["G0 Z5.000", "M3 S1000", "G4 P2.5"]
    assert lines[start + 2].startswith("G0 X")  # then to the first cut, the spindle up to speed


def test_end_position_rapids_there_at_clearance(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    program, data, _ = _run("grbl", ["--end-position", "0", "150"], tmp_path, capsys)
    assert program.moves[-2:][1] == Rapid(0.0, 150.0, None, contour=program.moves[-1].contour)
    assert data.decode().splitlines()[-4:] == ["G0 Z5.000", "G0 X0.000 Y150.000", "M5", "M2"]


def test_a_hostile_ramp_ends_quickly_with_a_usage_error(
    capsys: pytest.CaptureFixture[str],
) -> None:
    # 1 mm at 0.0001°: L = 1 / tan(0.0001°) = 572 958 mm per pass.
    code = main(
        ["post", str(LOGO), "-t", "grbl", "--scale", "20", "--depth", "1", "--ramp", "0.0001"]
    )
    out, err = capsys.readouterr()
    assert code == 2 and out == ""
    assert "--ramp 0.0001° needs 573 m of ramp per pass" in err and "give a steeper --ramp" in err


@pytest.mark.parametrize(
    ("name", "target"), [("gcodetools-circle.ngc", "grbl"), ("linuxcnc-inch.tap", "linuxcnc")]
)
def test_reposted_gcode_keeps_its_moves(
    name: str, target: str, capsys: pytest.CaptureFixture[str]
) -> None:
    # Nothing is added to a re-posted program's motion: no X0 Y0, no clearance move.
    path = ROOT / "tests" / "data" / name
    assert main(["post", str(path), "-t", target]) == 0
    out = capsys.readouterr().out
    back = load_target(target).post.parse(out).moves
    given = read_gcode(path).moves
    assert [(type(m), m.x, m.y, m.z) for m in back] == [
        (
            type(m),
            pytest.approx(m.x, abs=1e-3),
            pytest.approx(m.y, abs=1e-3),
            m.z and pytest.approx(m.z, abs=1e-3),
        )
        for m in given
    ]
    first = next(line for line in out.splitlines() if line.startswith("G"))
    assert first.startswith("G21")  # the safety line, then the program's own first move
    motion = [line for line in out.splitlines() if line.startswith(("G0 ", "G1 "))]
    assert motion[0] == {"grbl": "G0 Z5.000", "linuxcnc": "G0 Z2.540"}[target]
