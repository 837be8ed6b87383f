"""Strict checks of SVG attribute syntax: path data, transforms, lengths, point lists.

Design notes: docs/internals.md, ``camtool/importers/svgcheck.py``.
"""

from __future__ import annotations

import itertools
import math
import re

NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?", re.ASCII)
"""A number as SVG's grammar writes it (ASCII digits: Python's ``float`` reads more)."""
_BARE_POINT = re.compile(r"\d\.(?!\d)", re.ASCII)
"""A number's decimal point with no digit after it ("300.", "2.e-4"): SVG's grammar reads it,
svgelements stops reading the path or point list there and keeps what came before."""
_SEPARATORS = " \t\r\n\f,"
_ARITY = {"m": 2, "l": 2, "h": 1, "v": 1, "c": 6, "s": 4, "q": 4, "t": 2, "a": 7, "z": 0}
_LENGTH = re.compile(rf"\s*({NUMBER.pattern})(mm|cm|in|pt|pc|px|em|ex|%)?\s*", re.ASCII)
_TRANSFORM_ARGS = {
    "matrix": (6,),
    "translate": (1, 2),
    "scale": (1, 2),
    "rotate": (1, 3),
    "skewX": (1,),
    "skewY": (1,),
}
_TRANSFORM_ITEM = re.compile(r"[\s,]*([A-Za-z]+)\s*\(([^()]*)\)[\s,]*", re.ASCII)


_S = r"[ \t\r\n\f,]*+"
_N = rf"(?>{NUMBER.pattern})"  # NUMBER, as its match takes it


def _run_of(count: int) -> str:
    """A pattern of ``count`` numbers, each after any separators."""
    return f"(?:{_S}{_N}){{{count}}}"


_FLAG = f"{_S}[01]"
_COMMAND = (
    f"(?:[MmLlTt](?:{_run_of(2)})++|[HhVv](?:{_run_of(1)})++|[Cc](?:{_run_of(6)})++"
    f"|[SsQq](?:{_run_of(4)})++|[Aa](?:{_run_of(3)}{_FLAG}{_FLAG}{_run_of(2)})++|[Zz])"
)
_WELL_FORMED = re.compile(f"{_S}(?=[Mm])(?:{_COMMAND}{_S})*+", re.ASCII)
"""Path data :func:`check_path_data` reads without a fault, in one possessive match (no
backtracking): each command with a multiple of its count of numbers, numbers split where
its lexer splits them. What it does not match is read by the lexer, which says what is
wrong (or reads it: a subset is enough)."""


def check_path_data(d: str) -> str:
    """Check ``d`` against the SVG path data grammar, arc flags included.

    Returns:
        ``d`` as svgelements reads it whole: a 0 written after each decimal point that
        has no digit after it (``300.`` becomes ``300.0``, the same number).

    Raises:
        ValueError: the data does not start with a moveto, holds an unknown command, a
            number that cannot be read, or a count of numbers its command cannot take.
    """
    if _WELL_FORMED.fullmatch(d) is not None and _BARE_POINT.search(d) is None:
        return d  # what _read_path_data returns for it, without reading it number by number
    return _read_path_data(d)


def _read_path_data(d: str) -> str:
    """:func:`check_path_data`'s lexer: every command and number, one after the other."""
    pos, n = 0, len(d)
    command: str | None = None
    args = 0
    bare: list[int] = []  # where a 0 goes after a bare decimal point

    def close_command() -> None:
        if command is None:
            return
        arity = _ARITY[command.lower()]
        if (arity == 0 and args) or (arity and (args == 0 or args % arity)):
            need = "no numbers" if arity == 0 else f"a multiple of {arity} numbers"
            raise ValueError(f"command {command!r} takes {need}, got {args} (near character {pos})")

    while True:
        while pos < n and d[pos] in _SEPARATORS:
            pos += 1
        if pos >= n:
            break
        char = d[pos]
        if char.isalpha() and char not in "eE":
            if char.lower() not in _ARITY:
                raise ValueError(f"unknown command {char!r} at character {pos}")
            if command is None and char not in "Mm":
                raise ValueError(f"path data must start with M or m, not {char!r}")
            close_command()
            command, args, pos = char, 0, pos + 1
            continue
        if command is None:
            raise ValueError(f"path data must start with M or m, not {char!r}")
        if command in "Aa" and args % 7 in (3, 4):  # flags: one digit, separators optional
            if char not in "01":
                raise ValueError(f"arc flag must be 0 or 1, got {char!r} at character {pos}")
            pos, args = pos + 1, args + 1
            continue
        match = NUMBER.match(d, pos)
        if match is None:
            raise ValueError(f"cannot read a number at character {pos} ({d[pos : pos + 12]!r})")
        point = _BARE_POINT.search(match.group())
        if point is not None:
            bare.append(pos + point.end())
        pos, args = match.end(), args + 1
    close_command()
    cuts = [0, *bare, n]
    return "0".join(d[a:b] for a, b in itertools.pairwise(cuts))


def check_transform(text: str) -> None:
    """Check a ``transform`` attribute: a list of matrix/translate/scale/rotate/skewX/skewY.

    Raises:
        ValueError: an unknown function, a wrong number of arguments or unreadable text.
    """
    pos = 0
    while pos < len(text):
        match = _TRANSFORM_ITEM.match(text, pos)
        if match is None or match.end() == pos:
            if text[pos:].strip(_SEPARATORS) == "":
                return
            raise ValueError(f"cannot read the transform at character {pos}")
        name, body = match.group(1), match.group(2)
        if name not in _TRANSFORM_ARGS:
            known = ", ".join(_TRANSFORM_ARGS)
            raise ValueError(f"unknown transform function {name!r}; SVG has {known}")
        numbers = _numbers(body, f"{name}()")
        if len(numbers) not in _TRANSFORM_ARGS[name]:
            counts = " or ".join(str(c) for c in _TRANSFORM_ARGS[name])
            raise ValueError(f"{name}() takes {counts} numbers, got {len(numbers)}")
        pos = match.end()


def check_length(text: str, *, negative: bool = True) -> None:
    """Check a length attribute: a finite number with a unit camtool knows (mm cm in pt pc px %).

    Args:
        text: the attribute's value.
        negative: whether a negative value is allowed (coordinates yes, sizes and radii no).

    Raises:
        ValueError: anything else, font-relative units (em, ex) included.
    """
    match = _LENGTH.fullmatch(text)
    if match is None or not math.isfinite(float(match.group(1))):
        raise ValueError("must be a number with an optional unit (mm, cm, in, pt, pc, px, %)")
    if match.group(2) in ("em", "ex"):
        raise ValueError("font-relative units (em, ex) are not supported; use mm, px or %")
    if not negative and float(match.group(1)) < 0:
        raise ValueError("must not be negative")


def check_points(text: str) -> str:
    """Check a ``points`` attribute (polyline, polygon): an even count of numbers.

    Returns:
        The numbers as svgelements reads them all, one space apart, a 0 written after each
        decimal point that has no digit after it (``50.`` becomes ``50.0``).

    Raises:
        ValueError: a token is not a number, or the count is odd.
    """
    numbers = _numbers(text, "points")
    if len(numbers) % 2:
        count = len(numbers)
        raise ValueError(f"points must be x,y pairs, got an odd count of numbers ({count})")
    return " ".join(_BARE_POINT.sub(lambda m: m.group() + "0", number) for number in numbers)


def _numbers(text: str, what: str) -> list[str]:
    tokens = [t for t in re.split(r"[\s,]+", text.strip()) if t]
    out: list[str] = []
    for token in tokens:
        pos = 0
        while pos < len(token):  # "1-2" and "1.5.5" are two numbers each
            match = NUMBER.match(token, pos)
            if match is None:
                raise ValueError(f"{what}: cannot read a number in {token!r}")
            out.append(match.group())
            pos = match.end()
    return out
