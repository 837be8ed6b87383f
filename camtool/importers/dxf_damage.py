"""Damaged DXF data: numbers recover mode can only guess at, SPLINEs of the wrong degree.

Recover mode reads a number it cannot parse the way C's ``strtod`` does, up to the first
character that does not belong (``recover.py``, ``_search_float``/``_search_int``):
``"2,5"``, a decimal comma from a program that wrote the numbers in its user's
language, becomes ``2.0``; ``"1.#QNAN"`` becomes ``1.0``. It logs each such guess as
``recovered invalid floating point value "2,5" near line 80 as "2.0"``. A guessed
coordinate of an entity would move the cut with nothing but a warning, so
:func:`refuse_guessed_numbers` refuses the file when a guess lies in its ENTITIES or
BLOCKS section. A guess in the header or the tables (``$EXTMIN``, a view) changes
nothing camtool cuts, and stays a repair that ``camtool inspect`` lists.
"""

from __future__ import annotations

import itertools
import re
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from camtool.model.errors import InputError

_GUESS = re.compile(
    r'^recovered invalid (floating point|integer) value "(.*)" near line (\d+) as "(.*)"$'
)
_FLOAT = re.compile(r"[+-]?\d+(\.\d*)?([eE][+-]?\d+)?")
_INT = re.compile(r"[+-]?\d+")
HARMLESS_SECTIONS = frozenset({"HEADER", "CLASSES", "TABLES", "THUMBNAILIMAGE"})
"""Sections whose numbers place nothing camtool cuts (ENTITIES, BLOCKS and OBJECTS do:
an MLINE's style, for one, is an object)."""


@dataclass(frozen=True)
class Guess:
    """One number recover mode guessed: the text in the file, its 1-based line, the guess."""

    text: str
    line: int
    value: str


def guesses(repairs: Sequence[str]) -> list[Guess]:
    """The numbers among recover mode's repairs that were not numbers as written.

    A value recover mode re-read although it was whole (the ``0`` beside a damaged
    coordinate of the same point is re-read with it) is not a guess: only text with
    more than a number in it (after white space is stripped) counts.
    """
    out = []
    for message in repairs:
        found = _GUESS.match(message)
        if found is None:
            continue
        kind, text, line, value = found.groups()
        number = _FLOAT if kind == "floating point" else _INT
        if number.fullmatch(text.strip()) is None:
            out.append(Guess(text, int(line), value))
    return out


def _places(path: Path, lines: set[int]) -> dict[int, tuple[str, str]]:
    """For each of ``lines`` of an ASCII DXF file: its section and the entity it is in.

    The file is read as pairs of lines (group code, value); a line's section is the
    last ``0 SECTION`` / ``2 NAME`` before it, its entity the last ``0 TYPE`` tag.
    """
    places: dict[int, tuple[str, str]] = {}
    section, entity = "", ""
    last = max(lines)
    code = b""
    with path.open("rb") as f:
        for number, raw in enumerate(f, start=1):
            text = raw.strip()
            if number % 2:
                code = text
            elif code == b"0":
                entity = text.decode("ascii", "replace")
            elif code == b"2" and entity == "SECTION":
                section = text.decode("ascii", "replace").upper()
            if number in lines:
                places[number] = (section, entity)
            if number >= last:
                break
    return places


def refuse_guessed_numbers(
    path: Path, repairs: Sequence[str], line_of: Callable[[int], int] | None = None
) -> None:
    """Refuse a DXF file whose entities hold a number recover mode had to guess.

    Args:
        path: the DXF file, read by ezdxf's recover mode.
        repairs: the messages recover mode logged.
        line_of: the file's line of a line recover mode read, when it read a changed
            copy (:func:`~camtool.importers.dxf_subclass.with_subclass_markers`);
            ``None``: the same.

    Raises:
        InputError: a guessed number lies outside :data:`HARMLESS_SECTIONS` (or where
            the section cannot be told); the message names the file, the line (as
            recover mode counts it: near the number, not always on it), the
            text, the entity and what recover mode would have made of it, and how
            many such numbers there are.
    """
    found = guesses(repairs)
    if not found:
        return
    if line_of is not None:
        found = [Guess(g.text, line_of(g.line), g.value) for g in found]
    places = _places(path, {g.line for g in found})
    cut = [g for g in found if places.get(g.line, ("", ""))[0] not in HARMLESS_SECTIONS]
    if not cut:
        return
    first = cut[0]
    section, entity = places.get(first.line, ("", ""))
    where = f" of a {entity} in the {section} section" if section and entity else ""
    comma = "," in first.text
    hint = (
        " (a decimal comma: the program that wrote it used its language's number format; "
        "a DXF file takes a decimal point)"
        if comma
        else ""
    )
    more = f"; {len(cut) - 1} more such number(s)" if len(cut) > 1 else ""
    raise InputError(
        f"{path}: near line {first.line}: {first.text!r}{where} is not a number{hint}; ezdxf's "
        f"recover mode would read it as {first.value}, which would move the cut{more}."
        + (
            " Export the drawing again as DXF with decimal points"
            if comma
            else " Export the drawing again as DXF from the CAD program"
        )
    )


MAX_IMPLIED_DEGREE = 11
"""The highest degree :func:`implied_degree` derives (AutoCAD's SPLINE goes to 11)."""


def implied_degree(entity: Any) -> int | None:
    """The degree a SPLINE's knots and control points imply, where it declares another.

    A B-spline of ``n`` control points and degree ``p`` has ``n + p + 1`` knots, and a
    clamped one (as CAD programs write them) repeats its first and its last knot
    exactly ``p + 1`` times (Piegl & Tiller, *The NURBS Book*, 2nd ed., section 2.2).
    Some exporters write a quadratic's data under degree 3 (dxf-parser's
    ``arcs-as-splines.dxf``: circles of 9 control points, 12 knots). When the counts
    imply another degree ``p ≥ 1`` and the knot vector is clamped for exactly that
    ``p``, the numbers describe one curve and this is its degree.

    Returns:
        The implied degree, or ``None``: the SPLINE agrees with its declared degree, is
        stored periodically (``n + 1`` knots), has no control points, or its data fit
        no degree (it stays invalid).
    """
    if entity.dxftype() != "SPLINE":
        return None
    count, knots = entity.control_point_count(), list(entity.knots)
    declared = int(entity.dxf.degree)
    if count == 0 or len(knots) == count + declared + 1:
        return None
    if entity.closed and len(knots) == count + 1:
        return None
    p = len(knots) - count - 1
    weights = len(entity.weights)
    if not 1 <= p <= MAX_IMPLIED_DEGREE or count < p + 1 or weights not in (0, count):
        return None
    ends = knots[: p + 1] + knots[-p - 1 :]
    clamped = len(set(ends[: p + 1])) == 1 and len(set(ends[p + 1 :])) == 1
    inner = knots[p + 1 : -p - 1]
    rising = all(a <= b for a, b in itertools.pairwise(knots)) and knots[0] < knots[-1]
    if not (clamped and rising and all(knots[0] < k < knots[-1] for k in inner)):
        return None
    return p
