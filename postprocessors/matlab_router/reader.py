"""Reader of the ``matlab-router`` dialect: the GUI's ``.m`` script and its USB wire stream.

Source: Angel-11 §3 (the GUI, Appendix A.1), §2.7 (the USB stream), §2.8 (the master's
job). The writer is :mod:`camtool_postprocessors.matlab_router.dialect`.

Design notes: docs/internals.md, ``postprocessors/matlab_router/dialect.py``.
"""

from __future__ import annotations

import bisect
import re
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from camtool.model.errors import ParseError
from camtool.model.program import Linear, Move, Program, Rapid
from camtool.post.base import ContourCounter
from camtool_postprocessors.matlab_router.arrays import (
    RouterArrays,
    router_arrays,
)

if TYPE_CHECKING:  # numpy is imported where it is used: `camtool targets` loads this module
    import numpy as np

# -- the reader -------------------------------------------------------------------------
# Reader of the ``matlab-router`` dialect: the GUI's ``.m`` script and its USB wire stream.
#
# Both formats are written by :class:`camtool_postprocessors.matlab_router.MatlabRouterPost`
# (Angel-11 §3, §2.7, R2–R4) and read back here, strictly, into a
# :class:`~camtool.model.program.Program` of absolute mm, Y up: each job becomes a
# :class:`~camtool.model.program.Rapid` to its first point (the master homes and goes
# there, §2.8 st=0/st=1) followed by one :class:`~camtool.model.program.Linear` per
# segment (``contour`` = the job number).
#
# **What is the truth.** The firmware never sees ``xy``: the master replays the
# first point, ``lxy`` (distances) and ``velxy`` (signed speeds, whose signs are the
# directions, L3229–L3231). The verifier recomputes the speeds from the vertices
# with the GUI's own rule (:func:`~camtool_postprocessors.matlab_router.arrays.router_arrays`), so a
# file whose arrays disagree with that rule cannot be simulated as the firmware
# would run it: every ``lxy``/``velxy`` entry must be exactly what the GUI
# computes from the vertices at the dialect's ``speed``, else a
# :class:`~camtool.model.errors.ParseError` names the job, the array, the column
# (segment) and the value expected. A segment that moves an axis at speed 0 is
# refused (the slave never reaches its count and the job hangs, §4.2; on the wire
# its direction is lost).
#
# ``Program.lines`` holds, per move, a 1-based line: in the script, the line of
# that vertex's ``x`` in the ``xy`` matrix; in the wire stream, the record number
# (each value ends with CR, which editors show as a line break) of ``x1`` for a
# job's rapid and of ``lx(i)`` for segment ``i``.

COUNTS_PER_MM = 25_600
"""Encoder counts per mm on X and Y: 1024 × 75 / 3 mm (Angel-11 §2.2, R8)."""
TS_S = 0.005
"""Servo sample period of the slaves' speed loops, s (Angel-11 §2.6)."""
INT16_MAX = 32_767
"""Largest value the master's ``signed int16`` arrays hold (L4625–L4643)."""
WIRE_MAX_CHARS = 6
"""Characters per wire value: ``get_string_usb(s, 7)`` keeps 6 and a NUL (L5009–L5021)."""
UNITS_PER_MM = 10
"""GUI units (0.1 mm) per mm (Angel-11 §3, L3202–L3204)."""
ARRAYS = ("xy", "lxy", "velxy")
"""The variables of a job, in the order the script holds them."""

_INT = re.compile(r"0|-?[1-9]\d*")
"""A whole number as Matlab writes it: no leading zeros, no ``-0``."""
_WIRE_START = re.compile(r"-?\d")
"""A wire stream starts with its ``n``; a script with a comment or a variable."""
_ASSIGN = re.compile(r"([A-Za-z_]\w*)[ \t]*=[ \t]*")


def major_axis_feed_mm_min(speed: int) -> float:
    """Feed of the major axis at ``speed`` counts per 5 ms, mm/min (R7: 480 → 3.75 mm/s).

    ``speed · 200 / 25 600`` mm/s (Angel-11 §2.3, R7), so 480 gives 225 mm/min.
    """
    return speed / COUNTS_PER_MM / TS_S * 60.0


@dataclass(frozen=True)
class _Number:
    """One integer of the code with the 1-based line (or record) it sits on."""

    value: int
    line: int


@dataclass(frozen=True)
class _Job:
    """One job as read: vertices and the 1-based line of each move."""

    xy: np.ndarray  # (N, 2) int64, 0.1 mm
    lines: tuple[int, ...]  # N: the rapid's line, then one per segment


def read_router_code(
    code: str | bytes,
    *,
    source: str,
    speed: int,
    max_segments: int,
    first_pointy_as_char: bool,
) -> Program:
    """Read a script or a wire stream (autodetected) back into a program.

    A wire stream starts with a digit (its ``n``); anything else is read as a
    script. Bytes are decoded as UTF-8 (the wire is ASCII).

    Args:
        code: the code, text or bytes.
        source: file name for messages.
        speed: the major-axis speed the arrays must have been made with, counts/5 ms.
        max_segments: most segments a job may hold (the master's arrays, 128).
        first_pointy_as_char: the wire's ``y1`` is one character (the GUI's
            ``'%c'`` bug, L4306) instead of a decimal number.

    Returns:
        Rapid + Linear moves in mm, ``contour`` = job number, with ``lines``.

    Raises:
        ParseError: anything not written by the dialect, naming ``source``, the
            line (record) and the text, or an array that disagrees with the GUI's
            rule (naming the job, array and column).
    """
    if isinstance(code, bytes):
        try:
            code = code.decode("utf-8")
        except UnicodeDecodeError as exc:
            raise ParseError(
                f"{source}: byte {exc.start} is not text; matlab-router code is ASCII"
            ) from exc
    if not code.strip():
        raise ParseError(f"{source}: empty; expected a matlab-router script or wire stream")
    reader = _Reader(source, speed, max_segments)
    wire = _WIRE_START.match(code) is not None
    jobs = reader.wire(code, first_pointy_as_char) if wire else reader.script(code)
    return _program(jobs, speed)


def _program(jobs: list[_Job], speed: int) -> Program:
    """Rapid to each job's first point, then its segments, mm."""
    feed = major_axis_feed_mm_min(speed)
    moves: list[Move] = []
    lines: list[int] = []
    contours = ContourCounter()
    for job in jobs:
        (x0, y0), *rest = job.xy.tolist()
        moves.append(Rapid(x0 / UNITS_PER_MM, y0 / UNITS_PER_MM, contour=contours.next(True)))
        moves.extend(
            Linear(x / UNITS_PER_MM, y / UNITS_PER_MM, feed, contour=contours.next(False))
            for x, y in rest
        )
        lines.extend(job.lines)
    return Program(tuple(moves), lines=tuple(lines))


class _Reader:
    """Parsing state shared by both formats: where, speed, capacity."""

    def __init__(self, source: str, speed: int, max_segments: int) -> None:
        self.source, self.speed, self.max_segments = source, speed, max_segments

    def fail(self, line: int, message: str) -> ParseError:
        return ParseError(f"{self.source}:{line}: {message}")

    # -- checks common to both formats ----------------------------------------

    def check_job(
        self, job: int, xy: np.ndarray, line: int, speed_line: Callable[[int, int], int]
    ) -> RouterArrays:
        """Capacity, ranges, and the arrays the GUI computes from ``xy`` ((N, 2), 0.1 mm).

        ``line`` is the job's line; ``speed_line(axis, segment)`` the line of a speed.
        """
        import numpy as np

        n = len(xy) - 1
        if not 1 <= n <= self.max_segments:
            raise self.fail(
                line,
                f"job {job}: n = {n} segments; a job holds 1 to {self.max_segments} "
                "(the master's arrays X_ROUTE[128]..., Angel-11 §2.7 L4625)",
            )
        if xy[0, 0] < 0 or xy[0, 1] < 0:
            raise self.fail(
                line,
                f"job {job}: first point ({xy[0, 0]}, {xy[0, 1]}) is negative; the master "
                "goes there as an unsigned distance from home (L4792)",
            )
        if np.abs(xy).max() > INT16_MAX:
            raise self.fail(line, f"job {job}: a coordinate does not fit int16 (±{INT16_MAX})")
        arrays = router_arrays(xy, speed=self.speed)
        hang = (arrays.lxy > 0) & (arrays.velxy == 0)
        if hang.any():
            axis, col = (int(i[0]) for i in np.nonzero(hang))
            raise self.fail(
                speed_line(axis, col),
                f"job {job}, segment {col + 1}: {'XY'[axis]} moves {arrays.lxy[axis, col]} "
                "(0.1 mm) at speed 0: the slave never reaches its count and the job hangs "
                "(Angel-11 §4.2)",
            )
        return arrays

    def compare(self, job: int, name: str, got: list[_Number], want: np.ndarray, hint: str) -> None:
        """``got`` (row-major 2 × n) must equal ``want`` (2, n); else name the column."""
        n = want.shape[1]
        for k, number in enumerate(got):
            row, col = divmod(k, n)
            if number.value != want[row, col]:
                raise self.fail(
                    number.line,
                    f"job {job}, {name} column {col + 1} (segment {col + 1}), row {row + 1} "
                    f"({'xy'[row]}): {number.value} where the GUI's rule gives "
                    f"{want[row, col]} ({hint})",
                )

    # -- the script --------------------------------------------------------------

    def script(self, text: str) -> list[_Job]:
        """Jobs of a script: ``xy``, ``lxy``, ``velxy`` assignments in turn, ``%`` comments."""
        code = re.sub(r"%[^\n]*", "", text)
        starts = [0] + [i + 1 for i, c in enumerate(code) if c == "\n"]

        def line_at(offset: int) -> int:
            return bisect.bisect_right(starts, offset)

        found: list[tuple[str, list[_Number]]] = []
        pos = _skip_blank(code, 0)
        while pos < len(code):
            name, numbers, pos = self._assignment(code, pos, line_at)
            found.append((name, numbers))
            pos = _skip_blank(code, pos)
        if not found:
            raise self.fail(1, "no 'xy = [ ... ]' matrix; expected xy, lxy, velxy per job")
        jobs = []
        for j in range(0, len(found), 3):
            group = found[j : j + 3]
            names = [name for name, _ in group]
            if names != list(ARRAYS):
                bad = next((k for k, n in enumerate(names) if n != ARRAYS[k]), len(names) - 1)
                raise self.fail(
                    group[bad][1][0].line,
                    f"job {j // 3 + 1}: found {', '.join(names)}; each job is xy, lxy, "
                    "velxy in that order",
                )
            jobs.append(self._script_job(j // 3 + 1, [numbers for _, numbers in group]))
        return jobs

    def _assignment(
        self, code: str, pos: int, line_at: Callable[[int], int]
    ) -> tuple[str, list[_Number], int]:
        """``name = [ row ; row ]`` at ``pos``: the name, its numbers row-major, the end."""
        line = line_at(pos)
        assign = _ASSIGN.match(code, pos)
        if assign is None or assign.group(1) not in ARRAYS:
            snippet = code[pos:].split("\n", 1)[0].strip()[:40]
            raise self.fail(
                line, f"expected 'xy = ', 'lxy = ' or 'velxy = ' and a matrix, got {snippet!r}"
            )
        name = assign.group(1)
        start = _skip_blank(code, assign.end())
        end = code.find("]", start)
        if start >= len(code) or code[start] != "[" or end < 0 or "[" in code[start + 1 : end]:
            raise self.fail(line, f"{name}: expected a matrix '[ ...; ... ]' after '{name} ='")
        rows: list[list[_Number]] = [[]]
        for m in re.finditer(r"[^\s,;]+|[;\n]", code[start + 1 : end]):
            token, offset = m.group(0), start + 1 + m.start()
            if token in ";\n":
                rows.append([])
            elif _INT.fullmatch(token):
                if len(token) > 6 or abs(int(token)) > INT16_MAX:  # before numpy's int64
                    shown = token if len(token) <= 20 else f"{token[:12]}... ({len(token)} digits)"
                    raise self.fail(
                        line_at(offset),
                        f"{name}: {shown} does not fit the master's int16 (±{INT16_MAX})",
                    )
                rows[-1].append(_Number(int(token), line_at(offset)))
            else:
                raise self.fail(line_at(offset), f"{name}: {token!r} is not a whole number")
        rows = [r for r in rows if r]
        if len(rows) != 2 or len(rows[0]) != len(rows[1]):
            lengths = " and ".join(str(len(r)) for r in rows) or "no"
            raise self.fail(
                line,
                f"{name}: {lengths} numbers in {len(rows)} row(s); it needs 2 rows (x, then y) "
                "of equal length",
            )
        end = _skip_blank(code, end + 1)
        return name, rows[0] + rows[1], end + code.startswith(";", end)

    def _script_job(self, job: int, group: list[list[_Number]]) -> _Job:
        import numpy as np

        xy_numbers, lxy, velxy = group
        count = len(xy_numbers) // 2
        xy = np.array([n.value for n in xy_numbers], dtype=np.int64).reshape(2, count).T
        line = xy_numbers[0].line
        if count < 2:
            raise self.fail(line, f"job {job}: xy has {count} point(s); a job needs 2 or more")
        for name, numbers in (("lxy", lxy), ("velxy", velxy)):
            if len(numbers) != 2 * (count - 1):
                raise self.fail(
                    numbers[0].line,
                    f"job {job}: {name} has {len(numbers) // 2} columns; xy has {count} "
                    f"points, so {count - 1} segments",
                )
        arrays = self.check_job(job, xy, line, lambda a, i: velxy[a * (count - 1) + i].line)
        why = "the firmware replays lxy and velxy, not xy, so they must agree with it"
        self.compare(job, "lxy", lxy, arrays.lxy, f"|xy(i+1) - xy(i)|; {why}")
        self.compare(job, "velxy", velxy, arrays.velxy, f"at speed {self.speed}; {why}")
        return _Job(xy, tuple(n.line for n in xy_numbers[:count]))

    # -- the wire stream ---------------------------------------------------------

    def wire(self, text: str, as_char: bool) -> list[_Job]:
        """Jobs of a wire stream: ``n, x1, y1, lx…, ly…, velx…, vely…`` each ended by CR."""
        records = text.split("\r")
        if records[-1] != "":
            raise self.fail(
                len(records),
                f"{records[-1][:20]!r} does not end with CR (13); every wire value does",
            )
        records.pop()
        jobs: list[_Job] = []
        k = 0
        while k < len(records):
            job = len(jobs) + 1
            n = self._value(records, k, f"job {job}: n")
            if not 1 <= n <= self.max_segments:
                raise self.fail(
                    k + 1,
                    f"job {job}: n = {n}; a job holds 1 to {self.max_segments} segments "
                    "(the master's arrays, Angel-11 §2.7 L4625)",
                )
            if len(records) < k + 3 + 4 * n:
                raise self.fail(
                    len(records),
                    f"job {job}: the stream ends after {len(records) - k} of its "
                    f"3 + 4·{n} = {3 + 4 * n} values",
                )
            jobs.append(self._wire_job(job, records, k, n, as_char))
            k += 3 + 4 * n
        return jobs

    def _value(self, records: list[str], k: int, what: str) -> int:
        text = records[k]
        if not _INT.fullmatch(text) or len(text) > WIRE_MAX_CHARS:
            raise self.fail(
                k + 1,
                f"{what}: {text[:20]!r} is not a decimal integer of at most "
                f"{WIRE_MAX_CHARS} characters ended by CR (Matlab fprintf '%d', then char 13)",
            )
        value = int(text)
        if abs(value) > INT16_MAX:
            raise self.fail(k + 1, f"{what}: {value} does not fit the master's int16")
        return value

    def _wire_job(self, job: int, records: list[str], k: int, n: int, as_char: bool) -> _Job:
        import numpy as np

        x1 = self._value(records, k + 1, f"job {job}: x1")
        if as_char:
            if len(records[k + 2]) != 1:
                raise self.fail(
                    k + 3,
                    f"job {job}: y1 {records[k + 2][:20]!r} is not one character "
                    "(first_pointy_as_char: the GUI sent fprintf(s,'%c',first_pointy), L4306)",
                )
            y1 = ord(records[k + 2])
        else:
            y1 = self._value(records, k + 2, f"job {job}: y1")
        base = k + 3
        names = ("lx", "ly", "velx", "vely")
        values = [
            [
                self._value(records, base + a * n + i, f"job {job}: {names[a]}({i + 1})")
                for i in range(n)
            ]
            for a in range(4)
        ]
        lx, ly, velx, vely = (np.array(v, dtype=np.int64) for v in values)
        for name, d, a in (("lx", lx, 0), ("ly", ly, 1)):
            if (d < 0).any():
                i = int(np.argmax(d < 0))
                raise self.fail(
                    base + a * n + i + 1,
                    f"job {job}: {name}({i + 1}) = {d[i]}; distances are absolute values "
                    "(the direction is the sign of the speed)",
                )
        steps = np.stack([lx * np.where(velx < 0, -1, 1), ly * np.where(vely < 0, -1, 1)])
        first = np.array([[x1], [y1]], dtype=np.int64)
        xy = np.concatenate([first, first + np.cumsum(steps, axis=1)], axis=1).T
        arrays = self.check_job(job, xy, k + 2, lambda a, i: base + (2 + a) * n + i + 1)
        got = [
            _Number(int(v), base + 2 * n + a * n + i + 1)
            for a, row in enumerate((velx, vely))
            for i, v in enumerate(row)
        ]
        why = "the verifier derives the speeds from the vertices by that rule"
        self.compare(job, "velxy", got, arrays.velxy, f"at speed {self.speed}; {why}")
        return _Job(xy, (k + 2, *(base + i + 1 for i in range(n))))


def _skip_blank(code: str, pos: int) -> int:
    """Index of the first character at or after ``pos`` that is not white space."""
    while pos < len(code) and code[pos] in " \t\r\n":
        pos += 1
    return pos
