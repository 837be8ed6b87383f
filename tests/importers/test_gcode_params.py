"""Parameters set to numbers (``#100=2.0`` … ``Z#100``, ``#<depth>=1``), read as those numbers.

The rules are LinuxCNC's ("Parameters", G-code overview): a line reads all its parameters
before it sets any; a sign before ``#n`` negates it. tests/corpus/test_rs274.py has LinuxCNC's
own interpreter judge the same programs.
"""

from __future__ import annotations

import re
from collections.abc import Callable

import pytest

from camtool.importers.gcode import parse_gcode, parse_gcode_slow
from camtool.importers.gcode_params import expand_parameters
from camtool.model.errors import InputError
from camtool.model.program import Linear, Program, Rapid

GEDA = """(Created by G-code exporter)
(600 dpi)
(Unit: inch)
(Board size: 0.50x0.50 inches)#100=0.002000  (safe Z)
#101=-0.000050  (cutting depth)
(---------------------------------)
G17 G20 G90 G64 P0.003 M3 S3000 M7 F1
G0 Z#100
(polygon 1)
G0 X0.073333 Y0.410000    (start point)
G1 Z#101
G1 X0.065000 Y0.401667
G0 Z#100
M5 M9 M2
"""
"""The head of a program by gEDA PCB's G-code exporter (its own comments and layout)."""

PARALLEL = """#1 = 5.0 ( Safe Z )
#2 = -0.5 ( Engraving Depth Z )
#3=10
#4 = -#3 (#4 is -10)
G21 G90 G17
G0 Z#1
G0 X#3 Y-#4
G1 Z#2 F100
G1 X-#3 Y#4 #4=#3 #3=-3
G1 X#3 Y#4 Z-#2
M2
"""
"""A wizard-style program: its line 9 reads #3 = 10 and #4 = -10, then sets #4 = 10 and
#3 = -3, which line 10 reads (LinuxCNC's rs274 moves: (10, 10), (-10, -10), (-3, 10, 0.5))."""


def test_a_gEDA_export_reads_its_safe_z_and_depth_in_inches() -> None:
    program = parse_gcode(GEDA, source="board.ngc")
    rapids = [m for m in program.moves if isinstance(m, Rapid)]
    cuts = [m for m in program.moves if isinstance(m, Linear)]
    assert rapids[0].z == pytest.approx(0.002 * 25.4, abs=1e-12)
    assert (cuts[0].x, cuts[0].y, cuts[0].z) == pytest.approx(
        (0.073333 * 25.4, 0.41 * 25.4, -0.00005 * 25.4), abs=1e-12
    )
    assert rapids[-1].z == pytest.approx(0.002 * 25.4, abs=1e-12)


@pytest.mark.parametrize("parse", [parse_gcode, parse_gcode_slow])
def test_a_line_reads_its_parameters_before_it_sets_any(parse: Callable[..., Program]) -> None:
    program = parse(PARALLEL, source="wizard.ngc")
    ends = [(m.x, m.y, m.z) for m in program.moves if isinstance(m, Rapid | Linear)]
    assert ends == [
        (0.0, 0.0, 5.0),  # Z5 from the start, X and Y where they were
        (10.0, 10.0, None),  # None: Z stays
        (10.0, 10.0, -0.5),
        (-10.0, -10.0, None),
        (-3.0, 10.0, 0.5),
    ]


PLOTTER = """G21 ; All units in mm
G90 ; Set to absolute mode
; Parameters
#<pen_up> = -12
#<Pen_Down> = -13.5
G00 X35.000001 Y14.999999
G01 Z#<pen_down> F100.0(Penetrate)
G01 X25.000000 Y4.999998 F400.000000
G01 Z#<PEN_UP>
#<pen up> = -#<pen_down> (spaces do not count: #<penup>)
G01 Z#<penup> X#<pen_up>
M2
"""
"""A pen plotter's program, as a G-code generator for Inkscape writes it (named parameters
for the pen's heights, in any case): its last lines set ``#<penup>`` to 13.5 and read it
(LinuxCNC's rs274 moves: (35, 15, -13.5), (25, 5, -13.5), (25, 5, -12), (-12, 5, 13.5))."""


@pytest.mark.parametrize("parse", [parse_gcode, parse_gcode_slow])
def test_named_parameters_are_read_as_numbered_ones_are(parse: Callable[..., Program]) -> None:
    program = parse(PLOTTER, source="plot.ngc")
    ends = [(m.x, m.y, m.z) for m in program.moves if isinstance(m, Linear)]
    assert ends == [
        (35.000001, 14.999999, -13.5),
        (25.0, 4.999998, None),
        (25.0, 4.999998, -12.0),
        (-12.0, 4.999998, 13.5),
    ]


def test_a_program_number_line_is_no_o_word_to_stop_at() -> None:
    # Fanuc's and Haas's first line names the program: the parameters after it are read
    # (rs274 reads a bare O-number as nothing too); an O-word with more is refused there
    text = "%\nO1000 (PART)\nG21 G90\n#1=5\nG0 X#1 Y0\n/ o0002\nG0 Y-#1\nG1 X0 F9\nM30\n%\n"
    ends = [(m.x, m.y) for m in parse_gcode(text, source="t.nc").moves if isinstance(m, Rapid)]
    assert ends == [(5.0, 0.0), (5.0, -5.0)]


def test_lines_keep_their_numbers_comments_and_messages() -> None:
    text = "#1=2 (set #1)\r\nG0 X#1 (MSG, at #1)\rG0 Y-#1 ; #1\n(#1 only here)"
    assert expand_parameters(text, "t.ngc") == (
        " (set #1)\r\nG0X2(MSG, at #1)\rG0Y-2; #1\n(#1 only here)"
    )
    assert expand_parameters("G0 X1\n", "t.ngc") == "G0 X1\n"
    # a block-delete line with '#' in its comment only holds no parameter
    assert expand_parameters("/G0 X1 (#1 here)\n", "t.ngc") == "/G0 X1 (#1 here)\n"


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("G21\nG0 Z#7\n", "t.ngc:2: #7 is read before any line of the program sets it"),
        ("#2=#3\n", "t.ngc:1: #3 is read before any line"),
        ("#8=1 G0 X#8\n", "t.ngc:1: #8 is read before any line"),  # set after the read
        ("G0 Z#5220\n", "t.ngc:1: #5220 is a parameter the controller keeps"),
        ("#5211=0\n", "t.ngc:1: #5211 is a parameter the controller keeps"),
        ("G1 Z#<depth> F10\n", "t.ngc:1: #<depth> is read before any line of the program"),
        ("#<a>=5 #<b>=#<a>\n", "t.ngc:1: #<a> is read before any line"),  # LinuxCNC: 0
        ("#<_x>=5\n", "t.ngc:1: #<_x> is a global parameter"),  # LinuxCNC: read-only
        ("G1 X#<_metric> F10\n", "t.ngc:1: #<_metric> is a global parameter"),
        ("#<a>=5\nG1 X#<a>5 F10\n", "t.ngc:2: a '#' in 'G1 X#<a>5 F10' is neither"),
        ("#<>=1\n", "t.ngc:1: a '#' in '#<>=1' is neither"),
        ("#<a>=[1+2]\n", "t.ngc:1: '[ ]' expressions are not supported"),
        # a subroutine's own parameters (#1 its first argument) are not read at all: the
        # O-word's line comes first, as in LinuxCNC's circles.ngc
        ("o<circles> sub\n#<radius> = #1 (R)\n", "t.ngc:1: O-word"),
        ("N10 O100 sub\nG1 X#1 F10\n", "t.ngc:1: O-word"),
        ("(first) O100 sub\nG1 X#1 F10\n", "t.ngc:1: O-word"),  # after a comment
        ("#1=2\n/ o100 if [#1 GT 1]\nG1 X#1 F10\n", "t.ngc:2: O-word"),
        ("#1=2\nG1 X[#1*2] F10\n", "t.ngc:2: '[ ]' expressions are not supported"),
        ("#1=2\n##1=3\n", "t.ngc:2: indirect parameters ('##n') are not supported"),
        # what a line camtool cannot evaluate sets is not known: refused there, not where read
        ("#1=[1+2]\nG1 X#1 F10\n", "t.ngc:1: '[ ]' expressions are not supported"),
        ("#1=5\n#1=[#1*2]\nG1 X#1 F10\n", "t.ngc:2: '[ ]' expressions"),
        # LinuxCNC reads a line without its spaces, and a value right after its letter
        ("#1=5\nG1 X#1 .5 F10\n", "t.ngc:2: #1.5 names no parameter"),
        ("#1=5\nG1 X1#1 F10\n", "t.ngc:2: a '#' in 'G1 X1#1 F10' is neither a word's value"),
        ("#1=5.5.5\n", "t.ngc:1: a '#' in '#1=5.5.5' is neither"),
        ("#1=5\n/#1=6\nG1 X#1 F10\n", "t.ngc:2: a block-delete line ('/') sets or reads"),
    ],
)
def test_what_camtool_cannot_know_is_refused_at_its_line(text: str, message: str) -> None:
    with pytest.raises(InputError, match=re.escape(message)):
        parse_gcode(text + "G1 X1 F10\nM2\n", source="t.ngc")
