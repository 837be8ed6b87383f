"""G-code import keeps spindle, dwell, tool change and G28 as Program.commands."""

from __future__ import annotations

from pathlib import Path

import pytest

from camtool.importers.gcode import parse_gcode, read_gcode
from camtool.jobs.pipeline import post_program
from camtool.model.errors import InputError
from camtool.model.program import Dwell, Home, Linear, Program, Rapid, Spindle, Stop, ToolChange
from camtool.post.registry import load_target

DATA = Path(__file__).parents[1] / "data"


def parse(text: str) -> Program:
    return parse_gcode(text, source="t.ngc")


def test_spindle_dwell_and_tool_change_before_the_next_move() -> None:
    program = parse(
        "G21\n"
        "T3 M6\n"
        "S1200 M3\n"
        "G0 X1 Y1\n"
        "G4 P2.5\n"
        "G1 X2 F10\n"
        "M4\n"  # reverses at the modal S
        "G1 Y2\n"
        "M5\n"
        "M30\n"
    )
    assert program.commands == (
        (0, ToolChange(3)),
        (0, Spindle("cw", 1200.0)),
        (1, Dwell(2.5)),
        (2, Spindle("ccw", 1200.0)),
        (3, Spindle("off")),  # after the last move
    )
    assert program.warnings == ()


def test_order_of_execution_within_a_block() -> None:
    # RS-274/NGC (LinuxCNC "Order of Execution"): S, T, M6, M3/M4/M5, G4, then G28 and
    # motion (G4 and G28 are both non-modal: one block takes one of them).
    program = parse("G21 G0 X1 Y1\nG4 P1 M3 S500 M6 T2\nM5 S600 G28 X0 Y0\nG0 X3 Y3\nG1 X4 F9\n")
    assert program.commands == (
        (1, ToolChange(2)),
        (1, Spindle("cw", 500.0)),
        (1, Dwell(1.0)),
        (1, Spindle("off")),
        (2, Home("XY")),  # after its intermediate rapid to (0, 0)
    )
    assert program.moves[1] == Rapid(0.0, 0.0, contour=1)


def test_s_changes_a_turning_spindle_only() -> None:
    program = parse("G21 S100\nG0 X1 Y1\nS200\nM3\nG0 X2\nS300\nS300\nM5\nS400\nG1 X3 F9\nM2\n")
    assert program.commands == (
        (1, Spindle("cw", 200.0)),  # S100 then S200 while off: M3 takes the last
        (2, Spindle("cw", 300.0)),  # S300 while on: a new speed (the repeat changes nothing)
        (2, Spindle("off")),
    )


def test_bare_m3_has_no_speed_and_no_warning() -> None:
    # Gcodetools writes `M3` without S (tests/data/gcodetools-circle.ngc, Munoz-22 §3.3).
    program = read_gcode(DATA / "gcodetools-circle.ngc")
    assert program.commands == ((0, Spindle("cw")), (7, Spindle("off")))  # rpm None
    assert program.warnings == ()


def test_g28_is_a_home_command_on_the_axes_it_names() -> None:
    program = parse(
        "G21 G0 X1 Y1 Z1\nG91 G28 Z0\nG90 G28\nG28 X0 Y0\nG0 X2 Y2\nG30\nG0 X3 Y3\nG1 X4 F9\nM2\n"
    )
    assert program.commands == (
        (1, Home("Z")),  # incremental 0: no intermediate move
        (1, Home("XYZ")),
        (2, Home("XY")),  # after the rapid to the intermediate point (0, 0)
        (3, Home("XYZ", "G30")),  # the second stored position, not G28's
    )
    (g28, g30) = program.warnings
    assert g28.startswith("t.ngc:2: G28 return to the machine's stored position: kept as")
    assert g28.endswith("(3 times)")
    assert g30.startswith("t.ngc:6: G30 return to the machine's stored position: kept as")


def test_an_operator_message_goes_with_the_stop_after_it() -> None:
    """LinuxCNC shows ``(MSG, ...)`` to the operator: pcb2gcode names the bit to load there,
    before its ``M0``. The text is the stop's message (after the tool a ``T`` selected);
    one with a move before the stop is a comment like any other."""
    program = parse(
        "G21 G0 X0 Y0 Z5\nT3\n(MSG, Change tool bit to mill  diameter 0.12000mm)\nM0\n"
        "G1 X1 Y1 F100\n(msg,after the move)\nG1 X2 Y2\nM1\n(MSG,)\nM0\nM2\n"
    )
    assert [c for _, c in program.commands] == [
        Stop(False, "change to T3: Change tool bit to mill diameter 0.12000mm"),
        Stop(True, ""),
        Stop(False, ""),
    ]


def test_tool_selection_without_m6_and_m6_without_tool_warn() -> None:
    program = parse("G21 T4\nG0 X1 Y1\nT5\nM6\nT6\nG1 X2 F9\nM6\nT7\nM2\n")
    assert program.commands == ((1, ToolChange(5)), (2, ToolChange(6)))
    assert program.warnings == (
        "t.ngc:1: tool number T4 ignored: no M6 after it changes to that tool (2 times)",
    )  # T4 (replaced by T5) and T7 (the program ends)
    lonely = parse("G21 M6\nG1 X1 Y1 F9\nM2\n")
    assert lonely.commands == ()
    assert lonely.warnings == ("t.ngc:1: M6 without a T word: no tool selected, ignored",)


@pytest.mark.parametrize(
    ("block", "message"),
    [
        ("S-100 M3", "negative spindle speed S-100"),
        ("T1.5 M6", "T1.5: tool numbers are whole numbers ≥ 0"),
        ("T-1", "T-1: tool numbers are whole numbers"),
        ("G4 P-1", "G4 dwell needs a P word"),
    ],
)
def test_bad_command_words_are_refused_naming_the_line(block: str, message: str) -> None:
    with pytest.raises(InputError, match=r"^t\.ngc:2: ") as info:
        parse(f"G21 G0 X1 Y1\n{block}\n")
    assert message in str(info.value)


def test_reposted_to_pic_mmh_with_its_commands() -> None:
    # A typical program re-posted to pic-mmh (UNAM-GMM §3.8: the thesis users edited CAM
    # output by hand): Z moves are dropped (S000-08) and the commands are written in the
    # syntax of Tablas 21-22 at their new places.
    program = parse(
        "G21 G90\n"
        "M6 T1\n"
        "S2000 M3\n"
        "G0 Z1\n"
        "G0 X1 Y1\n"
        "G1 Z-0.1 F0.8\n"
        "G4 P3\n"
        "G1 X2 Y1\n"
        "G0 Z1\n"
        "M5\n"
        "G91 G28 Z0\n"
        "M30\n"
    )
    job = post_program(program, load_target("pic-mmh"))
    assert str(job.result.code).splitlines() == [
        "G54;",
        "G90;",
        "M06T01;",
        "M03S2000;",
        "G00X01000.00Y01000.00;",
        "G04P03;",
        "G01X02000.00Y01000.00F08;",
        "M05;",
        "G28Z0;",
        "M30;",
    ]
    back = load_target("pic-mmh").post.parse(str(job.result.code))
    assert back.commands == job.program.commands
    assert back.moves == (Rapid(1.0, 1.0, contour=1), Linear(2.0, 1.0, 0.8, contour=1))
