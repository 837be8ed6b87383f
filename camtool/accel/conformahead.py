"""A program's arcs conformed ahead, in a forked helper, while the writer works.

Design notes: docs/internals.md, ``camtool/accel/conformahead.py``.
"""

from __future__ import annotations

import mmap
import os
import struct
from contextlib import suppress
from typing import TYPE_CHECKING

from camtool.accel import enabled
from camtool.model.errors import CamtoolError
from camtool.model.program import ArcMove, Program
from camtool.model.shapes import Point

if TYPE_CHECKING:
    from camtool.post.wordaddress_arcs import ArcWriter

Key = tuple[Point, Point, Point, bool, Point]
"""An arc's arguments: ``(written start, end, centre, clockwise, exact start)``, mm."""
Blocks = list[tuple[Point, Point | None]]
"""The writer's blocks of one arc: ``(end, absolute centre)`` each."""

MIN_ARCS = 2000
"""Arcs of distinct centres (told apart by their x) from which a helper is forked (~50 ms
of conforming: below that, the fork and the helper's prediction cost about what they
save). The re-post benchmark repeats 1 653 arcs 17 times: the writer reuses their blocks, and
no helper runs."""
MAX_MOVES = 250_000
"""Moves above which no helper is forked: it walks the whole program, and the reference
counts it touches copy the program's memory into it (a 1.5 M-move program: 526 MB in the
helper beside the writer's 450 MB)."""
BATCH = 256
"""Arcs a record holds (~25 kB: under a pipe's buffer, so a record is read at once)."""
POLL_EVERY = 32
"""Lookups between two looks at the helper's pipe (a look costs a system call)."""
AT = struct.Struct("<q")
"""The shared count of arcs the writer has looked up (:class:`ConformAhead`)."""
NEAR = 2 * BATCH
"""Lookups ahead of a record's first arc from which the writer reads it."""


class ConformAhead:
    """The helper's answers, as :func:`start` forked it; :meth:`close` it after writing.

    Args:
        pid: the helper's process id.
        fd: the read end of the pipe its records come through.
        shared: memory shared with the helper, where :meth:`take` tells it how many arcs
            the writer has looked up (:data:`AT`): the helper stops at the arcs the
            writer has passed.
    """

    def __init__(self, pid: int, fd: int, shared: mmap.mmap) -> None:
        self.pid = pid
        self.fd: int | None = fd
        self.shared = shared
        self.got: dict[Key, Blocks] = {}
        # records as they came, (first arc, bytes), the latest arcs first: each is read
        # once the writer nears its arcs (~100 bytes an arc where ~800 read)
        self.raw: list[tuple[int, bytes]] = []
        self.looks = 0
        self.taken = 0

    def take(self, key: Key) -> Blocks | None:
        """The blocks the helper found for the arc ``key``, or ``None`` (not found yet, or not)."""
        self.looks += 1
        if self.looks % POLL_EVERY == 1:  # the first lookup too
            AT.pack_into(self.shared, 0, self.looks)
            self._read()
            self._open_near()
        found = self.got.pop(key, None)
        if found is not None:
            self.taken += 1
        return found

    def _read(self) -> None:
        """Take every record the helper has written so far, without waiting for more."""
        import select

        from camtool.accel.cores import read_record

        fd = self.fd
        while fd is not None and select.select([fd], [], [], 0.0)[0]:
            record = read_record(fd)
            if record is None:  # the helper has finished (or died): nothing more comes
                self._close_pipe()
                return
            self.raw.append((AT.unpack_from(record)[0], record))

    def _open_near(self) -> None:
        """Read the records of the arcs the writer is near into :attr:`got`.

        A record of the arcs from ``first`` (their place in :func:`arc_calls`) is read
        once the lookups reach ``first`` less :data:`NEAR`. The writer looks up the arcs
        the helper leaves out too (full circles, arcs that round away), so its count
        runs ahead of its place, and a record is read before the writer needs it. Only
        arcs that start where X or Y is written as exactly 0 are counted by the helper
        and not looked up: after more than :data:`NEAR` of them a record can be read
        late, and the writer then checks its arcs itself (the same blocks, more time).
        """
        import pickle

        raw, near = self.raw, self.looks + NEAR
        while raw and raw[-1][0] <= near:  # the earliest arcs came last
            self.got.update(pickle.loads(memoryview(raw.pop()[1])[AT.size :]))

    def _close_pipe(self) -> None:
        if self.fd is not None:
            os.close(self.fd)
            self.fd = None

    def close(self) -> None:
        """End the helper (it may still be working: its answers are no longer needed)."""
        from camtool.accel.cores import end_process

        self._close_pipe()
        with suppress(ChildProcessError):
            end_process(self.pid, kill=True)
        self.got.clear()
        self.raw.clear()
        self.shared.close()


def start(writer: ArcWriter, program: Program) -> ConformAhead | None:
    """Fork the helper that conforms ``program``'s arcs for ``writer``; ``None`` when not.

    Call it once ``writer`` holds the program's origin as written (``writer.written``),
    before its first block: the helper is a copy of it. Not under :data:`MIN_ARCS` arcs,
    without an arc check, on one core, in a worker process, or when no process can be
    forked (``None``: the writer conforms every arc itself).
    """
    if writer.spec.arc_check == "none" or not MIN_ARCS <= len(program.moves) <= MAX_MOVES:
        return None
    if not enabled():
        return None
    # Distinct arcs, told apart by their centre's x (a few ms; an estimate from below): a
    # program that cuts its contours again (at other depths, or copies) has the writer
    # reuse their blocks (ArcWriter._conformed_at), not conform them again.
    if len({m.cx for m in program.moves if isinstance(m, ArcMove)}) < MIN_ARCS:
        return None
    from camtool.accel.cores import (  # only here: ~9 ms that a re-post does not need
        default_jobs,
        fork_with_pipes,
        in_worker,
        quiet_crashes,
        write_record,
    )

    if default_jobs() < 2 or in_worker():
        return None

    import pickle

    shared = mmap.mmap(-1, AT.size)  # anonymous and shared with the helper
    AT.pack_into(shared, 0, 0)

    def serve(inbox: int, outbox: int) -> None:
        quiet_crashes()
        os.close(inbox)
        calls = arc_calls(writer, program)
        k = len(calls) - 1  # from the last arc back, until the writer has passed them
        while k >= 0 and k >= AT.unpack_from(shared)[0]:
            found = []
            keys = [key_of(writer, call) for call in calls[k : max(k - BATCH, -1) : -1]]
            known = [key for key in keys if key is not None]
            # the arcs the writer's own batch answers (camtool.post.arcbatch) are left to
            # it: the helper conforms the others, the ones that take the search
            plain = writer.plain_arcs(known)
            for key, answered in zip(known, plain, strict=True):
                blocks = None if answered is not None else _conformed(writer, key)
                if blocks is not None:
                    found.append((key, blocks))
            first = max(k - BATCH + 1, 0)
            data = pickle.dumps(found, protocol=pickle.HIGHEST_PROTOCOL)
            write_record(outbox, AT.pack(first) + data)
            k -= BATCH

    try:
        pid, to_child, from_child = fork_with_pipes(serve)
    except OSError:
        shared.close()
        return None
    os.close(to_child)
    return ConformAhead(pid, from_child, shared)


Call = tuple["Point | None", Point, Point, bool, Point]
"""An arc as :func:`arc_calls` gives it: ``(before, end, centre, clockwise, exact start)``."""


def arc_calls(writer: ArcWriter, program: Program) -> list[Call]:
    """Each arc of ``program`` once, in order: ``(before, end, centre, clockwise, start)``.

    ``before`` is where the last move writing X and Y before the arc ended, not yet
    printed (``None``: no such move, the controller holds the program's origin as
    written); ``start`` is the exact start, where the move before ended. A move that
    changes only Z writes no X or Y (``writer.z_only``); an arc does.
    Nothing is printed here, so the helper predicts the arcs in any order, the last first,
    with no pass over the program before its first answer (printing every end first took
    0.5 s of the SVG benchmark). An arc with a zero in it is left out (the module's
    docstring).
    """
    calls: list[Call] = []
    here = program.origin
    before: Point | None = None
    z_only = writer.z_only
    for move in program.moves:
        end = (move.x, move.y)
        if type(move) is ArcMove:
            centre = (move.cx, move.cy)
            if (
                0.0 not in end
                and 0.0 not in centre
                and 0.0 not in here
                and (before is None or 0.0 not in before)
            ):
                calls.append((before, end, centre, move.clockwise, here))
            before = end
        elif move.z is None or not z_only(here, move):  # type: ignore[arg-type]  # not an arc
            before = end
        here = end
    return list(dict.fromkeys(calls))  # an arc cut again: the writer reuses its blocks


def key_of(writer: ArcWriter, call: Call) -> Key | None:
    """The arguments ``writer`` will conform the arc ``call`` with, or ``None``.

    The start the controller holds is ``before`` as printed (``writer.written`` as the
    writer starts, for ``None``). ``None`` for an arc whose end prints as that start (a
    full circle, or an arc that rounds away: the writer conforms it otherwise), one with
    a zero in its key, and one after a number that cannot be printed (the writer raises
    there).
    """
    before, end, centre, clockwise, here = call
    try:
        written = writer.written if before is None else writer.written_xy(before)
        if writer.written_xy(end) == written:
            return None
    except CamtoolError:
        return None
    if 0.0 in written:
        return None
    return (written, end, centre, clockwise, here)


def _conformed(writer: ArcWriter, key: Key) -> Blocks | None:
    """The writer's blocks for the arc ``key`` (``ArcWriter.checked``), or ``None``.

    ``None`` when the check raises: the writer repeats the arc and says why.
    """
    try:
        pieces = writer.checked(*key)
    except Exception:  # repeated by the writer, which words it
        return None
    return [(p.end, p.centre) for p in pieces]
