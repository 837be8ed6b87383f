"""The ``pic-mmh`` dialect: the PIC18F8720 controller of the GMM micro machine tool.

Source: UNAM-GMM §3, requirements S000-01…08. Example
block, verbatim from the thesis (L1731)::

Design notes: docs/internals.md, ``postprocessors/pic_mmh/dialect.py``.
"""

from __future__ import annotations

import bisect
import math
import re
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from decimal import ROUND_HALF_UP, Decimal
from types import MappingProxyType
from typing import Any, ClassVar

from camtool.model.errors import DialectError, ParseError, quoted
from camtool.model.machine import Machine
from camtool.model.program import (
    ArcMove,
    Command,
    Coolant,
    DrillCycle,
    Dwell,
    Home,
    LengthOffset,
    Linear,
    Move,
    PathControl,
    PlaneArc,
    Program,
    Rapid,
    Spindle,
    Stop,
    ToolChange,
    WorkOffset,
)
from camtool.model.shapes import Arc, distance
from camtool.post.base import (
    ContourCounter,
    PostProcessor,
    PostResult,
    WriterState,
    check_placement,
    check_work_area,
    far_from_zero,
    from_options,
    input_line,
)
from camtool.post.numfmt import NumberFormat, format_int

# -- the feed table ---------------------------------------------------------------------
# The F word of the pic-mmh dialect: two-digit feed codes and the feed each one means.
#
# Source: UNAM-GMM §4.1 and §4.9, S000-05. The firmware reads F with its
# "obtención de 2 dígitos" routine into the variable ``Avance`` (L1839–L1845) and
# *computes* the interpolator period from it, it does not look it up in a table:
# ``FCIAALGORITMO = (PPR * AVANCE) / 60``, ``PDOALGORITMO = 1000000 / FCIAALGORITMO``
# with ``PPR = 1000 / RESOL`` steps/mm (annex A.5, L3662–L3664; Eq. 3.1
# reconstructed as ``f = d·F·0.1/60``). So the default table is linear: code
# ``n`` means ``n × 0.1`` mm/min, F01–F99 = 0.1–9.9 mm/min (F08 = 0.8 mm/min, the
# thesis example, L1731). A firmware that maps F codes to a table of step delays
# instead is described by an explicit ``feed_codes`` table.

DEFAULT_FEED_UNIT_MM_MIN = 0.1
"""mm/min per unit of F under the default, linear table (UNAM-GMM §4.9, S000-05)."""

MAX_CODE = 99
"""F has two digits (UNAM-GMM Tabla 21, L3297–L3358); F00 would divide by zero
in the firmware's period ``1000000 / FCIAALGORITMO`` (L3664), so codes are 1–99."""


@dataclass(frozen=True)
class FeedTable:
    """The feed codes a pic-mmh controller knows, each with its feed in mm/min.

    Attributes:
        codes: ``(code, feed_mm_min)`` pairs sorted by code; codes are 1–99 and
            the feeds strictly increase with the code (a faster code is never
            slower), each > 0 mm/min.
    """

    codes: tuple[tuple[int, float], ...]

    def __post_init__(self) -> None:
        if not self.codes:
            raise ValueError("feed_codes is empty; give at least one code = mm/min pair")
        previous: tuple[int, float] | None = None
        for code, feed in self.codes:
            if not 1 <= code <= MAX_CODE:
                raise ValueError(f"feed code {code} is not F01–F{MAX_CODE} (two digits, not F00)")
            if not (math.isfinite(feed) and feed > 0):
                raise ValueError(f"feed code {code}: {feed!r} mm/min must be a number > 0")
            if previous is not None and (code <= previous[0] or feed <= previous[1]):
                raise ValueError(
                    f"feed codes must be sorted with feeds strictly increasing: "
                    f"F{previous[0]:02d} = {previous[1]:g} then F{code:02d} = {feed:g} mm/min"
                )
            previous = (code, feed)

    @classmethod
    def linear(cls, unit_mm_min: float = DEFAULT_FEED_UNIT_MM_MIN) -> FeedTable:
        """Codes 1–99 meaning ``code × unit_mm_min`` mm/min (the firmware's formula).

        Raises:
            ValueError: ``unit_mm_min`` is not a finite number > 0.
        """
        unit = _positive("feed_unit_mm_min", unit_mm_min)
        return cls(tuple((n, n * unit) for n in range(1, MAX_CODE + 1)))

    @classmethod
    def from_option(cls, table: Mapping[Any, Any]) -> FeedTable:
        """The table of a ``[dialect_options] feed_codes`` TOML table.

        Keys are the codes as written (``"8"`` or ``"08"``; ints from Python),
        values the feed each code runs, mm/min.

        Raises:
            ValueError: ``table`` is not a table, a key is not a code 1–99 written
                with at most two digits, a value is not a number > 0, two keys
                name one code, or the feeds do not increase with the code.
        """
        if not isinstance(table, Mapping):
            raise ValueError(f"feed_codes must be a table of code = mm/min, not {table!r}")
        pairs: dict[int, float] = {}
        for key, value in table.items():
            code = _code(key)
            if code in pairs:
                raise ValueError(f"feed_codes names code {code} twice")
            pairs[code] = _positive(f"feed_codes[{key!r}]", value)
        return cls(tuple(sorted(pairs.items())))

    @property
    def lowest(self) -> tuple[int, float]:
        """The slowest ``(code, feed_mm_min)``."""
        return self.codes[0]

    @property
    def highest(self) -> tuple[int, float]:
        """The fastest ``(code, feed_mm_min)``."""
        return self.codes[-1]

    def feed_of(self, code: int) -> float | None:
        """The feed of ``code``, mm/min, or ``None`` when the table has no such code."""
        i = bisect.bisect_left(self.codes, (code, -math.inf))
        return self.codes[i][1] if i < len(self.codes) and self.codes[i][0] == code else None

    def nearest(self, feed_mm_min: float) -> tuple[int, float] | None:
        """The code whose feed is nearest ``feed_mm_min`` (ties go to the faster code).

        Returns ``None`` when the feed is not finite or lies beyond either end of
        the table by more than half the gap to its neighbour (for the linear
        table: outside 0.05–9.95 mm/min, i.e. what would round to F00 or F100).
        """
        if not math.isfinite(feed_mm_min):
            return None
        feeds = [f for _, f in self.codes]
        i = bisect.bisect_left(feeds, feed_mm_min)
        candidates = [j for j in (i - 1, i) if 0 <= j < len(feeds)]
        best = min(candidates, key=lambda j: (abs(feeds[j] - feed_mm_min), -j))
        tol = 1e-9 * max(1.0, abs(feed_mm_min))
        lo_gap = (feeds[1] - feeds[0]) / 2 if len(feeds) > 1 else 0.0
        hi_gap = (feeds[-1] - feeds[-2]) / 2 if len(feeds) > 1 else 0.0
        if feed_mm_min < feeds[0] - lo_gap - tol or feed_mm_min > feeds[-1] + hi_gap + tol:
            return None
        return self.codes[best]


def _code(key: Any) -> int:
    """A feed code from a table key: an int, or a string of one or two digits."""
    if isinstance(key, bool):
        raise ValueError(f"feed code {key!r} is not a number")
    if isinstance(key, int):
        return key
    if isinstance(key, str) and key.isascii() and key.isdigit() and 1 <= len(key) <= 2:
        return int(key)
    raise ValueError(f"feed code {key!r} is not a code of one or two digits (1–{MAX_CODE})")


def _positive(name: str, value: Any) -> float:
    """``value`` as a finite float > 0 (bools refused)."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ValueError(f"{name} must be a number of mm/min > 0, not {value!r}")
    number = float(value)
    if not (math.isfinite(number) and number > 0):
        raise ValueError(f"{name} must be a number of mm/min > 0, not {value!r}")
    return number


# -- the dialect ------------------------------------------------------------------------


@dataclass(frozen=True)
class Word:
    """One word of the fixed-width pic-mmh grammar: a letter and a zero-padded number.

    Both the writer (:meth:`format`, :meth:`coordinate`) and the reader
    (:meth:`pattern`) are derived from it (UNAM-GMM §3, S000-02…05).

    Attributes:
        letter: the address letter.
        digits: integer digits, zero-padded (``X02969.00``: 5; ``F08``: 2).
        decimals: digits after the point (0: an integer code without a point).
        what: the value's name in messages ("feed code").
        scale: code units per mm (coordinates: µm); 1 for codes.
    """

    letter: str
    digits: int
    decimals: int = 0
    what: str = ""
    scale: float = 1.0

    @property
    def largest(self) -> int:
        """Largest integer code the word holds (``99`` for 2 digits)."""
        return 10**self.digits - 1

    def pattern(self, group: str) -> str:
        """The regex of the word, its number captured as ``group`` (a sign only on decimals)."""
        if self.decimals:
            number = rf"[+-]?\d{{{self.digits}}}\.\d{{{self.decimals}}}"
        else:
            number = rf"\d{{{self.digits}}}"
        return rf"{self.letter}(?P<{group}>{number})"

    def coordinate(self, sign: str) -> NumberFormat:
        """The number format of a coordinate word, with the sign policy ``sign``."""
        return NumberFormat(
            scale=self.scale, decimals=self.decimals, int_digits=self.digits, sign=sign
        )

    def format(self, code: int) -> str:
        """The word of integer ``code`` (``F08``).

        Raises:
            DialectError: ``code`` is negative or needs more digits.
        """
        return self.letter + format_int(code, self.digits, what=self.what)


WORDS: Mapping[str, Word] = MappingProxyType(
    {
        **{a: Word(a, 5, 2, "coordinate", 1000.0) for a in "XYIJ"},  # µm, ±5.2 (S000-02/03)
        "F": Word("F", 2, what="feed code"),  # S000-05
        "P": Word("P", 2, what="dwell"),  # G04P##, seconds (L3359–L3366)
        "S": Word("S", 4, what="spindle speed"),  # M03S####, rev/min (Tabla 22)
        "T": Word("T", 2, what="tool"),  # M06T## (L3455–L3464)
    }
)
"""The grammar of every numbered word, declared once: the writer formats and the
reader's patterns are built from it."""

_W = WORDS
_BLOCK = re.compile(
    rf"^G0(?P<g>[0-3]){_W['X'].pattern('x')}{_W['Y'].pattern('y')}"
    rf"(?:{_W['I'].pattern('i')}{_W['J'].pattern('j')})?(?:{_W['F'].pattern('f')})?;$"
)
_FRAME = frozenset({"G54;", "G90;", "M30;"})
_FIXED: Mapping[str, Command] = MappingProxyType(
    {"M05;": Spindle("off"), "G28X0Y0;": Home("XY"), "G28Z0;": Home("Z")}
)
_ARGS = re.compile(
    rf"^(?:G04{_W['P'].pattern('p')}|M0(?P<m>[34]){_W['S'].pattern('s')}"
    rf"|M06{_W['T'].pattern('t')});$"
)

MAX_DWELL_S = WORDS["P"].largest
"""Longest dwell of one ``G04P##;`` block, s (2 digits, UNAM-GMM L3359–L3366)."""
MAX_RPM = WORDS["S"].largest
"""Highest spindle speed of ``M03S####;``, rev/min (4 digits, UNAM-GMM L3418–L3436)."""
MAX_TOOL = WORDS["T"].largest
"""Highest magazine position of ``M06T##;`` (2 digits, UNAM-GMM L3455–L3464)."""
BUFFER_CHARS = 35
"""The firmware's receive vector ``CadenaControl`` (UNAM-GMM L1739–L1744, S000-07)."""


class _Writer(WriterState[str]):
    """The blocks of one emit and what to warn about (:class:`WriterState`).

    Attributes:
        fast: blocks over the machine's step rate by feed code:
            ``code → [(block, contour), ...]`` (S000-05).
        program: the program being written (for the advice after a value too long).
    """

    def __init__(self, blocks: list[str], here: tuple[float, float], program: Program) -> None:
        super().__init__(blocks, here=here)
        self.fast: dict[int, list[tuple[int, int]]] = {}
        self.program = program
        self.substep = 0  # arcs written as G01: their centre on an end's step
        self.substep_off = 0.0  # mm, the farthest such an arc lies from its G01


class PicMmhPost(PostProcessor):
    """Writer and reader of the pic-mmh dialect (UNAM-GMM §3).

    Args:
        sign: ``"negative"`` (default, as the thesis example L1731: ``-`` only)
            or ``"always"`` (``+`` before positives too, as the templates
            ``X±`` show; S000-03). The issue's ``always_sign = true`` is
            ``sign = "always"``.
        feed_unit_mm_min: mm/min per unit of the F word: codes F01–F99 mean
            1–99 units (default 0.1, S000-05). Not with ``feed_codes``.
        feed_codes: an explicit table code → mm/min (``{"08": 0.8, ...}``) for a
            firmware that maps F codes to its own speeds
            (:meth:`FeedTable.from_option`). Not with ``feed_unit_mm_min``.
        max_line_chars: warn about blocks longer than this many characters,
            ``;`` included (S000-07 suggests 35, the receive buffer; off by
            default because the thesis's own G02 example has 43).

    Raises:
        ValueError: an unknown sign policy, a feed unit that is not > 0, a bad
            feed table, both feed options, or ``max_line_chars`` not an int ≥ 1.
    """

    formats: ClassVar[Mapping[str, str]] = MappingProxyType({"code": ".pic"})

    def __init__(
        self,
        *,
        sign: str = "negative",
        feed_unit_mm_min: float | None = None,
        feed_codes: Mapping[Any, Any] | None = None,
        max_line_chars: int | None = None,
    ) -> None:
        self.coord = WORDS["X"].coordinate(sign)
        if feed_codes is not None and feed_unit_mm_min is not None:
            raise ValueError("give feed_unit_mm_min or feed_codes, not both")
        if feed_codes is not None:
            self.feeds = FeedTable.from_option(feed_codes)
        elif feed_unit_mm_min is not None:
            self.feeds = FeedTable.linear(feed_unit_mm_min)
        else:
            self.feeds = FeedTable.linear()
        if max_line_chars is not None and (
            isinstance(max_line_chars, bool)
            or not isinstance(max_line_chars, int)
            or max_line_chars < 1
        ):
            raise ValueError(f"max_line_chars must be a whole number ≥ 1, not {max_line_chars!r}")
        self.max_line_chars = max_line_chars

    @property
    def tool_changes(self) -> str:
        """``"code"``: ``M06T##;`` changes to magazine position T (UNAM-GMM L3455–L3464)."""
        return "code"

    @property
    def homes(self) -> tuple[str, ...]:
        """``"G28"``: machine zero, ``G28X0Y0;`` / ``G28Z0;`` (UNAM-GMM Tabla 21); no G30."""
        return ("G28",)

    # -- writing ---------------------------------------------------------------

    def emit(self, program: Program, machine: Machine, *, fmt: str | None = None) -> PostResult:
        """Write ``program`` (moves and commands) as pic-mmh blocks.

        Raises:
            DialectError: a Z move, a coordinate over 5 integer digits, a feed
                beyond the feed table, a point (arcs by their extremes) outside
                the machine's work area, a cut right after ``G28X0Y0;``, or a
                command out of its field (spindle 1–9999 rev/min, tool 0–99, a
                negative dwell, a Home on axes other than XY, Z or XYZ); the
                message names the contour and block.
        """
        self.check_format(fmt)
        w = _Writer(["G54;", "G90;"], program.origin, program)
        w.warnings.extend(check_placement(program, machine))
        homed = False
        for index, (move, commands) in enumerate(_steps(program)):
            w.source = input_line(program, index, move=False)
            for command in commands:
                homed = self._command(command, move.contour if move else 0, w) or homed
            if move is None:
                continue
            w.source = input_line(program, index, move=True)
            start = w.here
            self._check_move(move, w, homed)
            check_work_area(
                start, move, machine, w.where(move.contour), program, reposted=program.from_code
            )
            homed = homed and not isinstance(move, Rapid)
            self._move(start, move, machine, w, _tolerance(program, machine))
            w.here = (move.x, move.y)
        w.source = ""
        w.blocks.append("M30;")
        self._rate_warnings(machine, w)
        self._length_warning(w)
        if w.substep:
            w.warnings.append(
                f"{w.substep} arc(s) whose centre falls on the step of their start or end "
                f"({_step_um(machine)} µm steps), which the controller's arc interpolation "
                "(UNAM-GMM A.6) cannot run, written as G01 lines to their ends (within "
                f"{w.substep_off * 1000:.3g} µm of the arc)"
            )
        if w.arcs:
            tol = _tolerance(program, machine)
            w.warnings.append(
                f"{w.arcs} arc(s) with a centre beyond the I/J field (±99.99999 mm, "
                f"5 integer digits of µm) written as {w.chords} G01 chords within "
                f"{tol:g} mm"
            )
        code = "\n".join(w.blocks) + "\n"
        return PostResult(code, len(w.blocks), (*w.warnings, *w.noted()))

    def _check_move(self, move: Move, w: _Writer, homed: bool) -> None:
        where = w.where(move.contour)
        if move.z is not None:
            raise DialectError(
                f"{where}: pic-mmh has no Z word (UNAM-GMM S000-08); "
                "set the depth by hand or use a target with a Z axis"
            )
        if homed and not isinstance(move, Rapid):
            raise DialectError(
                f"{where}: a cut right after G28X0Y0; would start from machine zero, which "
                "camtool does not know (the part zero is set by G54); go to the start of the "
                "cut with a rapid (G00) first"
            )

    def _move(
        self,
        start: tuple[float, float],
        move: Move,
        machine: Machine,
        w: _Writer,
        tolerance: float,
    ) -> None:
        if isinstance(move, Rapid):
            w.blocks.append(f"G00{self._xy(move.x, move.y, move, w)};")
            return
        code, feed = self._feed(move, w)
        if machine.max_step_rate_hz and machine.step_rate_hz(feed) > machine.max_step_rate_hz:
            w.fast.setdefault(code, []).append((len(w.blocks) + 1, move.contour))
        f = WORDS["F"].format(code)
        if isinstance(move, Linear):
            w.blocks.append(f"G01{self._xy(move.x, move.y, move, w)}{f};")
            return
        here = start
        for half in _halves(start, move):
            xy = self._xy(half.x, half.y, half, w)
            if not (self._fits(half.cx) and self._fits(half.cy)):
                points = Arc(here, (half.x, half.y), (half.cx, half.cy), half.clockwise).points(
                    tolerance
                )
                for x, y in points[1:-1]:
                    w.blocks.append(f"G01{self._xy(x, y, half, w)}{f};")
                w.blocks.append(f"G01{xy}{f};")
                w.chorded(len(points) - 1)
            elif self._centre_on_an_end(here, half, machine):
                # every point of the arc is within 2r of both ends, so of the chord
                centre = (half.cx, half.cy)
                off = 2 * max(distance(here, centre), distance((half.x, half.y), centre))
                if off > tolerance:
                    raise DialectError(
                        f"{w.where(half.contour)}: an arc of radius {off / 2 * 1000:.3g} µm "
                        f"has its centre on the step of its start or end ({_step_um(machine)} "
                        "µm steps): the controller's arc interpolation (UNAM-GMM A.6) cannot "
                        f"run it, and its chord lies up to {off * 1000:.3g} µm off, beyond "
                        f"--tolerance {tolerance:g} mm; draw the detail larger or give a "
                        "larger --tolerance"
                    )
                w.blocks.append(f"G01{xy}{f};")
                w.substep += 1
                w.substep_off = max(w.substep_off, off)
            else:
                g = "G02" if half.clockwise else "G03"
                ij = self._word("I", half.cx, half, w) + self._word("J", half.cy, half, w)
                w.blocks.append(f"{g}{xy}{ij}{f};")
            here = (half.x, half.y)

    def _centre_on_an_end(self, start: tuple[float, float], arc: ArcMove, machine: Machine) -> bool:
        """Whether ``arc``'s printed centre is its printed start's or end's step.

        The numbers are those written (µm, two decimals), in the machine's steps as its
        profile rounds them: the steps the controller's direct search (UNAM-GMM A.6)
        starts from. A centre on the start's step is an arc of radius 0, which the
        interpolation cannot run; one on the end's step ends nowhere on its circle.
        """
        spm = machine.steps_per_mm
        centre = (arc.cx, arc.cy)
        near = min(distance(start, centre), distance((arc.x, arc.y), centre))
        if near > 2 / min(spm[0], spm[1]):  # two steps apart: never the same step
            return False
        from camtool.verify.quantize import Rounding, steps_from_mm

        def steps(x: float, y: float) -> tuple[int, int]:
            return (
                steps_from_mm(self.coord.parse(self.coord.format(x)), 1 / spm[0], rounding),
                steps_from_mm(self.coord.parse(self.coord.format(y)), 1 / spm[1], rounding),
            )

        rounding: Rounding = machine.motion.rounding  # type: ignore[assignment]  # checked on load
        return steps(*centre) in (steps(*start), steps(arc.x, arc.y))

    def _fits(self, value_mm: float) -> bool:
        """True when ``value_mm`` fits the 5-integer-digit µm field."""
        try:
            self.coord.format(value_mm)
        except DialectError:
            return False
        return True

    def _word(self, letter: str, value_mm: float, move: Move, w: _Writer) -> str:
        try:
            return letter + self.coord.format(value_mm)
        except DialectError as exc:
            raise DialectError(
                f"{w.where(move.contour)}: {letter} = {exc} (µm; at most 99999.99 = 99.99999 mm)"
                + (
                    far_from_zero(w.program, letter, self.coord.reach_mm())
                    if letter in "XY"
                    else ""
                )
            ) from exc

    def _xy(self, x: float, y: float, move: Move, w: _Writer) -> str:
        return self._word("X", x, move, w) + self._word("Y", y, move, w)

    def _feed(self, move: Linear | ArcMove, w: _Writer) -> tuple[int, float]:
        """The feed code written for ``move`` and the feed it means, mm/min."""
        found = self.feeds.nearest(move.feed_mm_min)
        if found is None:
            (lo, lo_feed), (hi, hi_feed) = self.feeds.lowest, self.feeds.highest
            raise DialectError(
                f"{w.where(move.contour)}: feed {move.feed_mm_min:g} mm/min is outside "
                f"F{lo:02d}–F{hi:02d} ({lo_feed:g}–{hi_feed:g} mm/min)"
            )
        code, feed = found
        if abs(feed - move.feed_mm_min) > 1e-9 * max(1.0, feed):
            msg = f"feed {move.feed_mm_min:g} mm/min rounded to F{code:02d} ({feed:g} mm/min)"
            w.warn(msg)
        return code, feed

    def _rate_warnings(self, machine: Machine, w: _Writer) -> None:
        """S000-05: one warning per feed code whose step rate is over the machine's cap."""
        cap = machine.max_step_rate_hz
        for code, where in sorted(w.fast.items()):
            feed = self.feeds.feed_of(code) or 0.0
            capped_feed = cap * 60.0 / max(machine.steps_per_mm[:2])
            blocks = _listing("block", [b for b, _ in where])
            contours = _listing("contour", sorted({c for _, c in where if c}))
            in_contours = f" ({contours})" if contours else ""
            w.warnings.append(
                f"F{code:02d} = {feed:g} mm/min needs {machine.step_rate_hz(feed):.1f} steps/s "
                f"but the serial link limits the machine to {cap:g} Hz (UNAM-GMM S000-05, "
                f"L3195–L3199): {blocks}{in_contours} will run at about "
                f"{capped_feed:.3g} mm/min"
            )

    def _length_warning(self, w: _Writer) -> None:
        """S000-07: blocks longer than ``max_line_chars`` (``;`` included)."""
        limit = self.max_line_chars
        if limit is None:
            return
        long = [(n, len(line)) for n, line in enumerate(w.blocks, start=1) if len(line) > limit]
        if long:
            w.warnings.append(
                f"{len(long)} block(s) longer than {limit} characters (the firmware's receive "
                f"buffer holds {BUFFER_CHARS}, UNAM-GMM L1739–L1744, S000-07): "
                f"{_listing('block', [n for n, _ in long])}; the longest has "
                f"{max(c for _, c in long)}"
            )

    # -- commands --------------------------------------------------------------

    def _command(self, command: Command, contour: int, w: _Writer) -> bool:
        """Write ``command``; True when it homes X and Y (the position becomes unknown)."""
        where = w.where(contour)
        if isinstance(command, Spindle):
            w.blocks.extend(block for block in [_spindle(command, where, w)] if block)
        elif isinstance(command, Dwell):
            w.blocks.extend(_dwell(command, where, w))
        elif isinstance(command, ToolChange):
            if not 0 <= command.tool <= MAX_TOOL:
                raise DialectError(
                    f"{where}: tool {command.tool} does not fit M06T## (0–{MAX_TOOL}, "
                    "UNAM-GMM Tabla 22, L3455–L3464)"
                )
            w.blocks.append(f"M06{WORDS['T'].format(command.tool)};")
        elif isinstance(command, DrillCycle | PlaneArc):
            pass  # the moves that follow are the cycle, or the arc's chords: written as they are
        elif isinstance(command, Stop):
            raise DialectError(f"{where}: pic-mmh has no program stop (M0/M1)")
        elif isinstance(command, LengthOffset | WorkOffset | PathControl):
            w.drop(command)  # offsets refused: the program's numbers are in one pic-mmh lacks
        elif isinstance(command, Coolant):
            w.note(
                "coolant",
                f"{where}: coolant {command.state} dropped: pic-mmh has no coolant code "
                "(UNAM-GMM Tabla 22); switch it by hand",
            )
        elif command.code != "G28":
            w.drop(command)  # no second stored position; refused where its height matters
        else:
            blocks = _home(command, where)
            w.blocks.extend(blocks)
            return "G28X0Y0;" in blocks
        return False

    # -- reading ---------------------------------------------------------------

    def parse(self, code: str | bytes, *, source: str = "<code>") -> Program:
        """Read pic-mmh blocks back into moves and commands (the grammar of UNAM-GMM §3.6).

        ``G54;``, ``G90;`` and ``M30;`` carry nothing; ``M03S####;`` /
        ``M04S####;`` / ``M05;``, ``G04P##;``, ``M06T##;``, ``G28X0Y0;`` and
        ``G28Z0;`` become :attr:`Program.commands` before the next move.
        ``Program.lines`` holds each move's 1-based line.

        Raises:
            ParseError: a line that is not a pic-mmh block, a G01–G03 block
                without F, or an F code not in the feed table, naming ``source``
                and the line number.
        """
        if isinstance(code, bytes):
            code = code.decode("ascii", errors="replace")
        moves: list[Move] = []
        lines: list[int] = []
        commands: list[tuple[int, Command]] = []
        contours = ContourCounter()
        for number, raw in enumerate(code.splitlines(), start=1):
            line = raw.strip()
            if not line or line in _FRAME:
                continue
            command = _read_command(line)
            if command is not None:
                commands.append((len(moves), command))
                continue
            m = _BLOCK.match(line)
            if m is None:
                raise ParseError(f"{source}:{number}: not a pic-mmh block: {quoted(line)}")
            moves.append(self._read_move(m, number, source, contours.next(m["g"] == "0")))
            lines.append(number)
        return Program(tuple(moves), lines=tuple(lines), commands=tuple(commands))

    def _read_move(self, m: re.Match[str], number: int, source: str, contour: int) -> Move:
        g = int(m["g"])
        x, y = self.coord.parse(m["x"]), self.coord.parse(m["y"])
        has_centre = m["i"] is not None
        if (g >= 2) != has_centre:
            raise ParseError(f"{source}:{number}: G0{g} {'needs' if g >= 2 else 'takes no'} I/J")
        if g == 0:
            if m["f"] is not None:
                raise ParseError(f"{source}:{number}: G00 takes no F word")
            return Rapid(x, y, contour=contour)
        if m["f"] is None:
            raise ParseError(f"{source}:{number}: G0{g} needs an F word (two digits)")
        feed = self.feeds.feed_of(int(m["f"]))
        if feed is None:
            (lo, _), (hi, _) = self.feeds.lowest, self.feeds.highest
            codes = f"F{lo:02d}–F{hi:02d}" if hi - lo + 1 == len(self.feeds.codes) else "its codes"
            raise ParseError(
                f"{source}:{number}: F{m['f']} is not in the feed table ({codes}): {quoted(m[0])}"
            )
        if g == 1:
            return Linear(x, y, feed, contour=contour)
        cx, cy = self.coord.parse(m["i"]), self.coord.parse(m["j"])
        return ArcMove(x, y, cx, cy, g == 2, feed, contour=contour)


def _step_um(machine: Machine) -> str:
    """The machine's X step, µm, for messages (``"0.14"``)."""
    return f"{1000 / machine.steps_per_mm[0]:.3g}"


def _tolerance(program: Program, machine: Machine) -> float:
    """Chord tolerance, mm: the program's (``--tolerance``) or the machine's."""
    if program.tolerance_mm is not None:
        return program.tolerance_mm
    return machine.motion.chord_tolerance_mm


def _steps(program: Program) -> Iterator[tuple[Move | None, tuple[Command, ...]]]:
    """``(move, commands before it)``, from :meth:`Program.items`; last ``(None, trailing)``."""
    before: list[Command] = []
    for item in program.items():
        if isinstance(item, Rapid | Linear | ArcMove):
            yield item, tuple(before)
            before = []
        else:
            before.append(item)
    yield None, tuple(before)


def _halves(start: tuple[float, float], move: ArcMove) -> list[ArcMove]:
    """A full circle as two half arcs through the opposite point; other arcs as given."""
    if distance(start, (move.x, move.y)) > 1e-9:
        return [move]
    opposite = (2 * move.cx - start[0], 2 * move.cy - start[1])
    first = ArcMove(
        *opposite, move.cx, move.cy, move.clockwise, move.feed_mm_min, None, move.contour
    )
    return [first, move]


def _spindle(command: Spindle, where: str, w: _Writer) -> str | None:
    """``M03S####;`` / ``M04S####;`` (rev/min rounded half up), ``M05;``, or ``None``.

    ``None`` (with a warning) for a spindle started without a speed (a bare M3).

    Raises:
        DialectError: a speed outside 1–9999 rev/min once rounded (``S0`` included).
    """
    if command.direction == "off":
        return "M05;"
    rpm = command.rpm
    if rpm is None:
        w.note(
            "rpm-none",
            f"{where}: spindle on without a speed (a bare M3) dropped: "
            "M03S####/M04S#### needs 1–9999 rev/min; give the speed with S in the program",
        )
        return None
    writable = math.isfinite(rpm) and 0 < rpm < MAX_RPM + 1  # and few digits to round
    whole = int(Decimal(repr(float(rpm))).quantize(Decimal(1), ROUND_HALF_UP)) if writable else 0
    if not 1 <= whole <= MAX_RPM:
        raise DialectError(
            f"{where}: spindle speed {rpm:g} rev/min does not fit M03S####/M04S#### "
            f"(1–{MAX_RPM} rev/min, 4 digits, UNAM-GMM Tabla 22, L3418–L3436)"
        )
    if whole != rpm:
        w.note("rpm", f"spindle speed {rpm:g} rev/min rounded to S{whole:04d} (whole rev/min)")
    m = "M03" if command.direction == "cw" else "M04"
    return f"{m}{WORDS['S'].format(whole)};"


def _dwell(command: Dwell, where: str, w: _Writer) -> list[str]:
    """``G04P##;`` blocks of whole seconds: rounded up, split into 99 s pieces."""
    seconds = command.seconds
    if not (math.isfinite(seconds) and seconds >= 0):
        raise DialectError(f"{where}: dwell of {seconds:g} s; G04P## takes 0–99 whole seconds")
    whole = math.ceil(seconds - 1e-9)
    if whole - seconds > 1e-9:
        w.note(
            "dwell-round",
            f"{where}: dwell {seconds:g} s rounded up to {whole} s "
            "(G04P## takes whole seconds, UNAM-GMM L3359–L3366)",
        )
    pieces = [MAX_DWELL_S] * (whole // MAX_DWELL_S)
    if whole % MAX_DWELL_S or not pieces:
        pieces.append(whole % MAX_DWELL_S)
    if len(pieces) > 1:
        w.note(
            "dwell-split",
            f"{where}: dwell {whole} s written as {len(pieces)} G04 blocks of at most "
            f"{MAX_DWELL_S} s (P has 2 digits, UNAM-GMM L3359–L3366)",
        )
    return [f"G04{WORDS['P'].format(p)};" for p in pieces]


def _home(command: Home, where: str) -> list[str]:
    """``G28X0Y0;`` / ``G28Z0;``; XYZ homes Z first (UNAM-GMM §7: Z, then X, then Y)."""
    axes = set(command.axes.upper())
    if axes == {"X", "Y"} and len(command.axes) == 2:
        return ["G28X0Y0;"]
    if command.axes.upper() == "Z":
        return ["G28Z0;"]
    if axes == {"X", "Y", "Z"} and len(command.axes) == 3:
        return ["G28Z0;", "G28X0Y0;"]
    raise DialectError(
        f"{where}: cannot return to machine zero on {command.axes!r}: pic-mmh homes X and Y "
        "together (G28X0Y0;) or Z (G28Z0;) (UNAM-GMM Tabla 21, L3375–L3386)"
    )


def _read_command(line: str) -> Command | None:
    """The command of an auxiliary block, or ``None`` when ``line`` is not one."""
    if line in _FIXED:
        return _FIXED[line]
    m = _ARGS.match(line)
    if m is None:
        return None
    if m["p"] is not None:
        return Dwell(float(m["p"]))
    if m["t"] is not None:
        return ToolChange(int(m["t"]))
    return Spindle("cw" if m["m"] == "3" else "ccw", float(m["s"]))


def _listing(noun: str, numbers: list[int], most: int = 6) -> str:
    """``"block 4"``, ``"blocks 4, 5, 9"`` or ``"blocks 4, 5, 9, 12, 13, 15 … (9 in all)"``."""
    if not numbers:
        return ""
    text = ", ".join(str(n) for n in numbers[:most])
    more = f" … ({len(numbers)} in all)" if len(numbers) > most else ""
    return f"{noun}{'s' if len(numbers) > 1 else ''} {text}{more}"


def post_processor(options: Mapping[str, Any], where: str) -> PostProcessor:
    """The ``pic-mmh`` dialect built from a target file's ``[dialect_options]``.

    Raises:
        InputError: an unknown option or a bad value, naming ``where``.
    """
    return from_options(PicMmhPost, options, where)
