"""Program: the machine-neutral move list between the planner and the dialects.

A program is an immutable sequence of moves in absolute mm, Y up:

Design notes: docs/internals.md, ``camtool/model/program.py``.
"""

from __future__ import annotations

import dataclasses
import math
from array import array
from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Literal, TypeAlias, overload

from camtool.model.shapes import Arc, BBox, Line, Point, Segment, chord_count


@dataclass(frozen=True, slots=True)
class Rapid:
    """Rapid positioning to ``(x, y[, z])``, mm."""

    x: float
    y: float
    z: float | None = None
    contour: int = 0


@dataclass(frozen=True, slots=True)
class Linear:
    """Straight cut to ``(x, y[, z])`` at ``feed_mm_min`` (mm/min)."""

    x: float
    y: float
    feed_mm_min: float
    z: float | None = None
    contour: int = 0


@dataclass(frozen=True, slots=True)
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

    ``rpm`` is the programmed speed, rev/min (ignored when ``direction`` is "off"); 0 is a
    speed (``S0``: a laser's power off while M4 stays on), ``None`` none programmed: the
    speed in force stays.
    """

    direction: SpindleDirection
    rpm: float | None = None


CoolantState: TypeAlias = Literal["mist", "flood", "off"]
"""Coolant mist (M7), flood (M8; a laser's air assist), or off (M9)."""


@dataclass(frozen=True)
class Coolant:
    """Coolant on, mist (M07) or flood (M08), or off (M09), as a program read from code had it.

    A laser's air assist is M08 (LightBurn, LaserGRBL): dropped, the material burns.
    """

    state: CoolantState


@dataclass(frozen=True)
class Dwell:
    """Wait ``seconds`` before the next move (G04)."""

    seconds: float


@dataclass(frozen=True)
class ToolChange:
    """Change to tool (magazine position) ``tool`` (M06 T).

    ``description`` says what the operator loads (``"drill 3 mm"``): a dialect that
    changes tools by hand (a program stop) shows it in its comment; ``""``: nothing
    known but the number. ``length_offset``: a dialect that applies the tool table's
    length offsets applies the new tool's after the change (LinuxCNC's ``G43 H2``);
    ``False``: a program read from code had none there, so the offset in force stays.
    """

    tool: int
    description: str = ""
    length_offset: bool = True


@dataclass(frozen=True)
class LengthOffset:
    """Apply tool ``tool``'s length offset from the tool table (G43 H), or none (G49).

    Only in a program read from code for a dialect that applies length offsets itself
    (:attr:`ToolChange.length_offset`), where the code applied or cancelled one other
    than right after a change: the program's Z from here on is measured with it.
    ``None``: the offset is cancelled (G49).
    """

    tool: int | None


@dataclass(frozen=True)
class WorkOffset:
    """Select the work offset ``code`` (``"G55"``) the program's coordinates are in.

    Only in a program read from code for a dialect that writes work offsets
    (``work_offsets`` of its spec): the program chose one, and run in another it would
    cut elsewhere. Otherwise coordinates are the part zero's, the work offset the
    user has active.
    """

    code: str


@dataclass(frozen=True)
class PathControl:
    """The path control mode a program read from code selects (RS-274/NGC §3.5.14).

    ``code``: ``"G61"`` exact path, ``"G61.1"`` exact stop, ``"G64"`` blending, with its
    tolerance ``tolerance_mm`` (P) and naive CAM tolerance ``naive_mm`` (Q), mm
    (``None``: not given). Only for a dialect that writes the code (``path_controls`` of
    its spec): LinuxCNC run without the program's ``G64 P0.001`` blends corners by as
    much as its own default allows.
    """

    code: str
    tolerance_mm: float | None = None
    naive_mm: float | None = None


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
    """Return to a machine position on ``axes`` ("XY", "Z" or "XYZ") at rapid speed.

    ``code`` names the position, as RS-274/NGC does (LinuxCNC "G28, G28.1", "G30,
    G30.1", "G53"; GRBL 1.1 the same): ``"G28"`` the first stored position (machine
    zero on most machines), ``"G30"`` the second, ``"G53"`` a rapid in machine
    coordinates (``G53 G0 Z0``: machine zero; ``G53 G0 Z-5``, Carbide Create's retract:
    5 mm below it, :attr:`machine_mm`). That position is not the part zero and camtool
    does not know it, so a program's path after a Home is only known again from its next
    absolute move, and its Z only from the next move that gives Z.
    """

    axes: str = "XY"
    code: Literal["G28", "G30", "G53"] = "G28"
    machine_mm: tuple[float, ...] = ()
    """For ``"G53"``: the machine coordinate of each of :attr:`axes`, in order, mm (as
    written, with no work offset); ``()``: machine zero on each."""

    def machine_at(self, axis: str) -> float:
        """The machine coordinate ``axis`` (one of :attr:`axes`) goes to, mm (G53)."""
        return self.machine_mm[self.axes.index(axis)] if self.machine_mm else 0.0


Plane: TypeAlias = Literal["zx", "yz"]
"""An arc plane other than XY: ``"zx"`` (G18) or ``"yz"`` (G19)."""

PLANE_AXES: Mapping[str, tuple[int, int, int]] = MappingProxyType(
    {"zx": (2, 0, 1), "yz": (1, 2, 0)}
)
"""For each :data:`Plane`, the indices into ``(x, y, z)`` of its first axis, its second axis
and its linear (helix) axis: ZX is (Z, X) with Y linear, YZ is (Y, Z) with X linear
(RS-274/NGC, LinuxCNC "G17 - G19.1": the first axis × the second is +Y, resp. +X)."""

Point3: TypeAlias = tuple[float, float, float]


@dataclass(frozen=True)
class PlaneArc:
    """An arc in the ZX (G18) or YZ (G19) plane, standing for the ``moves`` chords after it.

    The chords are plain :class:`Linear` moves (each with its ``z``), so every motion
    consumer — verifier, preview, time — sees the arc as straight lines within the
    tolerance they were made with (:meth:`points`); a dialect that selects planes
    (``G18``/``G19``) may write the arc instead of them, one without writes the
    chords.

    Coordinates in the plane are ``(first, second)`` as :data:`PLANE_AXES` orders
    them: ZX is (Z, X), YZ is (Y, Z). ``clockwise`` (G2) is clockwise in that frame,
    i.e. seen from +Y for ZX and from +X for YZ, looking towards the origin — the
    RS-274/NGC convention, so G2/G3 keep their sense whatever the plane. A helix
    moves the linear axis (Y for ZX, X for YZ) evenly with the angle.

    Attributes:
        plane: :data:`Plane`.
        start: ``(x, y, z)`` where the arc starts, mm.
        end: ``(x, y, z)`` where it ends, mm (its first and second axes on the
            circle through ``start``; equal to ``start`` in the plane: a full circle).
        centre: the absolute centre, ``(first, second)`` in the plane, mm.
        clockwise: G2 when True, G3 otherwise.
        moves: how many of the program's moves after this command are its chords.
    """

    plane: Plane
    start: Point3
    end: Point3
    centre: Point
    clockwise: bool
    moves: int = 0

    def in_plane(self, p: Point3) -> Point:
        """``p``'s ``(first, second)`` coordinates in the arc's plane, mm."""
        a, b, _ = PLANE_AXES[self.plane]
        return (p[a], p[b])

    def arc(self) -> Arc:
        """The arc in the plane's ``(first, second)`` frame (``clockwise`` there as here)."""
        return Arc(self.in_plane(self.start), self.in_plane(self.end), self.centre, self.clockwise)

    def length(self) -> float:
        """The path's length, mm (a helix's along its turns)."""
        _, _, lin = PLANE_AXES[self.plane]
        return math.hypot(self.arc().length, self.end[lin] - self.start[lin])

    def points(self, tolerance_mm: float, max_chord_mm: float | None = None) -> list[Point3]:
        """Points of equal chords within ``tolerance_mm`` of the arc, ``start`` and ``end`` exact.

        The chords are those of :meth:`Arc.points` in the plane (the one sagitta rule,
        :func:`~camtool.model.shapes.chord_count`); the linear axis moves with the angle,
        so a helix's chords lie as close to it as their projections to the circle.
        ``max_chord_mm``: no chord longer than that either (for a dialect that moves Z in
        blocks of its own, whose staircase then stays that close to the arc).

        Raises:
            UsageError: ``tolerance_mm`` is not > 0, or the arc would need too many chords.
        """
        a, b, lin = PLANE_AXES[self.plane]
        arc = self.arc()
        n = chord_count(arc.radius, abs(arc.sweep), tolerance_mm)
        if max_chord_mm is not None:
            n = max(n, math.ceil(self.length() / max_chord_mm))
        out: list[Point3] = [self.start]
        for k in range(1, n):
            p = [0.0, 0.0, 0.0]
            p[a], p[b] = arc.point_at(k / n)
            p[lin] = self.start[lin] + (self.end[lin] - self.start[lin]) * k / n
            out.append((p[0], p[1], p[2]))
        out.append(self.end)
        return out


Command: TypeAlias = (
    Spindle
    | Coolant
    | Dwell
    | ToolChange
    | LengthOffset
    | WorkOffset
    | PathControl
    | Stop
    | DrillCycle
    | Home
    | PlaneArc
)
"""A non-motion instruction (see :attr:`Program.commands`)."""


class SourceLines(Sequence[int]):
    """An immutable sequence of line numbers held as 64-bit integers, 8 bytes each.

    A program read from a file of a million lines keeps one number per move; as a
    tuple each would be an integer object (36 bytes). Compares equal to any sequence
    of the same numbers (a tuple too), hashes as the tuple does, slices to its own kind.
    """

    __slots__ = ("_numbers",)

    def __init__(self, numbers: Iterable[int] = ()) -> None:
        self._numbers = numbers if isinstance(numbers, array) else array("q", numbers)

    def __len__(self) -> int:
        return len(self._numbers)

    @overload
    def __getitem__(self, index: int) -> int: ...

    @overload
    def __getitem__(self, index: slice) -> SourceLines: ...

    def __getitem__(self, index: int | slice) -> int | SourceLines:
        if isinstance(index, slice):
            return SourceLines(self._numbers[index])
        return self._numbers[index]

    def __iter__(self) -> Iterator[int]:
        return iter(self._numbers)

    def view(self) -> memoryview:
        """The numbers as a read-only buffer of int64 (``numpy.frombuffer`` reads it, no copy)."""
        return memoryview(self._numbers).toreadonly()

    def __eq__(self, other: object) -> bool:
        if isinstance(other, SourceLines):
            return self._numbers == other._numbers
        if isinstance(other, Sequence) and not isinstance(other, str | bytes):
            return len(other) == len(self._numbers) and all(
                a == b for a, b in zip(self._numbers, other, strict=True)
            )
        return NotImplemented

    def __hash__(self) -> int:
        return hash(tuple(self._numbers))

    def __repr__(self) -> str:
        return f"SourceLines({list(self._numbers)!r})"

    def __reduce__(self) -> tuple[type[SourceLines], tuple[array[int]]]:
        return (SourceLines, (self._numbers,))


@dataclass(frozen=True)
class Program:
    """An immutable list of moves, absolute mm, Y up.

    ``origin`` is where the machine stands before the first move (the part zero
    unless said otherwise). ``warnings`` carry what the planner or reader had to
    tell the user. ``lines`` gives, for a program read from code, the 1-based
    source line of each move (empty otherwise), so reports can point at a block;
    it is kept as :class:`SourceLines` (8 bytes a move), whatever sequence is given.
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
    lines: Sequence[int] = field(default=())
    commands: tuple[tuple[int, Command], ...] = field(default=())
    notes: tuple[str, ...] = field(default=())
    tolerance_mm: float | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.lines, SourceLines):
            object.__setattr__(self, "lines", SourceLines(self.lines))
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
        """A copy that starts the spindle and stops it after the last move.

        The spindle starts before the first move, or after it when that move is a
        Z-only rapid (:func:`spindle_start`). ``dwell_s`` > 0 waits that long after the
        spindle starts (spin-up), before the tool moves on.

        Raises:
            ValueError: ``rpm`` is not positive, ``direction`` is "off" or ``dwell_s`` < 0.
        """
        if not rpm > 0 or direction == "off" or not dwell_s >= 0:
            raise ValueError("spindle speed must be > 0 rev/min and the direction cw or ccw")
        end = len(self.moves)
        at = spindle_start(self.moves, 0, self.origin)
        start: tuple[tuple[int, Command], ...] = ((at, Spindle(direction, rpm)),)
        if dwell_s > 0:
            start = (*start, (at, Dwell(dwell_s)))
        commands = (*start, *self.commands, (end, Spindle("off")))
        return dataclasses.replace(self, commands=commands)

    def has_chords_of(self, index: int, arc: PlaneArc) -> bool:
        """Whether the ``arc.moves`` moves from ``index`` are still ``arc``'s chords.

        They are when they are all straight cuts, the last ends at ``arc.end`` (its ``z``
        given) and no other command runs between them; a dialect writes the arc instead
        of them only then.
        """
        moves = self.moves[index : index + arc.moves]
        if not moves or len(moves) != arc.moves or not all(isinstance(m, Linear) for m in moves):
            return False
        last = moves[-1]
        if (last.x, last.y, last.z) != arc.end:
            return False
        return not any(index < i < index + arc.moves for i, _ in self.commands)

    @property
    def from_code(self) -> bool:
        """Whether the program was read from code (its moves have input lines): re-posted."""
        return bool(self.lines)

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

        One pass over the moves (no list of their boxes): a program may hold millions.

        Raises:
            ValueError: the program has no moves.
        """
        box: list[float] | None = None
        for move, seg in self.segments():
            if cutting_only and isinstance(move, Rapid):
                continue
            b = seg.bbox()
            if box is None:
                box = list(b)
                continue
            # strict comparisons keep the first of equal values, as min() and max() do
            if b[0] < box[0]:
                box[0] = b[0]
            if b[1] < box[1]:
                box[1] = b[1]
            if b[2] > box[2]:
                box[2] = b[2]
            if b[3] > box[3]:
                box[3] = b[3]
        if box is None:
            raise ValueError("bbox of nothing")
        return (box[0], box[1], box[2], box[3])

    def path_lengths(self) -> array[float]:
        """The length of each move's path, Z included, mm (``len(moves)`` values).

        ``√(xy² + Δz²)``, where ``xy`` is the XY path (an arc's arc length): the distance a
        controller's planner times a move by (GRBL's ``planner.c`` takes the
        Euclidean length of the axis deltas; a helix's length by its arc). A Z-only move is
        its Z travel. The program starts at Z 0, as it starts at :attr:`origin` in XY.
        Returned as an ``array('d')`` (8 bytes a move; ``numpy.asarray`` reads it whole).
        """
        out = array("d")
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
        """Time of the cutting moves at their programmed feeds, Z included, s (no rapids).

        Each move's length as :meth:`path_lengths` gives it, in one pass (no list of them).
        """
        total = 0.0
        z = 0.0
        for move, seg in self.segments():
            dz = 0.0 if move.z is None else move.z - z
            z = move.z if move.z is not None else z
            if isinstance(move, Rapid) or move.feed_mm_min <= 0:
                continue
            total += math.hypot(seg.length, dz) / move.feed_mm_min * 60.0
        return total


def spindle_start(moves: Sequence[Move], index: int, here: Point) -> int:
    """Where a spindle that turns for ``moves[index:]`` starts: the index of a move.

    After ``moves[index]`` when that move is a Z-only rapid from ``here`` (XY within
    1 nm), the rise to clearance a program or an operation starts with; else before it.
    A program starts where the operator set Z zero, the tool on the stock's top: the
    spindle starts once the tool is clear of it, as the posts of GRBL and LinuxCNC
    users' CAM programs order it.
    """
    if index < len(moves):
        move = moves[index]
        still = math.dist(here, (move.x, move.y)) <= 1e-6
        if isinstance(move, Rapid) and move.z is not None and still:
            return index + 1
    return index


def segment_of(start: Point, move: Move) -> Segment:
    """The XY path of ``move`` from ``start``: an :class:`Arc` for arc moves, else a Line."""
    if isinstance(move, ArcMove):
        return Arc(start, (move.x, move.y), (move.cx, move.cy), move.clockwise)
    return Line(start, (move.x, move.y))


@dataclass(frozen=True)
class Chorded:
    """What :func:`plane_arcs_as_chords` did: arcs replaced, chords written, largest error.

    Attributes:
        arcs: plane arcs replaced by chords.
        chords: chords written for them.
        error_mm: the largest chord error (sagitta) of those chords, mm (0 without any);
            with ``max_chord_mm``, the longest chord (what a Z-apart staircase may stray).
    """

    arcs: int = 0
    chords: int = 0
    error_mm: float = 0.0


def plane_arcs_as_chords(
    program: Program, tolerance_mm: float, max_chord_mm: float | None = None
) -> tuple[Program, Chorded]:
    """``program`` with each :class:`PlaneArc` replaced by its chords within ``tolerance_mm``.

    For a dialect without G18/G19: the arc's moves become the chords of
    :meth:`PlaneArc.points` (``max_chord_mm`` long at most; each a :class:`Linear` with
    its ``z``, the feed and contour of the arc's first move, the source line of its first
    move), the command goes. A plane arc whose moves are no longer its chords (not all
    straight cuts, not ending at its end, or a command among them:
    :meth:`Program.has_chords_of`) loses its command and keeps its moves, which every
    consumer already sees. ``program`` itself is returned when it has no plane arc.

    Raises:
        UsageError: ``tolerance_mm`` is not > 0, or an arc would need too many chords.
    """
    if not any(isinstance(c, PlaneArc) for _, c in program.commands):
        return program, Chorded()
    moves: list[Move] = []
    lines: list[int] = []
    commands: list[tuple[int, Command]] = []
    arcs = chords = 0
    error = 0.0
    taken = 0  # moves of the input copied or replaced so far
    for index, command in program.commands:
        if index > taken:
            moves.extend(program.moves[taken:index])
            lines.extend(program.lines[taken:index])
            taken = index
        if not isinstance(command, PlaneArc):
            commands.append((len(moves), command))
            continue
        if index < taken or not program.has_chords_of(index, command):
            continue  # not (or no longer) its chords: the moves stay, the command goes
        first = program.moves[index]
        assert isinstance(first, Linear)
        points = command.points(tolerance_mm, max_chord_mm)
        line = program.line_of(index)
        for x, y, z in points[1:]:
            moves.append(Linear(x, y, first.feed_mm_min, z, first.contour))
            if line is not None:
                lines.append(line)
        taken = index + command.moves
        arc = command.arc()
        n = len(points) - 1
        arcs, chords = arcs + 1, chords + n
        sagitta = arc.radius * (1.0 - math.cos(abs(arc.sweep) / n / 2.0))
        error = max(error, sagitta if max_chord_mm is None else command.length() / n)
    moves.extend(program.moves[taken:])
    lines.extend(program.lines[taken:])
    out = dataclasses.replace(
        program,
        moves=tuple(moves),
        lines=tuple(lines) if program.lines else (),
        commands=tuple(commands),
    )
    return out, Chorded(arcs, chords, error)
