"""Tools loaded by hand: programs for a machine that cannot change tools.

A job of several tools, or a re-posted program that changes tools, is written one program
per tool (:func:`per_tool`; a re-post that cuts before its first change starts with a
program for the tool loaded at its start); a program whose one change comes before any cut
(:func:`changed_before_cutting`) is that tool's program (:func:`loaded_by_hand`). Each says
which tool to load.
"""

from __future__ import annotations

import dataclasses
import os
import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from camtool.model.program import (
    Command,
    Coolant,
    Move,
    Program,
    Rapid,
    Spindle,
    Stop,
    ToolChange,
    WorkOffset,
)

if TYPE_CHECKING:
    from camtool.post.base import PostResult, Target


@dataclass(frozen=True)
class ToolProgram:
    """One program of a job written per tool (a machine that cannot change tools).

    Attributes:
        number: its place in the run, 1-based.
        change: the tool change it starts with (the tool it cuts with, and what it is);
            ``None`` for a re-posted program's part before its first change, which cuts
            with the tool loaded when the program starts (the program names none).
        program: its moves and commands (its header says which program of how many).
        result: its code.
    """

    number: int
    change: ToolChange | None
    program: Program
    result: PostResult
    numbered: bool = False

    def path(self, output: str | Path) -> str:
        """Where it is written for ``-o output``: :func:`program_path` of its tool."""
        tool = None if self.change is None else self.change.tool
        return program_path(output, self.number, tool, self.numbered)

    @property
    def tool(self) -> str:
        """The tool it cuts with, in words: ``"T2"``, or the tool loaded at the start."""
        return _tool(self.change)


def program_path(output: str | Path, number: int, tool: int | None, numbered: bool) -> str:
    """Where the program of ``tool`` (``None``: the tool loaded at the start) is written.

    For ``-o part.nc``: ``part.T2.nc``, and ``part.start.nc`` for the part of a re-post
    before its first change. When a tool comes back (a job cut in the file's order, T1
    then T2 then T1 again: :func:`needs_numbers`), every program's name begins with its
    place in the run: ``part.1.T1.nc``, ``part.2.T2.nc``, ``part.3.T1.nc``; one name per
    tool would write the last T1 program over the first.
    """
    out = Path(output)
    which = "start" if tool is None else f"T{tool}"
    if numbered:
        which = f"{number}.{which}"
    return str(out.with_name(f"{out.stem}.{which}{out.suffix}"))


def pieces_beside(output: str | Path) -> list[str]:
    """The programs per tool (:func:`program_path`'s names for ``-o output``) in its folder.

    ``part.T2.nc``, ``part.start.nc``, ``part.1.T1.nc`` for ``-o part.nc``: those an earlier
    run left are not this run's; the caller names them. Sorted; ``[]`` when the folder
    cannot be read.
    """
    out = Path(output)
    name = re.compile(rf"{re.escape(out.stem)}\.(?:\d+\.)?(?:T\d+|start){re.escape(out.suffix)}")
    try:
        found = os.listdir(out.parent)
    except OSError:
        return []
    return sorted(str(out.with_name(n)) for n in found if name.fullmatch(n))


def earlier_pieces(output: str | Path, written: Sequence[str]) -> str | None:
    """A warning naming the programs per tool beside ``output`` that this run did not write.

    A job split per tool writes ``part.T1.nc``, ``part.T2.nc``...; run again with other
    tools (or as one program) it leaves the earlier ones, which an operator could take for
    this run's. They are named, not deleted (a file this run did not write is the user's).
    ``None`` when there are none (``written``: the paths this run wrote).
    """
    left = [p for p in pieces_beside(output) if p not in written]
    if not left:
        return None
    one = len(left) == 1
    shown = ", ".join(left[:4]) + (f" and {len(left) - 4} more" if len(left) > 4 else "")
    return (
        f"{shown}: {'a program' if one else 'programs'} per tool from an earlier run, not "
        f"part of what this run wrote to {output}: delete {'it' if one else 'them'} so that "
        f"no one runs {'it' if one else 'them'} by mistake"
    )


def needs_numbers(tools: Sequence[int | None]) -> bool:
    """Whether programs of ``tools`` (in the order they run) need :func:`program_path`'s numbers."""
    return len(set(tools)) < len(tools)


def _tool(change: ToolChange | None) -> str:
    """:attr:`ToolProgram.tool` of a program that starts with ``change``."""
    return "the tool loaded at the start" if change is None else f"T{change.tool}"


def loaded_by_hand(program: Program, target: Target) -> Program:
    """``program`` without its one tool change, when ``target`` cannot change tools.

    For a target whose :attr:`PostProcessor.tool_changes` is ``"none"``, a program whose
    only tool change comes before any cut (:func:`changed_before_cutting`) is that tool's
    program, as :func:`per_tool` writes each of several tools': the tool is loaded by hand
    before it runs, and the header (where the dialect has comments) and a warning say
    which; the change's own stop (``M6`` then ``M0``) goes with it, said in the header.
    Any other program is returned as it is (the writer refuses a change it cannot write;
    several tools are ``per_tool``'s).
    """
    changes = [c for _, c in program.commands if isinstance(c, ToolChange)]
    if target.post.tool_changes != "none" or len(changes) != 1:
        return program
    if not changed_before_cutting(program):
        return program
    change = changes[0]
    what = f" ({change.description})" if change.description else ""
    said = f"load T{change.tool}{what} before running: {target.name} cannot change tools"
    commands, stopped = own_stops_dropped(program.commands)
    stop = [line for m in stopped.values() for line in own_stop_notes(m)]
    return dataclasses.replace(
        program,
        commands=tuple((i, c) for i, c in commands if c is not change),
        notes=(*program.notes, said, *stop),
        warnings=(*program.warnings, f"the tool change to T{change.tool} is not written; {said}"),
    )


OWN_STOP = "the program's stop after this change is this program's start"
"""The header line of a program whose tool change's own stop (``M6`` then ``M0``) it drops."""


def changed_before_cutting(program: Program) -> bool:
    """Whether ``program``'s first tool change comes before any cut.

    Only rapids may come before it (pcb2gcode retracts to its tool change height first):
    they run with the tool the first program names, never a cut with an unnamed one.
    """
    first = next((i for i, c in program.commands if isinstance(c, ToolChange)), None)
    return first is not None and all(isinstance(m, Rapid) for m in program.moves[:first])


def own_stops_dropped(
    commands: Sequence[tuple[int, Command]],
) -> tuple[list[tuple[int, Command]], dict[int, str]]:
    """``commands`` without each tool change's own stop; those changes' ids and messages.

    Each change's id maps to its own stop's message (``""``: none; :func:`own_stop_notes`
    say it in a header).

    A change's own stop comes right after it, before any move (``M6`` then ``M0``, as
    pcb2gcode pauses for the new tool): where a program is cut at its changes (or its
    one change is loaded by hand), starting the program is that stop's resume; where the
    dialect changes tools by hand with a stop (GRBL 1.1's comment and ``M0``), that stop
    is it (the machine stops there once, not twice).
    """
    out: list[tuple[int, Command]] = []
    stopped: dict[int, str] = {}
    change: ToolChange | None = None
    at = -1
    for i, command in commands:
        if isinstance(command, ToolChange):
            change, at = command, i
        elif isinstance(command, Stop) and change is not None and i == at:
            if id(change) not in stopped:
                stopped[id(change)] = command.message
                continue
        else:
            change = None
        out.append((i, command))
    return out, stopped


def own_stop_notes(message: str) -> list[str]:
    """The header lines for a dropped own stop: :data:`OWN_STOP`, then what it said."""
    return [OWN_STOP, f"its message: {message}"] if message else [OWN_STOP]


def sideways_first(number: int, change: ToolChange | None, name: str) -> str:
    """The warning for a program per tool whose first move goes sideways before any Z.

    Its Z zero was just set for the new tool, on the stock's top: a re-posted program
    moves as the input gives it (it expected the tool change to leave the tool up).
    """
    return (
        f"{name} program {number} ({_tool(change)}) moves X/Y before any Z move: that move runs at "
        "the height where Z zero was set for the tool, on the stock's top; add a move up to "
        "a safe height after the tool change in the input"
    )


def idle_changes(program: Program) -> list[ToolChange]:
    """The tool changes after which ``program`` cuts nothing before the next change.

    A change at the program's end, or one changed again at once, loads a tool that
    never cuts: :func:`per_tool` writes no program for it (its rapids go with the
    program before, or the first program; the spindle and coolant its commands leave on
    are started by the next program that cuts).
    """
    every = [(i, c) for i, c in program.commands if isinstance(c, ToolChange)]
    starts = [i for i, _ in every[1:]] + [len(program.moves)]
    moves = program.moves
    return [
        c
        for (i, c), end in zip(every, starts, strict=True)
        if all(isinstance(m, Rapid) for m in moves[i:end])
    ]


def per_tool(program: Program, target: Target, fmt: str | None) -> tuple[ToolProgram, ...]:
    """``program`` cut at its tool changes into one program per tool, each written.

    Each piece holds the moves from its tool change to the next and the commands among
    them in program order (the spindle stop before a change ends the piece before it;
    the change itself is the piece's start; rapids before the first change are the first
    piece's, and a re-post that cuts before it gets a piece of its own for them, with the
    tool loaded at its start: GRBL's ``M0`` reads no line, so no Z zero could be set for
    the new tool within one program); its header is the job's, then which program of how
    many it is and what to load. A stop right after a change (``M6`` then ``M0``, as
    pcb2gcode pauses for the new tool) is that change's: starting the piece is its resume,
    said in the header; any other stop is kept. Each piece runs alone (the one before
    ended with ``M2``; Z zero was set again on the stock): one that moves sideways before
    any Z first rises to the Z the input's tool was at its change (above the work; else a
    warning), and one that moves or cuts before selecting the work offset or starting the
    spindle or coolant the input had there does so where the change was; both said in
    its header. Names:
    :func:`program_path`.

    Raises:
        DialectError: a piece the target cannot write.
    """
    every = [(i, c) for i, c in program.commands if isinstance(c, ToolChange)]
    idle = {id(c) for c in idle_changes(program)}
    found = [(i, c) for i, c in every if id(c) not in idle] or every[:1]
    changes: list[tuple[int, ToolChange | None]] = list(found)
    if not changed_before_cutting(program):  # it cuts with the tool loaded at its start
        changes.insert(0, (0, None))
    kept_ids = {id(c) for _, c in found}
    bounds = [0] + [i for i, _ in changes[1:]] + [len(program.moves)]
    commands: list[list[tuple[int, Command]]] = [[] for _ in changes]
    kept, stopped = own_stops_dropped(program.commands)
    piece, idle_tool = 0, False
    for i, command in kept:
        if isinstance(command, ToolChange):
            idle_tool = id(command) not in kept_ids
            if not idle_tool:
                piece = next(k for k, (_, c) in enumerate(changes) if c is command)
            continue
        if not idle_tool:
            commands[piece].append((i - bounds[piece], command))
    out: list[ToolProgram] = []
    here = program.origin
    numbered = needs_numbers([None if c is None else c.tool for _, c in changes])
    for k, (_, change) in enumerate(changes):
        moves = program.moves[bounds[k] : bounds[k + 1]]
        if change is None:
            load = "with the tool loaded at the start (the program names none)"
        else:
            load = f"load T{change.tool}" + (f" {change.description}" if change.description else "")
        after = f", after program {k} ({_tool(changes[k - 1][1])})" if k else ""
        stop = own_stop_notes(stopped[id(change)]) if change and id(change) in stopped else []
        notes = (*program.notes, f"program {k + 1} of {len(changes)}: {load}{after}", *stop)
        own = commands[k]
        warned: tuple[str, ...] = ()
        rose = 0
        if k > 0 and target.machine.has_z and _sideways(moves, here):
            z = next((m.z for m in reversed(program.moves[: bounds[k]]) if m.z is not None), None)
            if z is not None and z > 0:  # up to where the input's tool was when it changed
                moves = (Rapid(here[0], here[1], z), *moves)
                own, rose = [(j + 1, c) for j, c in own], 1
                notes = (*notes, f"rises to Z{z:g} first: the input's height at its tool change")
            else:
                warned = (sideways_first(k + 1, change, target.name),)
        if change is not None:  # the change's place in the piece, after a rise
            at = next(j for j, c in program.commands if c is change) - bounds[k] + rose
            offset, resumed = _resumed(program, change, moves, own, at)
            own = [*((at - rose, c) for c in offset), *((at, c) for c in resumed), *own]
            resumed = [*offset, *resumed]
            notes = (
                *notes,
                *(f"{_said(c)} as at the input's tool change" for c in resumed),
            )
        alone = Program(
            tuple(moves),
            here,
            (*program.warnings, *warned),
            commands=tuple(sorted(own, key=lambda jc: jc[0])),
            notes=notes,
            tolerance_mm=program.tolerance_mm,
        )
        out.append(ToolProgram(k + 1, change, alone, target.emit(alone, fmt=fmt), numbered))
        if moves:
            here = (moves[-1].x, moves[-1].y)
    return tuple(out)


def _sideways(moves: Sequence[Move], here: tuple[float, float]) -> bool:
    """Whether ``moves`` (a program per tool, from ``here``) go sideways before any Z move."""
    for m in moves:
        if m.z is not None:
            return False
        if (m.x, m.y) != here:
            return True
    return False


def _resumed(
    program: Program,
    change: ToolChange,
    moves: Sequence[Move],
    own: Sequence[tuple[int, Command]],
    at: int,
) -> tuple[list[Command], list[Command]]:
    """What ``program`` has in force at ``change`` that its piece does not set again.

    The work offset (before the piece's first move), then the spindle and coolant (before
    its first cut). A program per tool starts as a program does (the program before
    ended with ``M2``, which on GRBL and LinuxCNC stops the spindle and coolant and
    selects G54), so where the input selected another work offset, or turned the spindle
    on, before the change (before an idle one, or before the program's first) and the
    piece does not do it again before it moves (cuts), it is done where the change was
    (``at``: its place).
    """
    spindle: Spindle | None = None
    rpm: float | None = None
    coolant: Coolant | None = None
    offset: WorkOffset | None = None
    for _, c in program.commands:
        if c is change:
            break
        if isinstance(c, Spindle):
            rpm = c.rpm if c.rpm is not None else rpm
            spindle = None if c.direction == "off" else Spindle(c.direction, rpm)
        elif isinstance(c, Coolant):
            coolant = None if c.state == "off" else c
        elif isinstance(c, WorkOffset):
            offset = c
    cut = next((j for j, m in enumerate(moves) if not isinstance(m, Rapid)), len(moves))
    before = [c for j, c in own if j <= cut]
    out: list[Command] = []
    if spindle is not None and not any(isinstance(c, Spindle) for c in before):
        out.append(spindle)
    if coolant is not None and not any(isinstance(c, Coolant) for c in before):
        out.append(coolant)
    placed = any(isinstance(c, WorkOffset) for j, c in own if j <= at)
    return ([offset] if offset is not None and not placed else []), out


def _said(command: Command) -> str:
    """A resumed work offset, spindle or coolant command in words, for a program's header."""
    if isinstance(command, Spindle):
        speed = f", {command.rpm:g} rev/min" if command.rpm is not None else ""
        return f"spindle on ({command.direction}{speed})"
    if isinstance(command, WorkOffset):
        return f"work offset {command.code}"
    return f"coolant on ({command.state})" if isinstance(command, Coolant) else ""
