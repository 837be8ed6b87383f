"""Program: the machine-neutral move list between the planner and the dialects.

A program is an immutable sequence of moves in absolute mm, Y up:

- :class:`Rapid` — positioning at the machine's rapid rate (G00);
- :class:`Linear` — a straight cut at ``feed_mm_min`` (G01);
- :class:`ArcMove` — a circular cut (G02 when ``clockwise``, G03 otherwise)
  around the ABSOLUTE centre ``(cx, cy)``.

Every move carries its end point; the start of a move is the end of the one
before it (or :attr:`Program.origin` for the first). ``z`` is ``None`` when the
move does not change Z (2D machines never set it). ``contour`` is the 1-based
number of the toolpath contour a move belongs to (0 for none), used by
messages such as "contour 3, block 12".

Non-motion instructions (spindle, dwell, tool change, program stop, return to
machine zero)
are :data:`Command` values held beside the moves in :attr:`Program.commands`,
each with the index of the move it comes before; motion consumers (planner,
simulator, metrics) never see them.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Literal, TypeAlias

from camtool.model.shapes import Arc, BBox, Line, Point, Segment, bbox_union


@dataclass(frozen=True)
class Rapid:
    """Rapid positioning to ``(x, y[, z])``, mm."""

    x: float
    y: float
    z: float | None = None
    contour: int = 0


@dataclass(frozen=True)
class Linear:
    """Straight cut to ``(x, y[, z])`` at ``feed_mm_min`` (mm/min)."""

    x: float
    y: float
    feed_mm_min: float
    z: float | None = None
    contour: int = 0


@dataclass(frozen=True)
class ArcMove:
    """Circular cut to ``(x, y)`` around the absolute centre ``(cx, cy)``, mm.

    ``clockwise=True`` is G02 seen from +Z. An arc whose end equals its start is
    a full circle. ``feed_mm_min`` is the feed along the arc, mm/min.
    """

    x: float
    y: float
    cx: float
    cy: float
    clockwise: bool
    feed_mm_min: float
    z: float | None = None
    contour: int = 0


Move: TypeAlias = Rapid | Linear | ArcMove

SpindleDirection: TypeAlias = Literal["cw", "ccw", "off"]


@dataclass(frozen=True)
class Spindle:
    """Spindle on clockwise (M03), counter-clockwise (M04) or off (M05).

    ``rpm`` is the programmed speed, rev/min (ignored when ``direction`` is "off").
    """

    direction: SpindleDirection
    rpm: float = 0.0


@dataclass(frozen=True)
class Dwell:
    """Wait ``seconds`` before the next move (G04)."""

    seconds: float


@dataclass(frozen=True)
class ToolChange:
    """Change to tool (magazine position) ``tool`` (M06 T).

    ``description`` says what the operator loads (``"drill 3 mm"``): a dialect that
    changes tools by hand (a program stop) shows it in its comment; ``""``: nothing
    known but the number.
    """

    tool: int
    description: str = ""


@dataclass(frozen=True)
class Stop:
    """Program stop (M0), or optional stop (M1) when ``optional``.

    The machine halts until the operator resumes. ``message`` says why (``"change to
    T2: drill 3 mm"``); ``""``: no reason given. A stop is never dropped: a dialect
    that cannot write one refuses the program.
    """

    optional: bool = False
    message: str = ""


DrillKind: TypeAlias = Literal["drill", "peck", "chip-break"]
"""A canned drilling cycle: ``drill`` feeds to the bottom in one go (G81, G82 with a
dwell), ``peck`` retracts to the R plane after each peck (G83), ``chip-break`` backs off a
little after each peck (G73)."""


@dataclass(frozen=True)
class DrillCycle:
    """A canned drilling cycle at one hole, standing for the ``moves`` moves that follow it.

    The moves are the cycle's expansion (:func:`camtool.model.drilling.expand`, LinuxCNC's
    rules), so every motion consumer (verifier, preview, time) sees a drilled hole as plain
    rapids and feeds; a dialect with canned cycles may write the cycle instead of those
    moves (``G81``/``G82``/``G83``/``G73``), one without them writes the moves.

    Attributes:
        kind: see :data:`DrillKind`.
        x, y: the hole's centre, mm.
        bottom_z: the hole's bottom, mm (below the top: negative).
        r_z: the R plane, mm: rapids end there, feeds start there.
        feed_mm_min: the feed into the material, mm/min.
        peck_mm: depth of each peck (Q), mm (> 0); ``None`` for ``drill``.
        dwell_s: wait at the bottom, s (G82 ``P``); 0: none.
        retract: where the tool goes after the hole: ``"initial"`` (G98: back to the
            height it started from, or the R plane if that is higher) or ``"r-plane"``
            (G99).
        moves: how many of the program's moves after this command the cycle stands for.
    """

    kind: DrillKind
    x: float
    y: float
    bottom_z: float
    r_z: float
    feed_mm_min: float
    peck_mm: float | None = None
    dwell_s: float = 0.0
    retract: Literal["initial", "r-plane"] = "initial"
    moves: int = 0


@dataclass(frozen=True)
class Home:
    """Return to machine zero on ``axes`` ("XY", "Z" or "XYZ") at rapid speed (G28).

    Machine zero is not the part zero, so a program's XY path after a Home is
    only known again from its next absolute move.
    """

    axes: str = "XY"


Command: TypeAlias = Spindle | Dwell | ToolChange | Stop | DrillCycle | Home
"""A non-motion instruction (see :attr:`Program.commands`)."""


@dataclass(frozen=True)
class Program:
    """An immutable list of moves, absolute mm, Y up.

    ``origin`` is where the machine stands before the first move (the part zero
    unless said otherwise). ``warnings`` carry what the planner or reader had to
    tell the user. ``lines`` gives, for a program read from code, the 1-based
    source line of each move (empty otherwise), so reports can point at a block.
    ``commands`` holds ``(index, command)`` pairs in program order: ``command``
    runs before ``moves[index]`` (``index == len(moves)``: after the last move).

    ``notes`` are lines about the job for whoever reads the code (input file,
    target, tool, depth, camtool version), machine-neutral: a dialect with
    comments writes them as comments at the top, one without drops them. They
    never hold a timestamp (output stays byte-for-byte reproducible).
    ``tolerance_mm`` is the largest chord error (mm) a dialect may use when it
    must write an arc as straight lines (``--tolerance``); ``None``: the
    machine's ``motion.chord_tolerance_mm``.
    """

    moves: tuple[Move, ...]
    origin: Point = (0.0, 0.0)
    warnings: tuple[str, ...] = field(default=())
    lines: tuple[int, ...] = field(default=())
    commands: tuple[tuple[int, Command], ...] = field(default=())
    notes: tuple[str, ...] = field(default=())
    tolerance_mm: float | None = None

    def __post_init__(self) -> None:
        indices = [i for i, _ in self.commands]
        if indices != sorted(indices) or any(not 0 <= i <= len(self.moves) for i in indices):
            raise ValueError(f"command indices must be sorted within 0..{len(self.moves)}")

    def with_moves(self, moves: tuple[Move, ...]) -> Program:
        """A copy holding ``moves`` instead (source lines and commands dropped)."""
        return Program(
            moves, self.origin, self.warnings, notes=self.notes, tolerance_mm=self.tolerance_mm
        )

    def commands_before(self, index: int) -> tuple[Command, ...]:
        """The commands that run before ``moves[index]`` (or after the last, ``len(moves)``)."""
        return tuple(c for i, c in self.commands if i == index)

    def items(self) -> Iterator[Move | Command]:
        """Moves and commands interleaved in program order (what a dialect writes)."""
        commands, k = self.commands, 0
        for index, move in enumerate(self.moves):
            while k < len(commands) and commands[k][0] == index:
                yield commands[k][1]
                k += 1
            yield move
        for _, command in commands[k:]:
            yield command

    def with_spindle(
        self, rpm: float, direction: SpindleDirection = "cw", *, dwell_s: float = 0.0
    ) -> Program:
        """A copy that starts the spindle before the first move and stops it after the last.

        ``dwell_s`` > 0 waits that long after the spindle starts (spin-up), before the
        first move.

        Raises:
            ValueError: ``rpm`` is not positive, ``direction`` is "off" or ``dwell_s`` < 0.
        """
        if not rpm > 0 or direction == "off" or not dwell_s >= 0:
            raise ValueError("spindle speed must be > 0 rev/min and the direction cw or ccw")
        end = len(self.moves)
        start: tuple[tuple[int, Command], ...] = ((0, Spindle(direction, rpm)),)
        if dwell_s > 0:
            start = (*start, (0, Dwell(dwell_s)))
        commands = (*start, *self.commands, (end, Spindle("off")))
        return dataclasses.replace(self, commands=commands)

    def line_of(self, index: int) -> int | None:
        """Source line of move ``index``, or None when the program was not read from code."""
        return self.lines[index] if 0 <= index < len(self.lines) else None

    def steps(self) -> Iterator[tuple[Point, Move]]:
        """Each move with the XY point it starts from."""
        here = self.origin
        for move in self.moves:
            yield here, move
            here = (move.x, move.y)

    def segments(self) -> Iterator[tuple[Move, Segment]]:
        """Each move with its XY path as a geometry segment (rapids as lines)."""
        for start, move in self.steps():
            yield move, segment_of(start, move)

    def bbox(self, *, cutting_only: bool = False) -> BBox:
        """Bounding box of the XY path (arcs by their extremes), mm.

        Raises:
            ValueError: the program has no moves.
        """
        boxes = [
            seg.bbox()
            for move, seg in self.segments()
            if not (cutting_only and isinstance(move, Rapid))
        ]
        return bbox_union(boxes)

    def path_lengths(self) -> list[float]:
        """The length of each move's path, Z included, mm (``len(moves)`` values).

        ``√(xy² + Δz²)``, where ``xy`` is the XY path (an arc's arc length): the distance a
        controller's planner times a move by (GRBL's ``planner.c`` takes the
        Euclidean length of the axis deltas; a helix's length by its arc). A Z-only move is
        its Z travel. The program starts at Z 0, as it starts at :attr:`origin` in XY.
        """
        out = []
        z = 0.0
        for move, seg in self.segments():
            dz = 0.0 if move.z is None else move.z - z
            out.append(math.hypot(seg.length, dz))
            z = move.z if move.z is not None else z
        return out

    def cut_length(self) -> float:
        """Length of the cutting moves (not rapids), mm."""
        return sum(seg.length for move, seg in self.segments() if not isinstance(move, Rapid))

    def cutting_time_s(self) -> float:
        """Time of the cutting moves at their programmed feeds, Z included, s (no rapids)."""
        total = 0.0
        for move, length in zip(self.moves, self.path_lengths(), strict=True):
            if isinstance(move, Rapid) or move.feed_mm_min <= 0:
                continue
            total += length / move.feed_mm_min * 60.0
        return total


def segment_of(start: Point, move: Move) -> Segment:
    """The XY path of ``move`` from ``start``: an :class:`Arc` for arc moves, else a Line."""
    if isinstance(move, ArcMove):
        return Arc(start, (move.x, move.y), (move.cx, move.cy), move.clockwise)
    return Line(start, (move.x, move.y))
