"""The ``matlab-router`` dialect: the seed-002 wood router's Matlab GUI arrays.

Source: seed-002 §3 (the GUI, verbatim code in Appendix A.1), §2.7 (the USB
stream), §2.8 (the master's job), §8 R1–R7 (reference/seed-002.md).

The GUI turns clicked vertices into three integer arrays per figure
(:mod:`camtool.post.router_arrays`): ``xy`` (``2 × N`` absolute vertices, 0.1 mm),
``lxy`` (``2 × n`` absolute increments, 0.1 mm, ``n = N − 1``) and ``velxy``
(``2 × n`` signed speeds, encoder counts per 5 ms: the major axis at ±``speed``,
480 by default, the other scaled so both end together). Two formats:

- ``script`` (``.m``): the arrays in the thesis's display format (L3196–L3228),
  one ``xy``/``lxy``/``velxy`` triple per job, ``%`` comments naming the job,
  stroke and contour. Each matrix is ``name = `` on one line, then
  ``[`` + the x row (values right-aligned in 6 columns) + ``; `` and `` `` + the y
  row + `` ] ``. This is the thesis's ``velxy`` block character for character
  and the first row of every block; the thesis's second rows of ``xy`` and
  ``lxy`` sit one column further left (typed by hand), which camtool does not
  copy. camtool's points importer reads these files back as strokes.
- ``wire`` (``.txt``): the bytes the GUI sent the master over the USB-CDC port
  (``pushbutton2_Callback``, L4292–L4360): per job ``n``, ``x1``, ``y1``, then
  ``lx(1..n)``, ``ly(1..n)``, ``velx(1..n)``, ``vely(1..n)``, each as Matlab
  ``fprintf(s,'%d',v)`` followed by CR (char 13): ``3 + 4n`` values, no other
  byte. The GUI's pauses (10 ms after the header values, 1 ms after the
  others) are not bytes and are not written. ``first_pointy_as_char`` reproduces
  the GUI's ``fprintf(s,'%c',first_pointy)`` bug (L4306): ``y1`` as one character.

Jobs. The router has no travel inside a job (R6): a stroke (the cutting moves
between two rapids) is one job, which the master runs as home (Z, X, Y) → first
point (X then Y at speed 500) → tool down → segments, stopping at every vertex →
tool off; then it idles (seed-002 §2.8; multi-stroke figures in §6, L3938–L3966).
A rapid is therefore a job boundary, never written. A stroke of more than
``max_segments`` (128: the master's ``X_ROUTE[128]``, L4625) segments is split
into jobs that continue from the same vertex: the thesis machine can do that (it
is how it cut multi-stroke lettering), at the price of a tool lift, re-homing and
a re-plunge at the joint; camtool warns.

Rounding (R1): vertices are ``round(x_mm · 10)`` with Matlab's ``round`` (half
away from zero), as the GUI's ``round(xy*100)`` in cm. A vertex that rounds onto
the previous one is dropped (reported). Arcs become equal chords within
``chord_tolerance_mm`` (default: the machine's ``motion.chord_tolerance_mm``),
reported with the chord count and the largest sagitta measured.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import ClassVar

import numpy as np

from camtool.model.errors import DialectError, UsageError
from camtool.model.machine import Machine
from camtool.model.program import ArcMove, Linear, Move, Program, Rapid
from camtool.model.shapes import Arc, Point
from camtool.post.base import PostProcessor, PostResult, check_placement, check_work_area
from camtool.post.matlab_router_read import (
    INT16_MAX,
    major_axis_feed_mm_min,
    read_router_code,
)
from camtool.post.matlab_router_warnings import WriterNotes, jobs_warnings, notes_warnings
from camtool.post.numfmt import NumberFormat
from camtool.post.router_arrays import DEFAULT_SPEED, RouterArrays, points_01mm, router_arrays

FIRMWARE_MAX_SEGMENTS = 128
"""Segments (lines) one job holds: the master's ``X_ROUTE[128]`` … arrays (L4625–L4635)."""
PROSE_MAX_SEGMENTS = 255
"""The prose's limit, "256 puntos (255 líneas)" (L3175–L3181); needs another firmware."""
_INTEGER = NumberFormat(scale=1.0, decimals=0)
"""Every value of both formats: whole numbers (0.1 mm, counts per 5 ms), ``-`` if negative."""


@dataclass(frozen=True)
class RouterJob:
    """One job: the arrays the GUI sends for (part of) one stroke.

    Attributes:
        arrays: ``xy``, ``lxy``, ``velxy`` (read-only ``int64``, 0.1 mm and counts/5 ms).
        stroke: 1-based number of the stroke (run of cutting moves) it comes from.
        part: 1-based part of the stroke (``> 1`` when a long stroke was split).
        parts: number of jobs the stroke was split into.
        first_segment: 1-based number, within the stroke, of the job's first segment.
        contours: the program contours the job cuts.
        blocks: 1-based program move number of each segment (arcs give several).
    """

    arrays: RouterArrays
    stroke: int
    part: int
    parts: int
    first_segment: int
    contours: tuple[int, ...]
    blocks: tuple[int, ...]

    def where(self, segment: int | None = None) -> str:
        """Where in the program, for messages: ``"contour 2, block 7 (stroke 1, segment 4)"``.

        ``segment`` is 0-based within the job; ``None`` names the job's stroke only.
        """
        part = f" part {self.part} of {self.parts}" if self.parts > 1 else ""
        stroke = f"stroke {self.stroke}{part}"
        if segment is None:
            return _place(self.contours, stroke)
        number = self.first_segment + segment
        return _place(self.contours, f"block {self.blocks[segment]} ({stroke}, segment {number})")


@dataclass
class _Stroke:
    """Vertices of one stroke in mm and the move index that produced each after the first."""

    number: int
    points: list[Point]
    owners: list[int] = field(default_factory=list)


class MatlabRouterPost(PostProcessor):
    """Writer and reader of the seed-002 router's Matlab GUI arrays (seed-002 §3, R1–R7).

    Args:
        speed: major-axis speed of every segment, encoder counts per 5 ms (R7;
            480 in the GUI, L4458): a whole number 1–32767.
        max_segments: segments per job, 1–255: 128 is the thesis master's array
            size (L4625); up to 255 (the prose, L3175) for a modified firmware.
        chord_tolerance_mm: largest chord sagitta when arcs become chords, mm
            (``None``: the machine's ``motion.chord_tolerance_mm``).
        first_pointy_as_char: write ``y1`` on the wire as one character, as the
            GUI's ``fprintf(s,'%c',first_pointy)`` did (L4306); ``y1`` must then
            be 1–127 and not 10 or 13. Default: a decimal number, as the master
            parses it (``atol``, L5017).

    Raises:
        UsageError: an option out of range or of the wrong type.
    """

    arcs: ClassVar[bool] = False
    """Arcs are written as chords."""

    formats: ClassVar[Mapping[str, str]] = MappingProxyType({"script": ".m", "wire": ".txt"})
    binary: ClassVar[bool] = True
    """Code files are read as bytes: the wire's CR terminators must reach the reader
    untouched (text mode would turn them into line feeds)."""

    def __init__(
        self,
        *,
        speed: int = DEFAULT_SPEED,
        max_segments: int = FIRMWARE_MAX_SEGMENTS,
        chord_tolerance_mm: float | None = None,
        first_pointy_as_char: bool = False,
    ) -> None:
        if isinstance(speed, bool) or not isinstance(speed, int) or not 1 <= speed <= INT16_MAX:
            raise UsageError(
                f"speed must be a whole number 1–{INT16_MAX} (counts per 5 ms), got {speed!r}"
            )
        if (
            isinstance(max_segments, bool)
            or not isinstance(max_segments, int)
            or not 1 <= max_segments <= PROSE_MAX_SEGMENTS
        ):
            raise UsageError(
                f"max_segments must be a whole number 1–{PROSE_MAX_SEGMENTS} (the thesis master "
                f"holds {FIRMWARE_MAX_SEGMENTS}), got {max_segments!r}"
            )
        if chord_tolerance_mm is not None and (
            isinstance(chord_tolerance_mm, bool)
            or not isinstance(chord_tolerance_mm, int | float)
            or not chord_tolerance_mm > 0
        ):
            raise UsageError(f"chord_tolerance_mm must be > 0 mm, got {chord_tolerance_mm!r}")
        if not isinstance(first_pointy_as_char, bool):
            raise UsageError(
                f"first_pointy_as_char must be true or false, got {first_pointy_as_char!r}"
            )
        self.speed = speed
        self.max_segments = max_segments
        self.chord_tolerance_mm = None if chord_tolerance_mm is None else float(chord_tolerance_mm)
        self.first_pointy_as_char = first_pointy_as_char

    # -- writing ---------------------------------------------------------------

    def emit(self, program: Program, machine: Machine, *, fmt: str | None = None) -> PostResult:
        """Write ``program`` as one job per stroke, in the ``script`` or ``wire`` format.

        Returns:
            The code (text; the wire's values end with CR) with ``blocks`` = the
            number of jobs, and one warning per kind of conversion.

        Raises:
            DialectError: a Z move, a point (arcs by their extremes) outside the
                machine's work area or beyond int16, a segment whose minor-axis
                speed rounds to 0 (the job would hang), nothing to cut, or on the
                wire a ``y1`` that cannot be one character; the message names
                contour and block.
            UsageError: ``fmt`` is not ``script`` or ``wire``.
        """
        fmt = self.check_format(fmt)
        jobs, warnings = self.jobs(program, machine)
        code = "".join(self._wire(job) for job in jobs) if fmt == "wire" else self._script(jobs)
        return PostResult(code, len(jobs), tuple(warnings), fmt)

    def jobs(self, program: Program, machine: Machine) -> tuple[list[RouterJob], list[str]]:
        """The jobs ``program`` becomes, in order, and the warnings (errors: see :meth:`emit`)."""
        notes = WriterNotes()
        strokes = self._strokes(program, machine, notes)
        jobs: list[RouterJob] = []
        for stroke in strokes:
            jobs.extend(self._stroke_jobs(stroke, program, notes))
        if not jobs:
            raise DialectError(
                "nothing to cut: a matlab-router job needs at least one segment of 0.1 mm or "
                "more (rapids alone are not written)"
            )
        warnings = [*check_placement(program, machine), *notes.warnings]
        warnings += notes_warnings(notes, self.speed, self._tolerance(machine))
        return jobs, warnings + jobs_warnings(jobs, self.max_segments)

    def _tolerance(self, machine: Machine) -> float:
        return self.chord_tolerance_mm or machine.motion.chord_tolerance_mm

    def _strokes(self, program: Program, machine: Machine, notes: WriterNotes) -> list[_Stroke]:
        """Runs of cutting moves (mm, arcs as chords); rapids only end them."""
        strokes: list[_Stroke] = []
        current: _Stroke | None = None
        here = program.origin
        feed = major_axis_feed_mm_min(self.speed)
        tolerance = self._tolerance(machine)
        index = -1
        for item in program.items():
            if not isinstance(item, Rapid | Linear | ArcMove):
                notes.commands[type(item).__name__] += 1
                continue
            index += 1
            move: Move = item
            _check_move(here, move, index, machine, program)
            if isinstance(move, Rapid):
                current, here = None, (move.x, move.y)
                notes.trailing_rapid = here
                continue
            notes.trailing_rapid = None
            if current is None:
                current = _Stroke(len(strokes) + 1, [here])
                strokes.append(current)
            if not math.isclose(move.feed_mm_min, feed, rel_tol=1e-9):
                notes.feeds.add(move.feed_mm_min)
            points = (
                _chords(here, move, tolerance, notes)
                if isinstance(move, ArcMove)
                else [(move.x, move.y)]
            )
            current.points.extend(points)
            current.owners.extend([index] * len(points))
            here = (move.x, move.y)
        return strokes

    def _stroke_jobs(
        self, stroke: _Stroke, program: Program, notes: WriterNotes
    ) -> list[RouterJob]:
        """Quantise a stroke, drop repeated vertices, split it into jobs of ≤ max_segments."""
        xy = points_01mm(np.asarray(stroke.points, dtype=np.float64))
        keep = np.ones(len(xy), dtype=bool)
        keep[1:] = (np.diff(xy, axis=0) != 0).any(axis=1)
        owners = [o for o, k in zip(stroke.owners, keep[1:], strict=True) if k]
        contours = tuple(sorted({program.moves[o].contour for o in stroke.owners}))
        for i in np.nonzero(~keep)[0]:
            move = program.moves[stroke.owners[i - 1]]
            block = f"block {stroke.owners[i - 1] + 1}"
            notes.merged.append(
                _place((move.contour,), f"{block} ({xy[i, 0] / 10:g}, {xy[i, 1] / 10:g}) mm")
            )
        xy = xy[keep]
        if len(xy) < 2:
            notes.warnings.append(
                f"{_place(contours, f'stroke {stroke.number}')} rounds to the "
                f"single point ({xy[0, 0] / 10:g}, {xy[0, 1] / 10:g}) mm at 0.1 mm and is not "
                "written (a job needs a segment)"
            )
            return []
        if xy.min() < 0 or xy.max() > INT16_MAX:
            raise DialectError(
                f"{_place(contours, f'stroke {stroke.number}')} has a coordinate outside "
                f"0–{INT16_MAX} (0.1 mm): the master's int16 distances from home (L4639)"
            )
        n = len(xy) - 1
        parts = math.ceil(n / self.max_segments)
        jobs = []
        for part in range(parts):
            lo, hi = part * self.max_segments, min(n, (part + 1) * self.max_segments)
            job = RouterJob(
                arrays=router_arrays(xy[lo : hi + 1], speed=self.speed),
                stroke=stroke.number,
                part=part + 1,
                parts=parts,
                first_segment=lo + 1,
                contours=tuple(sorted({program.moves[o].contour for o in owners[lo:hi]})),
                blocks=tuple(o + 1 for o in owners[lo:hi]),
            )
            _check_speeds(job)
            jobs.append(job)
        return jobs

    # -- formatting --------------------------------------------------------------

    def _script(self, jobs: list[RouterJob]) -> str:
        """The thesis display format, one ``xy``/``lxy``/``velxy`` triple per job."""
        lines = [
            "% camtool matlab-router: the seed-002 Matlab GUI arrays (thesis display format)",
            f"% xy, lxy in 0.1 mm; velxy in encoder counts per 5 ms, major axis {self.speed}",
            f"% {len(jobs)} job(s); each job homes, goes to its first point and lowers the tool",
        ]
        for number, job in enumerate(jobs, start=1):
            a = job.arrays
            part = (
                f" (part {job.part} of {job.parts}, segments {job.first_segment}-"
                f"{job.first_segment + a.n - 1})"
                if job.parts > 1
                else ""
            )
            x1, y1 = a.first_point
            lines += [
                "",
                f"% job {number} of {len(jobs)}: stroke {job.stroke}{part}, contour "
                f"{', '.join(map(str, job.contours))}, n = {_int(a.n)}, first point "
                f"x = {_int(x1)}, y = {_int(y1)}",
            ]
            lines += [*_matrix("xy", a.xy), "", *_matrix("lxy", a.lxy), ""]
            lines += _matrix("velxy", a.velxy)
        return "\n".join(lines) + "\n"

    def _wire(self, job: RouterJob) -> str:
        """One job's bytes: ``n, x1, y1, lx…, ly…, velx…, vely…``, each ended by CR."""
        a = job.arrays
        x1, y1 = a.first_point
        arrays = (*a.lxy[0], *a.lxy[1], *a.velxy[0], *a.velxy[1])
        values = [_int(v) for v in (a.n, x1, y1, *arrays)]
        if self.first_pointy_as_char:
            if not 1 <= y1 <= 127 or y1 in (10, 13):
                raise DialectError(
                    f"{job.where()}: y1 = {y1} cannot be sent as one character "
                    "(first_pointy_as_char: 1–127 with 7 data bits, not LF or CR, L4276/L4306); "
                    "set first_pointy_as_char = false"
                )
            values[2] = chr(y1)
        return "".join(f"{v}\r" for v in values)

    # -- reading ---------------------------------------------------------------

    def parse(self, code: str | bytes, *, source: str = "<code>") -> Program:
        """Read a script or a wire stream (autodetected) back into Rapid + Linear moves.

        See :mod:`camtool.post.matlab_router_read`: each job is a Rapid to its
        first point and a Linear per segment (feed: the major axis's
        ``speed`` in mm/min); the arrays must be exactly the GUI's for the
        vertices at this dialect's ``speed``.

        Raises:
            ParseError: anything the dialect does not write, naming ``source``,
                the line (wire: the record) and the job, array and column.
        """
        return read_router_code(
            code,
            source=source,
            speed=self.speed,
            max_segments=self.max_segments,
            first_pointy_as_char=self.first_pointy_as_char,
        )


def _place(contours: tuple[int, ...], rest: str) -> str:
    """``"contour 2, " + rest`` for messages; no contour when the moves have none (0)."""
    named = [str(c) for c in contours if c]
    return f"contour {', '.join(named)}, {rest}" if named else rest


def _int(value: int) -> str:
    """A whole number as Matlab's ``%d`` writes it (``-`` for negatives only, never ``-0``)."""
    return _INTEGER.format(float(value))


def _matrix(name: str, arr: np.ndarray) -> list[str]:
    """``name = `` then the two rows as the thesis prints them (L3196–L3228), ``arr`` (2, n)."""
    rows = [[_int(v) for v in row] for row in arr.tolist()]
    width = max(6, 1 + max(len(v) for row in rows for v in row))
    x, y = ("".join(v.rjust(width) for v in row) for row in rows)
    return [f"{name} = ", f"[{x}; ", f" {y} ] "]


def _check_move(here: Point, move: Move, index: int, machine: Machine, program: Program) -> None:
    """Z and work-area checks of one move (``index`` 0-based)."""
    where = _place((move.contour,), f"block {index + 1}")
    if move.z is not None:
        raise DialectError(
            f"{where}: matlab-router has no Z (the Matlab GUI is 2D; the Z slave only lowers "
            "the tool by a fixed 100 units at each job's start, seed-002 §2.8 L6544); "
            "set the depth by hand"
        )
    check_work_area(here, move, machine, where, program)


def _chords(here: Point, move: ArcMove, tolerance: float, notes: WriterNotes) -> list[Point]:
    """Equal chords of an arc within ``tolerance``; records the count and measured sagitta."""
    arc = Arc(here, (move.x, move.y), (move.cx, move.cy), move.clockwise)
    points = arc.points(tolerance)
    cx, cy = arc.centre
    for (ax, ay), (bx, by) in itertools.pairwise(points):
        mid = math.hypot((ax + bx) / 2 - cx, (ay + by) / 2 - cy)
        notes.sagitta_mm = max(notes.sagitta_mm, arc.radius - mid)
    notes.arcs += 1
    notes.chords += len(points) - 1
    return points[1:]


def _check_speeds(job: RouterJob) -> None:
    """A moving axis whose speed rounds to 0 hangs the job (seed-002 §3, §4.2)."""
    a = job.arrays
    hang = (a.lxy > 0) & (a.velxy == 0)
    if hang.any():
        axis, col = (int(i[0]) for i in np.nonzero(hang))
        raise DialectError(
            f"{job.where(col)}: {'XY'[axis]} moves {a.lxy[axis, col] / 10:g} mm while the other "
            f"axis moves {a.lxy[1 - axis, col] / 10:g} mm: its speed {a.speed}·"
            f"{a.lxy[axis, col]}/{a.lxy[1 - axis, col]} rounds to 0 and the slave never reaches "
            "its count, so the job would hang (seed-002 §3, §4.2); straighten the segment or "
            "split it"
        )
