"""A trace simulated and measured a chunk of rows at a time, and a whole trace's measures.

A big trace is never held whole: :func:`simulate_big` simulates it in chunks of whole
moves and measures each as it comes, one chunk simulated ahead in a thread.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator, Sequence
from typing import TYPE_CHECKING, Any

import numpy as np

from camtool.accel.collector import release_free
from camtool.accel.cores import (
    ahead,
)
from camtool.model.machine import Machine
from camtool.model.program import Program, Rapid
from camtool.model.progress import Progress, Step, no_progress
from camtool.model.shapes import Drawing
from camtool.verify import trace_sources
from camtool.verify.chunked import (
    ChunkedSimulation,
    NotStreamable,
    StreamedTrace,
    TraceChunk,
    count_rows,
    simulate_or_count,
)
from camtool.verify.contour_measures import ContourMeasure, measure_contours
from camtool.verify.cutting_thin import (
    AGAINST_RESOLUTION_MM,
    CuttingStream,
    ThinTrace,
    thin_cutting,
)
from camtool.verify.dda import compiled
from camtool.verify.deviations import Deviation, deviation
from camtool.verify.drawing_compare import (
    Against,
    against_thinned,
)
from camtool.verify.motion import StepTrace, library
from camtool.verify.not_cut import CHAIN_JOIN_MM, FindingLike
from camtool.verify.path_shortfall import AlongPath, along_path
from camtool.verify.sources import ALL, Sources
from camtool.verify.steparray import read_only
from camtool.verify.trace_measures import TraceStream

if TYPE_CHECKING:
    pass

STREAM_ROWS = 1 << 20
"""Rows above which a trace is streamed (:func:`simulate_big`): a whole trace's arrays
and measures take ~100 bytes a row; the error budget's re-simulations are streamed
above :data:`CHUNK_ROWS` rows (:func:`without_source`)."""
CHUNK_ROWS = 1 << 16
"""Rows a streamed trace is simulated and measured at a time (a move is never split):
with their temporaries about 130 bytes a row, ~9 MB next to Python, numpy, scipy,
shapely and the loaded numba kernels (~160 MB)."""


Streamed = tuple[Deviation, AlongPath, tuple[ContourMeasure, ...], ThinTrace | None, bytes | None]
"""A streamed trace's measures, thinned cutting rows and their digest (:func:`stream_trace`)."""


def simulate_big(
    program: Program,
    machine: Machine,
    against: Drawing | None,
    chunk_rows: int,
    stream_above: int,
    *,
    streaming: Callable[[int], None] | None = None,
    progress: Progress = no_progress,
) -> tuple[StepTrace, Streamed | None]:
    """The trace of ``program``, and its measures when they were taken as it streamed.

    A trace of at most ``stream_above`` rows or one from a target's own simulator is
    simulated whole (:func:`simulate`) and measured by :func:`_measure` (then ``None``).
    A longer one of the step simulator is simulated again in chunks of ``chunk_rows``
    rows (:class:`camtool.verify.chunked.ChunkedSimulation`) and measured chunk by
    chunk (:class:`camtool.verify.trace_measures.TraceStream`: the same figures, the
    deviation's rms summed exactly); the trace returned (:class:`StreamedTrace`) then
    holds only the rows kept for the picture. With a drawing (``against``), the cutting
    rows the comparison keeps are gathered as the chunks pass
    (:class:`~camtool.verify.cutting_thin.CuttingStream`, the last item; ``None`` without a
    drawing): the comparison needs only those, so the trace is not held whole for it
    (13 M rows of a 213-icon SVG job took 1.65 GB), and their digest
    (:class:`~camtool.verify.cutting_thin.CutDigest`, the last item). Without the compiled
    kernels it is simulated whole.

    The measures need every move's row offsets first: a trace sure to be streamed has
    them counted (:func:`~camtool.verify.simulate.count_rows`, a DDA line in closed
    form), others from a simulation that drops its rows. The chunks, made one ahead in a
    thread (:func:`~camtool.accel.cores.ahead`), say where each move's rows start; should
    they not agree with the count, the offsets are simulated and the trace streamed again.
    ``streaming`` is told the rows of a trace about to be streamed, before it is (each
    time it is); ``progress``, the rows measured as it streams (a ``simulating`` step).
    """
    if library(machine).simulator(machine.motion.line) is not None:
        return trace_sources.simulate(program, machine), None
    counted = rows_at_least(program, machine) > stream_above
    if counted:  # it will be streamed: its rows are counted, and with the kernels
        compiled()
        got: StepTrace | np.ndarray = count_rows(program, machine)
    else:
        got = simulate_or_count(program, machine, stream_above)
    if isinstance(got, StepTrace):
        return got, None
    kernels = compiled()
    if kernels is None:
        return trace_sources.simulate(program, machine), None
    try:
        if streaming is not None:
            streaming(int(got[-1]))
        streamed = stream_trace(
            program, machine, against, chunk_rows, got, kernels, progress=progress
        )
        release_free()  # the simulation's and the measures' freed pages
        if streamed is None and counted:  # the count was not the rows': count them again
            got = simulate_or_count(program, machine, stream_above)
            if isinstance(got, StepTrace):  # not over the limit after all: the whole trace
                return got, None
            if streaming is not None:
                streaming(int(got[-1]))
            streamed = stream_trace(
                program, machine, against, chunk_rows, got, kernels, progress=progress
            )
    except NotStreamable:
        return trace_sources.simulate(program, machine), None
    if streamed is None:
        raise RuntimeError(
            "the chunked simulation did not repeat the first one"
        )  # pragma: no cover
    return streamed


RELEASE_EVERY = 256
"""Chunks a streamed trace measures between two :func:`~camtool.accel.collector.release_free`."""


def stream_trace(
    program: Program,
    machine: Machine,
    against: Drawing | None,
    chunk_rows: int,
    block_start: np.ndarray,
    kernels: Any,
    *,
    sources: Sources = ALL,
    rms: bool = True,
    progress: Progress = no_progress,
) -> tuple[StepTrace, Streamed] | None:
    """:func:`simulate_big`'s streamed trace and measures, its moves at ``block_start``.

    ``None`` when the chunked simulation's rows do not start where ``block_start`` says
    (the measures, which were told those offsets, are then not the trace's).
    ``sources``: the error sources simulated (the error budget's re-simulations);
    ``rms=False``: the deviation's rms is not measured (NaN; the budget has no use for it).
    ``progress`` is told the rows measured after each chunk (a ``simulating`` step).

    Raises:
        NotStreamable: the rows are not whole steps.
    """
    sim = ChunkedSimulation(program, machine, chunk_rows, sources=sources)
    summary = sim.trace_summary()
    stream = TraceStream(program, block_start, summary["start_mm"], kernels, rms=rms)
    cutting = None if against is None else cutting_stream(program, block_start)
    share = Share()
    total, done = int(block_start[-1]), 0
    progress(Step("simulating", 0, total))

    def made() -> Iterator[tuple[TraceChunk, Any]]:  # in the thread ahead
        clock = time.perf_counter()
        for chunk in sim.chunks():
            rows = max(1, len(chunk.rows))
            now = time.perf_counter()
            share.made(now - clock, rows)
            pre = None
            if share.take():
                pre = stream.distances(chunk.first_block, chunk.block_start, chunk.carriage_mm)
                share.measured_distances(time.perf_counter() - now, rows)
            yield chunk, pre
            clock = time.perf_counter()

    for k, (chunk, pre) in enumerate(ahead(made())):  # the next simulated meanwhile
        if k % RELEASE_EVERY == RELEASE_EVERY - 1:
            release_free()  # the chunks' freed pages, scattered, back to the system
        start = time.perf_counter()
        rows = max(1, len(chunk.rows))
        if not np.array_equal(
            chunk.block_start,
            block_start[chunk.first_block : chunk.first_block + len(chunk.block_start)],
        ):
            return None
        if pre is None:
            pre = stream.distances(chunk.first_block, chunk.block_start, chunk.carriage_mm)
            share.measured_distances(time.perf_counter() - start, rows)
        measuring = time.perf_counter()
        stream.add(
            chunk.first_block,
            chunk.block_start,
            chunk.carriage_mm,
            chunk.rows,
            chunk.compensation,
            pre,
        )
        if cutting is not None:
            cutting.add(chunk.carriage_mm, pre[0])  # the rows' moves, made with the distances
        share.measured(time.perf_counter() - measuring, rows)
        done += len(chunk.rows)
        progress(Step("simulating", min(done, total), total))
    summary = sim.trace_summary()
    if not np.array_equal(summary["block_start"], block_start):
        return None
    m = stream.finish()
    trace = StreamedTrace(
        rows=read_only(m.picture_steps),
        compensation=read_only(m.picture_compensation),
        block_of_row=read_only(m.picture_blocks),
        carriage_mm=read_only(m.picture_mm),
        **summary,
        total_rows=int(block_start[-1]),
        total_compensation_steps=m.compensation_steps,
    )
    if cutting is None:
        return trace, (m.deviation, m.along, m.contours, None, None)
    return trace, (m.deviation, m.along, m.contours, cutting.finish(), cutting.digest.digest())


class Share:
    """Which chunks' deviation distances the thread ahead takes (:func:`stream_trace`).

    The simulating thread (:func:`~camtool.accel.cores.ahead`) and the measuring one run
    on two cores; the slower sets the pace. On a program of long lines measuring is the
    slower (the distances alone, ``to_line``, take about as long as simulating), so the
    thread ahead also takes the distances (:meth:`TraceStream.distances`) of a share
    ``f`` of the chunks, chosen so that both take as long a row: with ``m`` its time a
    row, ``c`` the measuring thread's without the distances and ``d`` the distances',
    ``m + f·d = c + (1 − f)·d``, ``f = (c + d − m) / 2d`` in [0, 1]. The times are
    means over the last chunks (each written by one thread; a float's assignment is
    whole under the GIL). Only the wall time depends on it: the distances are the same
    whichever thread takes them.
    """

    MEAN = 0.25
    """Weight of the newest chunk in the means."""

    def __init__(self) -> None:
        self.make = self.measure = self.dist = 0.0  # seconds a row
        self.credit = 0.0

    def _mean(self, old: float, seconds: float, rows: int) -> float:
        rate = seconds / rows
        return rate if old == 0.0 else old + self.MEAN * (rate - old)

    def made(self, seconds: float, rows: int) -> None:
        """The thread ahead took ``seconds`` to simulate a chunk of ``rows`` rows."""
        self.make = self._mean(self.make, seconds, rows)

    def measured(self, seconds: float, rows: int) -> None:
        """The measuring thread took ``seconds`` for a chunk, its distances left out."""
        self.measure = self._mean(self.measure, seconds, rows)

    def measured_distances(self, seconds: float, rows: int) -> None:
        """One thread took ``seconds`` for a chunk's distances."""
        self.dist = self._mean(self.dist, seconds, rows)

    def take(self) -> bool:
        """Whether the thread ahead takes this chunk's distances."""
        if self.dist == 0.0 or self.measure == 0.0:
            return False  # nothing measured yet
        share = (self.measure + self.dist - self.make) / (2.0 * self.dist)
        self.credit += min(max(share, 0.0), 1.0)
        if self.credit < 1.0:
            return False
        self.credit -= 1.0
        return True


def cutting_stream(program: Program, block_start: np.ndarray) -> CuttingStream:
    """A :class:`CuttingStream` for the trace of ``program`` whose moves start at ``block_start``.

    The cutting rows are those of the moves that are not rapids (as :func:`cutting_rows`).
    """
    return CuttingStream(
        rapid_mask(program), cutting_count(program, block_start), AGAINST_RESOLUTION_MM
    )


def rows_at_least(program: Program, machine: Machine) -> int:
    """A lower bound of the rows of ``program``'s step trace (to load the kernels early).

    A row moves each motor at most one step, so a move takes at least as many rows as
    its larger axis has steps (less one for the rounding of its ends). Rapids count
    too. Only the speed depends on it: the kernels give the same rows as numpy.
    """
    sx, sy = float(machine.steps_per_mm[0]), float(machine.steps_per_mm[1])
    x, y = program.origin
    total = 0
    for move in program.moves:
        total += max(0, int(max(abs(move.x - x) * sx, abs(move.y - y) * sy)) - 1)
        x, y = move.x, move.y
    return total


def measure_trace(
    program: Program, trace: StepTrace, *, cutting: bool
) -> tuple[Deviation, AlongPath, tuple[ContourMeasure, ...], ThinTrace | None]:
    """The measures of ``trace`` itself, and its thinned cutting rows when ``cutting``.

    The drawing comparison (:func:`compare_drawing`) needs only the thinned rows, so a caller
    that is done with the trace can let it go before comparing.
    """
    points, blocks = trace.carriage_mm, trace.block_of_row
    dev = deviation(points, blocks, program)
    along = along_path(points, trace.block_start, trace.start_mm, program)
    contours = tuple(measure_contours(points, trace.block_start, trace.start_mm, program))
    thin = thin_cutting(*cutting_rows(program, trace)) if cutting else None
    return dev, along, contours, thin


def compare_drawing(
    program: Program,
    thin: ThinTrace,
    against: Drawing,
    tool_diameter: float,
    findings: Sequence[FindingLike],
    joint_mm: float = CHAIN_JOIN_MM,
) -> Against:
    """The machined edge of ``program``'s thinned cutting trace against the drawing.

    The one call of :func:`~camtool.verify.drawing_compare.against_thinned` of a verification,
    for a whole trace and a streamed one (:func:`verify_program`); the error budget's
    sources need only its largest distance (:func:`without_source`).
    """
    return against_thinned(
        thin,
        against,
        tool_diameter / 2.0,
        nominal=trace_sources._nominal_lines(program) if findings else (),
        findings=findings,
        joint_mm=joint_mm,
    )


def rapid_mask(program: Program) -> np.ndarray:
    """``(B,)`` bool: which moves of ``program`` are rapids (their rows do not cut)."""
    return np.asarray([isinstance(m, Rapid) for m in program.moves], dtype=bool)


def cutting_count(program: Program, block_start: np.ndarray) -> int:
    """Rows of the moves of ``program`` that are not rapids (their rows start at ``block_start``).

    For a whole trace, the length of :func:`cutting_rows`' answer.
    """
    rapid = rapid_mask(program)
    return int(np.diff(block_start)[~rapid].sum()) if len(rapid) else 0


def cutting_rows(program: Program, trace: StepTrace) -> tuple[np.ndarray, np.ndarray]:
    """The trace's cutting rows ``(N, 2)`` mm and the id of each one's run between rapids."""
    points, blocks = trace.carriage_mm, trace.block_of_row
    rapid = rapid_mask(program)
    cutting = ~rapid[blocks] if len(blocks) else np.zeros(0, dtype=bool)
    runs = np.cumsum(~cutting)[cutting]  # a new id after every rapid row
    return points[cutting], runs
