"""A re-posted program's refusal names the line of the input it comes from.

The word-address writer numbers its own blocks ("contour 1, block 3"); for a program read
from code the user edits the input, so the message also names the input's line: the
move's own, or for a command (a stop, a tool change) the line of the move it stands
before. Expected lines are read off the test programs below.
"""

from __future__ import annotations

import re

import pytest

from camtool.importers.gcode import parse_gcode
from camtool.jobs.pipeline import post_program
from camtool.model.errors import DialectError
from camtool.post.registry import load_target

FAST = "G21 G90\nG0 X1 Y1\nG0 Z1\n(the feed below has 5 integer digits)\nG1 Z-1 F25400\nM2\n"
STOP = "G21 G90\nG0 X1 Y1\nG1 Z-1 F100\n(pause)\nM1\n\nG1 X2 Y1\nM2\n"
LAST = "G21 G90\nG0 X1 Y1\nG1 Z-1 F100\nG1 X2 Y1\n(pause at the end)\nM1\nM2\n"


@pytest.mark.parametrize(
    ("text", "said"),
    [
        (FAST, "does not fit 4 integer digits (value 25400); flashcut writes at most 4 "
         "integer digits (input line 5)"),
        (STOP, "flashcut has no optional stop (M1); a stop is never dropped: post the program "
         "for a target that stops, or take the stop out of it (before input line 7)"),
        (LAST, "take the stop out of it (after input line 4)"),  # no move after it
    ],
)  # fmt: skip
def test_a_refusal_names_the_input_line(text: str, said: str) -> None:
    with pytest.raises(DialectError) as refused:
        post_program(parse_gcode(text, source="in.ngc"), load_target("flashcut"))
    assert str(refused.value).endswith(said)


# pic-mmh's feed table ends at F99 = 9.9 mm/min, its spindle field at 9999 rev/min; its
# blocks: G54; G90; then one per move (the refused one is block 5)
PIC_FEED = "G21 G90\nG0 X1 Y1\nG1 X2 Y1 F5\n(too fast for the table)\nG1 X3 Y1 F100\nM2\n"
PIC_SPINDLE = "G21 G90\nG0 X1 Y1\nG1 X2 Y1 F5\nS20000 M3\nG1 X3 Y1\nM2\n"


@pytest.mark.parametrize(
    ("text", "said"),
    [
        (PIC_FEED, "block 5 (input line 5): feed 100 mm/min is outside F01–F99"),
        (PIC_SPINDLE, "block 5 (before input line 5): spindle speed 20000 rev/min"),
    ],
)
def test_pic_mmh_s_own_writer_names_the_input_line(text: str, said: str) -> None:
    """pic-mmh writes its fixed-width blocks with a writer of its own: its refusals of a
    re-posted program name the input's line as the word-address writer's do."""
    with pytest.raises(DialectError, match=re.escape(said)):
        post_program(parse_gcode(text, source="in.ngc"), load_target("pic-mmh"))


def test_a_drawing_s_refusal_names_no_input_line() -> None:
    """A planned program has no source lines: the message is the writer's alone."""
    from camtool.model.program import Linear, Program, Rapid

    program = Program((Rapid(1.0, 1.0), Linear(2.0, 1.0, 25400.0, contour=1)), origin=(0, 0))
    with pytest.raises(DialectError) as refused:
        load_target("flashcut").emit(program)
    assert "input line" not in str(refused.value)
