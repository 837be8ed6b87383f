"""A long program's second part written in a forked helper while the writer writes the first.

The word-address writer (:class:`~camtool.post.wordaddress_write.BlockWriter`) writes a
program block after block, and what it writes for a move depends on what it wrote before:
the modal words last written, the position as written, the Z, the feed, the spindle.
That state is small and forgets quickly: a few moves after a Z move and a feed it is the
same whatever came before. So a helper forked before the first block writes the program
from item :attr:`Split.at` on, after writing a stretch before it (from the last Z move at
least :data:`WARM` moves back, with every command before that) only to reach the
writer's state there. The writer writes the items before :attr:`Split.at` meanwhile, and
then compares its own state with the one the helper started from (:meth:`Split.join`):
every attribute of the writer but its output, its counts and its caches, bit for bit
(``-0.0`` is not ``0.0``). Only when all are the same does it take the helper's blocks:
the helper then wrote what the writer itself would have. When anything differs, when
the helper wrote a warning the writer has not, failed or died, the writer writes the
rest itself: the same program, only slower. ``CAMTOOL_ACCEL=0`` never splits.

Design notes: docs/internals.md, ``camtool/accel/splitwrite.py``.
"""

from __future__ import annotations

import copy
import os
import pickle
import time
from bisect import bisect_right
from collections import Counter
from collections.abc import Iterator
from contextlib import suppress
from itertools import islice
from typing import TYPE_CHECKING, Any

from camtool.accel import enabled
from camtool.accel.later import same
from camtool.model.program import ArcMove, Linear, PlaneArc, Program, Rapid

if TYPE_CHECKING:
    from camtool.post.wordaddress_write import BlockWriter

MIN_MOVES = 40_000
"""Moves from which the program is split: below, the fork, the stretch written twice and
the hand-over cost about what the second core saves (docs/performance.md)."""
MAX_MOVES = 1_000_000
"""Moves above which it is not: the helper copies the memory it writes to, and counting a
reference to an object writes to its page, so its copy grows with its half of the moves
(docs/performance.md)."""
SHARE = 0.45
"""The part of the moves the writer writes itself: it also checks the program's placement
while the helper writes."""
WARM = 256
"""Moves the helper writes at least before :attr:`Split.at` to reach the writer's state."""
FAR = 0.1
"""The most of the program the helper's stretch before :attr:`Split.at` may be (a fraction
of its moves): a program with no Z move that near is not split."""
OUTPUT = frozenset(
    {
        "blocks",
        "_done",
        "_done_blocks",
        "warnings",
        "notes",
        "counts",
        "arcs",
        "chords",
        "chord_error_mm",
        "feeds",
        "grid_error_mm",
    }
)
"""The writer's output and what it adds up for its closing warnings: the helper's own from
:attr:`Split.at`, added to the writer's (:meth:`Split.join`)."""
FIXED = frozenset({"spec", "machine", "program", "_formats", "_parses", "_printed", "_quantum"})
"""The writer's dialect, machine, program and what it derives from them or keeps by value
(the same in the helper, a copy of it): not compared."""
_MOVES = (Rapid, Linear, ArcMove)


class Split:
    """The helper :func:`start` forked; the writer joins it after item :attr:`at`.

    Args:
        at: the items (:meth:`Program.items`) the writer writes itself.
        pid: the helper's process id.
        fd: the read end of the pipe its answer comes through.
    """

    def __init__(self, at: int, pid: int, fd: int) -> None:
        self.at = at
        self.pid = pid
        self.fd = fd
        self.started = time.monotonic()

    def join(self, writer: BlockWriter, index: int, written: int) -> bool:
        """Take the helper's blocks if it started from ``writer``'s state; False: write them.

        Call it once ``writer`` has written the first :attr:`at` items, ``index`` of them
        moves, the moves before ``written`` written (by a plane arc); True: ``writer`` has
        the whole program's blocks but its postamble, counts and state as if it had
        written every item itself.
        """
        from camtool.accel.cores import end_process, patience, read_record

        try:  # a helper that hung is ended at the deadline: the writer writes the rest
            record = read_record(self.fd, patience(self.started))
        finally:
            os.close(self.fd)
            with suppress(ChildProcessError):
                end_process(self.pid, kill=True)
        if record is None:
            return False
        answer = pickle.loads(record)
        if answer is None:
            return False  # it failed: an error names its block from here
        start, after, out = answer
        if not same(start, state(writer, index, written)):
            return False
        if not set(out["warnings"]) <= set(writer.warnings):
            return False  # a warning of its own names a block it counted from its start
        if not set(out["notes"]) <= set(writer.notes):
            return False  # the same for the first message of a kind
        if writer.blocks:
            writer._join_blocks()
        writer._done.extend(out["_done"])
        writer._done_blocks += out["_done_blocks"]
        writer.counts += out["counts"]
        writer.arcs += out["arcs"]
        writer.chords += out["chords"]
        writer.chord_error_mm = max(writer.chord_error_mm, out["chord_error_mm"])
        writer.feeds |= out["feeds"]
        writer.grid_error_mm = max(writer.grid_error_mm, out["grid_error_mm"])
        for name, value in after.items():
            if name not in ("#index", "#written"):
                setattr(writer, name, value)
        return True

    def close(self) -> None:
        """End the helper without its answer (the writer failed first)."""
        from camtool.accel.cores import end_process

        with suppress(OSError):
            os.close(self.fd)
        with suppress(ChildProcessError):
            end_process(self.pid, kill=True)


def start(writer: BlockWriter, program: Program) -> Split | None:
    """Fork the helper that writes ``program`` from the middle on; ``None`` when not.

    Call it before ``writer`` writes anything (the helper is a copy of it that throws
    away what it writes before the middle); the writer checks the program's placement
    and writes its header meanwhile. Not under :data:`MIN_MOVES` moves or
    over :data:`MAX_MOVES`, without a Z move near the middle (:data:`FAR`), on one core,
    in a worker process, switched off, or when no process can be forked.
    """
    moves = program.moves
    if not MIN_MOVES <= len(moves) <= MAX_MOVES or not enabled():
        return None
    middle = int(len(moves) * SHARE)
    first = _warm_from(program, middle)
    if first is None:
        return None
    from camtool.accel.cores import default_jobs, fork_with_pipes, in_worker, quiet_crashes

    if default_jobs() < 2 or in_worker():
        return None
    at = middle + sum(1 for i, _ in program.commands if i <= middle)  # items before move `middle`

    def serve(inbox: int, outbox: int) -> None:
        from camtool.accel.cores import write_record

        quiet_crashes()
        os.close(inbox)
        try:
            answer: Any = _second_part(writer, program, first, at)
        except Exception:
            answer = None
        write_record(outbox, pickle.dumps(answer, protocol=pickle.HIGHEST_PROTOCOL))

    try:
        pid, to_child, from_child = fork_with_pipes(serve)
    except OSError:
        return None
    os.close(to_child)
    return Split(at, pid, from_child)


def _warm_from(program: Program, middle: int) -> int | None:
    """The move the helper starts writing from (``None``: none near enough).

    The last straight move that sets Z at least :data:`WARM` moves before ``middle`` and
    not a chord of a plane arc (which the writer may write as an arc).
    """
    moves, limit = program.moves, middle - int(FAR * len(program.moves))
    arcs = [(i, i + c.moves) for i, c in program.commands if isinstance(c, PlaneArc)]
    starts = [i for i, _ in arcs]
    k = middle - WARM
    while k > limit and k > 0:
        move = moves[k]
        if move.z is not None and not isinstance(move, ArcMove):
            n = bisect_right(starts, k)
            if n == 0 or k >= arcs[n - 1][1]:
                return k
        k -= 1
    return None


def _second_part(writer: BlockWriter, program: Program, first: int, at: int) -> tuple[Any, ...]:
    """In the helper: the state at item ``at``, the state at the end, and what it wrote.

    The helper writes every command before move ``first`` (they set the spindle and the
    length offset; plane arcs are left out) and the items from move ``first`` (the
    commands and plane arc before it included) to item ``at``, throws those blocks away,
    then writes the rest.
    """
    commands = program.commands
    done = 0  # commands before move `first`
    while done < len(commands) and commands[done][0] < first:
        command = commands[done][1]
        if not isinstance(command, PlaneArc):  # skipped: compared as `written`
            writer.command(command)
        done += 1
    before = program.moves[first - 1]  # from here on, as the writer writes, from its end
    writer.here = (before.x, before.y)
    writer.written = writer.written_xy(writer.here)  # as its XY block wrote it
    items = _items_from(program, first, done)
    index = first
    done += first  # items before move `first`
    index, written = writer.write_items(islice(items, at - done), index, index)
    start = copy.deepcopy(state(writer, index, written))  # `last` changes in place
    writer.blocks.clear()
    writer._done.clear()
    writer._done_blocks = 0
    writer.warnings.clear()
    writer.notes.clear()
    writer.counts = Counter()
    writer.arcs = writer.chords = 0
    writer.chord_error_mm = writer.grid_error_mm = 0.0
    writer.feeds = set()
    index, written = writer.write_items(items, index, written)
    if writer.blocks:
        writer._join_blocks()
    out = {name: getattr(writer, name) for name in OUTPUT if name != "blocks"}
    return start, state(writer, index, written), out


def _items_from(program: Program, first: int, k: int) -> Iterator[Any]:
    """:meth:`Program.items` from move ``first`` on (``k``: the commands before it).

    The moves before are not touched (:data:`MAX_MOVES`).
    """
    moves, commands = program.moves, program.commands
    for index in range(first, len(moves)):
        while k < len(commands) and commands[k][0] == index:
            yield commands[k][1]
            k += 1
        yield moves[index]
    for _, command in commands[k:]:
        yield command


def state(writer: BlockWriter, index: int, written: int) -> dict[str, Any]:
    """What the writer's next blocks depend on.

    Every attribute but :data:`OUTPUT` and :data:`FIXED`, and the moves written
    (``index``, and ``written`` where a plane arc's chords run past it).
    """
    out = {
        name: value
        for name, value in vars(writer).items()
        if name not in OUTPUT and name not in FIXED and name != "_conformed_arcs"
    }
    out["#index"] = index
    out["#written"] = max(index, written)
    return out
