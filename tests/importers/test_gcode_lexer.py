"""The G-code lexer's fast paths equal its character loops exactly (issue 17).

``_strip_comments`` returns a line without ``; ( ) *`` as it is, and ``_words``
reads a line in one regular-expression pass; ``_strip_comments_by_char`` and
``_words_by_char`` are the loops every line went through before. On random lines
made of G-code words, blanks, comments and every kind of wrong character, the
results, or the error messages, are identical.
"""

from __future__ import annotations

import random

from camtool.importers import gcode_lexer
from camtool.model.errors import InputError

PIECES = [
    "G1",
    "G01",
    "X12.5",
    "Y-3",
    "Z.5",
    "F100",
    "I-0.",
    "J+1",
    "N10",
    "M3",
    "S2000",
    "x1",
    "O100",
    "#1",
    "[1+2]",
    "(c)",
    "(a;b)",
    ";x",
    "*71",
    "E5",
    "1e5",
    "X1e400",
    "X" + "9" * 400,
    " ",
    "  ",
    "\\t",
    "X",
    "Y-",
    "-",
    ".",
    "X..5",
    "G1X1Y2",
    "/",
    "%",
    ")",
    "(",
    "((",
    "é",
    "X١٢",
    "T1",
    "P0.5",
    "R1.5",
    "ß",
]


def _outcome(call: object, *args: object) -> object:
    try:
        return call(*args)  # type: ignore[operator]
    except InputError as exc:
        return f"InputError: {exc}"


def test_fast_paths_equal_the_loops_on_random_lines() -> None:
    rng = random.Random(17)
    for _ in range(40000):
        raw = "".join(rng.choice(PIECES) for _ in range(rng.randint(0, 8)))
        fast = _outcome(gcode_lexer._strip_comments, raw, "f:1")
        assert fast == _outcome(gcode_lexer._strip_comments_by_char, raw, "f:1"), raw
        code = "".join(raw.split()).upper()
        fast_words = _outcome(gcode_lexer._words, code, "f:1")
        assert fast_words == _outcome(gcode_lexer._words_by_char, code, "f:1"), code


def test_a_program_number_alone_is_a_line_without_words() -> None:
    """Fanuc and Haas posts begin ``O01001 (PART)``; LinuxCNC's ``rs274`` runs such a file."""
    assert gcode_lexer.lex_line("O01001 (PART)", 2, "f") is None
    assert gcode_lexer.lex_line("o1234", 2, "f") is None
    for line in ("O100 sub", "O1001 G21", "O<part> call", "O1.5"):
        try:
            gcode_lexer.lex_line(line, 2, "f")
        except InputError as exc:
            assert "f:2:" in str(exc)
        else:
            raise AssertionError(f"{line!r} was read")
