"""Hostile lines: a reading linear in the line's length, messages of one readable line.

A line of a million comments, of a hundred thousand blanks after its words or inside a
word cut at the end of the file used to take minutes to hours (the reader's cost grew
with the square of the line's length). Each is read here under a CPU-time bound far above
what it needs (:func:`tests.cpu.cpu_bound`). LinuxCNC's ``rs274`` refuses a digit that is
not ASCII ("bad number format" on ``Y١``); camtool read ``Y١`` as ``Y1``.
"""

from __future__ import annotations

import sys
import tracemalloc

import pytest

from camtool.importers.gcode import parse_gcode, parse_gcode_slow
from camtool.importers.gcode_lexer import _NO_BLANKS, MAX_WORDS
from camtool.importers.gcode_plain import PLAIN_LINE_CHARS
from camtool.model.errors import InputError
from camtool.model.program import Linear
from tests.cpu import cpu_bound

BOUND_S = 60
HEAD = "G21 G90\nG0 X0 Y0\n"
PARSERS = [parse_gcode, parse_gcode_slow]


def _ends(text: str, parse: object) -> list[tuple[float, float]]:
    with cpu_bound(BOUND_S):
        program = parse(text, source="p.ngc")  # type: ignore[operator]
    return [(m.x, m.y) for m in program.moves if isinstance(m, Linear)]


@pytest.mark.parametrize("parse", PARSERS)
def test_a_line_of_a_million_comments_is_read(parse: object) -> None:
    line = "G1 F100 X1" + " (c)" * 1_000_000 + " Y2"
    assert _ends(f"{HEAD}{line}\nM2\n", parse) == [(1.0, 2.0)]


@pytest.mark.parametrize("parse", PARSERS)
def test_blanks_at_the_end_of_a_line_are_read_as_nothing(parse: object) -> None:
    assert _ends(f"{HEAD}G1 F100 X1 Y2{' ' * 200_000}\nM2\n", parse) == [(1.0, 2.0)]


@pytest.mark.parametrize("parse", PARSERS)
def test_blanks_after_a_letter_in_a_cut_last_line_are_refused_quickly(parse: object) -> None:
    text = f"{HEAD}G1 F100 X1 Y1\nG1 X{' ' * 200_000}Y2"  # no end of line: X has no number
    with pytest.raises(InputError, match=r"p\.ngc:4: letter 'X' is not followed by a number"):
        _ends(text, parse)


@pytest.mark.parametrize("parse", PARSERS)
def test_a_digit_that_is_not_ascii_is_refused(parse: object) -> None:
    with pytest.raises(InputError, match="p\\.ngc:3: unexpected character '\u0661'"):
        _ends(f"{HEAD}G1 F100 X1 Y\u0661\nM2\n", parse)  # ARABIC-INDIC DIGIT ONE


@pytest.mark.parametrize("parse", PARSERS)
def test_a_checksum_of_thousands_of_digits_is_a_damaged_line(parse: object) -> None:
    with pytest.raises(InputError) as info:
        _ends(f"{HEAD}G1 F100 X1 Y2*{'1' * 5000}\nM2\n", parse)
    message = str(info.value)
    assert message.startswith("p.ngc:3: checksum *11111111... (5000 digits) does not match")
    assert len(message) < 200


@pytest.mark.parametrize(
    ("line", "what"),
    [
        ("/" * 1_000_000 + "G1 X1 Y1", "unexpected character '/'"),
        ("G1 F100 X1 Y" + "." * 1_000_000, "letter 'Y' is not followed by a number"),
        ("O100 " + "SUB " * 300_000, "O-word"),
        ("G1 X[" * 300_000, "'[ ]' expressions are not supported"),
        ("G1 X1 Y1 " + "*" * 1_000_000, "'*' must end the line"),
    ],
)
def test_a_message_quotes_a_huge_line_by_its_start_and_length(line: str, what: str) -> None:
    with pytest.raises(InputError) as info:
        _ends(f"{HEAD}{line}\nM2\n", parse_gcode)
    message = str(info.value)
    assert message.startswith("p.ngc:3: ") and what in message
    assert "characters)" in message and len(message) < 400


@pytest.mark.parametrize("parse", PARSERS)
def test_a_line_of_a_million_words_is_refused_at_its_65th_word(parse: object) -> None:
    """A program whose line ends were lost: refused before its million words are made."""
    line = "G1 F100 " + " ".join(f"X{i % 100}" for i in range(1_000_000))
    tracemalloc.start()
    try:
        with pytest.raises(InputError) as info:
            _ends(f"{HEAD}{line}\nM2\n", parse)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    message = str(info.value)
    assert message.startswith(f"p.ngc:3: more than {MAX_WORDS} words on one line ('G1F100X0X1")
    assert "characters)" in message and len(message) < 400
    assert peak < 4 * len(line)  # the line without its blanks, in upper case: no word objects


@pytest.mark.parametrize("parse", PARSERS)
@pytest.mark.parametrize("blanks", [0, 300])
def test_the_word_limit_counts_words(parse: object, blanks: int) -> None:
    """64 words reach the reader (which refuses the repeated letter); the 65th is refused."""
    words = ["G1", "F100", *(f"X{i}" for i in range(62))]
    gap = " " * blanks
    with pytest.raises(InputError, match=r"p\.ngc:3: two X words \(X0, X1\)"):
        _ends(f"{HEAD}{gap.join(words)}\nM2\n", parse)
    with pytest.raises(InputError, match=rf"p\.ngc:3: more than {MAX_WORDS} words on one line"):
        _ends(f"{HEAD}{gap.join([*words, 'Y1'])}\nM2\n", parse)


@pytest.mark.parametrize("parse", PARSERS)
def test_a_plain_line_longer_than_the_plain_search_is_read_by_the_lexer(parse: object) -> None:
    gap = " " * (PLAIN_LINE_CHARS + 1)
    assert _ends(f"{HEAD}G1 F100{gap}X1 Y\t{gap}2{gap}\nM2\n", parse) == [(1.0, 2.0)]


def test_the_lexer_drops_what_split_splits_at() -> None:
    """The long lines' table (``str.translate``) deletes exactly the blanks of ``str.split``."""
    blanks = {c for c in range(sys.maxunicode + 1) if len(f"a{chr(c)}b".split()) == 2}
    assert set(_NO_BLANKS) == blanks
