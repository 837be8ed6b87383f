"""RS-274/NGC parameters set to plain numbers: ``#100=2.0 (safe Z)`` … ``G0 Z#100``.

gEDA PCB's G-code export and LinuxCNC's G-code wizard scripts (engraving, dials) set a few
numbered parameters to numbers at the top of the program and read them as word values;
hand-written LinuxCNC programs and some plotters' G-code name them (``#<pen_up>=-12`` …
``G1 Z#<pen_up>``). :func:`expand_parameters` writes each read as the number it holds, line
by line, before the program is lexed, so the reader sees plain words. The rules are
LinuxCNC's ("Parameters" in its G-code overview): a parameter is set by ``#n=value`` or
``#<name>=value``; all the parameters a line reads are read before any it sets is set
("parameter setting is done in parallel"); a value is a number, or another parameter, with
a sign; a read comes right after its word's letter (``X#1``, ``X-#<depth>``); spaces do not
count (``#1 .5`` is ``#1.5``, which names no parameter; ``#<pen up>`` is ``#<penup>``), nor
does the case of a name. A ``#`` anywhere else, a parameter number that is not whole, or a
digit right after a name (``X#<a>5``) is refused as LinuxCNC refuses it.

What is left as it stands, for the lexer to refuse with its own message: a line with an
expression (``[ ]``) or an indirect parameter (``##1``). A block-delete line (``/``) with a
parameter is refused: whether it runs is the controller's switch. A parameter read before
any line sets it (LinuxCNC reads 0 for a number, or the value a previous run saved, and
refuses a name it has not met) and the controller's own (``#5061``… offsets and probe
results, above :data:`LAST_USER`; names that begin with ``_``, globals such as ``#<_x>``,
the position, which LinuxCNC does not let a program set) are refused: camtool cannot know
their values.
"""

from __future__ import annotations

import re

from camtool.importers.gcode_lexer import program_number
from camtool.model.errors import InputError, quoted

LAST_USER = 5000
"""The last numbered parameter a program sets for itself; above it LinuxCNC keeps its own
(probe results, coordinate-system offsets, the tool in the spindle)."""

Key = int | str
"""A parameter: its number, or its name in lower case (``#<Depth>`` is ``"depth"``)."""

_NUM = r"(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?![0-9.])"
"""A number, not followed by more digits or a point (``5.5.5`` is none)."""
_NAME = r"<([^<>#\[\]]+)>(?![0-9.])"
"""A parameter's name in angle brackets, not followed by a digit or a point (LinuxCNC
refuses ``X#<a>5``: "Bad character '5'")."""
_SET = re.compile(rf"#(?:({_NUM})|{_NAME})=([+-]?)(?:({_NUM})|#({_NUM})|#{_NAME})")
"""An assignment in a line without spaces: ``#n=`` or ``#<name>=`` a signed number or a
signed parameter."""
_READ = re.compile(rf"(?<=[A-Za-z])([+-]?)#(?:({_NUM})|{_NAME})")
"""A parameter read as a word's value, right after the word's letter (a sign between them
negates it): ``X#1``, ``X-#1``, ``Z#<depth>``. A ``#`` anywhere else starts a setting for
LinuxCNC."""
_O_WORD = re.compile(r"\s*(?:\([^)]*\)\s*)*(?:/\s*)?(?:[Nn]\s*[0-9.]+\s*)?[Oo]\s*[<0-9]")
"""A line that begins with an O-word (``o<circles> sub``, ``O100 while``) or a program
number, after comments, a block delete and a line number."""
_SPACE = re.compile(r"\s+")
_COMMENT = re.compile(r"\([^)]*\)|;.*")
_LINE = re.compile(r"([^\r\n]*)(\r\n|\r|\n|$)")
"""A line and its end, as the reader splits them (LF, CR LF or CR)."""


def expand_parameters(text: str, source: str) -> str:
    """``text`` with each read of a parameter set to a number written as that number.

    Lines keep their number and their comments; an assignment leaves a blank. A line this
    does not understand is kept as it stands (the lexer names what it holds), and so is
    every line after it: what such a line sets is not known, and the lexer stops at it first.
    So is an O-word's line (a subroutine, a loop: what runs after it, with which
    parameters, is not known; the lexer refuses it), with or without a parameter.

    Raises:
        InputError: a parameter read before any line sets it, a system parameter (above
            :data:`LAST_USER`) or a global name (``#<_x>``) read or set, or one on a
            block-delete line; the message names ``source:line``.
    """
    if "#" not in text:
        return text
    values: dict[Key, str] = {}
    out = []
    for number, m in enumerate(_LINE.finditer(text), start=1):
        if not m[0]:
            break  # the empty match at the end of the text
        line = m[1]
        if ("o" in line or "O" in line) and _o_word(line):
            out.append(text[m.start() :])  # the rest as it stands: the lexer refuses it
            break
        if "#" in line:
            expanded = _expand_line(line, values, f"{source}:{number}")
            if expanded is None:  # the rest as it stands: the lexer refuses this line
                out.append(text[m.start() :])
                break
            line = expanded
        out.append(line + m[2])
    return "".join(out)


def _o_word(raw: str) -> bool:
    """Whether the line ``raw`` holds an O-word the lexer refuses (:data:`_O_WORD`).

    A program number alone (``O1000 (PART)``, Fanuc's and Haas's first line) is none: the
    lexer reads it as nothing, and the parameters after it are read.
    """
    if not _O_WORD.match(raw):
        return False
    code = "".join(text for text, comment in _split_comments(raw) if not comment)
    return not program_number(_SPACE.sub("", code.strip().removeprefix("/")))


def _expand_line(raw: str, values: dict[Key, str], where: str) -> str | None:
    """One line with its reads written as numbers; its sets go into ``values`` after.

    ``None`` for a line with an expression or an indirect parameter.
    """
    parts = _split_comments(raw)
    code = "".join(text for text, comment in parts if not comment)
    if "#" not in code:
        return raw  # in a comment only
    if code.lstrip()[:1] == "/":
        raise InputError(
            f"{where}: a block-delete line ('/') sets or reads a parameter: whether it runs "
            "depends on the controller's block-delete switch, which camtool cannot know; "
            "remove the line or its '/'"
        )
    if any(c in code for c in "[]") or "##" in code.replace(" ", ""):
        return None
    sets: dict[Key, str] = {}
    out = []
    for text, comment in parts:
        if not comment:  # LinuxCNC reads a line without its spaces: `#1 .5` is `#1.5`
            text = _SPACE.sub("", text)
            text = _SET.sub(lambda m: _assign(m, values, sets, where), text)
            text = _READ.sub(
                lambda m: _signed(m[1], _value(_key(m[2], m[3], where), values, where)), text
            )
            if "#" in text:
                raise InputError(
                    f"{where}: a '#' in {quoted(code.strip())} is neither a word's value ('X#1') "
                    "nor a setting ('#1=2.5'), which LinuxCNC refuses; write the number itself"
                )
        out.append(text)
    values.update(sets)  # a line's sets after all its reads
    return "".join(out)


def _split_comments(raw: str) -> list[tuple[str, bool]]:
    """``raw`` cut into ``(text, is_comment)`` runs: ``( … )`` and a ``;`` to the end."""
    parts: list[tuple[str, bool]] = []
    at = 0
    for m in _COMMENT.finditer(raw):
        parts.append((raw[at : m.start()], False))
        parts.append((m[0], True))
        at = m.end()
    parts.append((raw[at:], False))
    return parts


def _assign(m: re.Match[str], values: dict[Key, str], sets: dict[Key, str], where: str) -> str:
    """Note the set ``#n=value`` or ``#<name>=value`` of the match for after the line.

    It leaves a blank.
    """
    key = _user(_key(m[1], m[2], where), where)
    held = m[4] if m[4] is not None else _value(_key(m[5], m[6], where), values, where)
    sets[key] = _signed(m[3], held)
    return " "


def _key(number: str | None, name: str | None, where: str) -> Key:
    """The parameter a match names: ``number`` (:func:`_index`) or ``name``, case-folded."""
    if number is not None:
        return _index(number, where)
    assert name is not None
    return name.casefold()


def _shown(key: Key) -> str:
    """``#12`` or ``#<depth>``, as a message names the parameter."""
    return f"#{key}" if isinstance(key, int) else f"#<{key}>"


def _index(text: str, where: str) -> int:
    """The parameter number ``text`` names: a whole number (``1.0`` is 1), else refused."""
    value = float(text)
    if value != int(value):
        raise InputError(
            f"{where}: #{text} names no parameter: a parameter's number is a whole number "
            "(LinuxCNC refuses the line)"
        )
    return int(value)


def _value(key: Key, values: dict[Key, str], where: str) -> str:
    """The number the parameter ``key`` holds, as written."""
    _user(key, where)
    if key not in values:
        reads = (
            "reads 0, or the value a run before saved"
            if isinstance(key, int)
            else "refuses it: 'named parameter not defined'"
        )
        raise InputError(
            f"{where}: {_shown(key)} is read before any line of the program sets it "
            f"(LinuxCNC {reads}): set it with {_shown(key)}=value first"
        )
    return values[key]


def _user(key: Key, where: str) -> Key:
    """``key`` if a program may set and read it, else refused.

    Numbers 1 to :data:`LAST_USER`; names that do not begin with ``_`` (LinuxCNC's globals,
    among them its own read-only ones: ``#<_x>``, ``#<_metric>``).
    """
    if isinstance(key, str):
        if key.startswith("_"):
            raise InputError(
                f"{where}: {_shown(key)} is a global parameter, a name under which LinuxCNC "
                "keeps its own values too (the position #<_x>, the units #<_metric>), which "
                "a program cannot set: camtool reads a program's own named parameters "
                "(#<name>, without '_'); post the program again with plain numbers"
            )
        return key
    if not 1 <= key <= LAST_USER:
        raise InputError(
            f"{where}: #{key} is a parameter the controller keeps (offsets, probe results, "
            f"the tool), not one the program sets (#1 to #{LAST_USER}): camtool cannot know "
            "its value; post the program again with plain numbers"
        )
    return key


def _signed(sign: str, text: str) -> str:
    """``text`` (a number, maybe signed) with ``sign`` applied exactly: ``-`` of ``-2``: ``2``."""
    if sign != "-":
        return text
    if text.startswith("-"):
        return text[1:]
    return "-" + text.removeprefix("+")
