"""RS-274 lexer: one text line of G-code into a :class:`Block` of words.

What a line may hold (RS-274/NGC as LinuxCNC documents it, and the FlashCut
and Gcodetools programs of Yanez-07 §3 and Munoz-22 §3.3):

Design notes: docs/internals.md, ``camtool/importers/gcode_lexer.py``.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from typing import NoReturn

from camtool.model.errors import InputError, quoted
from camtool.model.units import LARGEST_VALUE

_NUMBER = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)")
_WORD = re.compile(r"([A-NP-Z])(" + _NUMBER.pattern + ")")
"""A word as :func:`_words_by_char` reads it: a letter (not O) and its number."""
_PROGRAM_NUMBER = re.compile(r"O[0-9]+")
"""A Fanuc/Haas program number line (``O01001 (PART)``): no effect on the moves; LinuxCNC's
interpreter reads a bare O-number as nothing too (its ``rs274`` runs such a file)."""
_COMMENT_CHARS = re.compile(r"[;()*]")
_CHECKSUM = re.compile(r"\*([0-9]+)$")
_CUT = re.compile(r"[A-Za-z]\s*+[+-]?\s*+(?:[0-9][0-9\s]*+)?\.$|[A-Za-z]\s*+[+-]?$")
"""The end of a line cut inside a word: ``X12.``, ``X-``, ``Y`` (spaces may sit inside)."""
MAX_WORDS = 64
"""Most words one line may hold. A block holds each letter once, G codes once per modal
group and at most four M codes (LinuxCNC's interpreter): about 45 words. More is a program
whose line ends were lost, or no G-code: refused at the first word past the limit, before
the rest of the line is made into words."""
_LONG_LINE = 255
"""Longest line whose blanks :func:`lex_line` drops by splitting it (LinuxCNC's interpreter
refuses any longer line: ``LINELEN`` in its ``rs274ngc.hh``); a longer one is translated,
which makes no piece per word."""
_NO_BLANKS = {c: None for c in range(0x3001) if chr(c).isspace()}
"""``str.translate`` table that deletes what ``str.split()`` splits at (no code point above
U+3000 is a blank)."""


@dataclass(frozen=True)
class Word:
    """One word: ``letter`` (upper case) and its ``value`` as written (file units).

    ``text`` is the number as it stood in the file, for messages.
    """

    letter: str
    value: float
    text: str

    def __str__(self) -> str:
        return f"{self.letter}{self.text}"


@dataclass(frozen=True)
class Block:
    """The words of one line; ``line`` is the 1-based line number in the file."""

    line: int
    words: tuple[Word, ...]
    block_delete: bool = False


def program_number(code: str) -> bool:
    """Whether a line's code is a program number alone (:data:`_PROGRAM_NUMBER`).

    ``code``: the line without its comments, blanks and block-delete ``/``, in any case.
    """
    return _PROGRAM_NUMBER.fullmatch(code.upper()) is not None


def lex_line(raw: str, line: int, source: str) -> Block | None:
    """Split one line into words; ``None`` for a line without words.

    A line with only comments, blanks, a ``%`` tape marker or a program number
    (``O01001``, :data:`_PROGRAM_NUMBER`) gives ``None``.

    Args:
        raw: the line, without its end-of-line characters.
        line: its 1-based number in the file, for messages.
        source: the file name, for messages.

    Raises:
        InputError: a construct camtool does not read, or a malformed line;
            the message names ``source:line`` and the construct.
    """
    where = f"{source}:{line}"
    code, star_at = _strip_comments(raw, where)
    code = code.strip()
    if code.startswith("%"):
        if code[1:].strip():
            raise InputError(f"{where}: text after the '%' tape marker: {quoted(code)}; remove it")
        return None
    if star_at is not None:
        code = _check_checksum(raw, code, star_at, where)
    block_delete = code.startswith("/")
    if block_delete:
        code = code[1:]
    code = "".join(code.split()) if len(code) <= _LONG_LINE else code.translate(_NO_BLANKS)
    if not code.isascii():
        _refuse_non_ascii(code, where)
    code = code.upper()
    if program_number(code):
        return None  # a program number alone: no words (O-words with more are refused)
    words = _words(code, where)
    if not words:
        if block_delete:
            return Block(line, (), True)
        return None
    return Block(line, tuple(words), block_delete)


def _refuse_non_ascii(code: str, where: str) -> NoReturn:
    """Refuse a character outside ASCII in a line's words (comments are already out).

    Named as it is in the file, before any case change: Python upper-cases some letters
    outside ASCII to ASCII ones (``'ı'`` to ``I``, ``'ſ'`` to ``S``, ``'ﬀ'`` to ``FF``), which
    would read a word LinuxCNC's ``rs274`` refuses ("Bad character") as a valid one.
    """
    c = next(c for c in code if not c.isascii())
    raise InputError(
        f"{where}: unexpected character {c!r} in {quoted(code)}: G-code words are ASCII "
        "letters and numbers; remove it or put it in a comment '( )'"
    )


_MSG = re.compile(r"\(\s*MSG\s*,([^)]*)\)", re.IGNORECASE)


def operator_message(raw: str) -> str | None:
    """The text of LinuxCNC's message to the operator on line ``raw``: ``(MSG, text)``."""
    found = _MSG.search(raw)
    return None if found is None else found.group(1)


def _strip_comments(raw: str, where: str) -> tuple[str, int | None]:
    """The line without comments, and the index in ``raw`` of a ``*`` outside them.

    A line without ``;``, ``(``, ``)`` or ``*`` (most lines) is returned as it is,
    which is what the character loop of :func:`_strip_comments_by_char` gives it.
    """
    if _COMMENT_CHARS.search(raw) is None:
        return raw, None
    return _strip_comments_by_char(raw, where)


def _strip_comments_by_char(raw: str, where: str) -> tuple[str, int | None]:
    """:func:`_strip_comments` of any line, character by character (naming what is wrong).

    Linear in the line's length, however many comments it holds: each comment looks only
    at the last character kept before it and the first one after it.
    """
    kept: list[str] = []
    solid = -1  # index in ``kept`` of its last non-blank character
    star_at: int | None = None
    i = 0
    while i < len(raw):
        c = raw[i]
        if c == ";":
            break
        if c == "(":
            close = raw.find(")", i + 1)
            if close < 0:
                raise InputError(f"{where}: comment '(' is not closed; add ')' on the same line")
            if raw.find("(", i + 1, close) >= 0:
                raise InputError(f"{where}: nested comment '(... (...' is not allowed; remove it")
            _check_not_in_word(raw, kept, solid, close, where)
            kept.append(" ")
            i = close + 1
            continue
        if c == ")":
            raise InputError(f"{where}: ')' without '('; remove it or open the comment")
        if c == "*" and star_at is None:
            star_at = i
        kept.append(c)
        if not c.isspace():
            solid = len(kept) - 1
        i += 1
    return "".join(kept), star_at


_WORD_GOES_ON = frozenset("0123456789.+-")
"""What may follow a word's letter or come within its number: a comment there splits it."""
_BLANKS = re.compile(r"\s*")


def _check_not_in_word(raw: str, kept: list[str], solid: int, close: int, where: str) -> None:
    """Refuse a comment ``(...)`` (ending at ``raw[close]``) inside a word: ``X1(c)0``.

    ``kept[solid]`` is the last non-blank character kept before the comment (``solid``
    is -1 when there is none).
    Blanks inside a number are read as nothing (``X1 0`` is ``X10``, as LinuxCNC reads it),
    but a comment there is not: LinuxCNC's ``rs274`` stops with "Bad character" at what
    follows it, so camtool must not read ``X10`` (nor ``X(c)10``, ``X-(c)1``).
    """
    after_at = _BLANKS.match(raw, close + 1).end()  # type: ignore[union-attr]
    if solid < 0 or after_at == len(raw) or raw[after_at] not in _WORD_GOES_ON:
        return
    last = kept[solid]
    if last.isalpha() or last in _WORD_GOES_ON:
        before = "".join(kept[: solid + 1])  # only on the way to the error
        tail = re.search(r"[A-Za-z][0-9.+\- ]*$", before)
        word = (tail[0] if tail else before.split()[-1]).replace(" ", "")
        raise InputError(
            f"{where}: a comment inside the word {word!r}...{raw[after_at]!r}: LinuxCNC refuses "
            "it (a word's number cannot go on after a comment); move the comment after the word"
        )


def _check_checksum(raw: str, code: str, star_at: int, where: str) -> str:
    """Verify a RepRap ``*NN`` checksum and return ``code`` without it."""
    m = _CHECKSUM.search(code)
    if m is None:
        _refuse_special("[" if "[" in code else "", code, where)  # '*' in an expression
        raise InputError(
            f"{where}: '*' must end the line followed by a checksum (e.g. '*71'): {quoted(code)}"
        )
    expected = 0
    for byte in raw[:star_at].encode("latin-1", errors="replace"):
        expected ^= byte
    digits = m[1].lstrip("0")
    if len(digits) > 3 or int(m[1]) != expected:  # a checksum is one byte, 0 to 255
        shown = m[1] if len(m[1]) <= 12 else f"{m[1][:8]}... ({len(m[1])} digits)"
        raise InputError(
            f"{where}: checksum *{shown} does not match the line (computed *{expected}); "
            "the line was damaged: export the program again"
        )
    return code[: m.start()]


def _words(code: str, where: str) -> list[Word]:
    """Words of a comment-free, upper-case line without blanks.

    One regular-expression pass (:data:`_WORD`, the letter and then
    :data:`_NUMBER` exactly as :func:`_words_by_char` matches them at each letter)
    when the words follow each other to the end of the line and every number is
    in range; any other line goes to :func:`_words_by_char`, which finds its error.
    """
    words: list[Word] = []
    pos = 0
    for m in _WORD.finditer(code):
        text = m[2]
        value = float(text)
        if m.start() != pos or not abs(value) < LARGEST_VALUE:
            return _words_by_char(code, where)
        words.append(Word(m[1], value, text))
        pos = m.end()
        if len(words) > MAX_WORDS:
            _too_many_words(code, where)
    if pos != len(code):
        return _words_by_char(code, where)
    return words


def _words_by_char(code: str, where: str) -> list[Word]:
    """:func:`_words` of any line, one character at a time (naming what is wrong)."""
    words: list[Word] = []
    i = 0
    while i < len(code):
        c = code[i]
        _refuse_special(c, code, where)
        if not ("A" <= c <= "Z"):
            raise InputError(f"{where}: unexpected character {c!r} in {quoted(code)}")
        if c == "O":
            raise InputError(
                f"{where}: O-word {quoted(code)} (subroutines, loops, conditions) is not "
                "supported; expand the program in your CAM (a Fanuc program number line can be "
                "deleted)"
            )
        m = _NUMBER.match(code, i + 1)
        if m is None:
            _refuse_special(code[i + 1 : i + 2], code, where)
            _refuse_special("[" if "[" in code[i:] else "", code, where)  # X SQRT[2], ...
            raise InputError(f"{where}: letter {c!r} is not followed by a number in {quoted(code)}")
        value = float(m[0])
        if not abs(value) < LARGEST_VALUE:
            shown = m[0] if len(m[0]) <= 20 else f"{m[0][:12]}... ({len(m[0])} characters)"
            raise InputError(
                f"{where}: {c}{shown} is out of range (a number's magnitude must be below "
                f"{LARGEST_VALUE:.0e}); the file is damaged or not in mm/inch: check the line"
            )
        words.append(Word(c, value, m[0]))
        i = m.end()
        if len(words) > MAX_WORDS:
            _too_many_words(code, where)
    return words


def _too_many_words(code: str, where: str) -> NoReturn:
    """Refuse line ``code``: it holds more than :data:`MAX_WORDS` words.

    Raises:
        InputError: naming ``where`` and the line's start.
    """
    raise InputError(
        f"{where}: more than {MAX_WORDS} words on one line ({quoted(code)}); a block holds "
        "each letter once (G and M codes once per modal group): the file's line ends may have "
        "been lost, or it is no G-code; split the line into its blocks"
    )


def cut_mid_word(raw: str) -> str | None:
    """The unfinished word a line ends with (``"X12."``, ``"X-"``, ``"Y"``), else ``None``.

    Meant for the last line of a file that has no end of line after it: a
    program cut while it was being copied or written stops inside a word.
    LinuxCNC refuses a letter without its number ("bad number format"); a
    number ending in its decimal point is refused here too, as it is where a
    cut ``X12.5`` stops. A line ending in a comment, a blank or a complete
    number (``X12``) is not cut (a complete last block needs no end of line).
    """
    in_comment = False
    for c in raw:
        if c == ";" and not in_comment:
            return None  # the line ends in a ';' comment
        if c in "()":
            in_comment = c == "("
    if in_comment or raw.endswith(")"):
        return None
    m = _CUT.search(raw)
    return m[0].replace(" ", "") if m else None


def lines_with_words(rest: Iterable[str], first: int, source: str) -> Iterator[int]:
    """The numbers of the lines of ``rest`` (the first is line ``first``) that hold words.

    A line the lexer refuses counts as one: it is neither blank nor a comment.
    """
    for number, raw in enumerate(rest, start=first):
        try:
            words = lex_line(raw, number, source) is not None
        except InputError:
            words = True
        if words:
            yield number


def refuse_words_after_percent(rest: Iterable[str], percent_line: int, source: str) -> None:
    """Refuse a line with words after a '%' that ends a program no '%' opened.

    A '%' is a tape marker: on the first line it opens the program, and the next one ends
    it. One after the program began, with none before it, is an error for LinuxCNC
    (``rs274``: "Bad character '%' used"), which stops there: the lines after it never
    run. With only comments and blank lines after it, it is the program's end.

    Raises:
        InputError: naming the '%' line and the first line with words after it.
    """
    number = next(lines_with_words(rest, percent_line + 1, source), None)
    if number is not None:
        raise InputError(
            f"{source}:{percent_line}: this '%' ends the program (no '%' opened it on its "
            f"first line, and LinuxCNC stops at it: \"Bad character '%'\"), but line "
            f"{number} goes on: if the program ends here, delete the lines after the '%'; "
            "if not, delete the '%'"
        )


_PLAIN = (
    "camtool reads plain numbers: post the program again from its CAM program without "
    "variables, or post the drawing it was made from (DXF, SVG)"
)
"""What to do with a program written with variables or expressions (pstoedit's G-code, say)."""


def _refuse_special(c: str, code: str, where: str) -> None:
    """Raise for the parameter and expression characters of RS-274/NGC."""
    if c == "#":
        kind = (
            "'[ ]' expressions"
            if "[" in code
            else "indirect parameters ('##n')"
            if "##" in code
            else "'#' parameters on this line"
        )
        raise InputError(
            f"{where}: {kind} are not supported ({quoted(code)}); camtool reads "
            "parameters set to numbers ('#1=2.5' or '#<depth>=2.5', then 'X#1' or "
            f"'Z#<depth>') and {_PLAIN.removeprefix('camtool reads ')}"
        )
    if c and c in "[]":
        raise InputError(f"{where}: '[ ]' expressions are not supported ({quoted(code)}); {_PLAIN}")
    if c == "$" and code.startswith("$"):
        raise InputError(
            f"{where}: {quoted(code)} is a GRBL system command (settings, homing, jogging), not "
            "G-code: camtool reads G-code only; delete the line, and give the command to the "
            "machine yourself before running the program"
        )
