"""A long program's later plain lines read ahead in a forked helper, taken where they fit.

A plain line (:mod:`camtool.importers.gcode_plain`) is read from the line's text and a few
modal values alone: the position, the motion, the plane, the distance and centre modes,
the units, the feed, whether a cut has begun the contour (:func:`state_of`). A run of plain
lines read from the same values gives the same moves, whatever came before. So the reader
of a long program forks a helper (:func:`start`) that reads the program from its middle on,
from nothing known, and records each run of plain lines it reads: the values it started
from, its moves and line numbers, the values it ended with. The reader reads the program
from its start, and at the first line of each recorded run compares its own values with
the run's, bit for bit (:func:`~camtool.accel.later.same`). Where they are the same it
takes the run's moves (their contours numbered on from its own) and goes on after the
run; where not (the helper did not know yet what came before), it reads the lines itself.
Every other line (a comment, a tool change, a mode) it reads itself, as before: commands,
notes and offsets are its own. The program read is the same either way.
"""

from __future__ import annotations

import dataclasses
import pickle
import re
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from camtool.accel import later
from camtool.accel.later import same
from camtool.importers.gcode_plain import _arc_move, _linear, _rapid
from camtool.model.program import ArcMove, Linear
from camtool.model.units import INCH

if TYPE_CHECKING:
    from camtool.importers.gcode_plain import PlainLines

MIN_CHARS = 2_000_000
"""Programs from which the helper is forked (characters; ~60 000 lines): below, the fork
and the hand-over cost about what the second core saves."""
SHARE = 0.55
"""Where in the text the helper starts reading (a fraction of its characters)."""
RUN_LINES = 1000
"""The most lines a run holds."""
STATE = (
    "x",
    "y",
    "z",
    "positioned",
    "motion",
    "plane",
    "absolute",
    "arc_absolute",
    "inch",
    "units_seen",
    "feed_mm_min",
    "cut_in_contour",
)
"""The reader's values a plain line reads besides its text (and the contour, counted on)."""


_UNITS = re.compile(r"G0*[27]([01])(?![0-9.])", re.IGNORECASE)
_FEED = re.compile(r"F([0-9]*\.?[0-9]+)", re.IGNORECASE)
_Z = re.compile(r"Z([+-]?[0-9]*\.?[0-9]+)", re.IGNORECASE)
SEEN = 1_000_000
"""Characters before the helper's start where it looks for the units and the feed."""


def seed(reader: PlainLines, text: str, position: int) -> None:
    """Give the helper's ``reader`` the units, feed and Z the text last set before ``position``.

    The program is taken to have given X and Y by then (``positioned``), as it has at
    the reader's side wherever a run can fit: a first move that depends on the start is
    the reader's to refuse, not the helper's.

    A guess from the text (the last ``G20``/``G21`` or ``G70``/``G71``, ``F`` and ``Z``
    word in the :data:`SEEN` characters before, comments and all): a program that sets them
    once, at its top, has no run the helper reads from its own values otherwise. A wrong
    guess only makes the runs read from it fail to fit.
    """
    reader.positioned = True  # by then the program has given X and Y (else no run fits)
    window = text[max(0, position - SEEN) : position]
    units = [m.group(1) for m in _UNITS.finditer(window)]
    if units:
        reader.inch = units[-1] == "0"
    scale = INCH if reader.inch else 1.0
    feeds = [m.group(1) for m in _FEED.finditer(window)]
    if feeds:
        reader.feed_mm_min = float(feeds[-1]) * scale
    heights = [m.group(1) for m in _Z.finditer(window)]
    if heights:
        reader.z = float(heights[-1]) * scale


def state_of(reader: PlainLines) -> tuple[Any, ...]:
    """The values of :data:`STATE`, in order."""
    return tuple(getattr(reader, name) for name in STATE)


@dataclass(frozen=True)
class Run:
    """Lines ``first`` to ``last`` (1-based), all plain, as the helper read them.

    ``after``: the character where the line after ``last`` starts; ``start``/``end``: the
    reader's :data:`STATE` before the first line and after the last; ``contour``: its
    contour count before the first; ``moves``: the range of the run's moves in the record.
    """

    first: int
    last: int
    after: int
    start: tuple[Any, ...]
    end: tuple[Any, ...]
    contour: int
    end_contour: int
    moves: tuple[int, int]


class Recorder:
    """In the helper: the runs of plain lines its reader reads (:class:`Run`)."""

    def __init__(self, reader: PlainLines) -> None:
        self.reader = reader
        self.runs: list[Run] = []
        self.open: tuple[int, tuple[Any, ...], int, int] | None = (
            None  # first, start, contour, moves
        )
        self.pending: tuple[tuple[Any, ...], int, int] = ((), 0, 0)  # as :meth:`before` saw it
        self.last = 0
        self.after = 0

    def before(self, number: int) -> None:
        """Call before reading line ``number``: a run may start here.

        A run is closed after :data:`RUN_LINES` lines, so that a later one starts from
        values the helper knows by then (the position, once a move has given it).
        """
        if self.open is not None and number - self.open[0] >= RUN_LINES:
            self.broken()
        if self.open is None:
            r = self.reader
            self.pending = (state_of(r), r.contour, len(r.moves))

    def plain(self, number: int, after: int) -> None:
        """Line ``number`` was read as plain; the next line starts at character ``after``."""
        if self.open is None:
            start, contour, moves = self.pending
            self.open = (number, start, contour, moves)
        self.last, self.after = number, after

    def broken(self) -> None:
        """The line read was not plain (or failed): the run open, if any, ends before it."""
        if self.open is None:
            return
        first, start, contour, moves = self.open
        r = self.reader
        end = (moves, len(r.moves))
        self.runs.append(
            Run(first, self.last, self.after, start, state_of(r), contour, r.contour, end)
        )
        self.open = None

    def pack(self) -> bytes:
        """The runs and their moves as rows, for :class:`Runs`.

        A row is ``(kind, x, y, z, cx, cy, feed, contour, line)``: kind 0 a rapid, 1 a
        line, 2 a clockwise and 3 an anticlockwise arc; what a move lacks is ``None``.
        """
        self.broken()
        moves, lines = self.reader.moves, self.reader.lines
        rows: list[tuple[Any, ...]] = []
        runs = []
        for run in self.runs:
            a, b = run.moves
            base = len(rows)
            for k in range(a, b):
                m = moves[k]
                if type(m) is ArcMove:
                    kind = 2 if m.clockwise else 3
                    rows.append(
                        (kind, m.x, m.y, m.z, m.cx, m.cy, m.feed_mm_min, m.contour, lines[k])
                    )
                elif type(m) is Linear:
                    rows.append((1, m.x, m.y, m.z, None, None, m.feed_mm_min, m.contour, lines[k]))
                else:
                    rows.append((0, m.x, m.y, m.z, None, None, None, m.contour, lines[k]))
            runs.append(dataclasses.replace(run, moves=(base, len(rows))))
        return pickle.dumps((runs, rows), protocol=pickle.HIGHEST_PROTOCOL)


class Runs:
    """In the reader: the helper's runs by first line, taken where the state is the same.

    Args:
        data: what :meth:`Recorder.pack` packed.
    """

    def __init__(self, data: bytes) -> None:
        runs, self.rows = pickle.loads(data)
        self.by_first: dict[int, Run] = {run.first: run for run in runs}
        self.taken = 0

    def take(self, reader: PlainLines, number: int) -> Run | None:
        """The run from line ``number``, its moves added to ``reader``, if it fits; else ``None``.

        It fits when ``reader``'s :data:`STATE` is the run's start, bit for bit. Then
        ``reader`` holds the moves, line numbers and state it would hold after reading
        the run's lines itself.
        """
        run = self.by_first.get(number)
        if run is None or not reader.units_seen or not same(state_of(reader), run.start):
            return None  # (units not seen: the run's first move added a note in the helper)
        shift = reader.contour - run.contour
        append, lines = reader.moves.append, reader.lines.append
        a, b = run.moves
        for kind, x, y, z, cx, cy, feed, contour, line in self.rows[a:b]:
            if kind == 0:
                append(_rapid(x, y, z, contour + shift))
            elif kind == 1:
                append(_linear(x, y, feed, z, contour + shift))
            else:
                append(_arc_move(x, y, cx, cy, kind == 2, feed, z, contour + shift))
            lines(line)
        for name, value in zip(STATE, run.end, strict=True):
            setattr(reader, name, value)
        reader.contour = run.end_contour + shift
        reader.line = run.last
        self.taken += 1
        return run


def start(text: str, read: Callable[[int, int], bytes]) -> tuple[later.Later, int] | None:
    """Fork the helper for ``text``: ``(its answer, the line it starts at)``, or ``None``.

    ``read(position, number)`` reads the program in the helper from character
    ``position``, the start of line ``number + 1``, and returns :meth:`Recorder.pack`'s
    bytes. Not under :data:`MIN_CHARS` characters, nor where the helper cannot run
    (:func:`camtool.accel.later.start`).
    """
    if len(text) < MIN_CHARS:
        return None
    position = text.find("\n", int(len(text) * SHARE)) + 1
    if position <= 0:
        return None
    number = text.count("\n", 0, position) + _lone_returns(text, position)
    helper = later.start(lambda: read(position, number))
    return None if helper is None else (helper, number + 1)


def _lone_returns(text: str, end: int) -> int:
    """Line ends in ``text[:end]`` that are a CR alone (a CR LF is one end, counted as LF)."""
    return text.count("\r", 0, end) - text.count("\r\n", 0, end)
