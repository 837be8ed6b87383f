"""Reading the i8751 stream back: records → a Program (see :mod:`camtool.post.i8751`).

The reader sums the steps from X = Y = Z = 0 and divides by the machine's
steps/mm; a record that moves X/Y and Z gives two moves (X/Y, then Z), as the
interface runs them (seed-003 §4.3, R11); waits T1/T2 give dwells. A move that
ends with the tool above Z = 0 is a rapid, any other a cut at the cruise feed.
"""

from __future__ import annotations

from camtool.model.machine import Machine
from camtool.model.program import Command, Dwell, Linear, Move, Program, Rapid
from camtool.post.i8751_stream import ACCESS_KEY, Record

CRUISE_HZ = 104.0
"""Cruise step rate of the firmware ramp, X = 11H (seed-003 §4.4), used when the
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
    contour = 0

    def add(number: int, z: float | None) -> None:
        nonlocal contour
        x, y = pos[0] / spm[0], pos[1] / spm[1]
        move: Move
        if pos[2] > 0:
            contour += not (moves and isinstance(moves[-1], Rapid))
            move = Rapid(x, y, z, contour=contour)
        else:
            move = Linear(x, y, feed, z, contour=contour)
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
