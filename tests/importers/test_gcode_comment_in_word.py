"""A comment inside a word is refused, as LinuxCNC refuses it; blanks inside a number are not.

LinuxCNC 2.9's ``rs274`` reads ``G1 X1 0 Y2`` as ``X10`` (blanks are nothing) but stops at
``G1 X1(c)0 Y2`` with "Bad character '0' used", and likewise at ``X(c)10``, ``X-(c)1`` and
``X1.(c)5``; ``X1(c) Y2`` is two words. camtool read all of them as ``X10``, ``X-1`` …
(tests/corpus/test_rs274.py runs rs274 on the same lines).
"""

from __future__ import annotations

import pytest

from camtool.importers.gcode import parse_gcode, parse_gcode_slow
from camtool.model.errors import InputError

REFUSED = ["X1(c)0 Y2", "X1 (c) 0 Y2", "X(c)10 Y2", "X-(c)1 Y2", "X1.(c)5 Y2", "G1X1(c)0Y2"]
READ = {"X1 0 Y2": (10.0, 2.0), "X1(c) Y2": (1.0, 2.0), "X1(c)Y2": (1.0, 2.0)}


def program(words: str) -> str:
    return f"G21 G90 G17\nG0 X0 Y0 Z5\nG1 Z-1 F100\nG1 {words}\nG0 Z5\nM2\n"


@pytest.mark.parametrize("words", REFUSED)
@pytest.mark.parametrize("parse", [parse_gcode, parse_gcode_slow])
def test_a_comment_inside_a_word_is_refused_naming_the_line(words: str, parse: object) -> None:
    with pytest.raises(InputError, match=r"p.ngc:4: a comment inside the word"):
        parse(program(words), source="p.ngc")  # type: ignore[operator]


@pytest.mark.parametrize("words", list(READ))
@pytest.mark.parametrize("parse", [parse_gcode, parse_gcode_slow])
def test_blanks_and_comments_between_words_are_read(words: str, parse: object) -> None:
    moves = parse(program(words), source="p.ngc").moves  # type: ignore[operator]
    assert (moves[-2].x, moves[-2].y) == READ[words]
