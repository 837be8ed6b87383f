"""The ``pic-mmh`` dialect: the PIC18F8720 controller of the GMM micro machine tool.

Source: seed-000 §3 (reference/seed-000.md), requirements S000-01…08. Example
block, verbatim from the thesis (L1731)::

    G02X02969.00Y03400.00I03012.00J03040.00F08;

- one block per line, no spaces, no N-words, no comments, every block ends
  with ``;`` (S000-01);
- coordinates in µm, absolute from the G54 part zero: axis letter, ``-`` only
  for negatives (or ``+`` too with ``sign = "always"``), 5 zero-padded integer
  digits, ``.``, 2 decimals (S000-02, S000-03);
- ``I``/``J`` are the ABSOLUTE arc centre, same format (S000-04);
- ``F`` is two zero-padded digits in units of 0.1 mm/min: ``F08`` = 0.8 mm/min
  (S000-05); F01…F99 only;
- programs open with ``G54;`` ``G90;`` and close with ``M30;`` (S000-06);
- no Z words (S000-08): a program that moves Z is refused;
- a full circle is written as two half arcs (the firmware takes the start from
  its current position; a zero-length G02 is ambiguous, seed-000 §3.7 item 7).
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import ClassVar

from camtool.errors import DialectError, ParseError
from camtool.geometry import distance
from camtool.machine import Machine
from camtool.post.base import PostProcessor, PostResult
from camtool.post.numfmt import NumberFormat, format_int
from camtool.program import ArcMove, Linear, Move, Program, Rapid, segment_of

_COORD = r"([+-]?\d{5}\.\d{2})"
_BLOCK = re.compile(rf"^G0(?P<g>[0-3])X{_COORD}Y{_COORD}(?:I{_COORD}J{_COORD})?(?:F(?P<f>\d\d))?;$")
_AUX = re.compile(r"^(?:G54|G90|M30|M05|G04P\d\d|G28X0Y0|G28Z0|M0[34]S\d{4}|M06T\d\d);$")


@dataclass
class _Writer:
    """Accumulates blocks; knows the contour and block number for messages."""

    lines: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)

    def where(self, move: Move) -> str:
        block = len(self.lines) + 1
        return f"contour {move.contour}, block {block}" if move.contour else f"block {block}"


class PicMmhPost(PostProcessor):
    """Writer and reader of the pic-mmh dialect (seed-000 §3).

    Args:
        sign: ``"negative"`` (default, as the thesis example) or ``"always"``.
        feed_unit_mm_min: mm/min per unit of the F word (default 0.1, S000-05).
    """

    formats: ClassVar[Mapping[str, str]] = MappingProxyType({"code": ".pic"})

    def __init__(self, *, sign: str = "negative", feed_unit_mm_min: float = 0.1) -> None:
        self.coord = NumberFormat(scale=1000.0, decimals=2, int_digits=5, sign=sign)
        self.feed_unit_mm_min = feed_unit_mm_min

    # -- writing ---------------------------------------------------------------

    def emit(self, program: Program, machine: Machine, *, fmt: str | None = None) -> PostResult:
        """Write ``program`` as pic-mmh blocks.

        Raises:
            DialectError: a Z move, a coordinate over 5 integer digits, a feed
                outside F01–F99, or a point (arcs by their extremes) outside the
                machine's work area; the message names the contour and block.
        """
        self.check_format(fmt)
        w = _Writer(["G54;", "G90;"])
        fast_feeds: set[str] = set()
        for start, move in program.steps():
            if move.z is not None:
                raise DialectError(
                    f"{w.where(move)}: pic-mmh has no Z word (seed-000 S000-08); "
                    "set the depth by hand or use a target with a Z axis"
                )
            self._check_area(start, move, machine, w)
            if isinstance(move, Rapid):
                w.lines.append(f"G00{self._xy(move.x, move.y, move, w)};")
                continue
            f = self._feed(move, w)
            if machine.max_step_rate_hz and machine.step_rate_hz(move.feed_mm_min) > (
                machine.max_step_rate_hz
            ):
                fast_feeds.add(f)
            if isinstance(move, Linear):
                w.lines.append(f"G01{self._xy(move.x, move.y, move, w)}F{f};")
            else:
                for half in _halves(start, move):
                    g = "G02" if half.clockwise else "G03"
                    xy = self._xy(half.x, half.y, half, w)
                    ij = self._word("I", half.cx, half, w) + self._word("J", half.cy, half, w)
                    w.lines.append(f"{g}{xy}{ij}F{f};")
        w.lines.append("M30;")
        for f in sorted(fast_feeds):
            rate = machine.step_rate_hz(int(f) * self.feed_unit_mm_min)
            w.warnings.append(
                f"F{f} needs {rate:.0f} steps/s but the serial link limits the machine to "
                f"{machine.max_step_rate_hz:.0f} Hz (seed-000 S000-05); it will run slower"
            )
        return PostResult("\n".join(w.lines) + "\n", len(w.lines), tuple(w.warnings))

    def _word(self, letter: str, value_mm: float, move: Move, w: _Writer) -> str:
        try:
            return letter + self.coord.format(value_mm)
        except DialectError as exc:
            raise DialectError(
                f"{w.where(move)}: {letter} = {exc} (µm; at most 99999.99 = 99.99999 mm)"
            ) from exc

    def _xy(self, x: float, y: float, move: Move, w: _Writer) -> str:
        return self._word("X", x, move, w) + self._word("Y", y, move, w)

    def _feed(self, move: Linear | ArcMove, w: _Writer) -> str:
        exact = move.feed_mm_min / self.feed_unit_mm_min
        code = int(exact + 0.5)
        if not 1 <= code <= 99:
            lo, hi = self.feed_unit_mm_min, 99 * self.feed_unit_mm_min
            raise DialectError(
                f"{w.where(move)}: feed {move.feed_mm_min:g} mm/min is outside F01–F99 "
                f"({lo:g}–{hi:g} mm/min)"
            )
        text = format_int(code, 2, what="feed code")
        if abs(exact - code) > 1e-6:
            msg = (
                f"feed {move.feed_mm_min:g} mm/min rounded to F{text} "
                f"({code * self.feed_unit_mm_min:g} mm/min)"
            )
            if msg not in w.warnings:
                w.warnings.append(msg)
        return text

    @staticmethod
    def _check_area(start: tuple[float, float], move: Move, machine: Machine, w: _Writer) -> None:
        box = segment_of(start, move).bbox()
        if machine.outside_work_area(box):
            x0, y0, x1, y1 = machine.work_area_mm
            raise DialectError(
                f"{w.where(move)}: reaches ({box[0]:.4f}, {box[1]:.4f})–({box[2]:.4f}, "
                f"{box[3]:.4f}) mm, outside the {x1 - x0:g} × {y1 - y0:g} mm work area "
                f"of {machine.name}; move the drawing or use --fit"
            )

    # -- reading ---------------------------------------------------------------

    def parse(self, code: str | bytes, *, source: str = "<code>") -> Program:
        """Read pic-mmh blocks back into moves (the grammar of seed-000 §3.6).

        ``G04``, ``G28``, ``G54``, ``G90``, ``M03/M04/M05/M06`` and ``M30`` are
        accepted and carry no motion in the returned program.

        Raises:
            ParseError: a line that is not a pic-mmh block, or a G01–G03 block
                before any feed, naming ``source`` and the line number.
        """
        if isinstance(code, bytes):
            code = code.decode("ascii", errors="replace")
        moves: list[Move] = []
        lines: list[int] = []
        contour = 0
        for number, raw in enumerate(code.splitlines(), start=1):
            line = raw.strip()
            if not line or _AUX.match(line):
                continue
            m = _BLOCK.match(line)
            if m is None:
                raise ParseError(f"{source}:{number}: not a pic-mmh block: {line!r}")
            moves.append(self._move(m, number, source, contour + (m["g"] == "0")))
            lines.append(number)
            contour += m["g"] == "0"
        return Program(tuple(moves), lines=tuple(lines))

    def _move(self, m: re.Match[str], number: int, source: str, contour: int) -> Move:
        g = int(m["g"])
        x, y = self.coord.parse(m[2]), self.coord.parse(m[3])
        has_centre = m[4] is not None
        if (g >= 2) != has_centre:
            raise ParseError(f"{source}:{number}: G0{g} {'needs' if g >= 2 else 'takes no'} I/J")
        if g == 0:
            if m["f"] is not None:
                raise ParseError(f"{source}:{number}: G00 takes no F word")
            return Rapid(x, y, contour=contour)
        if m["f"] is None:
            raise ParseError(f"{source}:{number}: G0{g} needs an F word (two digits)")
        feed = int(m["f"]) * self.feed_unit_mm_min
        if g == 1:
            return Linear(x, y, feed, contour=contour)
        cx, cy = self.coord.parse(m[4]), self.coord.parse(m[5])
        return ArcMove(x, y, cx, cy, g == 2, feed, contour=contour)


def _halves(start: tuple[float, float], move: ArcMove) -> list[ArcMove]:
    """A full circle as two half arcs through the opposite point; other arcs as given."""
    if distance(start, (move.x, move.y)) > 1e-9:
        return [move]
    opposite = (2 * move.cx - start[0], 2 * move.cy - start[1])
    first = ArcMove(
        *opposite, move.cx, move.cy, move.clockwise, move.feed_mm_min, None, move.contour
    )
    return [first, move]
