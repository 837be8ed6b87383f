"""Tool changes and stops reach the machine in its own way, or the program is refused.

Expected behaviour from the controllers' documents: LinuxCNC changes tools with ``T2 M6``
and applies the length offset with ``G43 H2`` ("M6 Tool Change", "G43"); GRBL 1.1 has no
M6 (gcode.c answers error:20) and reads no line while its ``M0`` pauses, so it gets one
program per tool, as the thesis machines without a changer or a stop do (or, asked for,
one program with a pause at each change).
"""

from __future__ import annotations

from pathlib import Path

import pytest

from camtool.cli.main import main
from camtool.importers import read_drawing
from camtool.importers.gcode import parse_gcode, read_gcode
from camtool.jobs.jobfile import load_job
from camtool.jobs.pipeline import post_program
from camtool.jobs.run import run_job
from camtool.model.errors import DialectError
from camtool.model.program import Linear, Rapid, Stop, ToolChange
from camtool.post.base import Target
from camtool.post.registry import load_target

ROOT = Path(__file__).resolve().parents[2]
EAGLE = ROOT / "tests" / "data" / "eagle-drill.nc"
PART = ROOT / "samples" / "part.dxf"
JOB = ROOT / "samples" / "part.toml"


def test_a_drill_programs_manual_tool_changes_are_read_as_stops() -> None:
    program = read_gcode(EAGLE)
    stops = [(i, c) for i, c in program.commands if isinstance(c, Stop)]
    # T01 / M00 before the first hole, T02 / M00 before the third
    assert [c.message for _, c in stops] == ["change to T1", "change to T2"]
    assert stops[1][0] == 7  # before the eighth move, the rapid to the third hole
    assert (program.moves[7].x, program.moves[7].y) == (30.0, 15.0)


@pytest.mark.parametrize("target", ["grbl", "linuxcnc"])
def test_re_posted_stops_are_kept_before_the_holes_they_precede(target: str) -> None:
    code = str(post_program(read_gcode(EAGLE), load_target(target)).result.code)
    lines = code.splitlines()
    stops = [i for i, line in enumerate(lines) if line == "M0"]
    assert len(stops) == 2
    # LinuxCNC shows a (MSG, ...) to the operator at the pause; GRBL has no such message
    said = "(MSG, change to T{})" if target == "linuxcnc" else "(change to T{})"
    assert [lines[i - 1] for i in stops] == [said.format(1), said.format(2)]
    # the 0.9 mm holes come after the second stop, never before it
    assert lines.index("G0 X30.000 Y15.000") > stops[1]


@pytest.mark.parametrize("target", ["valcnc", "flashcut", "i8751"])
def test_a_target_without_a_stop_refuses_a_program_with_stops(target: str) -> None:
    with pytest.raises(DialectError, match="never drop"):
        post_program(read_gcode(EAGLE), load_target(target))


def test_a_job_for_a_machine_without_a_changer_is_one_program_per_tool() -> None:
    done = run_job(read_drawing(PART), load_target("valcnc"), load_job(JOB))
    assert [p.change.tool for p in done.pieces] == [2, 1]
    assert done.pieces[0].path("out/part.ngc") == "out/part.T2.ngc"
    assert done.pieces[1].program.notes[-1] == (
        "program 2 of 2: load T1 end-mill 3 mm, after program 1 (T2)"
    )
    # together the pieces are the job's moves, in order
    moves = [m for p in done.pieces for m in p.program.moves]
    assert moves == list(done.program.moves)
    # the second program starts where the first left the tool, and first rises to clearance
    first = done.pieces[1].program.moves[0]
    assert first.z == 10.0 and (first.x, first.y) == done.pieces[1].program.origin
    cuts = [m for m in done.pieces[0].program.moves if isinstance(m, Linear)]
    assert min(m.z for m in cuts if m.z is not None) == -6.5  # drilling only


def test_post_writes_each_tools_program_and_refuses_stdout(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "part.ngc"
    assert main(["post", str(PART), "-t", "valcnc", "--job", str(JOB), "-o", str(out)]) == 0
    err = capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["part.T1.ngc", "part.T2.ngc"]
    assert "run " + str(tmp_path / "part.T2.ngc") + " (T2), then" in err
    assert main(["post", str(PART), "-t", "valcnc", "--job", str(JOB)]) == 2
    assert "give -o FILE.ngc" in capsys.readouterr().err


def test_batch_names_each_tools_program_and_refuses_to_overwrite_them(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    args = ["batch", str(PART), "-t", "valcnc", "-o", str(tmp_path), "--job", str(JOB)]
    assert main([*args, "--jobs", "1"]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["part.T1.ngc", "part.T2.ngc"]
    capsys.readouterr()
    assert main([*args, "--jobs", "1"]) == 2
    assert "part.T1.ngc" in capsys.readouterr().err


ONE_TOOL = """
[job]
origin = "lower-left"
clearance_z = 10.0
safe_z = 2.0

[[tools]]
id = 1
type = "end-mill"
diameter = 3.0
feed = 400

[[operations]]
name = "mark"
type = "engrave"
tool = 1
layers = ["ENGRAVE"]
depth = 0.3
"""


def test_a_one_tool_job_for_a_machine_without_a_changer_is_that_tool_s_program(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """One tool is one program, as each of several tools' is: no change, "load T1" said.

    Before, the job was refused ("post one program per tool (a job does so ...)"), a remedy
    that a job of one tool could not follow."""
    job = tmp_path / "one.toml"
    job.write_text(ONE_TOOL)
    done = run_job(read_drawing(PART), load_target("valcnc"), load_job(job))
    assert not done.pieces
    assert not any(isinstance(c, ToolChange) for _, c in done.program.commands)
    assert done.program.notes[-1] == (
        "load T1 (end-mill 3 mm) before running: valcnc cannot change tools"
    )
    out = tmp_path / "one.ngc"
    assert main(["post", str(PART), "-t", "valcnc", "--job", str(job), "-o", str(out)]) == 0
    assert "the tool change to T1 is not written; load T1" in capsys.readouterr().err
    assert out.exists() and sorted(p.name for p in tmp_path.iterdir()) == ["one.ngc", "one.toml"]


@pytest.mark.parametrize("target", ["valcnc", "flashcut", "i8751"])
def test_a_re_posted_program_of_one_tool_is_written_without_its_change(target: str) -> None:
    """FreeCAD's and CAMotics' programs begin with their one tool change (``M6 T2``)."""

    text = "G21 G90\nM6 T2\nG0 X1 Y1 Z5\nG1 Z-1 F100\nG1 X5\nG0 Z5\nM2\n"
    done = post_program(parse_gcode(text, source="one.ngc"), load_target(target))
    assert not done.pieces
    assert any("the tool change to T2 is not written; load T2" in w for w in done.warnings)
    two = text.replace("G0 Z5\nM2", "G0 Z5\nM6 T3\nG1 X9 Y9 F100\nM2")
    assert len(post_program(parse_gcode(two, source="two.ngc"), load_target(target)).pieces) == 2


def test_pic_mmh_changes_tools_in_its_own_code() -> None:
    """UNAM-GMM's dialect has ``M06T##;``, a change to magazine position T (L3455–L3464):
    a program of two tools is one pic-mmh program with both changes, not one per tool."""

    text = "G21 G90\nM6 T1\nG0 X1 Y1\nG1 X2 F0.8\nM6 T2\nG1 X3 Y1\nM2\n"
    done = post_program(parse_gcode(text, source="two.ngc"), load_target("pic-mmh"))
    assert not done.pieces
    assert [b for b in str(done.result.code).splitlines() if b.startswith("M06")] == [
        "M06T01;",
        "M06T02;",
    ]


def _grbl_by_stop(tmp_path: Path) -> Target:
    """GRBL changing tools with a pause in one program (``by_hand = "stop"``, as a target
    file of a user whose tools are preset in length writes it)."""
    text = (ROOT / "postprocessors" / "grbl" / "grbl.toml").read_text()
    assert 'by_hand = "programs"' in text
    path = tmp_path / "grbl-stop.toml"
    path.write_text(text.replace('by_hand = "programs"', 'by_hand = "stop"'))
    return load_target(str(path))


def test_a_grbl_job_of_two_tools_is_one_program_per_tool(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """GRBL reads no line while its ``M0`` pauses (gcode.c: the pause is a feed hold inside
    the line's execution): no jog, no ``G10 L20``, so no Z zero can be set for a new tool
    there. Each tool gets its own program, run after Z zero is set for that tool; each
    rises to the clearance height, then starts the spindle, before any X/Y move."""
    done = run_job(read_drawing(PART), load_target("grbl"), load_job(JOB))
    assert [p.change.tool for p in done.pieces] == [2, 1]
    for piece in done.pieces:
        lines = str(piece.result.code).splitlines()
        assert "M0" not in lines and not any("change to" in line for line in lines)
        motion = [line for line in lines if line.startswith(("G0 ", "G1 ", "G2 ", "G3 "))]
        assert motion[0] == "G0 Z10.000"
        # the operator set Z zero on the stock's top: the spindle starts once it has risen
        spindle = next(i for i, line in enumerate(lines) if line.startswith("M3"))
        assert lines.index(motion[0]) < spindle < lines.index(motion[1])
    assert [m for p in done.pieces for m in p.program.moves] == list(done.program.moves)
    out = tmp_path / "part.gcode"
    assert main(["post", str(PART), "-t", "grbl", "--job", str(JOB), "-o", str(out)]) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["part.T1.gcode", "part.T2.gcode"]
    assert "set Z zero for each tool before its program" in capsys.readouterr().err


def test_programs_per_tool_an_earlier_run_left_are_named_not_deleted(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """An operator runs every ``part.T*.gcode`` in the folder: one an earlier run wrote
    (another job, or a tool this one no longer uses) would cut what this job does not ask
    for. Each run names those it did not write; it deletes nothing it did not write."""
    (tmp_path / "part.T3.gcode").write_text("G0 X0\n")  # an earlier job's third tool
    (tmp_path / "part.2.T1.gcode").write_text("G0 X0\n")  # a job whose tool came back
    (tmp_path / "part.T1.nc").write_text("G0 X0\n")  # another ending: another -o
    (tmp_path / "other.T1.gcode").write_text("G0 X0\n")  # another stem
    out = tmp_path / "part.gcode"
    capsys.readouterr()
    assert main(["post", str(PART), "-t", "grbl", "--job", str(JOB), "-o", str(out)]) == 0
    err = capsys.readouterr().err
    earlier = f"{tmp_path / 'part.2.T1.gcode'}, {tmp_path / 'part.T3.gcode'}: programs per tool"
    assert f"camtool: warning: {earlier} from an earlier run" in err
    assert "part.T1.gcode," not in err.split("warning:")[1]  # written now: not named
    assert (tmp_path / "part.T3.gcode").read_text() == "G0 X0\n"  # kept, as the user left it
    # one program (a machine with a changer) beside the pieces of a run for GRBL
    assert main(["post", str(PART), "-t", "linuxcnc", "--job", str(JOB), "-o", str(out)]) == 0
    err = capsys.readouterr().err
    names = ", ".join(str(tmp_path / f"part.{n}.gcode") for n in ("2.T1", "T1", "T2", "T3"))
    assert f"camtool: warning: {names}: programs per tool from an earlier run" in err


def test_after_a_change_by_hand_the_first_move_is_up_to_the_clearance_height(
    tmp_path: Path,
) -> None:
    """GRBL pauses (``M0``) for the operator to change a tool preset in length.

    The Z the program left the old tool at means nothing to the new one (another length,
    another zero), so the first move after each pause rises to the job's clearance height
    (``clearance_z = 10`` in samples/part.toml) before any X/Y move; the old tool's Z10 was
    not written again, and the next rapid crossed the part at whatever height the new tool
    was left.
    """
    done = run_job(read_drawing(PART), _grbl_by_stop(tmp_path), load_job(JOB))
    lines = str(done.result.code).splitlines()
    pauses = [i for i, line in enumerate(lines) if line == "M0"]
    assert len(pauses) == 2  # T2 (the drill) first, then T1
    for i in pauses:
        motion = next(line for line in lines[i + 1 :] if line.startswith(("G0", "G1", "G2")))
        assert motion == "G0 Z10.000", (lines[i - 1], motion)


def test_a_re_posted_move_sideways_right_after_a_change_by_hand_is_warned_of(
    tmp_path: Path,
) -> None:
    """A program for a tool changer (``T2 M6`` then ``G0 X20 Y20``) re-posted for GRBL.

    GRBL pauses (``M0``) for the change by hand; the program's next move goes sideways at
    the height the new tool was left, which camtool keeps (moves as the input gives them)
    and says. A program that rises first (the change to T1 here) is not warned of.
    """

    text = (
        "G21 G90\nT1 M6\nG0 Z5\nG0 X0 Y0\nG1 Z-1 F100\nG1 X10\nG0 Z5\n"
        "T2 M6\nG0 X20 Y20\nG1 Z-1 F100\nG1 X30\nG0 Z5\nM2\n"
    )
    done = post_program(parse_gcode(text, source="m6.ngc"), _grbl_by_stop(tmp_path))
    said = [w for w in done.warnings if "by hand" in w]
    assert len(said) == 1 and "after the tool change to T2 by hand" in said[0]
    assert "moves X/Y before any Z move" in said[0]
    code = str(done.result.code).splitlines()
    assert code[code.index("(change to T2)") + 2] == "G0 X20.000 Y20.000"  # as it was given


CUTS_THEN_CHANGES = (
    "G21 G90\nM3 S10000\nG0 Z5\nG0 X0 Y0\nG1 Z-1 F100\nG1 X10 F300\nG0 Z5\nM5\n"
    "T2 M6\nM3 S8000\nG0 Z5\nG0 X20 Y0\nG1 Z-1 F100\nG1 X30 F300\nG0 Z5\nM5\nM2\n"
)
"""A program for a tool changer that cuts with the tool loaded at its start, then changes."""


def test_a_re_post_that_cuts_before_its_first_change_is_one_program_per_tool_on_grbl(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """GRBL's ``M0`` reads no line while it pauses, so no Z zero can be set for T2 inside one
    program: the part before the change is a program of its own (the tool the input starts
    with, which it names none), then T2's; no stop, no change comment, every move kept."""
    source = tmp_path / "cuts.ngc"
    source.write_text(CUTS_THEN_CHANGES)
    program = read_gcode(source)
    done = post_program(program, load_target("grbl"))
    assert [p.change and p.change.tool for p in done.pieces] == [None, 2]
    first, second = (p.program for p in done.pieces)
    assert [(m.x, m.y) for m in first.moves if isinstance(m, Linear)] == [(0, 0), (10, 0)]
    assert [(m.x, m.y) for m in second.moves if isinstance(m, Linear)] == [(20, 0), (30, 0)]
    # T2's program first rises to Z5, where the input's tool was at the change (its own
    # "G0 Z5" after "T2 M6" moves nothing in the input, so it is no move of the input's)
    assert second.moves[0] == Rapid(10.0, 0.0, 5.0)
    assert [*first.moves, *second.moves[1:]] == list(program.moves)
    for piece in done.pieces:
        lines = str(piece.result.code).splitlines()
        assert "M0" not in lines and not any("change to" in line for line in lines)
    code = [ln for ln in str(done.pieces[1].result.code).splitlines() if not ln.startswith("(")]
    assert code[1:4] == ["G0 Z5.000", "M3 S8000", "G0 X10.000 Y0.000"]
    out = tmp_path / "cuts.gcode"
    assert main(["post", str(source), "-t", "grbl", "-o", str(out)]) == 0
    written = sorted(p.name for p in tmp_path.iterdir() if p.suffix == ".gcode")
    assert written == ["cuts.T2.gcode", "cuts.start.gcode"]
    err = capsys.readouterr().err
    assert "cuts.start.gcode (the tool loaded at the start), then" in err
    assert "moves X/Y before any Z move" not in err  # T2's program rises first


def test_a_change_at_the_end_of_a_re_post_that_cut_before_it_writes_one_program() -> None:
    """``T2 M6`` just before ``M2`` (nothing cut with T2): no program for T2, no stop at the
    end; the one program cuts with the tool loaded at its start, as the input does."""
    text = CUTS_THEN_CHANGES.split("T2 M6")[0] + "T2 M6\nM0\nM2\n"
    done = post_program(parse_gcode(text, source="end.ngc"), load_target("grbl"))
    assert done.pieces == ()
    lines = str(done.result.code).splitlines()
    assert "M0" not in lines and not any("T2" in line for line in lines)
    assert [line for line in lines if line.startswith("G1 X")] == ["G1 X10.000 Y0.000 F300"]
    assert "no program for T2: the program cuts nothing after changing to it" in done.warnings


def test_a_program_per_tool_that_moves_sideways_first_rises_to_the_input_s_height(
    tmp_path: Path,
) -> None:
    """Without its ``G0 Z5`` after ``T2 M6`` the input goes sideways at Z5, where its tool
    was at the change; T2's program, whose Z zero was just set on the stock's top, rises
    there first instead of going sideways on the stock."""
    source = tmp_path / "cuts.ngc"
    source.write_text(CUTS_THEN_CHANGES.replace("M3 S8000\nG0 Z5\n", "M3 S8000\n"))
    done = post_program(read_gcode(source), load_target("grbl"))
    assert not [w for w in done.warnings if "before any Z move" in w]
    code = str(done.pieces[1].result.code).splitlines()
    assert "(rises to Z5 first: the input's height at its tool change)" in code
    start = code.index("G0 Z5.000")
    assert code[start : start + 3] == ["G0 Z5.000", "M3 S8000", "G0 X20.000 Y0.000"]


def test_a_program_per_tool_sideways_where_the_input_set_no_height_is_warned_of(
    tmp_path: Path,
) -> None:
    """An input that never set Z before its change (drawn flat) gives no height to rise
    to: T2's program goes sideways as the input gives it, and that is said."""
    source = tmp_path / "flat.ngc"
    source.write_text(
        "G21 G90\nM3 S1000\nG0 X0 Y0\nG1 X10 F300\nM5\nT2 M6\nM3 S1000\n"
        "G0 X20 Y0\nG1 X30 F300\nM5\nM2\n"
    )
    done = post_program(read_gcode(source), load_target("grbl"))
    said = [w for w in done.warnings if "before any Z move" in w]
    assert said == [
        "grbl program 2 (T2) moves X/Y before any Z move: that move runs at the height where "
        "Z zero was set for the tool, on the stock's top; add a move up to a safe height "
        "after the tool change in the input"
    ]
    code = str(done.pieces[1].result.code).splitlines()
    assert code[code.index("M3 S1000") + 1] == "G0 X20.000 Y0.000"  # as the input gives it
    # a machine without Z (the router's pen is set by hand) has no such height to warn of
    router = post_program(read_gcode(source), load_target("matlab-router"))
    assert len(router.pieces) == 2 and not any("before any Z" in w for w in router.warnings)


PCB2GCODE_DRILL = """( pcb2gcode 2.5.0 )
G94 ( Millimeters per minute feed rate. )
G21 ( Units == Millimeters. )
G90 ( Absolute coordinates. )
G00 S10000 ( RPM spindle speed. )
G01 F600.00000 ( Feedrate. )
G00 Z10.00000 (Retract to tool change height)
T1
M5      (Spindle stop.)
(MSG, Change tool bit to drill size 0.8mm)
M6      (Tool change.)
M0      (Temporary machine stop.)
M3      (Spindle on clockwise.)
G00 Z1.00000
G00 X2.00000 Y2.00000
G01 Z-1.50000 F50.00000
G01 Z1.00000
G00 X4.00000 Y2.00000
G01 Z-1.50000
G01 Z1.00000
G00 Z10.00000 (Retract to tool change height)
T2
M5      (Spindle stop.)
(MSG, Change tool bit to drill size 1.0mm)
M6      (Tool change.)
M0      (Temporary machine stop.)
M3      (Spindle on clockwise.)
G00 Z1.00000
G00 X6.00000 Y3.00000
G01 Z-1.50000
G01 Z1.00000
G00 Z10.00000 (All done -- retract)
M5      (Spindle off.)
M9      (Coolant off.)
M2      (Program end.)
"""
"""A drill file in the form of pcb2gcode 2.5's (its test data: testing/gerbv_example/*/expected/
drill.ngc), shortened to two drills and three holes, the tool change height 10 mm for
flashcut's 20 mm of Z: a retract before the first change, each change ``M6`` then ``M0``."""


def test_a_pcb2gcode_drill_file_is_one_program_per_drill_for_a_machine_without_a_changer(
    tmp_path: Path,
) -> None:
    """The retract before T1 is the first program's; each change's ``M0`` is its program's
    start (flashcut has no stop to write for it); every move is kept, in order."""
    source = tmp_path / "drill.ngc"
    source.write_text(PCB2GCODE_DRILL)
    program = read_gcode(source)
    job = post_program(program, load_target("flashcut"))
    assert [p.change.tool for p in job.pieces] == [1, 2]
    first, second = (p.program for p in job.pieces)
    assert (first.moves[0].x, first.moves[0].y, first.moves[0].z) == (0.0, 0.0, 10.0)
    assert [(m.x, m.y) for m in first.moves if m.z == -1.5] == [(2.0, 2.0), (4.0, 2.0)]
    assert [(m.x, m.y) for m in second.moves if m.z == -1.5] == [(6.0, 3.0)]
    assert len(first.moves) + len(second.moves) == len(program.moves)
    assert not any(isinstance(c, Stop) for p in job.pieces for _, c in p.program.commands)
    assert all(
        "stop after this change is this program's start" in " ".join(p.program.notes)
        for p in job.pieces
    )
    said = [[n for n in p.program.notes if n.startswith("its message")] for p in job.pieces]
    assert said == [  # the (MSG, ...) before each change's M0, in its program's header
        ["its message: Change tool bit to drill size 0.8mm"],
        ["its message: Change tool bit to drill size 1.0mm"],
    ]


def test_a_stop_that_is_not_a_changes_own_stays_and_is_refused_where_it_cannot_be_written(
    tmp_path: Path,
) -> None:
    """A stop between two holes (not right after a change) is kept: flashcut refuses it."""
    source = tmp_path / "drill.ngc"
    source.write_text(PCB2GCODE_DRILL.replace("G00 X4.00000 Y2.00000", "M0\nG00 X4.00000 Y2.00000"))
    with pytest.raises(DialectError, match="never dropped"):
        post_program(read_gcode(source), load_target("flashcut"))


def test_a_pcb2gcode_program_of_one_tool_is_that_tools_program(tmp_path: Path) -> None:
    """pcb2gcode's isolation and outline files: one change (``M6`` ``M0``) after a retract.

    For flashcut (no changer, no stop) the program is written without the change and its
    stop, saying which tool to load; every move kept.
    """
    one = PCB2GCODE_DRILL[
        : PCB2GCODE_DRILL.index("G00 Z10.00000 (Retract to tool change height)\nT2")
    ]
    source = tmp_path / "outline.ngc"
    source.write_text(one + "M2\n")
    program = read_gcode(source)
    done = post_program(program, load_target("flashcut"))
    assert not done.pieces
    assert done.program.moves == program.moves
    assert not any(isinstance(c, Stop | ToolChange) for _, c in done.program.commands)
    assert "the program's stop after this change is this program's start" in done.program.notes
    assert any("the tool change to T1 is not written; load T1" in w for w in done.warnings)


def test_a_pcb2gcode_change_and_its_own_stop_pause_grbl_once(tmp_path: Path) -> None:
    """Changing tools by hand with a stop: ``M6`` then ``M0`` is one pause, not two."""
    source = tmp_path / "drill.ngc"
    source.write_text(PCB2GCODE_DRILL)
    target = _grbl_by_stop(tmp_path)
    lines = str(post_program(read_gcode(source), target).result.code).splitlines()
    stops = [i for i, line in enumerate(lines) if line == "M0"]
    assert [lines[i - 1] for i in stops] == [  # with the (MSG, ...) of the own stop
        "(change to T1: Change tool bit to drill size 0.8mm)",
        "(change to T2: Change tool bit to drill size 1.0mm)",
    ]


def test_pic_mmh_changes_pcb2gcodes_tools_itself_without_their_stops(tmp_path: Path) -> None:
    """pic-mmh changes tools by code (``M06T##;``) and has no stop: a change's own ``M0``
    (pcb2gcode's pause to change the bit by hand) is not written, said once; a stop of
    the program's own between two holes is still refused."""
    source = tmp_path / "drill.ngc"
    source.write_text(PCB2GCODE_DRILL.replace("S10000", "S9000"))  # pic-mmh's 4 digits
    done = post_program(read_gcode(source), load_target("pic-mmh"))
    code = str(done.result.code).splitlines()
    assert [b for b in code if b.startswith("M06")] == ["M06T01;", "M06T02;"]
    assert not any(b.startswith(("M00", "M01")) for b in code)
    assert [w for w in done.warnings if "stop(s) right after a tool change" in w] == [
        "2 stop(s) right after a tool change (M6 then M0: a pause to change the tool by hand) "
        "not written: pic-mmh changes tools itself and has no stop"
    ]
    between = PCB2GCODE_DRILL.replace("S10000", "S9000").replace(
        "G00 X4.00000 Y2.00000", "M0\nG00 X4.00000 Y2.00000"
    )
    source.write_text(between)
    with pytest.raises(DialectError, match="no program stop"):
        post_program(read_gcode(source), load_target("pic-mmh"))


def test_a_pcb2gcode_drill_file_per_tool_is_verified_as_written(tmp_path: Path) -> None:
    """``--verify`` reads the programs per tool back one after the other: the changes'
    own stops are left out there too (it stopped at the first, which flashcut cannot write)."""
    source = tmp_path / "drill.ngc"
    source.write_text(PCB2GCODE_DRILL)
    out = tmp_path / "drill.nc"
    code = main(["post", str(source), "-t", "flashcut", "-o", str(out), "--verify"])
    assert code == 0
    assert (tmp_path / "drill.T1.nc").is_file() and (tmp_path / "drill.T2.nc").is_file()


def test_a_change_after_which_nothing_is_cut_gets_no_program(tmp_path: Path) -> None:
    """T2 loaded at the end, and T3 changed again at once to T4: no program for either
    (it would hold nothing); the rapid before the first change stays the
    first program's, and every cut is in the program of the tool that makes it."""
    text = (
        "G21 G90\nG0 Z5\nT1 M6\nG0 X1 Y1\nG1 Z-1 F100\nG1 X5\nG0 Z5\n"
        "T3 M6\nM3\nT4 M6\nM3\nG0 X2 Y2\nG1 Z-1\nG1 X3\nG0 Z5\nT2 M6\nM2\n"
    )
    source = tmp_path / "idle.ngc"
    source.write_text(text)
    program = read_gcode(source)
    done = post_program(program, load_target("flashcut"))
    assert [p.change.tool for p in done.pieces] == [1, 4]
    first, second = (p.program for p in done.pieces)
    assert (first.moves[0].x, first.moves[0].y, first.moves[0].z) == (0.0, 0.0, 5.0)
    assert [(m.x, m.y) for m in first.moves if m.z == -1.0] == [(1.0, 1.0)]
    assert [(m.x, m.y) for m in second.moves if m.z == -1.0] == [(2.0, 2.0)]
    # T4's goes sideways first in the input, at Z5: its program rises there first
    assert second.moves[0] == Rapid(5.0, 1.0, 5.0)
    assert len(first.moves) + len(second.moves) == len(program.moves) + 1
    assert any("no program for T3, T2: the program cuts nothing after" in w for w in done.warnings)
