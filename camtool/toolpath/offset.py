"""Arc-preserving 2D offsets of closed contours (OpenCASCADE), with a fallback.

Design notes: docs/internals.md, ``camtool/toolpath/offset.py``.
"""

from __future__ import annotations

import contextlib
import math
import os
import pickle
import select
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, TypeAlias

from camtool.accel.cores import (
    FORK,
    default_jobs,
    end_process,
    fork_with_pipes,
    how_ended,
    in_worker,
    quiet_crashes,
    read_exactly,
    read_record,
    wait_readable,
    write_record,
)
from camtool.geometry.area import enclosed
from camtool.geometry.chain import chain
from camtool.model.errors import ToolpathError
from camtool.model.shapes import Contour, Point, distance
from camtool.toolpath.occt_shapes import _JOIN_MM, _from_edge, _to_wire, _where, _wire_edges

if TYPE_CHECKING:
    from shapely.geometry.base import BaseGeometry

_MAX_QUAD_SEGS = 4096


@dataclass(frozen=True)
class OffsetResult:
    """An offset and how it was made.

    Attributes:
        pieces: closed contours, mm, oriented as described in the module
            docstring; empty when the offset leaves nothing.
        fallback: why OpenCASCADE's result was not used (the pieces are
            shapely's buffer fitted with arcs), ``None`` when they are exact.
    """

    pieces: tuple[Contour, ...]
    fallback: str | None = None


def offset_contour(contour: Contour, amount: float) -> Contour:
    """Offset a closed contour by ``amount`` mm into exactly one piece (OpenCASCADE).

    The result keeps the contour's orientation (clockwise stays clockwise) and
    starts at the vertex nearest the contour's own start.

    Args:
        contour: a closed contour, mm.
        amount: offset distance, mm; positive is away from the enclosed area.

    Returns:
        The offset contour.

    Raises:
        ToolpathError: the contour is open, OpenCASCADE cannot offset it, the
            offset leaves nothing (a region narrower than the tool), splits into
            several pieces, or holds curves other than lines and arcs.
    """
    if amount == 0:
        if not contour.closed:
            raise ToolpathError(f"{_where(contour)}: only closed contours can be offset")
        return contour
    pieces = offset_pieces(contour, amount)
    if not pieces:
        raise ToolpathError(
            f"{_where(contour)}: offset by {amount:+.4g} mm leaves nothing; the region is "
            "narrower than the tool"
        )
    if len(pieces) > 1:
        raise ToolpathError(
            f"{_where(contour)}: offset by {amount:+.4g} mm splits into {len(pieces)} pieces; "
            "camtool cuts one piece per contour (use a smaller tool)"
        )
    return pieces[0]


def offset_pieces(contour: Contour, amount: float) -> list[Contour]:
    """Offset a closed contour by ``amount`` mm with OpenCASCADE, every piece kept.

    A shrink can split a region at a waist narrower than ``2·|amount|`` (a
    dumbbell) into several pieces, or leave nothing; a grow can close a "C" and
    leave a hole in the offset region. Each piece starts at its vertex nearest
    the contour's start.

    Args:
        contour: a closed contour, mm.
        amount: offset distance, mm; positive is away from the enclosed area.

    Returns:
        The closed pieces, oriented as described in the module docstring
        (``[contour]`` for ``amount == 0``, ``[]`` when nothing is left).

    Raises:
        ToolpathError: the contour is open, OpenCASCADE fails, a piece does
            not close, or the offset holds curves other than lines and arcs.
    """
    if not contour.closed:
        raise ToolpathError(f"{_where(contour)}: only closed contours can be offset")
    if amount == 0:
        return [contour]
    try:
        wires = _occt_offset(contour, amount)
    except Exception as exc:  # OCCT's StdFail_* types share no base below Exception
        raise ToolpathError(
            f"{_where(contour)}: offset by {amount:+.4g} mm failed ({exc}); the region may "
            "be narrower than the tool"
        ) from exc
    pieces: list[Contour] = []
    for wire in wires:
        try:
            edges = [_from_edge(e, contour) for e in _wire_edges(wire)]
        except ToolpathError:
            raise
        except Exception as exc:  # OCCT's Standard_* errors measuring an edge it made
            raise ToolpathError(
                f"{_where(contour)}: offset by {amount:+.4g} mm gives an edge OpenCASCADE "
                f"cannot measure ({type(exc).__name__})"
            ) from exc
        joined = chain(
            [Contour((e,), False, contour.layer, contour.source) for e in edges], _JOIN_MM
        )
        if any(not j.closed for j in joined):
            raise ToolpathError(
                f"{_where(contour)}: offset by {amount:+.4g} mm gives pieces that do not close"
            )
        pieces.extend(joined)
    pieces = [p for p in pieces if abs(p.signed_area()) > 1e-12]
    return _oriented(pieces, contour)


Answer: TypeAlias = "list[Contour] | ToolpathError | OffsetResult"
"""An item of :func:`offset_all`: OpenCASCADE's pieces or its error, or with a tolerance
the checked offset (:func:`offset_checked`)."""


def offset_all(
    jobs: Sequence[tuple[Contour, float]],
    *,
    tolerance: float | None = None,
    done: Callable[[int], None] | None = None,
) -> list[Answer]:
    """:func:`offset_pieces` of every ``(contour, amount)``, OpenCASCADE run in a child process.

    OCCT's 2D offset can crash the process (SIGSEGV in ``BRepOffsetAPI_MakeOffset``: Tango's
    ``filequickprint.svg`` grown by 0.5 mm, a valid contour of 22 arcs and 2 lines), which
    no ``except`` can catch. So on Linux the offsets are made in a forked child, one
    after the other, each answer sent back as it is made; when the child dies, the job
    it was making gets a :class:`ToolpathError` naming the signal (its caller falls back
    to shapely's buffer, :func:`offset_checked`) and a new child takes the jobs after it.
    The child gets each contour pickled (every float kept) and runs this module's own
    :func:`offset_pieces`, so its answers are the ones made here, bit for bit. Elsewhere
    the offsets are made in this process.

    OpenCASCADE (about 230 MB and 0.5 s to load) is loaded by the child, so the process of
    a single job (``camtool post``) never holds it: the largest process of ``post
    --preview`` of a profiled part is then ~290 MB where it was ~600 MB. The child can be
    started ahead (:func:`start_ahead`), so that it loads OpenCASCADE while this process
    reads and plans. A process that offsets again (``camtool batch --jobs 1``: one job
    after another) or a worker of a pool loads it here first, from its second call or at
    once, so that each child inherits it instead of loading it again
    (:data:`CHILDREN`).

    Args:
        jobs: ``(contour, amount)`` as :func:`offset_pieces` takes them.
        tolerance: when given, mm: each worker also checks its offset against shapely's
            buffer and makes the fallback where it fails, as :func:`offset_checked` with
            this tolerance would here, and answers that :class:`OffsetResult` (the checks
            then run on the workers' cores too: Inkscape's ``filters.svg``, ~35 s of this
            process's time). Where the check raised, or the worker died, the answer is
            OpenCASCADE's own (pieces or error), for :func:`offset_checked` here to make
            the result (and raise the same error) from.
        done: called in this process with the number of jobs answered so far, as the
            answers come in (for a progress report; it does not change them).

    Returns:
        Per job, in order, the pieces (as :func:`offset_pieces`) or the
        :class:`ToolpathError` it raised; with ``tolerance``, mostly the checked
        :class:`OffsetResult`.
    """
    if not jobs:
        return []
    if not FORK:
        return [_attempt(contour, amount) for contour, amount in jobs]
    CHILDREN.calls += 1
    if CHILDREN.calls > 1 or in_worker():
        _load_occt()
    workers = _workers(jobs)
    out: list[Answer] = []
    while len(out) < len(jobs):
        try:
            child = CHILDREN.take()
        except OSError:  # no fork now (a process limit, memory): made here, as without fork
            out.extend(_attempt(contour, amount) for contour, amount in jobs[len(out) :])
            break
        try:
            got, died = child.make(jobs[len(out) :], workers, tolerance, _after(len(out), done))
        finally:
            child.close()
        out.extend(got)
        if died is not None and len(out) < len(jobs):
            out.append(_crashed(*jobs[len(out)], died))
    return out


def _after(before: int, done: Callable[[int], None] | None) -> Callable[[int], None] | None:
    """``done`` told ``before + n`` for a child's ``n`` answers (``None`` stays ``None``)."""
    if done is None:
        return None
    return lambda n: done(before + n)


PARALLEL_SEGMENTS = 2000
"""Offsets of at least this many segments in all (and at least two contours) are made by
two workers at once where this process may use two cores (:func:`offset_all`): OCCT takes
~0.1–0.5 ms a segment, so below this a second worker would not pay for its fork."""

OCCT_LIMIT_S = (30.0, 0.02)
"""Longest an offset job may take in a worker, s: the first plus the second per segment of
its contour. OpenCASCADE takes ~0.1–1 ms a segment, but on some contours it runs for
minutes and then fails, so a job past its limit is stopped and answered as an OpenCASCADE
failure: shapely's buffer replaces it."""


def occt_limit(contour: Contour) -> float:
    """How long an offset job of ``contour`` may take in a worker, s (:data:`OCCT_LIMIT_S`)."""
    base, per_segment = OCCT_LIMIT_S
    return base + per_segment * len(contour.segments)


def _workers(jobs: Sequence[tuple[Contour, float]]) -> int:
    """How many workers make ``jobs`` at once: 2 for a large job on 2+ cores, else 1.

    A process that is itself a worker (``camtool batch``, Dask) keeps to one: its pool
    already keeps the cores busy.
    """
    if len(jobs) < 2 or in_worker() or default_jobs() < 2:
        return 1
    segments = sum(len(contour.segments) for contour, _ in jobs)
    return 2 if segments >= PARALLEL_SEGMENTS else 1


def _crashed(contour: Contour, amount: float, died: str) -> ToolpathError:
    """The error of a job whose process died making it (``died``: how it ended)."""
    return ToolpathError(
        f"{_where(contour)}: the process making the offset by {amount:+.4g} mm crashed ({died})"
    )


def start_ahead() -> None:
    """Start the child that will make this process's first offsets now (Linux).

    It loads OpenCASCADE while this process goes on reading and planning (on another
    core: ~0.5 s off a profiled part's ``post``), then waits for :func:`offset_all`'s
    jobs. Nothing is started where :func:`offset_all` would not use it: without ``fork``,
    in a worker process, after this process's first offsets, when one is waiting already,
    or when this process holds OpenCASCADE itself (:func:`load_here`). :func:`stop_ahead`
    stops it if no offsets came.
    """
    fresh = CHILDREN.ahead is None and CHILDREN.calls == 0
    if FORK and fresh and not in_worker() and not _occt_here():
        with contextlib.suppress(OSError):  # no fork now: offset_all makes its own, or not
            CHILDREN.ahead = _Child()


def load_here() -> None:
    """Load OpenCASCADE into this process now, for one that makes offsets job after job.

    ``camtool batch --jobs 1`` posts its files one after the other in its own process:
    each job's child then inherits OpenCASCADE (loaded once, not once a job), and no child
    is started ahead (:func:`start_ahead`), whose load a small job would only wait for.
    """
    _load_occt()


def _occt_here() -> bool:
    """Whether this process has loaded OpenCASCADE (:func:`_load_occt`)."""
    return "OCP.BRepOffsetAPI" in sys.modules


def stop_ahead() -> None:
    """Stop the child :func:`start_ahead` started, if :func:`offset_all` did not use it."""
    ahead, CHILDREN.ahead = CHILDREN.ahead, None
    if ahead is not None:
        ahead.close(kill=True)  # no need to wait for OpenCASCADE to load


class _Children:
    """This process's OpenCASCADE children: the offset runs so far, and one started ahead.

    Attributes:
        calls: calls of :func:`offset_all` in this process so far: from the second on
            (or in a worker process, :func:`~camtool.accel.cores.in_worker`),
            OpenCASCADE is loaded here before the child is forked. A count, not a
            setting: only the time and memory depend on it.
        ahead: the child :func:`start_ahead` started, until :func:`offset_all` takes it.
    """

    def __init__(self) -> None:
        self.calls = 0
        self.ahead: _Child | None = None

    def take(self) -> _Child:
        """The child started ahead, else a new one.

        Raises:
            OSError: no fork now (a process limit, memory).
        """
        child, self.ahead = self.ahead, None
        return child if child is not None else _Child()


CHILDREN = _Children()
"""The OpenCASCADE children of this process (one process, one set)."""


def _attempt(contour: Contour, amount: float) -> list[Contour] | ToolpathError:
    try:
        return offset_pieces(contour, amount)
    except ToolpathError as exc:
        return exc


def _answer(contour: Contour, amount: float, tolerance: float | None) -> Answer:
    """In a worker: OpenCASCADE's answer, checked with ``tolerance`` unless ``None``.

    OpenCASCADE's own answer where the check raised, so that the job's process checks
    it again and raises the error there, at its place.
    """
    occt = _attempt(contour, amount)
    if tolerance is None:
        return occt
    try:
        return offset_checked(contour, amount, tolerance, occt=occt)
    except Exception:
        return occt


def _load_occt() -> None:
    """Import the OCP modules the offsets use (once per process)."""
    import OCP.BRepBuilderAPI
    import OCP.BRepOffsetAPI
    import OCP.BRepTools  # noqa: F401


class _Child:
    """A forked child that loads OpenCASCADE and has the offsets sent to it made.

    It reads one pickled ``(workers, tolerance, jobs)`` (:meth:`make`), and :func:`_serve`
    answers each job in order as it is made (a pickled ``("ok", pieces)``, ``("error", message)`` or
    ``("died", how)``) and leaves, without running any of this process's code; one started
    ahead and never used is killed (:meth:`close`). The offsets themselves are made by
    workers it forks (:class:`_Worker`): a crash of OpenCASCADE takes down a worker, whose
    job is answered ``"died"``, and a new worker, forked from this child (OpenCASCADE and
    the jobs already loaded: a few ms), makes the jobs after it. Before, each crash cost a
    new child forked from the job's own process, loading OpenCASCADE again (~0.5 s) and
    sent every job left: Inkscape's ``filters.svg`` fitted to 299 × 199 mm and grown by
    1 mm crashed OCCT on 438 of its 1 752 contours, and ran for over 25 minutes.
    """

    def __init__(self) -> None:
        """Fork it.

        Raises:
            OSError: it cannot be forked now (:func:`~camtool.accel.cores.fork_with_pipes`).
        """

        def child(jobs: int, answers: int) -> None:
            quiet_crashes()
            _load_occt()
            with os.fdopen(jobs, "rb") as inbox, os.fdopen(answers, "wb") as out:
                _serve(inbox, out)

        pid, jobs, answers = fork_with_pipes(child)
        self.pid: int | None = pid
        self.jobs = os.fdopen(jobs, "wb")
        self.answers = os.fdopen(answers, "rb")

    def make(
        self,
        jobs: Sequence[tuple[Contour, float]],
        workers: int = 1,
        tolerance: float | None = None,
        done: Callable[[int], None] | None = None,
    ) -> tuple[list[Answer], str | None]:
        """The answers the child sends for ``jobs``, and how it died (``None``: it did not).

        ``workers``: how many of its workers make the jobs at once (:func:`_serve`);
        ``tolerance``: as for :func:`offset_all`; ``done``: told the number of answers so
        far, after each.
        """
        got: list[Answer] = []
        try:
            task = (workers, tolerance, list(jobs))
            pickle.dump(task, self.jobs, protocol=pickle.HIGHEST_PROTOCOL)
            self.jobs.flush()
        except OSError:  # it died before it read them
            return got, self._death()
        wait_readable(self.answers.fileno())  # what the job needs next is loaded meanwhile
        while len(got) < len(jobs):
            try:
                kind, value = pickle.load(self.answers)
            except Exception:  # the end of the pipe, or a record cut off by a crash
                return got, self._death()
            if kind == "died":
                got.append(_crashed(*jobs[len(got)], value))
            elif kind == "late":
                contour, amount = jobs[len(got)]
                got.append(
                    ToolpathError(
                        f"{_where(contour)}: offset by {amount:+.4g} mm stopped: OpenCASCADE "
                        f"did not finish it within {value:.0f} s"
                    )
                )
            else:
                got.append(ToolpathError(value) if kind == "error" else value)
            if done is not None:
                done(len(got))
        return got, None

    def close(self, *, kill: bool = False) -> None:
        """Close its pipes (it leaves; ``kill``: at once) and wait for it (idempotent)."""
        for pipe in (self.jobs, self.answers):
            with contextlib.suppress(OSError):
                pipe.close()
        if self.pid is not None:
            end_process(self.pid, kill=kill)
            self.pid = None

    def _death(self) -> str:
        """How the child ended (after it stopped answering): a signal or an exit code."""
        assert self.pid is not None
        with contextlib.suppress(OSError):
            self.jobs.close()  # a child still waiting for jobs leaves
        status = end_process(self.pid)
        self.pid = None
        return how_ended(status)


def _serve(inbox: Any, out: Any) -> None:
    """In the child: answer the jobs read from ``inbox`` (none if it closes first), in order.

    The jobs come as ``(workers, tolerance, jobs)``. That many :class:`_Worker` make them,
    one job at a time each, the next job going to the first worker free. Each answer is
    sent on ``out`` as soon as every job before it is answered; a job whose worker died is
    answered ``("died", how)``, one past its :func:`occt_limit` is killed and answered
    ``("late", limit_s)``, and a new worker takes the place of either. The answers are
    those of :func:`_answer` in this process, whichever worker made them.
    """
    try:
        workers, tolerance, jobs = pickle.load(inbox)
    except EOFError:  # this process ended before it sent any
        return
    if tolerance is not None:
        import shapely  # noqa: F401  (once here, not once a worker: the checks use it)
    closing = (inbox.fileno(), out.fileno())
    done: dict[int, bytes] = {}  # answers made but not sent yet, by job
    sent = given = 0
    busy: dict[int, _Worker] = {}  # by the fd its answers come on
    try:
        while sent < len(jobs):
            while len(busy) < workers and given < len(jobs):
                # the new worker closes the others' pipes: a worker holding another's
                # pipe of indices open would keep that one from seeing its end
                others = [fd for w in busy.values() for fd in (w.given, w.answers)]
                worker = _Worker(jobs, tolerance, (*closing, *others))
                busy[worker.answers] = worker
                worker.give(given)
                given += 1
            now = time.monotonic()
            wait = max(0.0, min(w.deadline for w in busy.values()) - now)
            ready = select.select(list(busy), [], [], wait)[0]
            now = time.monotonic()
            for fd in [fd for fd, w in busy.items() if fd not in ready and w.deadline <= now]:
                worker = busy.pop(fd)  # past its limit: stopped, and a new one takes its place
                worker.close(kill=True)
                done[worker.job] = pickle.dumps(("late", occt_limit(jobs[worker.job][0])))
            for fd in ready:
                worker = busy[fd]
                answer = worker.answer()
                if answer is None:  # it died making its job
                    del busy[fd]
                    done[worker.job] = pickle.dumps(("died", worker.close()))
                    continue
                done[worker.job] = answer
                if given < len(jobs):
                    worker.give(given)
                    given += 1
                else:
                    del busy[fd]
                    worker.close()
            while sent in done:
                out.write(done.pop(sent))
                sent += 1
            out.flush()
    finally:
        for worker in busy.values():
            worker.close(kill=True)


class _Worker:
    """In the child: a process forked from it that makes the jobs it is given, one at a time.

    It is given a job's index (:meth:`give`), makes it with :func:`_answer` and sends back
    the pickled answer (:meth:`answer`), framed by its length; it leaves when its pipe of
    indices closes (:meth:`close`). A crash of OpenCASCADE ends it, and only it.
    """

    def __init__(
        self,
        jobs: Sequence[tuple[Contour, float]],
        tolerance: float | None,
        closing: Sequence[int],
    ) -> None:
        """Fork it; ``closing``: the fds it must not hold (the child's own, other workers')."""
        pid, given, answers = fork_with_pipes(
            lambda inbox, out: _work(jobs, tolerance, inbox, out), closing=closing
        )
        self.pid: int | None = pid
        self.given = given
        self.answers = answers
        self.jobs = jobs
        self.job = -1
        self.deadline = math.inf

    def give(self, job: int) -> None:
        """Have it make job number ``job``, by :attr:`deadline` (:func:`occt_limit` from now).

        A dead worker's pipe is found by :meth:`answer`.
        """
        self.job = job
        self.deadline = time.monotonic() + occt_limit(self.jobs[job][0])
        with contextlib.suppress(OSError):
            os.write(self.given, job.to_bytes(8, "little"))

    def answer(self) -> bytes | None:
        """The pickled answer to its job (waits for it); ``None`` when it died first."""
        return read_record(self.answers)

    def close(self, *, kill: bool = False) -> str:
        """End it (``kill``: at once) and wait for it; how it ended.

        As :func:`camtool.accel.cores.how_ended` says it.
        """
        for fd in (self.given, self.answers):
            with contextlib.suppress(OSError):
                os.close(fd)
        if self.pid is None:
            return "exit code 0"
        status = end_process(self.pid, kill=kill)
        self.pid = None
        return how_ended(status)


def _work(
    jobs: Sequence[tuple[Contour, float]], tolerance: float | None, given: int, answers: int
) -> None:
    """In a worker: make each job whose index comes on ``given``, answer it on ``answers``."""
    while (head := read_exactly(given, 8)) is not None:
        got = _answer(*jobs[int.from_bytes(head, "little")], tolerance)
        record = ("error", str(got)) if isinstance(got, ToolpathError) else ("ok", got)
        write_record(answers, pickle.dumps(record, protocol=pickle.HIGHEST_PROTOCOL))


def offset_checked(
    contour: Contour,
    amount: float,
    tolerance: float,
    *,
    occt: list[Contour] | ToolpathError | None = None,
) -> OffsetResult:
    """Offset with OpenCASCADE, checked against shapely; fall back to the buffer.

    OCCT's pieces are used when they close, hold only lines and arcs, change
    the area the way ``amount`` asks (grow: larger, shrink: smaller) and lie
    within ``10·tolerance + 1e-3`` mm (Hausdorff distance) of shapely's buffer
    of the contour's polygon. Otherwise :func:`buffer_pieces` replaces them and
    :attr:`OffsetResult.fallback` says why. Both agree that nothing is left when
    the buffer is empty or nowhere wider than ``tolerance``.

    Args:
        contour: a closed contour, mm.
        amount: offset distance, mm; positive grows the enclosed area.
        tolerance: chord and fitting tolerance, mm (> 0).
        occt: OpenCASCADE's answer for this contour and amount when it was made
            already (an item of :func:`offset_all`); ``None`` makes it here.

    Raises:
        ToolpathError: the contour is open.
    """
    if not contour.closed:
        raise ToolpathError(f"{_where(contour)}: only closed contours can be offset")
    if amount == 0:
        return OffsetResult((contour,))
    reference = _buffer(contour, amount, tolerance)
    try:
        if isinstance(occt, ToolpathError):
            raise occt
        pieces = offset_pieces(contour, amount) if occt is None else occt
        reason = _disagreement(pieces, contour, amount, reference, tolerance)
    except ToolpathError as exc:  # OCCT failed or gave curves other than lines and arcs
        reason = str(exc).split(": ", 1)[-1]
    if reason is None:
        return OffsetResult(tuple(pieces))
    return OffsetResult(tuple(_fitted(reference, contour, tolerance)), reason)


def buffer_pieces(contour: Contour, amount: float, tolerance: float) -> list[Contour]:
    """Offset by shapely's buffer, each ring fitted with lines and arcs.

    The contour's polygon (chords within ``tolerance/4``) is buffered with
    enough segments per quarter circle that the buffer's chords stay within
    ``tolerance/4`` of its round joins, and each ring is fitted with
    :func:`~camtool.geometry.arcfit.fit_polyline` within ``tolerance/2``: the
    result lies within ``tolerance`` of the exact offset. Regions nowhere wider
    than ``tolerance`` are dropped.

    Args:
        contour: a closed contour, mm.
        amount: offset distance, mm; positive grows the enclosed area.
        tolerance: largest distance from the exact offset, mm (> 0).

    Returns:
        The closed pieces, oriented as :func:`offset_pieces` orients them.
    """
    return _fitted(_buffer(contour, amount, tolerance), contour, tolerance)


def quad_segs(radius: float, chord_error: float) -> int:
    """Segments per quarter circle so a buffer's chords stay within ``chord_error`` mm.

    A chord spanning angle θ of a circle of ``radius`` deviates from it by the
    sagitta ``r·(1 − cos(θ/2))``; a quarter circle in ``q`` chords has
    ``θ = π/(2q)``. At least 8 (shapely's default), at most 4096.
    """
    if chord_error >= radius:
        return 8
    half = math.acos(1.0 - chord_error / radius)
    if half <= 0.0:  # chord_error / radius below float resolution: as fine as allowed
        return _MAX_QUAD_SEGS
    return max(8, min(_MAX_QUAD_SEGS, math.ceil(math.pi / (4.0 * half))))


def _buffer(contour: Contour, amount: float, tolerance: float) -> BaseGeometry:
    """The shapely buffer of the contour's polygon, slivers narrower than ``tolerance`` dropped."""
    from shapely import MultiPolygon

    poly = enclosed(contour.points(tolerance / 4))
    buf = poly.buffer(amount, quad_segs=quad_segs(abs(amount), tolerance / 4))
    parts = [p for p in getattr(buf, "geoms", [buf]) if _wider_than(p, tolerance)]
    return MultiPolygon(parts)


def _wider_than(poly: Any, width: float) -> bool:
    """True when the polygon's mean width (2·area / perimeter) exceeds ``width`` mm."""
    return bool(not poly.is_empty and 2.0 * poly.area > width * poly.length)


def _disagreement(
    pieces: list[Contour], contour: Contour, amount: float, reference: Any, tolerance: float
) -> str | None:
    """Why OCCT's pieces disagree with the buffer ``reference``, or ``None``."""
    from shapely import MultiLineString

    if not pieces:
        return None if reference.is_empty else "it left nothing where shapely's buffer did not"
    if reference.is_empty:
        return "it left pieces where shapely's buffer left nothing"
    area = _region_area(pieces)
    original = abs(contour.signed_area())
    if (amount > 0) != (area > original):
        return f"the area went from {original:.4g} to {area:.4g} mm² for {amount:+.4g} mm"
    rings = MultiLineString([p.points(tolerance / 4) for p in pieces])
    gap = rings.hausdorff_distance(reference.boundary)
    if gap > 10 * tolerance + 1e-3:
        return f"it lies up to {gap:.4g} mm from shapely's buffer"
    return None


def _region_area(pieces: list[Contour]) -> float:
    """Area enclosed by oriented pieces (holes run against the outer rings), mm²."""
    if not pieces:
        return 0.0
    outer = max(pieces, key=lambda p: abs(p.signed_area()))
    sign = 1.0 if outer.signed_area() > 0 else -1.0
    return sign * sum(p.signed_area() for p in pieces)


def _fitted(region: Any, contour: Contour, tolerance: float) -> list[Contour]:
    """Each ring of a (multi)polygon fitted with lines and arcs within ``tolerance/2``."""
    from camtool.geometry.arcfit import fit_polyline

    pieces: list[Contour] = []
    for poly in getattr(region, "geoms", [region]):
        for ring in (poly.exterior, *poly.interiors):
            segs = fit_polyline(list(ring.coords), tolerance / 2, closed=True)
            pieces.append(Contour(tuple(segs), True, contour.layer, contour.source))
    return _oriented(pieces, contour)


def _oriented(pieces: list[Contour], contour: Contour) -> list[Contour]:
    """Orient pieces like ``contour`` (holes of the region the other way); start near it."""
    from shapely import Point as ShapelyPoint
    from shapely import Polygon

    ccw = contour.signed_area() > 0
    polys = [Polygon(p.points(1e-3)) for p in pieces]
    out: list[Contour] = []
    for k, piece in enumerate(pieces):
        probe = ShapelyPoint(piece.start)
        depth = sum(1 for j, poly in enumerate(polys) if j != k and poly.contains(probe))
        want_ccw = ccw == (depth % 2 == 0)
        turned = piece if (piece.signed_area() > 0) == want_ccw else piece.reversed()
        out.append(_start_near(turned, contour.start))
    return out


def _occt_offset(contour: Contour, amount: float) -> list[Any]:
    """OCCT's offset wires (``TopoDS_Wire``); several when the region splits.

    OCP (OpenCASCADE's bindings) directly: the same calls build123d makes for its
    ``Wire``/``Edge`` (build123d 0.13, ``topology/one_d.py``), without importing it.
    """
    from OCP.BRepOffsetAPI import BRepOffsetAPI_MakeOffset
    from OCP.GeomAbs import GeomAbs_JoinType
    from OCP.TopAbs import TopAbs_WIRE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    builder = BRepOffsetAPI_MakeOffset()
    builder.Init(GeomAbs_JoinType.GeomAbs_Arc)
    builder.AddWire(_to_wire(contour))
    builder.Perform(amount)
    if not builder.IsDone():
        raise ToolpathError(f"OpenCASCADE's 2D offset by {amount:+.4g} mm did not finish")
    wires = []
    explorer = TopExp_Explorer(builder.Shape(), TopAbs_WIRE)
    while explorer.More():
        wires.append(TopoDS.Wire(explorer.Current()))
        explorer.Next()
    return wires


def _start_near(contour: Contour, p: Point) -> Contour:
    """Rotate a closed contour so it starts at the segment start nearest ``p``."""
    segs = contour.segments
    if len(segs) == 1:
        return contour
    k = min(range(len(segs)), key=lambda i: (distance(segs[i].start, p), i))
    rotated = segs[k:] + segs[:k]
    return Contour(rotated, True, contour.layer, contour.source)
