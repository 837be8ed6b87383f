"""The ``i8751`` dialect: binary packets for the 8751 serial stepper interface.

Design notes: docs/internals.md, ``postprocessors/i8751/dialect.py``.
"""

from __future__ import annotations

import copy
import math
from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import replace
from types import MappingProxyType
from typing import Any, ClassVar

from camtool.model.errors import DialectError, UsageError
from camtool.model.machine import Machine
from camtool.model.program import (
    ArcMove,
    Command,
    Coolant,
    Dwell,
    Home,
    Linear,
    Move,
    Program,
    Rapid,
    Spindle,
    ToolChange,
)
from camtool.model.shapes import Arc, Point
from camtool.post.base import (
    ContourCounter,
    PostProcessor,
    PostResult,
    WriterState,
    check_placement,
    check_work_area,
    check_written_z,
    from_options,
    input_line,
)
from camtool.post.numfmt import NumberFormat
from camtool_postprocessors.i8751.packets import (
    ACCESS_KEY,
    MAX_STEPS,
    MAX_WAIT_S,
    Record,
    binary_locator,
    decode_stream,
    dump_stream,
    encode_stream,
    packets,
    undump,
)

# -- the reader -------------------------------------------------------------------------
# Reading the i8751 stream back: records → a Program (see :mod:`camtool_postprocessors.i8751`).
#
# The reader sums the steps from X = Y = Z = 0 and divides by the machine's
# steps/mm; a record that moves X/Y and Z gives two moves (X/Y, then Z), as the
# interface runs them (Intf8751 §4.3, R11); waits T1/T2 give dwells. A move that
# ends with the tool above Z = 0 is a rapid, any other a cut at the cruise feed.

CRUISE_HZ = 104.0
"""Cruise step rate of the firmware ramp, X = 11H (Intf8751 §4.4), used when the
machine profile gives no ``max_step_rate_hz``."""


def cruise_feed(machine: Machine) -> float:
    """Feed of the firmware's cruise on the faster-stepping axis, mm/min."""
    rate = machine.max_step_rate_hz or CRUISE_HZ
    return rate * 60.0 / max(machine.steps_per_mm[:2])


def is_text(code: bytes) -> bool:
    """True when ``code`` reads as a dump: UTF-8 without control characters but tab, CR, LF."""
    if not code or code[0] == ACCESS_KEY:
        return False
    try:
        text = code.decode("utf-8")
    except UnicodeDecodeError:
        return False
    return all(c >= " " or c in "\t\r\n" for c in text)


def program_from_records(
    records: list[Record], machine: Machine, warnings: tuple[str, ...]
) -> Program:
    """The program a session's records describe (see the module docstring).

    Args:
        records: the decoded moves, in stream order.
        machine: gives steps/mm (positions, mm = steps / steps_per_mm) and the
            cruise rate (the feed of cuts, :func:`cruise_feed`).
        warnings: carried into ``Program.warnings``.

    Returns:
        Moves in absolute mm from (0, 0, 0); ``lines`` = the 1-based record
        number of each move; ``commands`` = one Dwell per run of waits.
    """
    spm = machine.steps_per_mm
    feed = cruise_feed(machine)
    pos = [0, 0, 0]
    moves: list[Move] = []
    lines: list[int] = []
    commands: list[tuple[int, Command]] = []
    contours = ContourCounter()

    def add(number: int, z: float | None) -> None:
        x, y = pos[0] / spm[0], pos[1] / spm[1]
        move: Move
        if pos[2] > 0:
            move = Rapid(x, y, z, contour=contours.next(True))
        else:
            move = Linear(x, y, feed, z, contour=contours.next(False))
        moves.append(move)
        lines.append(number)

    def wait(seconds: int) -> None:
        if not seconds:
            return
        if commands and commands[-1][0] == len(moves):
            index, last = commands[-1]
            if isinstance(last, Dwell):
                commands[-1] = (index, Dwell(last.seconds + seconds))
                return
        commands.append((len(moves), Dwell(float(seconds))))

    for number, record in enumerate(records, start=1):
        dx, dy, dz = record.steps
        if dx or dy:
            pos[0] += dx
            pos[1] += dy
            add(number, None)
        wait(record.wait_t1_s)
        if dz:
            pos[2] += dz
            add(number, pos[2] / spm[2])
        wait(record.wait_t2_s)
    return Program(tuple(moves), warnings=warnings, lines=tuple(lines), commands=tuple(commands))


# -- the writer -------------------------------------------------------------------------

_DROPPED = {
    Spindle: "spindle command(s): the interface drives only the three axis motors",
    ToolChange: "tool change(s): the interface has no tool changer",
    Home: "home command(s): homing is only proposed in the thesis (Intf8751 §6)",
    Coolant: "coolant command(s): the interface drives only the three axis motors",
}


def _round_steps(value: float, scale: float) -> int:
    """``value`` × ``scale`` rounded half away from zero (numfmt's rule)."""
    return int(NumberFormat(scale=scale, decimals=0).quantize(value))


def _share(part: int, whole: int, total: int) -> int:
    """``total · part / whole`` rounded half away from zero, in integers."""
    q = (2 * abs(total) * part + whole) // (2 * whole)
    return q if total >= 0 else -q


def split_xy(dx: int, dy: int) -> list[tuple[int, int]]:
    """An X/Y move of ``(dx, dy)`` steps as pieces of at most 65 535 steps per axis.

    The longest axis advances 65 535 steps per piece (the last takes the rest,
    Intf8751 R3); the other axis goes to the nearest step of the segment.
    Returns ``[]`` for no move.
    """
    n = max(abs(dx), abs(dy))
    pieces, here = [], (0, 0)
    for k in range(1, math.ceil(n / MAX_STEPS) + 1):
        d = min(k * MAX_STEPS, n)
        there = (_share(d, n, dx), _share(d, n, dy))
        pieces.append((there[0] - here[0], there[1] - here[1]))
        here = there
    return pieces


def split_count(n: int) -> list[int]:
    """A signed count as chunks of at most 65 535 (``[]`` for 0)."""
    sign = 1 if n > 0 else -1
    full, rest = divmod(abs(n), MAX_STEPS)
    return [sign * MAX_STEPS] * full + ([sign * rest] if rest else [])


class _Writer(WriterState[Record]):
    """The records of one emit and what to warn about (:class:`WriterState`, local to one call).

    :attr:`blocks` are the move records; :attr:`counts` counts the conversions
    (``"rapids"``, ``"lifts"``, ``"split"``, ``"xyz"``, ``"tiny"``, the dwells)
    and the commands not written.

    Args:
        spm: the machine's ``(x, y, z)`` steps/mm.
        lift_steps: Z lift around runs of rapids, steps (0: none).
        here: where the program starts, mm.

    Attributes:
        pos: where the records have brought the axes, steps ``[x, y, z]``.
        lifted: True while Z is raised by :attr:`lift_steps`.
    """

    def __init__(
        self, spm: tuple[float, float, float], lift_steps: int, here: Point = (0.0, 0.0)
    ) -> None:
        super().__init__(here=here)
        self.spm = spm
        self.lift_steps = lift_steps
        self.pos = [self.steps(here[0], 0), self.steps(here[1], 1), 0]
        self.lifted = False

    def steps(self, value_mm: float, axis: int) -> int:
        return _round_steps(value_mm, self.spm[axis])

    def goto(self, x: float, y: float, z: float | None, *, checked: bool = True) -> None:
        """Records from the current position to ``(x, y[, z])``.

        A record runs X/Y before Z (Intf8751 §3.7). A move that goes down runs its X/Y
        at the old height, then Z (one record); a move that rises, a cut as well as a
        rapid, goes up first (a Z-only record, then X/Y), so its X/Y never runs below
        the height the program gives: the tool stays on or above the programmed path.
        ``checked``: refuse a height above the stock written at its top
        (:func:`check_written_z`; not for a helix's inner chords).
        """
        target = [self.steps(x, 0), self.steps(y, 1)]
        if z is None:
            target.append(self.pos[2])
        else:
            target.append(self.steps(z, 2))
            if checked:
                check_written_z(z, target[2] / self.spm[2], self.where())
        dx, dy, dz = (t - p for t, p in zip(target, self.pos, strict=True))
        xy = split_xy(dx, dy)
        zs = split_count(dz)
        if len(xy) > 1 or len(zs) > 1:
            self.counts["split"] += 1
        if xy and zs:
            self.counts["xyz"] += 1
        records = [Record((px, py, 0)) for px, py in xy]
        if dz > 0:
            records = [Record((0, 0, n)) for n in zs] + records
        else:
            if records and zs:
                records[-1] = Record((*records[-1].steps[:2], zs.pop(0)))
            records += [Record((0, 0, n)) for n in zs]
        for record in records:
            self.append(record)
        self.pos = target

    def append(self, record: Record) -> None:
        """Add ``record``; a Z-only one joins a record that moved only X/Y (R4).

        The thesis's move is "X/Y, wait T1, Z, wait T2" (Intf8751 §3.7): a dwell
        between the two (held in the earlier record's T2) becomes T1.
        """
        last = self.blocks[-1] if self.blocks else None
        if (
            last is not None
            and record.steps[:2] == (0, 0)
            and record.wait_t1_s == 0
            and last.steps[2] == 0
            and any(last.steps[:2])
        ):
            steps = (last.steps[0], last.steps[1], record.steps[2])
            self.blocks[-1] = Record(steps, last.wait_t2_s, record.wait_t2_s)
            return
        self.blocks.append(record)

    def lift(self, up: bool) -> None:
        self.append(Record((0, 0, self.lift_steps if up else -self.lift_steps)))
        self.pos[2] += self.lift_steps if up else -self.lift_steps
        self.lifted = up
        self.counts["lifts"] += up

    def dwell(self, seconds: float) -> None:
        whole = int(NumberFormat(decimals=0).quantize(seconds))
        if whole != seconds:
            self.counts["dwell_rounded"] += 1
        if whole <= 0:
            self.counts["dwell_dropped"] += 1
            return
        if self.blocks and self.blocks[-1].wait_t2_s < MAX_WAIT_S:
            last = self.blocks[-1]
            put = min(MAX_WAIT_S - last.wait_t2_s, whole)
            self.blocks[-1] = replace(last, wait_t2_s=last.wait_t2_s + put)
            whole -= put
        while whole > 0:
            put = min(MAX_WAIT_S, whole)
            self.blocks.append(Record((0, 0, 0), 0, put))
            whole -= put


MAX_LIFT_MM = 1000.0
"""Largest ``lift_mm``: no Z axis of a small machine travels a metre."""


class I8751Post(PostProcessor):
    """Writer and reader of the i8751 binary protocol (Intf8751 §3.7).

    Args:
        lift_mm: raise Z by this much around each run of rapids of a program
            that has no Z of its own (0: no lift; rapids then cut), mm, ≥ 0.
        placeholder_steps_per_mm: the ``(x, y, z)`` steps/mm of the profile's
            documented placeholder; posting or reading with exactly these
            warns that the step counts assume them (the thesis gives none).
            Empty: no warning.

    Attributes:
        machine: the machine whose steps/mm :meth:`parse` uses (``None`` until
            bound by :meth:`for_machine`, which every Target does).

    Raises:
        ValueError: a ``lift_mm`` outside 0 to :data:`MAX_LIFT_MM`, or a placeholder that
            is not three positive numbers.
    """

    arcs: ClassVar[bool] = False
    """Arcs are written as chords."""

    formats: ClassVar[Mapping[str, str]] = MappingProxyType({"bin": ".bin", "dump": ".txt"})
    binary: ClassVar[bool] = True

    def __init__(
        self, *, lift_mm: float = 0.0, placeholder_steps_per_mm: Sequence[float] = ()
    ) -> None:
        if isinstance(lift_mm, bool) or not (
            math.isfinite(lift_mm) and 0 <= lift_mm <= MAX_LIFT_MM
        ):
            raise ValueError(
                f"lift_mm must be a number of mm from 0 to {MAX_LIFT_MM:g} (a physical "
                f"machine), not {lift_mm!r}"
            )
        placeholder = tuple(float(v) for v in placeholder_steps_per_mm)
        if placeholder and (len(placeholder) != 3 or min(placeholder) <= 0):
            raise ValueError(
                f"placeholder_steps_per_mm must be [x, y, z] > 0, not {placeholder_steps_per_mm!r}"
            )
        self.lift_mm = float(lift_mm)
        self.placeholder_steps_per_mm = placeholder
        self.machine: Machine | None = None

    def for_machine(self, machine: Machine) -> I8751Post:
        """A copy that reads code with ``machine``'s steps/mm (see :meth:`parse`)."""
        bound = copy.copy(self)
        bound.machine = machine
        return bound

    def written_z(self, z: float, machine: Machine) -> float | None:
        """``z`` as whole motor steps of Z (half away from zero), in mm."""
        spm = machine.steps_per_mm[2]
        return _round_steps(z, spm) / spm

    # -- writing ---------------------------------------------------------------

    @property
    def writes_feeds(self) -> bool:
        """False: every move runs at the 8751's delay-loop ramp (Intf8751 §4.4)."""
        return False

    def emit(self, program: Program, machine: Machine, *, fmt: str | None = None) -> PostResult:
        """Write ``program`` as an 8751 session: raw bytes (``bin``) or a dump (``dump``).

        Returns:
            ``code`` is ``bytes`` for ``bin`` and ``str`` for ``dump``;
            ``blocks`` is the number of move records written.

        Raises:
            DialectError: a point (arcs by their extremes) outside the machine's
                work area, or a Z move on a machine without Z; the message names
                the contour and block (the 1-based move record).
            UsageError: an unknown ``fmt``.
        """
        fmt = self.check_format(fmt)
        has_z = any(m.z is not None for m in program.moves)
        lift = self.lift_mm if machine.has_z and not has_z else 0.0
        lift_steps = _round_steps(lift, machine.steps_per_mm[2])
        if lift_steps > MAX_STEPS:  # one record lifts, one lowers
            raise DialectError(
                f"lift_mm = {self.lift_mm:g} mm is {lift_steps} Z steps, more than one move "
                f"record holds ({MAX_STEPS}); give a smaller lift_mm in [dialect_options]"
            )
        w = _Writer(machine.steps_per_mm, lift_steps, program.origin)
        index = 0  # of the next move
        for item in program.items():
            if isinstance(item, Rapid | Linear | ArcMove):
                w.source = input_line(program, index, move=True)
                self._move(w, item, machine, program)
                w.here = (item.x, item.y)
                index += 1
            else:
                w.source = input_line(program, index, move=False)
                self._command(w, item)
        w.source = ""
        warnings = (
            *check_placement(program, machine),
            *self._warnings(w, program, machine),
        )
        if fmt == "bin":
            return PostResult(encode_stream(w.blocks), len(w.blocks), warnings, fmt)
        text = dump_stream(w.blocks, machine.steps_per_mm, self._header(w, machine))
        return PostResult(text, len(w.blocks), warnings, fmt)

    def _move(self, w: _Writer, move: Move, machine: Machine, program: Program) -> None:
        start, w.contour = w.here, move.contour
        check_work_area(start, move, machine, w.where(), program, reposted=program.from_code)
        if move.z is not None and not machine.has_z:
            raise DialectError(f"{w.where()}: Z = {move.z:g} mm but {machine.name} has no Z")
        if isinstance(move, Rapid):
            w.counts["rapids"] += 1
            if w.lift_steps and not w.lifted:
                w.lift(True)
        else:
            if w.lifted:
                w.lift(False)
            w.feeds.add(move.feed_mm_min)
        before = len(w.blocks)
        points = [(move.x, move.y)]
        if isinstance(move, ArcMove):
            points = self._chords(w, start, move, _tolerance(program, machine))
        # a helix's Z in equal parts over its chords, as the arc's XY: each chord's
        # staircase (goto) stays within one part of the programmed helix, above it
        z0 = w.pos[2] / w.spm[2]
        n = len(points)
        for k, (x, y) in enumerate(points, start=1):
            if move.z is None or k == n:
                w.goto(x, y, move.z)
            else:
                w.goto(x, y, z0 + (move.z - z0) * k / n, checked=False)
        if len(w.blocks) == before:
            w.counts["tiny"] += 1

    @staticmethod
    def _chords(w: _Writer, start: Point, move: ArcMove, tolerance_mm: float) -> list[Point]:
        arc = Arc(start, (move.x, move.y), (move.cx, move.cy), move.clockwise)
        points = arc.points(tolerance_mm)[1:]
        angle = abs(arc.sweep) / len(points)
        w.chorded(len(points), arc.radius * (1.0 - math.cos(angle / 2.0)))
        return points

    @staticmethod
    def _command(w: _Writer, command: Command) -> None:
        if isinstance(command, Dwell):
            w.dwell(command.seconds)
        else:
            w.drop(command)

    def _warnings(self, w: _Writer, program: Program, machine: Machine) -> tuple[str, ...]:
        c, out = w.counts, []
        spm = machine.steps_per_mm
        if self.placeholder_steps_per_mm and tuple(spm) == self.placeholder_steps_per_mm:
            out.append(
                f"step counts assume {_spm(spm)} steps/mm (X, Y, Z), a placeholder: the thesis "
                "gives no steps/mm; set yours with --machine my.toml "
                "([machine] steps_per_mm = [x, y, z])"
            )
        if program.origin != (0.0, 0.0):
            out.append(
                f"the program starts at {program.origin} mm: the stream is relative and is read "
                "back from (0, 0)"
            )
        if w.feeds:
            feeds = ", ".join(f"{f:g}" for f in sorted(w.feeds)[:4])
            out.append(
                f"feeds are not expressible: the 8751 runs every move at its delay-loop ramp "
                f"(8 Hz start, {cruise_feed(machine):.1f} mm/min cruise, Intf8751 §4.4); "
                f"feed(s) {feeds} mm/min ignored"
            )
        if c["rapids"]:
            how = (
                f"Z raised {self.lift_mm:g} mm around them ({c['lifts']} lift(s), lift_mm)"
                if c["lifts"]
                else "they run at the heights the program gives (its own Z)"
                if any(m.z is not None for m in program.moves)
                else "the tool stays down and cuts along them (raise Z in the program or set "
                "lift_mm in [dialect_options])"
            )
            out.append(
                f"{c['rapids']} rapid(s) written as ordinary moves (the 8751 has no rapid); {how}"
            )
        if w.arcs:
            out.append(
                f"{w.arcs} arc(s) written as {w.chords} chords (the 8751 has no arcs, "
                f"Intf8751 §4.1): largest chord error {w.chord_error_mm:.4f} mm "
                f"(within {_tolerance(program, machine):g} mm)"
            )
        out += _count_warnings(c)
        return tuple(out)

    def _header(self, w: _Writer, machine: Machine) -> list[str]:
        n = len(packets(w.blocks))
        return [
            f"i8751 session (Intf8751, section 3.7): access key {ACCESS_KEY:02X}H, packets of <= 5 "
            "moves ended by 45H, end of data 54H",
            "move = M1 D PH PL | M2 D PH PL | 00 T1 | M3 D PH PL | 00 T2; D 03H +, 04H -, "
            "05H no move (no PH PL); steps = PH*256+PL; T1, T2 in s",
            f"machine: {machine.name}, {_spm(machine.steps_per_mm)} steps/mm (X, Y, Z); "
            f"{len(w.blocks)} move(s) in {n} packet(s); positions in mm from the start",
        ]

    # -- reading ---------------------------------------------------------------

    def parse(self, code: str | bytes, *, source: str = "<code>") -> Program:
        """Read a session (raw bytes or a dump, as ``str`` or ``bytes``) back into moves.

        Bytes that start with the access key 13H, or that are not UTF-8 text
        without control characters, are read as the binary stream; anything
        else as a dump. Positions
        are the summed steps divided by the bound machine's steps/mm, from
        (0, 0, 0). ``Program.lines`` holds each move's 1-based record number.

        Raises:
            ParseError: anything off the grammar of
                :mod:`camtool_postprocessors.i8751.packets`, naming ``source`` and the byte
                offset (and the dump line).
            UsageError: the dialect is not bound to a machine (use a Target, or
                :meth:`for_machine`).
        """
        if self.machine is None:
            raise UsageError(
                "the i8751 reader needs the machine's steps/mm: read through a target "
                "(camtool.post.registry.load_target) or I8751Post().for_machine(machine)"
            )
        if isinstance(code, bytes) and not is_text(code):
            records = decode_stream(code, binary_locator(source))
        else:
            text = code.decode("utf-8") if isinstance(code, bytes) else code
            data, locate = undump(text, source)
            records = decode_stream(data, locate)
        return program_from_records(records, self.machine, self._reading_warnings(self.machine))

    def _reading_warnings(self, machine: Machine) -> tuple[str, ...]:
        spm = machine.steps_per_mm
        if self.placeholder_steps_per_mm and tuple(spm) == self.placeholder_steps_per_mm:
            return (
                f"steps read as mm with {_spm(spm)} steps/mm (X, Y, Z), a placeholder: give "
                "the --machine the code was posted with",
            )
        return ()


def _count_warnings(c: Counter[str]) -> list[str]:
    """Warnings for the counted conversions and drops of one emit."""
    out = []
    if c["xyz"]:
        out.append(
            f"{c['xyz']} move(s) change X/Y and Z together: the 8751 runs X/Y first, then Z "
            "(Intf8751 §4.3, R11), so each is written going down as X/Y then Z, rising as Z "
            "then X/Y: the tool runs on or above the programmed path, never below it; they "
            "read back as two moves"
        )
    if c["split"]:
        out.append(
            f"{c['split']} move(s) over {MAX_STEPS} steps on an axis split into several "
            "records (Intf8751 R3)"
        )
    if c["tiny"]:
        out.append(f"{c['tiny']} move(s) shorter than half a step written as nothing")
    if c["dwell_rounded"]:
        out.append(
            f"{c['dwell_rounded']} dwell(s) rounded to whole seconds (the 8751 waits in 1 s "
            "units, Intf8751 §3.7)"
        )
    if c["dwell_dropped"]:
        out.append(f"{c['dwell_dropped']} dwell(s) of 0 s (after rounding) dropped")
    for kind, why in _DROPPED.items():
        if c[kind.__name__]:
            out.append(f"{c[kind.__name__]} {why}: dropped")
    return out


def _spm(spm: Sequence[float]) -> str:
    fmt = NumberFormat(decimals=4)
    return ", ".join(fmt.format(v).rstrip("0").rstrip(".") for v in spm)


def post_processor(options: Mapping[str, Any], where: str) -> PostProcessor:
    """The ``i8751`` dialect built from a target file's ``[dialect_options]``.

    Raises:
        InputError: an unknown option or a bad value, naming ``where``.
    """
    return from_options(I8751Post, options, where)


def _tolerance(program: Program, machine: Machine) -> float:
    """Chord sagitta, mm: ``--tolerance`` when coarser than the machine's ``chord_tolerance_mm``.

    The machine's sagitta is the finest its steps hold; finer chords only add moves
    shorter than half a step, written as nothing.
    """
    return max(machine.motion.chord_tolerance_mm, program.tolerance_mm or 0.0)
