"""The ``matlab-router`` dialect: the Angel-11 wood router's Matlab GUI arrays.

Source: Angel-11 §3 (the GUI, verbatim code in Appendix A.1), §2.7 (the USB
stream), §2.8 (the master's job), §8 R1–R7.

Design notes: docs/internals.md, ``postprocessors/matlab_router/dialect.py``.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, ClassVar

from camtool.model.errors import DialectError, UsageError
from camtool.model.machine import Machine
from camtool.model.program import ArcMove, Linear, Move, Program, Rapid
from camtool.model.shapes import Arc, Point
from camtool.post.base import (
    PostProcessor,
    PostResult,
    WriterState,
    check_placement,
    check_work_area,
    from_options,
    input_line,
)
from camtool.post.numfmt import NumberFormat
from camtool_postprocessors.matlab_router.arrays import (
    DEFAULT_SPEED,
    RouterArrays,
    matlab_round,
    points_01mm,
    router_arrays,
)
from camtool_postprocessors.matlab_router.reader import (
    INT16_MAX,
    major_axis_feed_mm_min,
    read_router_code,
)

if TYPE_CHECKING:  # numpy is imported where it is used: `camtool targets` loads this module
    import numpy as np

# -- warnings: one per kind of conversion ----------------------------------------------
# The warnings of the ``matlab-router`` writer: one per kind of conversion.
#
# Gathered in a :class:`RouterWriter` (below) while :class:`MatlabRouterPost`
# writes, then worded here (Angel-11 §2.8, §3, §4.2 for the reasons given).

FIRST_POINT_SPEED = 500
"""Speed of the move from home to a job's first point, counts per 5 ms (L4796)."""

COMMAND_REASONS = {
    "Spindle": "the Z slave switches the Dremel on at the first segment and off at the end "
    "of every job by itself (Angel-11 §2.8, L6556–L6560)",
    "Dwell": "the GUI has no pause; the master stops at every vertex anyway",
    "ToolChange": "the router has one tool, changed by hand",
    "Home": "every job homes Z, X and Y before it starts (Angel-11 §2.8 st=0)",
    "Coolant": "the router has no coolant; switch it by hand",
}
"""Why each kind of :data:`~camtool.model.program.Command` is not written."""


def notes_warnings(
    notes: RouterWriter, speed: int, tolerance: float, grid_mm: float = 0.1
) -> list[str]:
    """One warning per kind of conversion the writer made (commands, feeds, arcs, merges).

    ``grid_mm``: the grid the vertices were rounded to (the dialect's ``grid_mm``).
    """
    w = [
        f"{count} {kind} command(s) not written: {COMMAND_REASONS.get(kind, 'no word for it')}"
        for kind, count in notes.dropped()
    ]
    if notes.feeds:
        feeds = ", ".join(f"{f:g}" for f in sorted(notes.feeds))
        w.append(
            f"feeds ignored ({feeds} mm/min): the router runs the longer axis of every segment "
            f"at {speed} counts per 5 ms = {major_axis_feed_mm_min(speed):g} mm/min and scales "
            "the other (Angel-11 §3, R7)"
        )
    if notes.arcs:
        w.append(
            f"{notes.arcs} arc(s) written as {notes.chords} chords within {tolerance:g} mm "
            f"(largest sagitta {notes.chord_error_mm:.4f} mm), then rounded to {grid_mm:g} mm: the "
            "router "
            "has straight segments only (Angel-11 §4.1)"
        )
    if notes.counts["merged"]:
        w.append(
            f"{notes.counts['merged']} vertex(es) rounded onto the previous one at {grid_mm:g} mm "
            "and "
            f"dropped (first: {notes.notes['merged']})"
        )
    if notes.counts["held"]:
        w.append(
            f"{notes.counts['held']} segment(s) whose shorter axis would move at a speed that "
            f"rounds to 0 (the job would hang, Angel-11 §4.2) cut into pieces of at most {speed} "
            f"counts, each end on the {grid_mm:g} mm grid within {grid_mm / 2:g} mm of the segment "
            "(first: "
            f"{notes.notes['held']})"
        )
    if notes.trailing_rapid is not None:
        x, y = notes.trailing_rapid
        w.append(
            f"the final rapid to ({x:g}, {y:g}) mm is not written: after a job the master "
            "idles with the tool where the job ended (Angel-11 §2.8 st=3)"
        )
    return w


def jobs_warnings(jobs: list[RouterJob], max_segments: int) -> list[str]:
    """Warnings about the jobs themselves: splits, several jobs, firmware hazards."""
    import numpy as np

    w = []
    split = [j for j in jobs if j.part == 2]
    if split:
        joints = "; ".join(
            f"stroke {j.stroke} at ({j.arrays.xy[0, 0] / 10:g}, {j.arrays.xy[1, 0] / 10:g}) mm"
            for j in split[:3]
        )
        w.append(
            f"{len(split)} stroke(s) longer than {max_segments} segments split into jobs that "
            f"continue from the same vertex ({joints}): the master holds {max_segments} per job "
            "(L4625); the tool lifts, homes and re-plunges at each joint"
        )
    if len(jobs) > 1:
        w.append(
            f"{len(jobs)} jobs: the router has no travel inside a job; each job homes Z, X, Y, "
            f"goes to its first point X then Y at speed {FIRST_POINT_SPEED} and lowers the tool, "
            "and the master idles after it (Angel-11 §2.8, §6 L3938–L3966): send the jobs "
            "one at a time, resetting the master in between"
        )
    ones = [
        f"{j.where(int(c))} {'XY'[a]}"
        for j in jobs
        for a, c in zip(*np.nonzero(j.arrays.lxy == 1), strict=True)
    ]
    if ones:
        w.append(
            f"{len(ones)} segment(s) move an axis by 0.1 mm (first: {ones[0]}): the thesis "
            "slave's chunk counter underflows on a distance of 1 (factor - 1 = 65535, "
            "Angel-11 §4.2) and that axis runs away; check the slave firmware or snap the "
            "drawing to 0.2 mm"
        )
    return w


# -- the writer -------------------------------------------------------------------------

CHUNK_MM = 0.2
"""The listed slave firmware's unit of motion, mm: ``floor(d / 2)`` chunks (Angel-11 §4.2)."""

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


class RouterWriter(WriterState[RouterJob]):
    """What the writer has made and has to tell the user (:class:`WriterState`).

    :attr:`blocks` are the jobs written; :attr:`warnings` the warnings already
    worded (strokes that round to one point); :attr:`counts` the commands not
    written by kind and, as the ``"merged"`` :meth:`note`, where vertices that
    rounded onto the previous one were dropped; the chord tally (largest
    sagitta measured, before rounding to 0.1 mm) and :attr:`feeds` (programmed
    feeds other than the router's, mm/min) come with the base.

    Attributes:
        trailing_rapid: end of a rapid after the last cut (not written), mm.
    """

    def __init__(self, here: Point = (0.0, 0.0)) -> None:
        super().__init__(here=here)
        self.trailing_rapid: Point | None = None


@dataclass
class _Stroke:
    """Vertices of one stroke in mm and the move index that produced each after the first."""

    number: int
    points: list[Point]
    owners: list[int] = field(default_factory=list)


class MatlabRouterPost(PostProcessor):
    """Writer and reader of the Angel-11 router's Matlab GUI arrays (Angel-11 §3, R1–R7).

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
        grid_mm: the grid the vertices are rounded to, 0.2 or 0.1 mm. 0.2 (default):
            the listed slave moves an axis ``floor(d / 2)`` chunks of 0.2 mm for a
            distance of ``d`` × 0.1 mm, so it loses 0.1 mm on an odd distance (the losses
            add up, every move being relative) and on a distance of 1 its chunk counter
            underflows and the axis runs away (Angel-11 §4.2); on the 0.2 mm grid every
            distance is whole chunks. 0.1: the GUI's own grid (R1), for a slave that moves
            exact counts (a 0.1 mm move is then written with a warning).

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
        grid_mm: float = CHUNK_MM,
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
        if isinstance(grid_mm, bool) or grid_mm not in (0.1, CHUNK_MM):
            raise UsageError(
                f"grid_mm must be 0.2 (the listed slave's chunk) or 0.1 (the GUI's grid, for a "
                f"slave that moves exact counts), got {grid_mm!r}"
            )
        self.first_pointy_as_char = first_pointy_as_char
        self.grid_mm = float(grid_mm)
        self.grid = 2 if grid_mm == CHUNK_MM else 1  # in 0.1 mm units

    # -- writing ---------------------------------------------------------------

    @property
    def writes_feeds(self) -> bool:
        """False: every move runs at 480 counts per 5 ms on its longer axis (Angel-11 §3)."""
        return False

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
        notes = RouterWriter(program.origin)
        strokes = self._strokes(program, machine, notes)
        for stroke in strokes:
            notes.blocks.extend(self._stroke_jobs(stroke, program, notes, machine))
        jobs = notes.blocks
        if not jobs:
            raise DialectError(
                "nothing to cut: a matlab-router job needs at least one segment of 0.1 mm or "
                "more (rapids alone are not written)"
            )
        warnings = [
            *check_placement(program, machine),
            *notes.warnings,
        ]
        warnings += notes_warnings(
            notes, self.speed, self._tolerance(program, machine), self.grid_mm
        )
        return jobs, warnings + jobs_warnings(jobs, self.max_segments)

    def _tolerance(self, program: Program, machine: Machine) -> float:
        """Chord sagitta, mm: ``--tolerance`` when coarser than the dialect's or machine's.

        The dialect's (else the machine's) sagitta is the finest a 0.1 mm grid can hold:
        finer chords would only add 0.1 mm segments (Angel-11 §4.2).
        """
        finest = self.chord_tolerance_mm or machine.motion.chord_tolerance_mm
        return max(finest, program.tolerance_mm or 0.0)

    def _strokes(self, program: Program, machine: Machine, notes: RouterWriter) -> list[_Stroke]:
        """Runs of cutting moves (mm, arcs as chords); rapids only end them."""
        strokes: list[_Stroke] = []
        current: _Stroke | None = None
        feed = major_axis_feed_mm_min(self.speed)
        tolerance = self._tolerance(program, machine)
        index = -1
        for item in program.items():
            if not isinstance(item, Rapid | Linear | ArcMove):
                notes.drop(item)
                continue
            index += 1
            move: Move = item
            _check_move(notes, move, index, machine, program)
            if isinstance(move, Rapid):
                current, notes.here = None, (move.x, move.y)
                notes.trailing_rapid = notes.here
                continue
            notes.trailing_rapid = None
            if current is None:
                current = _Stroke(len(strokes) + 1, [notes.here])
                strokes.append(current)
            if not math.isclose(move.feed_mm_min, feed, rel_tol=1e-9):
                notes.feeds.add(move.feed_mm_min)
            points = (
                _chords(notes.here, move, tolerance, notes)
                if isinstance(move, ArcMove)
                else [(move.x, move.y)]
            )
            current.points.extend(points)
            current.owners.extend([index] * len(points))
            notes.here = (move.x, move.y)
        return strokes

    def _stroke_jobs(
        self, stroke: _Stroke, program: Program, notes: RouterWriter, machine: Machine
    ) -> list[RouterJob]:
        """Quantise a stroke, drop repeated vertices, split it into jobs of ≤ max_segments.

        Raises:
            DialectError: a vertex outside int16, or one that the grid moves out of the
                machine's work area (a bound off the grid, from ``--machine``).
        """
        import numpy as np

        xy = points_01mm(np.asarray(stroke.points, dtype=np.float64) / self.grid) * self.grid
        keep = np.ones(len(xy), dtype=bool)
        keep[1:] = (np.diff(xy, axis=0) != 0).any(axis=1)
        owners = [o for o, k in zip(stroke.owners, keep[1:], strict=True) if k]
        contours = tuple(sorted({program.moves[o].contour for o in stroke.owners}))
        for i in np.nonzero(~keep)[0]:
            move = program.moves[stroke.owners[i - 1]]
            block = notes.where(move.contour, stroke.owners[i - 1] + 1)
            notes.note("merged", f"{block} ({xy[i, 0] / 10:g}, {xy[i, 1] / 10:g}) mm")
        xy = xy[keep]
        if len(xy) < 2:
            notes.warnings.append(
                f"{_place(contours, f'stroke {stroke.number}')} rounds to the "
                f"single point ({xy[0, 0] / 10:g}, {xy[0, 1] / 10:g}) mm at {self.grid_mm:g} mm "
                "and is not "
                "written (a job needs a segment)"
            )
            return []
        if xy.min() < 0 or xy.max() > INT16_MAX:
            raise DialectError(
                f"{_place(contours, f'stroke {stroke.number}')} has a coordinate outside "
                f"0–{INT16_MAX} (0.1 mm): the master's int16 distances from home (L4639)"
            )
        lo, hi = xy.min(axis=0) / 10.0, xy.max(axis=0) / 10.0
        if machine.outside_work_area((lo[0], lo[1], hi[0], hi[1]), 1e-9):
            x0, y0, x1, y1 = machine.work_area_mm
            raise DialectError(
                f"{_place(contours, f'stroke {stroke.number}')} reaches ({lo[0]:g}, {lo[1]:g})"
                f"–({hi[0]:g}, {hi[1]:g}) mm on the {self.grid_mm:g} mm grid, outside the work "
                f"area X {x0:g}…{x1:g}, Y {y0:g}…{y1:g} mm; move the drawing {self.grid_mm / 2:g} "
                "mm in from the edge (--translate) or give the work area's bounds on the grid"
            )
        xy, owners = _held_speeds(xy, owners, self.speed, notes, program, self.grid)
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
            "% camtool matlab-router: the Angel-11 Matlab GUI arrays (thesis display format)",
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

        See :mod:`camtool_postprocessors.matlab_router.dialect`: each job is a Rapid to its
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


def _check_move(
    notes: RouterWriter, move: Move, index: int, machine: Machine, program: Program
) -> None:
    """Z and work-area checks of one move from ``notes.here`` (``index`` 0-based).

    A program read from code names the move's input line too (:func:`input_line`).
    """
    line = input_line(program, index, move=True)
    where = notes.where(move.contour, index + 1) + (f" ({line})" if line else "")
    if move.z is not None:
        raise DialectError(
            f"{where}: matlab-router has no Z (the Matlab GUI is 2D; the Z slave only lowers "
            "the tool by a fixed 100 units at each job's start, Angel-11 §2.8 L6544); "
            "set the depth by hand"
        )
    check_work_area(notes.here, move, machine, where, program, reposted=program.from_code)


def _chords(here: Point, move: ArcMove, tolerance: float, notes: RouterWriter) -> list[Point]:
    """Equal chords of an arc within ``tolerance``; records the count and measured sagitta."""
    arc = Arc(here, (move.x, move.y), (move.cx, move.cy), move.clockwise)
    points = arc.points(tolerance)
    cx, cy = arc.centre
    sagitta = 0.0
    for (ax, ay), (bx, by) in itertools.pairwise(points):
        mid = math.hypot((ax + bx) / 2 - cx, (ay + by) / 2 - cy)
        sagitta = max(sagitta, arc.radius - mid)
    notes.chorded(len(points) - 1, sagitta)
    return points[1:]


def _held_speeds(
    xy: np.ndarray,
    owners: list[int],
    speed: int,
    notes: RouterWriter,
    program: Program,
    grid: int = 1,
) -> tuple[np.ndarray, list[int]]:
    """Split each segment whose minor-axis speed rounds to 0 into pieces the firmware runs.

    The minor axis's speed is ``round(speed · minor / major)``: 0 when ``minor / major`` is
    under ``1 / (2 · speed)`` (1 count in 1061 at 480), and the slave then never reaches
    its count, so the job hangs (Angel-11 §3, §4.2). A piece whose major axis moves at
    most ``speed`` counts has a speed of at least 1 wherever its minor axis moves, so such
    a segment is cut into ``ceil(major / speed)`` pieces whose ends are the segment's
    points at equal steps, rounded to the vertices' grid: each within half of it of the
    segment, as every vertex already is after rounding. Other segments are left as they are.

    Args:
        xy: ``(n + 1, 2)`` vertices of a stroke, 0.1 mm counts.
        owners: the move index of each segment (``n``), for the warning.
        speed: the major axis's speed, counts per 5 ms.
        notes: where the split is counted (``"held"``) for the warning.
        program: the program, to name the block.
        grid: the vertices' grid, 0.1 mm counts (1 or 2).

    Returns:
        The vertices and owners with the split segments' pieces in their place.
    """
    import numpy as np

    d = np.abs(np.diff(xy, axis=0))
    major, minor = d.max(axis=1), d.min(axis=1)
    # the minor axis's speed as router_arrays computes it: speed / (major / minor), rounded
    ratio = np.divide(major, minor, out=np.full(len(d), np.inf), where=minor > 0)
    hangs = (minor > 0) & (matlab_round(float(speed) / ratio) == 0)
    if not hangs.any():
        return xy, owners
    points: list[np.ndarray] = [xy[:1]]
    kept: list[int] = []
    for i in range(len(xy) - 1):
        if not hangs[i]:
            points.append(xy[i + 1 : i + 2])
            kept.append(owners[i])
            continue
        k = math.ceil(int(major[i]) / speed)
        steps = np.arange(1, k + 1, dtype=np.float64)[:, None] / k
        piece = (xy[i] + (xy[i + 1] - xy[i]) * steps) / grid  # away from zero at .5, as Matlab
        points.append(np.sign(piece) * np.floor(np.abs(piece) + 0.5) * grid)
        kept += [owners[i]] * k
        move = program.moves[owners[i]]
        notes.note(
            "held",
            f"{notes.where(move.contour, owners[i] + 1)}: {int(minor[i])} in {int(major[i])} "
            f"counts, in {k} pieces",
        )
    return np.concatenate(points).astype(xy.dtype), kept


def _check_speeds(job: RouterJob) -> None:
    """A moving axis whose speed rounds to 0 hangs the job (Angel-11 §3, §4.2)."""
    import numpy as np

    a = job.arrays
    hang = (a.lxy > 0) & (a.velxy == 0)
    if hang.any():
        axis, col = (int(i[0]) for i in np.nonzero(hang))
        raise DialectError(
            f"{job.where(col)}: {'XY'[axis]} moves {a.lxy[axis, col] / 10:g} mm while the other "
            f"axis moves {a.lxy[1 - axis, col] / 10:g} mm: its speed {a.speed}·"
            f"{a.lxy[axis, col]}/{a.lxy[1 - axis, col]} rounds to 0 and the slave never reaches "
            "its count, so the job would hang (Angel-11 §3, §4.2); straighten the segment or "
            "split it"
        )


def post_processor(options: Mapping[str, Any], where: str) -> PostProcessor:
    """The ``matlab-router`` dialect built from a target file's ``[dialect_options]``.

    Raises:
        InputError: an unknown option or a bad value, naming ``where``.
    """
    return from_options(MatlabRouterPost, options, where)
