"""G-code import: RS-274 as CAM programs write it, FlashCut (Yanez-07 §3), Gcodetools (Munoz-22)."""

from __future__ import annotations

import codecs
import dataclasses
import math
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from camtool.importers.gcode import parse_gcode, parse_gcode_slow, read_gcode
from camtool.importers.gcode_target import Reading
from camtool.model.errors import InputError
from camtool.model.program import ArcMove, Home, Linear, Move, Program, Rapid, Spindle, Stop
from camtool.model.shapes import Arc
from camtool.post.registry import load_target

DATA = Path(__file__).parents[1] / "data"
SQRT2 = math.sqrt(2.0)


def parse(text: str) -> Program:
    return parse_gcode(text, source="t.ngc")


def arcs(program: Program) -> list[Arc]:
    return [seg for _, seg in program.segments() if isinstance(seg, Arc)]


def rows(moves: tuple[Move, ...]) -> list[tuple[object, ...]]:
    """Moves as (kind, fields...) rows, for pytest.approx on inch-converted numbers."""
    return [(type(m).__name__, *dataclasses.astuple(m)) for m in moves]


def refused(text: str) -> str:
    with pytest.raises(InputError) as info:
        parse(text)
    return str(info.value)


# -- Yanez-07 (FlashCut, Yáñez Soto 2007) --------------------------------------------------


def test_seed001_r2_g02_golden_arc() -> None:
    # Yanez-07 §10 R2 / §3.3 (L1004-1005): centre (2,2), r = √2, CW sweep −180°,
    # passing through (2−√2, 2).
    program = parse("G01 X1.0 Y1.0 F3.0\nG02 X3.0 Y3.0 I1.0 J1.0\n")
    line, arc_move = program.moves
    assert line == Linear(1.0, 1.0, 3.0, contour=1)
    assert arc_move == ArcMove(3.0, 3.0, 2.0, 2.0, True, 3.0, contour=1)  # F modal (R3)
    (arc,) = arcs(program)
    assert arc.radius == pytest.approx(SQRT2)
    assert arc.sweep == pytest.approx(-math.pi)
    # 225° → 180° is a quarter of the sweep
    assert arc.point_at(0.25) == pytest.approx((2.0 - SQRT2, 2.0))


def test_seed001_r2_g03_golden_arc() -> None:
    # Yanez-07 §10 R2 / §3.3 (L1020-1021): centre (1,2), CCW +180°, through (1+√2, 2).
    program = parse("G01 X2.0 Y1.0 F8.0\nG03 X0.0 Y3.0 I-1.0 J1.0\n")
    assert program.moves[1] == ArcMove(0.0, 3.0, 1.0, 2.0, False, 8.0, contour=1)
    (arc,) = arcs(program)
    assert arc.radius == pytest.approx(SQRT2)
    assert arc.sweep == pytest.approx(math.pi)
    assert arc.point_at(0.25) == pytest.approx((1.0 + SQRT2, 2.0))


def test_flashcut_file_with_the_four_literal_examples() -> None:
    # tests/data/flashcut-seed001.nc: Yanez-07 §3.3's four lines in one file (CR LF ends);
    # no units anywhere (mm implied, §3.3) → a warning naming line 1; no M2/M30 either (the
    # thesis shows four lines, not a whole program) → a warning naming the last block.
    program = read_gcode(DATA / "flashcut-seed001.nc")
    assert program.moves == (
        Linear(1.0, 1.0, 3.0, contour=1),
        ArcMove(3.0, 3.0, 2.0, 2.0, True, 3.0, contour=1),
        Linear(2.0, 1.0, 8.0, contour=1),
        ArcMove(0.0, 3.0, 1.0, 2.0, False, 8.0, contour=1),
    )
    assert program.origin == (0.0, 0.0)
    units, end = program.warnings
    assert units.startswith(f"{DATA / 'flashcut-seed001.nc'}:1: no G20/G21")
    assert end.startswith(f"{DATA / 'flashcut-seed001.nc'}:4: no M2/M30")


def test_flashcut_n_words_comments_and_m_codes_are_tolerated() -> None:
    # Yanez-07 R1 (M00/M02/M03/M04/M05/M30) and R5 (N-words, comments): the program loads.
    program = parse(
        "%\n"
        "N1 (LMM logo) M03\n"
        "N2 G00 X1.0 Y1.0 ; start\n"
        "N3 G01 X2.0 Y1.0 F3.0\n"
        "N4 M00\n"
        "N5 M04\n"
        "N6 G01 X2.0 Y2.0\n"
        "N7 M05\n"
        "N8 M30\n"
        "%\n"
    )
    assert [type(m) for m in program.moves] == [Rapid, Linear, Linear]
    assert program.moves[-1] == Linear(2.0, 2.0, 3.0, contour=1)
    assert program.commands[1:3] == ((2, Stop()), (2, Spindle("ccw")))  # M00: kept


def test_flashcut_missing_axis_word_keeps_its_value() -> None:
    # Yanez-07 R4: the app refused `G01 X2.0` without Y; camtool reads leniently (RS-274).
    program = parse("G21 G01 X1.0 Y1.0 F3.0\nG01 X2.0\nG00 Y5.0\n")
    assert program.moves[1] == Linear(2.0, 1.0, 3.0, contour=1)
    assert program.moves[2] == Rapid(2.0, 5.0, contour=2)


def test_g20_g21_have_their_modern_meaning() -> None:
    # Yanez-07 R6: G20/G21 are inch/mm, not the textbook's interpolation codes.
    program = parse("G20 G1 X1 Y2 F10\nG21 G1 X1 Y2\n")
    assert program.moves[0] == Linear(25.4, 50.8, 254.0, contour=1)
    assert program.moves[1] == Linear(1.0, 2.0, 254.0, contour=1)  # feed stays physical


# -- Munoz-22 (Gcodetools .ngc, S004-R07) -------------------------------------------------


def test_gcodetools_ngc_file() -> None:
    # tests/data/gcodetools-circle.ngc, written as Gcodetools 0.7 writes (header/footer
    # comments, G21, G00 Z5 retracts, G01 Z-1 F100 (Penetrate), G02 X Y Z I J F400, M2).
    # Munoz-22 §3.3: cut depth Z = −1 mm.
    program = read_gcode(DATA / "gcodetools-circle.ngc", source_name="logo.ngc")
    assert program.moves == (
        Rapid(0.0, 0.0, 5.0, contour=1),
        Rapid(5.0, 10.0, contour=1),
        Linear(5.0, 10.0, 100.0, -1.0, contour=1),
        ArcMove(15.0, 10.0, 10.0, 10.0, True, 400.0, contour=1),  # Z-1 unchanged: no z
        ArcMove(5.0, 10.0, 10.0, 10.0, True, 400.0, contour=1),
        Linear(5.0, 20.0, 400.0, contour=1),
        Rapid(5.0, 20.0, 5.0, contour=2),
        Rapid(0.0, 0.0, contour=2),
    )
    assert program.warnings == ()
    assert program.lines == (12, 13, 15, 16, 17, 18, 19, 26)  # 1-based file lines
    assert sum(arc.length for arc in arcs(program)) == pytest.approx(2 * math.pi * 5.0)


def test_linuxcnc_inch_file_with_absolute_centres_and_r_arcs() -> None:
    # tests/data/linuxcnc-inch.tap: G20, G90.1 absolute I/J, R-form, N-words, preamble codes.
    program = read_gcode(DATA / "linuxcnc-inch.tap", source_name="p.tap")
    expected = (
        Rapid(0.0, 0.0, 2.54, contour=1),
        Rapid(0.0, 0.0, contour=1),
        Linear(0.0, 0.0, 50.8, -0.254, contour=1),
        Linear(25.4, 0.0, 254.0, contour=1),
        ArcMove(38.1, 12.7, 25.4, 12.7, False, 254.0, contour=1),  # centre (1, 0.5) in
        ArcMove(50.8, 25.4, 50.8, 12.7, True, 254.0, contour=1),  # R0.5 → centre (2, 0.5) in
        Rapid(50.8, 25.4, 2.54, contour=2),
    )
    assert rows(program.moves) == [pytest.approx(row, abs=1e-12) for row in rows(expected)]
    assert program.warnings == (
        "p.tap:3: G40 (cutter compensation off) read as a no-op",
        "p.tap:3: G49 (tool length offset off) read as a no-op",
        "p.tap:3: G54 work offset assumed 0: coordinates are taken from the part zero",
    )


# -- RS-274 rules ---------------------------------------------------------------------------


def test_r_form_positive_and_negative() -> None:
    # LinuxCNC "G2 G3 Arcs", radius format: R > 0 turns ≤ 180°, R < 0 more than 180°.
    r = repr(SQRT2)
    program = parse(f"G21 G1 X0 Y0 F10\nG2 X2 Y0 R{r}\nG2 X0 Y0 R-{r}\nG3 X2 Y0 R{r}\n")
    short_cw, long_cw, short_ccw = arcs(program)
    assert short_cw.centre == pytest.approx((1.0, -1.0))
    assert short_cw.sweep == pytest.approx(-math.pi / 2)
    assert long_cw.centre == pytest.approx((1.0, -1.0))
    assert long_cw.sweep == pytest.approx(-3 * math.pi / 2)
    assert short_ccw.centre == pytest.approx((1.0, 1.0))
    assert short_ccw.sweep == pytest.approx(math.pi / 2)


def test_g90_1_absolute_and_g91_1_incremental_centres() -> None:
    program = parse("G21 G0 X4 Y1\nG90.1 G3 X6 Y3 I4 J3 F5\nG91.1 G2 X8 Y5 I2 J0\n")
    first, second = program.moves[1:]
    assert isinstance(first, ArcMove) and (first.cx, first.cy) == (4.0, 3.0)
    assert isinstance(second, ArcMove) and (second.cx, second.cy) == (8.0, 3.0)


def test_g91_incremental_xy_and_modal_motion() -> None:
    program = parse("G21 G91 G1 X1 Y1 F100\nX1 Y1\nX-2\nG90 X5 Y5\n")
    assert [(m.x, m.y) for m in program.moves] == [(1, 1), (2, 2), (0, 2), (5, 5)]
    assert all(isinstance(m, Linear) and m.feed_mm_min == 100.0 for m in program.moves)


@pytest.mark.parametrize(
    ("text", "start"),
    [
        ("G21 G91 G1 X1 Y1 F100\n", "t.ngc:1: incremental X1 (G91) before the program gives"),
        ("G21 G90 G0 Z5\nG91 G0 Y-2\nG1 X1 F9\n", "t.ngc:2: incremental Y-2 (G91) before"),
        (
            "G21 G0 X3\nG0 Y4\nG1 X5 Y5 F9\n",
            "t.ngc:1: G0 X3 gives X but not Y, and the program has not",
        ),
        ("G21 G0 Z5\nG1 Y4 Z-1 F9\n", "t.ngc:2: G1 Y4 gives Y but not X"),
        ("G21 G0 Z5\nG2 X10 Y0 I5 J0 F9\n", "t.ngc:2: G2 starts from where the machine"),
        ("G21 G0 Z5\nG3 I5 J0 F9\n", "t.ngc:2: G3 starts from where the machine"),
        ("G21 G0 Z5\nG2 X10 Y0 R5 F9\n", "t.ngc:2: G2 starts from where the machine"),
        ("G21 G18 G0 Z5\nG2 X10 Z5 I5 K0 F9\n", "t.ngc:2: G2 starts from where the machine"),
    ],
)
def test_a_first_move_that_depends_on_where_the_machine_stands_is_not_written_again(
    text: str, start: str
) -> None:
    """Until the program gives X and Y, the machine is wherever it stands, not at the guess.

    RS-274/NGC keeps an axis a block does not name where it is, and G91 moves from there;
    rs274 and GRBL take that position from the machine. camtool's (0, 0) is a guess: read
    for a post, a move whose end or centre depends on it would be written again from the
    guess (``G0 X3`` as ``G0 X3 Y0``), so it is refused, naming the line and the remedy.
    Read as written (preview, send), the guess stands, as before.
    """
    with pytest.raises(InputError) as info:
        parse_gcode(text, source="t.ngc", reading=Reading(known_start=True))
    message = str(info.value)
    assert message.startswith(start), message
    assert "cannot know" in message and "G0" in message
    assert parse(text).moves  # read as written: from the program's zero


def test_a_first_move_that_does_not_depend_on_the_start_is_written_again() -> None:
    """Both axes absolute, a Z alone, a cut to X Y: the same wherever the machine stands."""
    program = parse_gcode(
        "G21 G0 Z5\nG1 Z-1 F9\nG1 X2 Y3\nG91 X1\nG90 G2 X5 Y3 R1 F9\n",
        source="t.ngc",
        reading=Reading(known_start=True),
    )
    assert [(type(m).__name__, m.x, m.y) for m in program.moves] == [
        ("Rapid", 0.0, 0.0),
        ("Linear", 0.0, 0.0),
        ("Linear", 2.0, 3.0),
        ("Linear", 3.0, 3.0),
        ("ArcMove", 5.0, 3.0),
    ]


def test_full_circle_without_axis_words() -> None:
    # LinuxCNC centre format: an arc ending where it starts is a full circle.
    program = parse("G21 G0 X5 Y0\nG3 I-5 J0 F60\n")
    (circle,) = arcs(program)
    assert circle.is_full_circle and circle.centre == (0.0, 0.0)
    assert circle.length == pytest.approx(2 * math.pi * 5)


def test_g0_with_f_keeps_f_modal() -> None:
    # Yanez-07 R3: G00 ignores F for its own speed, but F stays set.
    program = parse("G21 G0 X1 Y0 F50\nG1 X2\n")
    assert program.moves == (Rapid(1.0, 0.0, contour=1), Linear(2.0, 0.0, 50.0, contour=1))


@pytest.mark.parametrize(
    ("text", "x", "y"),
    [
        ("G01X1.Y2", 1.0, 2.0),
        ("g1 x.5 y-0.", 0.5, 0.0),
        ("G1 X+1 Y-.25", 1.0, -0.25),
        ("G 0 1 X 1 . 5 Y 2", 1.5, 2.0),
        ("N0010G01X1Y2(comment)", 1.0, 2.0),
        ("/G1 X1 Y2", 1.0, 2.0),
        ("G1\u00a0X1\u00a0.5 Y2", 1.5, 2.0),  # a no-break space is a blank, as a space is
    ],
)
def test_word_syntax(text: str, x: float, y: float) -> None:
    (move,) = parse(f"G21 F1\n{text}\n").moves
    assert (move.x, move.y) == (x, y)


def test_z_is_carried_when_it_changes_and_helix() -> None:
    program = parse("G21 G0 Z0\nG0 X0 Y0\nG1 Z0 F10\nG1 Z-1 X1\nG2 X3 Y0 I1 J0 Z-2\nG1 X4 Z-2\n")
    assert [m.z for m in program.moves] == [0.0, None, None, -1.0, -2.0, None]
    assert isinstance(program.moves[4], ArcMove)


def test_contours_start_at_rapids_after_cutting() -> None:
    program = parse("G21 G0 X1 Y1\nG0 Z1\nG1 X2 F9\nG1 X3\nG0 Z5\nG0 X0\nG1 Y1\nG0 X9\n")
    assert [m.contour for m in program.moves] == [1, 1, 1, 1, 2, 2, 2, 3]


def test_checksum_is_verified() -> None:
    line = "N1 G1 X1 Y1 F10"
    checksum = 0
    for c in line.encode():
        checksum ^= c
    (move,) = parse(f"G21\n{line}*{checksum}\n").moves
    assert (move.x, move.y) == (1.0, 1.0)
    message = refused(f"G21\n{line}*{(checksum + 1) % 256}\n")
    assert message.startswith("t.ngc:2: checksum") and "damaged" in message


ARC_ENDS = [
    # (units, arc from X0 Y0, whether LinuxCNC 2.9's rs274 runs it): a half circle whose end
    # is e off its circle, or an R arc short of half its chord
    ("G21", "G2 X20.004 Y0 I10 J0", True),  # e = 0.004 mm
    ("G21", "G2 X40.027 Y0 I20 J0", True),  # 0.027 mm (0.13 %) ≤ 0.0283 mm
    ("G21", "G2 X40.029 Y0 I20 J0", False),  # 0.029 mm and 0.14 %
    ("G21", "G2 X200.09 Y0 I100 J0", True),  # 0.09 mm, 0.09 %
    ("G21", "G2 X200.11 Y0 I100 J0", False),  # 0.11 mm, 0.11 %
    ("G21", "G2 X10002.7 Y0 I5000 J0", True),  # 0.054 %, ≤ 2.83 mm
    ("G21", "G2 X10002.9 Y0 I5000 J0", False),  # over 2.83 mm
    ("G20", "G2 X2.0027 Y0 I1 J0", True),  # 0.0027 in ≤ 0.00283 in
    ("G20", "G2 X2.0029 Y0 I1 J0", False),
    ("G20", "G2 X20.009 Y0 I10 J0", True),  # 0.09 %
    ("G20", "G2 X20.011 Y0 I10 J0", False),
    ("G21", "G2 X20.0024 Y0 R10", True),  # R 0.0012 mm short of half the chord ≤ 0.00127
    ("G21", "G2 X20.003 Y0 R10", False),  # 0.0015 mm short
    ("G20", "G2 X2.00008 Y0 R1", True),  # 0.00004 in short ≤ 0.00005 in
    ("G20", "G2 X2.00012 Y0 R1", False),  # 0.00006 in short
]
"""Arcs at the edges of LinuxCNC's tolerances (``interp_arc.cc``: I/J ends within 2·0.01·√2
mm, or 0.1 % of the larger radius up to 100 times that; 2·0.001·√2 in and 0.283 in in
G20; an R 0.00127 mm or 0.00005 in short of half the chord), each run through ``rs274``:
tests/corpus/test_rs274.py runs them again where it is installed."""


def arc_program(units: str, arc: str) -> str:
    """The program of an :data:`ARC_ENDS` case."""
    return f"{units} G1 X0 Y0 F1\n{arc}\n"


@pytest.mark.parametrize(("units", "arc", "runs"), ARC_ENDS)
def test_arc_end_tolerance_of_linuxcnc(units: str, arc: str, runs: bool) -> None:
    if runs:
        assert len(parse(arc_program(units, arc)).moves) == 2
    else:
        message = refused(arc_program(units, arc))
        assert message.startswith("t.ngc:2: G2 ")
        assert ("off its circle" in message) != ("less than half" in message)


def test_an_arc_off_its_circle_is_named_with_linuxcncs_limits() -> None:
    ok = parse("G21 G1 X0 Y0 F1\nG2 X20.004 Y0 I10 J0\n")  # accepted as written
    assert ok.moves[1] == ArcMove(20.004, 0.0, 10.0, 0.0, True, 1.0, contour=1)
    assert not any("off its circle" in w for w in ok.warnings)  # within 0.005 mm: no note
    noted = parse("G21 G1 X0 Y0 F1\nG2 X40.027 Y0 I20 J0\nG2 X80.047 Y0 I20 J0\n")
    assert [w for w in noted.warnings if "off its circle" in w] == [
        "t.ngc:2: G2 ends 0.0270 mm off its circle, read as written (LinuxCNC cuts it as a "
        "spiral; verify cuts it on its start's circle, then a chord to its end: the offset "
        "shows in its deviation) (2 times)"
    ]
    message = refused("G21 G1 X0 Y0 F1\nG2 X40.029 Y0 I20 J0\n")
    assert message.startswith("t.ngc:2: G2 end point is 0.029 mm off its circle")
    assert "LinuxCNC allows 0.0283 mm, or 0.1 % of the larger radius up to 2.83 mm" in message
    assert "G91.1" in message


def test_after_program_end_nothing_is_read() -> None:
    program = parse("G21 G1 X1 Y1 F10\nM2\nG0 X5 Y5\n(comment)\nG0 X6 Y6\n")
    assert program.moves == (Linear(1.0, 1.0, 10.0, contour=1),)
    assert program.warnings == ("t.ngc:3: 2 lines after the program end on line 2 not read",)


def test_g28_intermediate_point_then_unknown_position() -> None:
    program = parse("G21 G0 X1 Y1\nG28 X0 Y0\nG0 X5 Y5\nG1 X6 F10\n")
    assert program.moves == (
        Rapid(1.0, 1.0, contour=1),
        Rapid(0.0, 0.0, contour=1),
        Rapid(5.0, 5.0, contour=1),
        Linear(6.0, 5.0, 10.0, contour=1),
    )
    assert program.warnings[0].startswith("t.ngc:2: G28 return to the machine's stored position")
    message = refused("G21 G0 X1 Y1\nG28\nG1 X6 Y6 F10\n")
    assert message.startswith("t.ngc:3: G1 starts from the position after G28 on line 2")
    message = refused("G21 G0 X1 Y1\nG28\nG91 G0 X6 Y6\n")
    assert message.startswith("t.ngc:3: incremental X6 (G91)")


@pytest.mark.parametrize("home", ["G28", "G30"])
def test_typical_footer_g91_g28_z0(home: str) -> None:
    text = f"G21 G0 Z5\nG0 X1 Y1\nG1 Z-1 F10\nG0 Z5\nG91 {home} Z0\n{home} X0 Y0\nM30\n"
    program = parse(text)
    assert len(program.moves) == 4  # incremental 0: no intermediate move
    (warning,) = program.warnings
    assert warning.startswith(f"t.ngc:5: {home} return") and warning.endswith("(2 times)")


def test_g80_alone_is_a_no_op() -> None:
    program = parse("G21 G80\nG1 X1 Y1 F10\nM2\n")
    assert program.moves == (Linear(1.0, 1.0, 10.0, contour=1),)
    assert program.warnings == ()


# -- safe conversions: one warning per kind, with count and first line ---------------------


@pytest.mark.parametrize(
    ("block", "expected"),
    [
        ("G40", "G40 (cutter compensation off) read as a no-op"),
        ("G43 H1", "G43 tool length offset assumed 0"),
        ("G49", "G49 (tool length offset off) read as a no-op"),
        ("G54", "G54 work offset assumed 0"),
        ("G55", "G55 work offset assumed 0"),
        ("G61", "G61 path control mode ignored"),
        ("G64", "G64 path blending (with its P/Q tolerances, if any) ignored"),
        ("G64 P0.01 Q0.01", "G64 path blending (with its P/Q tolerances, if any) ignored"),
        ("G97 S1000", "G97 spindle speed mode ignored"),
        # cancels of modes refused below (Fanuc; Fusion 360's Fanuc post writes G69)
        ("G15", "G15 (polar coordinates off) read as a no-op"),
        ("G69", "G69 (coordinate rotation off) read as a no-op"),
        ("G50.1", "G50.1 (mirror image off) read as a no-op"),
        ("T2", "tool number T2 ignored"),
        ("/M5", "'/' block delete: the line is read"),
    ],
)
def test_safe_conversion_warns_once_with_count_and_first_line(block: str, expected: str) -> None:
    program = parse(f"G21 G0 X1 Y1\n{block}\nG1 X2 F10\n{block}\n")
    assert len(program.moves) == 2
    (warning,) = [w for w in program.warnings if expected in w]
    assert warning.startswith(f"t.ngc:2: {expected}")
    assert warning.endswith("(2 times)")


# -- refused constructs: the message names the line and the construct ----------------------


@pytest.mark.parametrize(
    ("block", "construct"),
    [
        ("O100 sub", "O-word"),
        ("G1 X#1 F10", "#1 is read before any line of the program sets it"),
        ("#<_depth> = 5", "#<_depth> is a global parameter"),
        ("G1 X[1+2] F10", "'[ ]' expressions"),
        # LinuxCNC's own tests (tests/ccomp, tests/interp/bad): a '*' or a function name
        # inside the brackets was named as a bad checksum or a letter without a number
        ("G3 X1 Y0 R[.5*SQRT[2]] Z.5", "'[ ]' expressions"),
        ("G0 X EXISTS[1]", "'[ ]' expressions"),
        ("G2 X200 I[0.9985 * 100]", "'[ ]' expressions"),
        ("$H", "'$H' is a GRBL system command"),  # gSender's examples start so
        ("$32=1", "'$32=1' is a GRBL system command"),
        ("$J=G91 X10 F100", "'$J=G91X10F100' is a GRBL system command"),
        ("G41 D1", "G41 (cutter radius compensation)"),
        ("G42", "G42 (cutter radius compensation)"),
        ("G18.1", "G18.1 selects a plane in the UVW axes"),
        ("G19.1", "G19.1 selects a plane in the UVW axes"),
        ("G84 X1 Y1 Z-1 R1", "G84 is a canned cycle"),  # tapping: not read
        ("G85 X1 Y1 Z-1 R1", "G85 is a canned cycle"),  # boring: not read
        ("G93", "G93 (inverse-time / per-revolution feed)"),
        ("G95", "G95 (inverse-time / per-revolution feed)"),
        ("G92 X0 Y0", "G92 changes the coordinate offsets"),
        ("G53 G1 Z0 F100", "G53 Z0 moves in machine coordinates"),  # a feed, not a rapid
        ("G91 G53 G0 Z0", "G53 Z0 moves in machine coordinates"),
        ("G91 G53 G0 Z-5", "G53 Z-5 moves in machine coordinates"),
        ("G5.1 X1 Y1 I1 J1", "G5.1 splines"),
        ("G16", "G16 (polar coordinates: X is a radius, Y an angle)"),
        ("G68 X0 Y0 R30", "G68 rotates the coordinate system"),
        ("G68.2 X0 Y0 Z0 I0 J30 K0", "G68.2 rotates the coordinate system"),
        ("G51.1 X0", "G51.1 (mirror image)"),
        ("G12 X1", "unknown or unsupported code G12"),
        ("M98 P100", "unknown or unsupported code M98"),
        ("G2 X3 Y1 F10", "G2 without a centre"),
        ("G2 X4 Y1 I1 J0 F10", "G2 end point is 1 mm off its circle"),
        ("G0 G1 X2", "G0 and G1 are both motion codes"),
        ("G90 G91", "G90 and G91 are both distance codes"),
        ("G1 X2 X3 F1", "two X words (X2, X3)"),
        ("G2 X1 Y1 R1 F10", "G2 R1 ends where it starts"),
        ("G3 X5 Y1 R1 F10", "radius 1.0000 mm is less than half"),
        ("G90.1 G2 X3 Y1 I2 F10", "G2 in G90.1 (absolute centre) needs both I and J"),
        ("G2 X3 Y1 I1 J0 R1 F10", "both R and I/J"),
        ("G2 X3 Y1 I1 P2 F10", "multi-turn arcs"),
        (
            "G2 X3 Y1 I1 K0.5 F10",
            "K0.5: an arc in the XY plane (G17) takes its centre from I and J",
        ),
        ("G1 X2 Y1", "G1 before any F word"),
        ("G1 X2 Y1 F0", "G1 with feed F0"),
        ("G0 X2 I1", "I1 has no code to use it"),
        ("G4", "G4 dwell needs a P word"),
        ("G1 X2 E0.5 F10", "E0.5 is a 3D-printer extrusion word"),
        # a Marlin program's start (cncjs's example part.gcode): named as a printer's
        ("G92 E0", "E0 is a 3D-printer extrusion word"),
        ("M104 S200", "M104 is a 3D printer's code"),
        ("M140 S60", "M140 is a 3D printer's code"),
        ("G0 A90", "A90 is an axis camtool does not have"),
        ("G0 X1 (open", "comment '(' is not closed"),
        ("G0 X1 (a (b) c)", "nested comment"),
        ("G0 X1 @", "unexpected character '@'"),
        # letters Python upper-cases to ASCII ones ('ı' to I, 'ſ' to S, 'ﬀ' to FF): rs274
        # refuses each ("Bad character"), so read as words they would make a wrong move
        ("G2 X3 Y1 \u0131 1 J0 F10", "unexpected character '\u0131' in 'G2X3Y1\u01311J0F10'"),
        ("G1 X2 F10 \u017f100", "unexpected character '\u017f'"),
        ("G1 X2 \ufb0010", "unexpected character '\ufb00'"),
        ("G1 X2 Y1 F10 \u00e9", "unexpected character '\u00e9' in 'G1X2Y1F10\u00e9'"),
        ("G0 X", "letter 'X' is not followed by a number"),
        ("G1 X1 F-5", "negative feed F-5"),
        ("G80 X1", "X1 has no code to use it"),
        ("G28 G1 X0 Y0", "G28 and G1 both use the axis words"),
        ("G91 Z-1", "incremental Z-1 (G91) but the Z position is not known yet"),
        ("G55", "G55 after G54"),
    ],
)
def test_refused_construct_names_line_and_construct(block: str, construct: str) -> None:
    message = refused(f"G21 G54\nG0 X1 Y1\n{block}\n")
    assert message.startswith("t.ngc:3: ")
    assert construct in message


def test_a_program_written_with_variables_is_refused_with_what_to_do() -> None:
    """pstoedit's ``gcode`` format (its header, as pstoedit 3.78 writes it) sets variables,
    which are read (tests/importers/test_gcode_params.py), and scales each point with an
    expression, which is not: refused at the first, and a variable it never sets too."""
    header = "G20\nG90\n#1000 = 0.100  ( safe Z )\n#1003 = 0.0041  ( x scale factor )\n"
    message = refused(header + "G00 Z#1000\nG00 X[#1003*12.5] Y0\n")
    assert message.startswith("t.ngc:6: '[ ]' expressions are not supported ('G00 X[#1003*12.5]")
    assert "post the drawing it was made from (DXF, SVG)" in message
    unset = refused(header + "G01 Z#1000 F#1001\n")
    assert unset.startswith("t.ngc:5: #1001 is read before any line of the program sets it")
    expression = refused("G21\nG0 X[1*72] Y1\n")
    assert expression.startswith("t.ngc:2: '[ ]' expressions are not supported")
    assert "without variables" in expression


def test_axis_words_before_any_motion_mode() -> None:
    assert refused("G21\nX1 Y1\n").startswith("t.ngc:2: X1 has no code to use it")


def test_axis_words_after_a_tool_change_say_what_grbl_would_do() -> None:
    """Fusion 360's GRBL post writes ``T12 M6`` then ``Z10`` (UGS's circle_test fixture).

    LinuxCNC's rs274 refuses the block ("Cannot use axis values without a g code that
    uses them"); GRBL moves it in G0, its power-on motion mode. camtool refuses it as
    LinuxCNC does, and says how to write what GRBL does; after G80 GRBL refuses it too.
    """
    message = refused("G21 G90\nG28 G91 Z0\nG90\nT12 M6\nZ10\nG0 X1 Y1\nG1 Z-1 F100\n")
    assert message.startswith("t.ngc:5: Z10 has no code to use it")
    assert "GRBL moves in its power-on G0" in message and "write G0 Z10" in message
    after_g80 = refused("G21\nG1 X1 F100\nG80\nX2\n")
    assert after_g80.startswith("t.ngc:4: X2 has no code to use it") and "GRBL" not in after_g80


def test_program_without_moves() -> None:
    assert "no move" in refused("%\n(only a header)\nG21 M3\nM2\n%\n")


def test_read_gcode_errors_and_encodings(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"missing\.nc: cannot read"):
        read_gcode(tmp_path / "missing.nc")
    latin = tmp_path / "pieza.nc"
    latin.write_bytes("(pieza maquinada en el LMM: ñ)\nG1 X1 Y1 F9\nM2\n".encode("latin-1"))
    assert read_gcode(latin, source_name="-").moves == (Linear(1.0, 1.0, 9.0, contour=1),)
    # a UTF-8 mark, then a byte no UTF-8 holds: the mark is not what the message names
    latin.write_bytes(codecs.BOM_UTF8 + b"G21\nG1 X1 Y1 F9\n\xe9M2\n")
    with pytest.raises(InputError, match=r"pieza\.nc:3: unexpected character"):
        read_gcode(latin)
    unicode = tmp_path / "notepad.nc"  # Notepad's "Unicode": UTF-16 LE with its mark
    unicode.write_bytes("(pièce)\r\nG21 G90\r\nG1 X1 Y1 F9\r\nM2\r\n".encode("utf-16"))
    assert read_gcode(unicode).moves == (Linear(1.0, 1.0, 9.0, contour=1),)
    for order in ("utf-16-le", "utf-16-be"):  # no mark: every other byte a NUL
        unicode.write_bytes("(pièce)\r\nG21 G90\r\nG1 X1 Y1 F9\r\nM2\r\n".encode(order))
        assert read_gcode(unicode).moves == (Linear(1.0, 1.0, 9.0, contour=1),), order
    unicode.write_bytes(b"G21\r\nG1 X1\x00 Y1 F9\r\n")  # one NUL is no UTF-16: refused
    with pytest.raises(InputError, match=r"notepad\.nc:2:"):
        read_gcode(unicode)
    with pytest.raises(InputError, match=r"^<stdin>:2: G41"):
        bad = tmp_path / "bad.nc"
        bad.write_text("G21\r\nG41\r\n")
        read_gcode(bad, source_name="<stdin>")


def test_binary_data_is_named_as_such_not_read_as_latin_1(tmp_path: Path) -> None:
    import gzip
    import io
    import zipfile

    program = b"G21 G90\nG0 X1 Y1\nG1 X5 Y1 F100 (#1 pass)\nM2\n"
    packed = tmp_path / "part.nc"
    # a gzip file starts 1F 8B (RFC 1952); a zip archive "PK" 03 04 (PKWARE's APPNOTE 4.3.7)
    packed.write_bytes(gzip.compress(program, mtime=0))
    with pytest.raises(InputError, match=r"part\.nc: binary data, not a G-code text file: "):
        read_gcode(packed)
    with pytest.raises(InputError, match=r"byte 0, on line 1, is 0x1F.*compressed"):
        read_gcode(packed)
    archive = io.BytesIO()
    with zipfile.ZipFile(archive, "w", zipfile.ZIP_DEFLATED) as zipped:
        zipped.writestr(zipfile.ZipInfo("part.nc", date_time=(2026, 12, 5, 0, 0, 0)), program)
    packed.write_bytes(archive.getvalue())
    with pytest.raises(InputError, match=r"byte 2, on line 1, is 0x03"):
        read_gcode(packed)
    # Windows-1252 text (an en dash 0x96 in a comment) ending in DOS's end-of-file mark is
    # text, read as Latin-1; a NUL in a UTF-8 program is no binary data either: the lexer
    # names it at its line
    dos = tmp_path / "dos.nc"
    dos.write_bytes(b"(L\xe4nge \x96 10 mm)\r\nG21\r\nG1 X1 Y1 F9\r\nM2\r\n\x1a")
    assert read_gcode(dos).moves == (Linear(1.0, 1.0, 9.0, contour=1),)
    dos.write_bytes(b"G21\nG1 X1 Y1 F9\n\x00\nM2\n")
    with pytest.raises(InputError, match=r"dos\.nc:3: unexpected character"):
        read_gcode(dos)


# -- properties (Munoz-22 S004-R03: G91 and R-form read to the same points) ---------------

coords = st.integers(-50_000, 50_000).map(lambda n: n / 1000)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(coords, coords), min_size=1, max_size=8))
def test_g91_reads_like_g90(points: list[tuple[float, float]]) -> None:
    absolute = "G21 G90 F100\n" + "".join(f"G1 X{x:.3f} Y{y:.3f}\n" for x, y in points)
    steps, here = [], (0.0, 0.0)
    for x, y in points:
        steps.append(f"G1 X{x - here[0]:.3f} Y{y - here[1]:.3f}\n")
        here = (x, y)
    incremental = "G21 G91 F100\n" + "".join(steps)
    a, b = parse(absolute).moves, parse(incremental).moves
    assert [v for m in b for v in (m.x, m.y)] == pytest.approx([v for m in a for v in (m.x, m.y)])


@settings(max_examples=60, deadline=None)
@given(
    cx=coords,
    cy=coords,
    r=st.integers(100, 20_000).map(lambda n: n / 1000),
    start=st.floats(-math.pi, math.pi),
    sweep=st.floats(0.1, 2 * math.pi - 0.1).filter(lambda s: abs(s - math.pi) > 0.1),
    clockwise=st.booleans(),
)
def test_r_form_reads_like_ij(
    cx: float, cy: float, r: float, start: float, sweep: float, clockwise: bool
) -> None:
    sx, sy = cx + r * math.cos(start), cy + r * math.sin(start)
    end = start - sweep if clockwise else start + sweep
    ex, ey = cx + r * math.cos(end), cy + r * math.sin(end)
    g = "G2" if clockwise else "G3"
    head = f"G21 G0 X{sx:.10f} Y{sy:.10f}\n"
    signed_r = r if sweep < math.pi else -r
    ij = parse(f"{head}{g} X{ex:.10f} Y{ey:.10f} I{cx - sx:.10f} J{cy - sy:.10f} F1\n").moves[1]
    rf = parse(f"{head}{g} X{ex:.10f} Y{ey:.10f} R{signed_r:.10f} F1\n").moves[1]
    assert isinstance(ij, ArcMove) and isinstance(rf, ArcMove)
    assert (rf.cx, rf.cy) == pytest.approx((ij.cx, ij.cy), abs=1e-6)
    assert rf.clockwise == ij.clockwise == clockwise


# -- round trip through the pic-mmh dialect ---------------------------------------------------


def _same(a: Move, b: Move) -> bool:
    tol = 1e-5  # 0.01 µm
    if type(a) is not type(b) or abs(a.x - b.x) > tol or abs(a.y - b.y) > tol:
        return False
    if isinstance(a, ArcMove) and isinstance(b, ArcMove):
        centre = abs(a.cx - b.cx) <= tol and abs(a.cy - b.cy) <= tol
        return centre and a.clockwise == b.clockwise and a.feed_mm_min == b.feed_mm_min
    if isinstance(a, Linear) and isinstance(b, Linear):
        return a.feed_mm_min == b.feed_mm_min
    return True


def test_round_trip_through_pic_mmh() -> None:
    # Z-free, inside the pic-mmh 10 × 7 mm work area (UNAM-GMM L2359-L2360), feeds on the
    # F01-F99 grid of 0.1 mm/min (S000-05).
    program = parse(
        "G21 G90 G17\n"
        "G0 X1 Y1\n"
        "G1 X4 Y1 F0.8\n"
        "G3 X6 Y3 I0 J2\n"
        "G2 X7.12345 Y4.5 R2.5\n"
        "G1 X1.00001 Y6.99999\n"
        "G0 X2 Y2\n"
        "G91 G1 X1.5 F1.5\n"
        "G90 G2 X2.5 Y2 I-0.5 J0\n"
        "M30\n"
    )
    target = load_target("pic-mmh")
    back = target.post.parse(str(target.emit(program).code))
    assert len(back.moves) == len(program.moves)
    assert all(_same(a, b) for a, b in zip(program.moves, back.moves, strict=True))


# -- program ends, truncation and absurd numbers (issues 13 §4, 14) -------------------------


def test_percent_delimited_program_ends_at_the_closing_percent() -> None:
    program = parse("(header)\n%\nG21 G1 X1 Y1 F10\n%\nG1 X5 Y5\n")
    assert program.moves == (Linear(1.0, 1.0, 10.0, contour=1),)
    assert program.warnings == ("t.ngc:5: 1 line after the program end on line 4 not read",)


def test_missing_end_warns_once_naming_the_last_block() -> None:
    program = parse("G21\nG1 X1 Y1 F10\nG1 X2\n(trailing comment)\n\n")
    assert program.warnings == (
        "t.ngc:3: no M2/M30 (nor a closing '%'): the file may be truncated; check that its "
        "last moves are all there",
    )


def test_percent_after_the_first_block_ends_the_program_or_is_refused() -> None:
    # LinuxCNC takes '%' as a delimiter on the first line only: later, rs274 stops at it with
    # "Bad character '%' used" (checked by hand), so the lines after it never run. camtool
    # read on through it, and wrote the cut of line 3; with nothing but comments after it,
    # the '%' ends the program
    message = refused("G21\n%\nG1 X1 Y1 F10\nM2\n")
    assert message.startswith("t.ngc:2: this '%' ends the program (no '%' opened it")
    assert "but line 3 goes on" in message
    message = refused("G21\nG1 X1 Y1 F10\n%\n(more)\n\nG1 X2\n")
    assert message.startswith("t.ngc:3: this '%' ends the program") and "line 6 goes on" in message
    program = parse("G21\nG1 X1 Y1 F10\n%\n(the end)\n\n")
    assert program.moves == (Linear(1.0, 1.0, 10.0, contour=1),)
    assert program.warnings == ()  # a '%' ends it: not "the file may be truncated"


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("G21\nG1 X1 Y1 F10\nG1 X2.", "t.ngc:3: the file ends in the middle of a word ('X2.'"),
        ("G21\nG1 X1 Y1 F10\nG1 X2 Y", "t.ngc:3: the file ends in the middle of a word ('Y'"),
        ("G21\nG1 X1 Y1 F10\nG1 X-", "t.ngc:3: the file ends in the middle of a word ('X-'"),
        ("G21\nG1 X1 Y1 F1e3\nM2\n", "t.ngc:2: E3 is a 3D-printer extrusion word, or an exponent"),
        ("G21\nG1 X1 Y-1000000000 F10\n", "t.ngc:2: Y-1000000000 is out of range"),
        ("G21\nG1 X1 Y1 F1" + "0" * 400 + "\n", "t.ngc:2: F100000000000... (401 characters)"),
    ],
)
def test_truncated_and_absurd_input_is_refused(text: str, message: str) -> None:
    assert refused(text).startswith(message)


@pytest.mark.parametrize("last", ["G1 X2", "G1 X2 (to X)", "G1 X2 ; Y", "G1 X2. "])
def test_complete_last_line_without_end_of_line_is_read(last: str) -> None:
    assert parse(f"G21\nG1 X1 Y1 F10\n{last}").moves[-1] == Linear(2.0, 1.0, 10.0, contour=1)


def test_unclosed_comment_on_a_cut_last_line_stays_a_comment_error() -> None:
    assert "comment '(' is not closed" in refused("G21\nG1 X1 Y1 F10\nG1 X2 (cut X")


# -- blocks that move nowhere, G53, a program without F (FreeCAD's posts) ------------------


@pytest.mark.parametrize("reader", [parse_gcode, parse_gcode_slow])
def test_a_block_that_moves_nowhere_before_any_xy_makes_no_move(reader: object) -> None:
    """Before the first X or Y word the machine's XY is unknown (the reader assumes 0, 0).

    FreeCAD 0.20's LinuxCNC post repeats ``G0 Z15.00`` before its first XY; the second one
    moves nowhere. Read as a move at the assumed XY, it was written back as ``G0 X0 Y0``:
    a rapid to a place the program never named.
    """
    text = "G21 G90\nG0 Z15\nG0 Z15\nG1 Z15 F100\nG0 X10 Y10\nG1 Z9\nG1 X0\nG0 Z15\nG0 Z15\nM2\n"
    program = reader(text, source="t.ngc")  # type: ignore[operator]
    assert [(type(m).__name__, m.x, m.y, m.z) for m in program.moves] == [
        ("Rapid", 0.0, 0.0, 15.0),  # a Z-only move (the writer writes no X, Y)
        ("Rapid", 10.0, 10.0, None),
        ("Linear", 10.0, 10.0, 9.0),
        ("Linear", 0.0, 10.0, None),
        ("Rapid", 0.0, 10.0, 15.0),
        ("Rapid", 0.0, 10.0, None),  # after X and Y are known: the position, as written
    ]


def test_a_cut_that_moves_nowhere_before_any_xy_still_needs_a_feed() -> None:
    assert "G1 before any F word" in refused("G21 G0 Z5\nG1 Z5\n")


def test_g53_without_axis_words_moves_nowhere() -> None:
    """FreeCAD 0.20's Centroid post begins its programs ``G53 G00 G17``: no axis, no move."""
    program = parse("G90 G80 G40 G49\nG53 G00 G17\nG21\nG0 X1 Y1\nG1 X2 F100\nM2\n")
    assert [(m.x, m.y) for m in program.moves] == [(1.0, 1.0), (2.0, 1.0)]
    assert any("G53 without axis words" in w for w in program.warnings)


def test_g53_rapid_to_machine_zero_is_a_home_and_leaves_its_axes_unknown() -> None:
    """``G53 G0 Z0.``, Haas-style posts' retract (and Fusion 360's "G53" safe retracts)."""
    text = "G21 G90\nG0 X1 Y1 Z2\nG53 G0 Z0.\nG0 X3 Y1\nG53 Z0\nG0 Z5\nG1 X4 F100\nM2\n"
    program = parse(text)
    assert program.commands == ((1, Home("Z", "G53")), (2, Home("Z", "G53")))  # G0 modal
    assert program.moves[1] == Rapid(3.0, 1.0, contour=program.moves[1].contour)  # Z unknown
    assert any("G53 G0 rapid to machine zero" in w for w in program.warnings)


def test_a_g53_rapid_elsewhere_keeps_its_machine_coordinates() -> None:
    """Carbide Create's retract ``G53G0Z-5.000`` (and a G53 rapid in X and Y, in inches)."""
    text = "G20 G90\nG0 X1 Y1 Z0.2\nG53G0Z-0.2\nG0 X3 Y1 Z0.2\nG1 Z0 F4\nG53 G0 X-1 Y-2\nM2\n"
    program = parse(text)
    assert program.commands == (
        (1, Home("Z", "G53", (-5.08,))),
        (3, Home("XY", "G53", (-25.4, -50.8))),
    )
    assert any("G53 G0 rapid in machine coordinates" in w for w in program.warnings)


def test_a_program_without_f_reads_with_the_feed_post_gives() -> None:
    text = "G21 G90\nG0 X0 Y0 Z5\nG1 Z-1\nG1 X10\nG2 X20 Y0 I5 J0\nM2\n"
    message = refused(text)
    assert "G1 before any F word" in message and "--feed" in message
    program = parse_gcode(text, source="t.ngc", reading=Reading(feed_mm_min=300.0))
    assert [m.feed_mm_min for m in program.moves if not isinstance(m, Rapid)] == [300.0] * 3
    program = parse_gcode(
        text.replace("G1 X10", "G1 X10 F50"), source="t.ngc", reading=Reading(feed_mm_min=300.0)
    )
    assert [m.feed_mm_min for m in program.moves if not isinstance(m, Rapid)] == [300, 50, 50]


@pytest.mark.parametrize("block", ["G00 G80 X1 Y1", "G80 G0 X1 Y1"])
def test_g80_beside_a_motion_code_leaves_the_motion(block: str) -> None:
    """CAMotics' ``cameo.nc`` begins ``N1 G00 G17 G21 G40 G49 G80 G90``; LinuxCNC 2.9's
    rs274 reads ``G0 G80 X1 Y1`` as the rapid (STRAIGHT_TRAVERSE to 1, 1) and ``G1 G80`` as
    the cut, so camtool reads them so too. Two motion codes other than G80 stay refused."""
    program = parse(f"G21\n{block}\nG80 G1 X2 F100\nG2 G80 X3 Y1 I0.5 J0\nM2\n")
    assert [type(m).__name__ for m in program.moves] == ["Rapid", "Linear", "ArcMove"]
    assert [(m.x, m.y) for m in program.moves] == [(1.0, 1.0), (2.0, 1.0), (3.0, 1.0)]
    assert "G0 and G1 are both motion codes" in refused("G21\nG0 G1 X1 F10\n")
    assert "G80 and G80 are both motion codes" in refused("G21\nG80 G80\n")
