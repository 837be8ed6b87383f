"""The verifier: emitted code → program → simulated machine → measured error → report.

Design notes: docs/internals.md, ``camtool/verify/verifier.py``.
"""

from __future__ import annotations

import os
import pickle
import signal
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import ExitStack, suppress
from dataclasses import dataclass, field
from functools import cached_property, partial
from typing import TYPE_CHECKING, Any, Generic, TypeVar

import numpy as np

from camtool.accel.cores import (
    FORK,
    ForkedWork,
    ahead,
    default_jobs,
    end_process,
    fork_with_pipes,
    in_worker,
    quiet_crashes,
    read_record,
    wait_readable,
    write_record,
)
from camtool.model.errors import CamtoolError, InputError, UsageError
from camtool.model.machine import Machine
from camtool.model.program import Dwell, Program, Rapid
from camtool.model.progress import Progress, Step, no_progress
from camtool.model.shapes import Drawing
from camtool.model.units import fmt_num
from camtool.verify import budget as eb
from camtool.verify import report, trace_sources
from camtool.verify.clock import timing_warnings
from camtool.verify.contour_measures import ContourMeasure, measure_contours
from camtool.verify.cutting_thin import (
    AGAINST_RESOLUTION_MM,
    CutDigest,
    CuttingStream,
    ThinTrace,
    thin_cutting,
)
from camtool.verify.dda import compiled
from camtool.verify.deviations import Deviation, deviation
from camtool.verify.drawing_compare import (
    Against,
    FindingLike,
    against_thinned,
    against_worst,
    prepare_comparison,
    prepare_stream,
)
from camtool.verify.motion import StepTrace, library
from camtool.verify.path_shortfall import AlongPath, along_path
from camtool.verify.simulate import (
    ChunkedSimulation,
    NotStreamable,
    StreamedTrace,
    TraceChunk,
    count_rows,
    simulate_or_count,
)
from camtool.verify.sources import ALL, SOURCES, Sources
from camtool.verify.steparray import read_only
from camtool.verify.trace_measures import TraceStream

if TYPE_CHECKING:
    from camtool.post.base import Target

T = TypeVar("T")
R = TypeVar("R")

STREAM_ROWS = 1 << 20
"""Rows above which a trace is streamed (:func:`_simulate_big`): a whole trace's arrays
and measures take ~100 bytes a row; the error budget's re-simulations are streamed
above :data:`CHUNK_ROWS` rows (:func:`_without`)."""
CHUNK_ROWS = 1 << 16
"""Rows a streamed trace is simulated and measured at a time (a move is never split):
with their temporaries about 130 bytes a row, ~9 MB next to Python, numpy, scipy,
shapely and the loaded numba kernels (~160 MB)."""


@dataclass(frozen=True, eq=False)
class Part:
    """A part of a program verified alone: a job's operation, against its own drawing.

    Attributes:
        label: how the report names it (``"operation 2 (pocket 'floor') T1"``).
        moves: ``(first, end)``: the program's moves it holds.
        verification: the part written, read back and simulated alone, and compared
            with the drawing it cuts with its own tool.
    """

    label: str
    moves: tuple[int, int]
    verification: Verification


@dataclass(frozen=True, eq=False)
class Verification:
    """Everything one verification produced.

    Attributes:
        target: target name (or the machine's name for a bare profile).
        program: the program that was simulated (read back from the code).
        machine: the machine profile used.
        trace: the step-level simulation.
        deviation: trace vs the nominal path.
        contours: closure, size and circle measures per cut contour.
        against: trace swept by the tool vs the drawing, when one was given.
        block_time_s: ``(B,)`` float64 estimated time of each move, s.
        warnings: what a machinist should know before cutting.
        against_skipped: why a drawing that was given was not compared (the
            program and the drawing do not overlap), else ``None``; then
            ``against`` is ``None`` and no limit can be judged against it.
        along: the programmed path seen from the trace (the shortfall, the
            error at every move's end), ``None`` for a verification built by hand.
        planned: the unrounded plan the code was written from, when at hand
            (the ``rounding`` source of the error budget), else ``None``.
        budget: whether :attr:`error_budget` re-simulates (``False``: ``--no-budget``).
        drawing: the drawing given to compare with (the budget measures it again).
        tool_diameter: the tool diameter the drawing was compared with, mm.
        findings: the plan's findings the drawing was compared with.
        parts: the program's parts verified each alone (a job's operations, each with
            its tool against its own drawing); their errors count in the limits.
        cut_digest: the :class:`~camtool.verify.cutting_thin.CutDigest` of the trace's cutting
            rows when a streamed trace was compared with a drawing (the error budget tells
            by it which re-simulations cut the same rows), else ``None``.
    """

    target: str
    program: Program
    machine: Machine
    trace: StepTrace
    deviation: Deviation
    contours: tuple[ContourMeasure, ...]
    against: Against | None
    block_time_s: np.ndarray
    warnings: tuple[str, ...] = field(default=())
    against_skipped: str | None = None
    along: AlongPath | None = None
    planned: Program | None = None
    budget: bool = True
    drawing: Drawing | None = None
    tool_diameter: float = 0.0
    findings: Sequence[FindingLike] = ()
    parts: tuple[Part, ...] = ()
    cut_digest: bytes | None = None

    @cached_property
    def error_budget(self) -> eb.ErrorBudget:
        """The error budget by source (:mod:`camtool.verify.budget`), computed on first use.

        Re-simulates the program once per modelled source, the sources shared out among
        forked workers (:class:`camtool.accel.cores.ForkedWork`: the same figures as one
        after the other); skipped (with the reason) when :attr:`budget` is off or the
        trace is over :data:`camtool.verify.budget.MAX_ROWS` rows.

        Raises:
            CamtoolError: a re-simulation fails (the full model did not).
        """
        return _budget(self)

    def measure_budget(self, progress: Progress = no_progress) -> eb.ErrorBudget:
        """:attr:`error_budget`, computed now if it is not yet, telling ``progress`` of it.

        ``progress`` gets a ``budget`` :class:`~camtool.model.progress.Step` at the start
        and as each source's figures come in (``done`` the sources finished, ``total`` the
        modelled ones, ``name`` the next in order), so a long verification can say what
        it is doing; the budget is the same. The sources are re-simulated in forked
        workers, one per core (:class:`camtool.accel.cores.ForkedWork`): the part of
        the preview benchmark takes 2.6 s for its three where it took 3.8 s.

        Raises:
            CamtoolError: as :attr:`error_budget`.
        """
        if "error_budget" not in self.__dict__:  # cached_property's own slot
            self.__dict__["error_budget"] = _budget(self, progress)
        return self.error_budget

    @property
    def dwell_s(self) -> float:
        """Time the program's dwells (G04) add, s."""
        return sum(c.seconds for _, c in self.program.commands if isinstance(c, Dwell))

    @property
    def time_s(self) -> float:
        """Estimated machining time, s: every move's time plus the dwells."""
        return float(self.block_time_s.sum()) + self.dwell_s

    @property
    def max_error_um(self) -> float:
        """The predicted error a limit is checked against, µm.

        The largest of the deviation from the nominal path, the shortfall along
        it (the part of the path the tool never reached, :class:`AlongPath`)
        and, when a drawing was given, the machined edge's distance from it and
        its overcut, over what was cut as drawn (features the planner reported
        it cannot cut with this tool are left out: see :attr:`strict_error_um`).
        """
        worst = self.deviation.max_um
        if self.along is not None:
            worst = max(worst, self.along.shortfall_um)
        if self.against is not None:
            worst = max(worst, self.against.max_um, self.against.overcut_um)
        return max([worst, *(p.verification.max_error_um for p in self.parts)])

    @property
    def strict_error_um(self) -> float:
        """:attr:`max_error_um` with the features not cut as drawn included, µm."""
        worst = self.max_error_um
        if self.against is not None:
            worst = max(worst, self.against.strict_max_um)
        return max([worst, *(p.verification.strict_error_um for p in self.parts)])

    def over_limit(self, limit_um: float, *, strict: bool = False) -> str | None:
        """Why this verification fails ``--max-error-um limit_um``, or ``None`` when it passes.

        The limit judges what was cut as drawn (``strict``: also the features the
        planner reported it cannot cut with this tool). A drawing that was given but
        not compared (it does not overlap the program) fails: it cannot pass unjudged.
        """
        skipped = [p.label for p in self.parts if p.verification.against_skipped is not None]
        if self.against_skipped is not None or skipped:
            where = f" of {', '.join(skipped)}" if skipped else ""
            return (
                f"--max-error-um {limit_um:g} cannot be judged: the drawing{where} was not "
                "compared (it does not overlap the program; see the warning above)"
            )
        error = self.strict_error_um if strict else self.max_error_um
        if error <= limit_um:
            return None
        hint = "" if strict or self.strict_error_um == self.max_error_um else " (what was cut)"
        return (
            f"predicted error {fmt_num(error, 2)} µm{hint} exceeds --max-error-um "
            f"{limit_um:g}" + (" with --strict" if strict else "")
        )


def verify_code(
    code: str | bytes,
    target: Target,
    *,
    source: str = "<code>",
    against: Drawing | None = None,
    tool_diameter: float = 0.0,
    findings: Sequence[FindingLike] = (),
    planned: Program | None = None,
    budget: bool = True,
    budget_now: Progress | None = None,
) -> Verification:
    """Read ``code`` with ``target``'s reader and verify it on ``target``'s machine.

    ``findings`` are the plan's, ``planned`` the unrounded plan, ``budget`` the error
    budget switch and ``budget_now`` when it is computed (see :func:`verify_program`).

    Raises:
        ParseError: the code is not valid in the target's dialect (names the line).
        InputError: the code holds no cutting move (nothing to verify).
        DialectError: the program does not fit the machine; the message starts with
            ``source`` (:func:`check_area`).
    """
    program = target.post.parse(code, source=source)
    if all(isinstance(move, Rapid) for move in program.moves):
        moves = f"only {len(program.moves)} rapid move(s)" if program.moves else "no move"
        raise InputError(
            f"{source}: no cutting move in the code ({moves}): nothing to verify; "
            f"is this the whole program for {target.name}?"
        )
    return verify_program(
        program,
        target.machine,
        name=target.name,
        against=against,
        tool_diameter=tool_diameter,
        findings=findings,
        planned=planned,
        budget=budget,
        source=source,
        budget_now=budget_now,
    )


def verify_program(
    program: Program,
    machine: Machine,
    *,
    name: str = "",
    against: Drawing | None = None,
    tool_diameter: float = 0.0,
    findings: Sequence[FindingLike] = (),
    planned: Program | None = None,
    budget: bool = True,
    chunk_rows: int = CHUNK_ROWS,
    stream_above: int = STREAM_ROWS,
    source: str = "",
    budget_now: Progress | None = None,
) -> Verification:
    """Simulate ``program`` on ``machine`` and measure the machined error.

    Args:
        program: moves in mm as the controller reads them.
        machine: the machine profile.
        name: the target name for the report.
        against: the drawing to compare the machined edge with (same coordinates).
        tool_diameter: tool diameter, mm; the machined edge is the trace swept by
            half of it (0: a scribing point, or a path on the line).
        findings: what planning found (:class:`camtool.toolpath.cuts.Finding`):
            features it reported as impossible with this tool (a tight corner, a
            region narrower than the tool) are measured apart from the rest of
            the drawing (:func:`camtool.verify.drawing_compare.not_cut_groups`).
        planned: the unrounded plan ``program`` was emitted from, in the same
            coordinates (the error budget's ``rounding`` source); ``None`` when
            only the code is known.
        budget: compute the error budget when it is asked for
            (:attr:`Verification.error_budget`); ``False`` skips it.
        chunk_rows: rows simulated and measured at a time when the trace is streamed.
        stream_above: a trace of more rows than this is streamed (simulated and
            measured ``chunk_rows`` at a time, :func:`_simulate_big`) when it can be.
        source: the file the program was read from, named in the messages of
            :func:`check_area` (``""``: the line alone).
        budget_now: compute the error budget now, told to this progress callback as
            :meth:`Verification.measure_budget` tells it: its sources are re-simulated
            in forked workers while this process measures the trace and compares it
            with the drawing (the same budget; ``post --preview`` of the
            benchmark part took 6.1 s where the two one after the other took 6.7 s).
            A budget that fails is left to be computed, and to fail, when it is asked
            for. ``None``: when it is asked for. The kernels the measures need are
            loaded first (:func:`~camtool.verify.drawing_compare.prepare_comparison`), so each
            worker inherits them instead of loading them again; the workers are then
            forked at once, before this process's own measures (their core is idle
            otherwise; with the kernels loaded while the plan waited for
            OpenCASCADE, :func:`camtool.accel.cores.meanwhile`, ~0.3 s of that part's
            preview).

    A drawing whose box does not overlap the program's (less than
    :data:`MIN_OVERLAP`) is not compared: ``against`` is ``None``,
    ``against_skipped`` and a warning say why.

    Raises:
        UsageError: a negative tool diameter, or an inconsistent machine profile.
        InputError: the profile names an unknown interpolator, chord rule or
            timing model (the message lists the valid names).
        DialectError: the program does not fit the machine (:func:`check_area`).
    """
    if tool_diameter < 0:
        raise UsageError(f"tool diameter must be >= 0 mm, got {tool_diameter!r}")
    placement = report.check_area(program, machine, source)
    skipped = None if against is None else report._no_overlap(program, against, tool_diameter / 2.0)
    compared_with = against if skipped is None else None
    with ExitStack() as stack:  # leaving it stops the budget's workers, if any
        early = None
        if budget_now is not None and budget and compared_with is None:
            early = _EarlyBudget(program, machine, planned, tool_diameter, findings, budget_now)
            stack.callback(early.close)
        trace, streamed = _simulate_big(
            program,
            machine,
            compared_with,
            chunk_rows,
            stream_above,
            streaming=None if early is None else early.start,
        )
        warnings = report._warnings(program, trace)
        if skipped is not None:
            warnings.append(skipped)
        run = None if early is None else early.run_for(trace.row_count)
        now = budget_now if streamed is None and run is None else None  # else when asked for
        if now is not None and budget and compared_with is not None:
            prepare_comparison(compared_with)  # loaded once here, not once per worker
        inputs = _Inputs(program, machine, trace, planned, compared_with, tool_diameter, findings)
        if now is not None:  # the budget's workers are forked once this process has loaded
            run = stack.enter_context(_BudgetRun(inputs, budget, now))  # what it needs
        digest = None
        if streamed is not None:
            dev, along, contours, thin, digest = streamed
        else:
            dev, along, contours, thin = _trace_measures(
                program, trace, cutting=compared_with is not None
            )
        compared = None
        if thin is not None and compared_with is not None:  # the drawing, meanwhile
            compared = _compare(program, thin, compared_with, tool_diameter, findings)
        times = report.block_times(trace, program, machine)
        warnings.extend(timing_warnings(trace, program, machine))
        v = Verification(
            target=name or machine.name,
            program=program,
            machine=machine,
            trace=trace,
            deviation=dev,
            contours=contours,
            against=compared,
            block_time_s=times,
            warnings=tuple(dict.fromkeys((*warnings, *placement))),
            against_skipped=skipped,
            along=along,
            planned=planned,
            budget=budget,
            drawing=compared_with,
            tool_diameter=tool_diameter,
            findings=tuple(findings),
            cut_digest=digest,
        )
        if run is not None:
            with suppress(CamtoolError):  # then asked for, it is computed (and fails) again
                v.__dict__["error_budget"] = run.gather(v)  # cached_property's own slot
    return v


_Streamed = tuple[Deviation, AlongPath, tuple[ContourMeasure, ...], ThinTrace | None, bytes | None]
"""A streamed trace's measures, thinned cutting rows and their digest (:func:`_stream`)."""


class _EarlyBudget:
    """A verification's error budget of one source, started before its trace.

    Without a drawing, the budget's re-simulations need only the program, the machine and
    the trace's row count: a streamed trace (:func:`_simulate_big`) is told to
    :meth:`start` the one source as soon as its rows are counted, and it runs in a helper
    of its own (:class:`_BudgetRun`, ``alongside``) while this process simulates and
    measures the trace: the two peaks of memory are in two processes, not one after the
    other in one. The kernels both call are loaded first, so the helper inherits them
    (:func:`~camtool.verify.drawing_compare.prepare_stream`). Two sources or more are
    re-simulated side by side once the trace is measured, as before: started with it,
    three processes shared two cores and took longer.
    """

    def __init__(
        self,
        program: Program,
        machine: Machine,
        planned: Program | None,
        tool_diameter: float,
        findings: Sequence[FindingLike],
        progress: Progress,
    ) -> None:
        self.program, self.machine, self.planned = program, machine, planned
        self.tool_diameter, self.findings, self.progress = tool_diameter, findings, progress
        self.run: _BudgetRun | None = None
        statuses = trace_sources.source_statuses(program, machine, planned=planned)
        self.one = sum(s.status == "modelled" for s in statuses) == 1

    def start(self, rows: int) -> None:
        """Start the budget of a trace of ``rows`` rows (again, if another count came first).

        Not for two sources or more, nor for a trace whose budget is skipped (over
        :data:`camtool.verify.budget.MAX_ROWS` rows).
        """
        if not self.one or rows > eb.MAX_ROWS:
            self.close()
            return
        if self.run is not None and self.run.rows == rows:
            return
        self.close()
        prepare_stream()  # the helper inherits the kernels this process calls too
        inputs = _Inputs(
            self.program,
            self.machine,
            None,
            self.planned,
            None,
            self.tool_diameter,
            self.findings,
            rows=rows,
        )
        self.run = _BudgetRun(inputs, True, self.progress, alongside=True)

    def run_for(self, rows: int) -> _BudgetRun | None:
        """The run started for a trace of ``rows`` rows (``None``, closed: none, or another)."""
        if self.run is not None and self.run.rows != rows:
            self.close()
        return self.run

    def close(self) -> None:
        """Stop what was started (idempotent)."""
        if self.run is not None:
            self.run.work.close()
            self.run = None


def _simulate_big(
    program: Program,
    machine: Machine,
    against: Drawing | None,
    chunk_rows: int,
    stream_above: int,
    *,
    streaming: Callable[[int], None] | None = None,
) -> tuple[StepTrace, _Streamed | None]:
    """The trace of ``program``, and its measures when they were taken as it streamed.

    A trace of at most ``stream_above`` rows or one from a target's own simulator is
    simulated whole (:func:`simulate`) and measured by :func:`_measure` (then ``None``).
    A longer one of the step simulator is simulated again in chunks of ``chunk_rows``
    rows (:class:`camtool.verify.simulate.ChunkedSimulation`) and measured chunk by
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
    time it is).
    """
    if library().simulator(machine.motion.line) is not None:
        return trace_sources.simulate(program, machine), None
    counted = _rows_at_least(program, machine) > stream_above
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
        streamed = _stream(program, machine, against, chunk_rows, got, kernels)
        if streamed is None and counted:  # the count was not the rows': count them again
            got = simulate_or_count(program, machine, stream_above)
            if isinstance(got, StepTrace):  # not over the limit after all: the whole trace
                return got, None
            if streaming is not None:
                streaming(int(got[-1]))
            streamed = _stream(program, machine, against, chunk_rows, got, kernels)
    except NotStreamable:
        return trace_sources.simulate(program, machine), None
    if streamed is None:
        raise RuntimeError(
            "the chunked simulation did not repeat the first one"
        )  # pragma: no cover
    return streamed


def _stream(
    program: Program,
    machine: Machine,
    against: Drawing | None,
    chunk_rows: int,
    block_start: np.ndarray,
    kernels: Any,
    *,
    sources: Sources = ALL,
    rms: bool = True,
) -> tuple[StepTrace, _Streamed] | None:
    """:func:`_simulate_big`'s streamed trace and measures, its moves at ``block_start``.

    ``None`` when the chunked simulation's rows do not start where ``block_start`` says
    (the measures, which were told those offsets, are then not the trace's).
    ``sources``: the error sources simulated (the error budget's re-simulations);
    ``rms=False``: the deviation's rms is not measured (NaN; the budget has no use for it).

    Raises:
        NotStreamable: the rows are not whole steps.
    """
    sim = ChunkedSimulation(program, machine, chunk_rows, sources=sources)
    summary = sim.trace_summary()
    stream = TraceStream(program, block_start, summary["start_mm"], kernels, rms=rms)
    cutting = None if against is None else _cutting_stream(program, block_start)
    share = _Share()

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

    for chunk, pre in ahead(made()):  # the next chunk simulated while this one is measured
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


class _Share:
    """Which chunks' deviation distances the thread ahead takes (:func:`_stream`).

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


def _cutting_stream(program: Program, block_start: np.ndarray) -> CuttingStream:
    """A :class:`CuttingStream` for the trace of ``program`` whose moves start at ``block_start``.

    The cutting rows are those of the moves that are not rapids (as :func:`_cutting_rows`).
    """
    return CuttingStream(
        _rapids(program), _cutting_count(program, block_start), AGAINST_RESOLUTION_MM
    )


def _rows_at_least(program: Program, machine: Machine) -> int:
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


def _trace_measures(
    program: Program, trace: StepTrace, *, cutting: bool
) -> tuple[Deviation, AlongPath, tuple[ContourMeasure, ...], ThinTrace | None]:
    """The measures of ``trace`` itself, and its thinned cutting rows when ``cutting``.

    The drawing comparison (:func:`_compare`) needs only the thinned rows, so a caller
    that is done with the trace can let it go before comparing.
    """
    points, blocks = trace.carriage_mm, trace.block_of_row
    dev = deviation(points, blocks, program)
    along = along_path(points, trace.block_start, trace.start_mm, program)
    contours = tuple(measure_contours(points, trace.block_start, trace.start_mm, program))
    thin = thin_cutting(*_cutting_rows(program, trace)) if cutting else None
    return dev, along, contours, thin


def _compare(
    program: Program,
    thin: ThinTrace,
    against: Drawing,
    tool_diameter: float,
    findings: Sequence[FindingLike],
) -> Against:
    """The machined edge of ``program``'s thinned cutting trace against the drawing.

    The one call of :func:`~camtool.verify.drawing_compare.against_thinned` of a verification,
    for a whole trace and a streamed one (:func:`verify_program`); the error budget's
    sources need only its largest distance (:func:`_without`).
    """
    return against_thinned(
        thin,
        against,
        tool_diameter / 2.0,
        nominal=trace_sources._nominal_lines(program) if findings else (),
        findings=findings,
    )


def _rapids(program: Program) -> np.ndarray:
    """``(B,)`` bool: which moves of ``program`` are rapids (their rows do not cut)."""
    return np.asarray([isinstance(m, Rapid) for m in program.moves], dtype=bool)


def _cutting_count(program: Program, block_start: np.ndarray) -> int:
    """Rows of the moves of ``program`` that are not rapids (their rows start at ``block_start``).

    For a whole trace, the length of :func:`_cutting_rows`' answer.
    """
    rapid = _rapids(program)
    return int(np.diff(block_start)[~rapid].sum()) if len(rapid) else 0


def _cutting_rows(program: Program, trace: StepTrace) -> tuple[np.ndarray, np.ndarray]:
    """The trace's cutting rows ``(N, 2)`` mm and the id of each one's run between rapids."""
    points, blocks = trace.carriage_mm, trace.block_of_row
    rapid = _rapids(program)
    cutting = ~rapid[blocks] if len(blocks) else np.zeros(0, dtype=bool)
    runs = np.cumsum(~cutting)[cutting]  # a new id after every rapid row
    return points[cutting], runs


def _same_against(v: _Inputs, program: Program, digest: bytes | None) -> bool:
    """Whether the drawing comparison of a re-simulation gets exactly ``v``'s inputs.

    The same cutting rows and runs (the same :class:`~camtool.verify.cutting_thin.CutDigest`,
    ``digest`` the re-simulation's) and (with findings) the same programmed path: then
    its figures are the verification's own (``against``, measured whenever there is a
    drawing), bit for bit, and need not be measured again (the ``rounding`` source of
    a machine whose steps absorb the emitted rounding).
    """
    if v.drawing is None or digest is None or digest != v.digest:
        return False
    if not v.findings or program is v.program:
        return True
    mine, theirs = trace_sources._nominal_lines(program), trace_sources._nominal_lines(v.program)
    return len(mine) == len(theirs) and all(
        np.array_equal(a, b) for a, b in zip(mine, theirs, strict=True)
    )


def _trace_digest(program: Program, trace: StepTrace) -> bytes:
    """The :class:`~camtool.verify.cutting_thin.CutDigest` of a whole trace, a chunk at a time."""
    digest = CutDigest(_rapids(program))
    points, blocks = trace.carriage_mm, trace.block_of_row
    for lo in range(0, len(points), CHUNK_ROWS):
        digest.add(points[lo : lo + CHUNK_ROWS], blocks[lo : lo + CHUNK_ROWS])
    return digest.digest()


def _budget(v: Verification, progress: Progress = no_progress) -> eb.ErrorBudget:
    """The error budget of ``v`` (see :attr:`Verification.error_budget`), told to ``progress``."""
    inputs = _Inputs(
        v.program,
        v.machine,
        v.trace,
        v.planned,
        v.drawing,
        v.tool_diameter,
        v.findings,
        v.cut_digest,
    )
    with _BudgetRun(inputs, v.budget, progress) as run:
        return run.gather(v)


@dataclass(frozen=True)
class _Inputs:
    """What a verification measures: its program, machine and trace, and what it was told.

    ``trace`` is ``None`` for a budget started before a streamed trace is simulated
    (without a drawing, it needs only the trace's ``rows``).
    """

    program: Program
    machine: Machine
    trace: StepTrace | None
    planned: Program | None
    drawing: Drawing | None
    tool_diameter: float
    findings: Sequence[FindingLike]
    cut_digest: bytes | None = None
    rows: int = -1

    @property
    def row_count(self) -> int:
        """Rows of the verification's trace."""
        if self.trace is not None:
            return self.trace.row_count
        return self.rows

    @cached_property
    def digest(self) -> bytes | None:
        """The trace's :class:`~camtool.verify.cutting_thin.CutDigest` (``None``: no drawing)."""
        if self.drawing is None:
            return None
        if self.cut_digest is not None:
            return self.cut_digest
        assert self.trace is not None  # a budget started before its trace has no drawing
        return _trace_digest(self.program, self.trace)


class _BudgetRun:
    """The error budget's re-simulations, started in forked workers when it is made.

    The workers (:class:`~camtool.accel.cores.ForkedWork`, one per core) need only the
    verification's inputs and trace, so they can start before all its measures are
    taken (:func:`verify_program` starts them before the drawing comparison, and before
    a streamed trace without a drawing: they need only its row count);
    :meth:`gather` joins their figures with the verification's own. A context manager:
    leaving it stops the workers. ``alongside``: this process has work of its own
    meanwhile (a streamed trace to simulate and measure), so even one source is
    re-simulated in a process of its own (:class:`_ForkedOne`).
    """

    def __init__(
        self, inputs: _Inputs, budget: bool, progress: Progress, *, alongside: bool = False
    ) -> None:
        self.progress = progress
        self.skipped: str | None = None
        rows = inputs.row_count
        self.rows = rows
        if not budget:
            self.skipped = "switched off (--no-budget)"
        elif rows > eb.MAX_ROWS:
            self.skipped = (
                f"the trace has {rows} rows (over {eb.MAX_ROWS}): re-simulating it once per "
                "source would take too long; verify a part of the program to see it"
            )
        self.statuses = trace_sources.source_statuses(
            inputs.program, inputs.machine, planned=inputs.planned
        )
        self.modelled = (
            [] if self.skipped else [s.name for s in self.statuses if s.status == "modelled"]
        )
        self._answered(0)
        work = partial(_without, inputs)
        self.work: ForkedWork[str, _Without] | _ForkedOne[str, _Without]
        if alongside and len(self.modelled) == 1:
            self.work = _ForkedOne(work, self.modelled[0])
        else:
            self.work = ForkedWork(work, self.modelled)

    def __enter__(self) -> _BudgetRun:
        return self

    def __exit__(self, *exc: object) -> None:
        self.work.close()

    def _answered(self, count: int) -> None:
        if count < len(self.modelled):
            name = self.modelled[count]
            self.progress(Step("budget", count, len(self.modelled), SOURCES[name]))

    def gather(self, v: Verification) -> eb.ErrorBudget:
        """The budget of ``v``, whose inputs and trace this run was made from.

        Raises:
            CamtoolError: a re-simulation fails (the full model did not).
        """
        total = eb.figures(v.deviation, v.along, v.contours, v.against)
        if self.skipped is not None:
            return eb.ErrorBudget(total, skipped=self.skipped)
        notes = []
        if len(v.contours) > eb.MAX_CONTOURS:
            notes.append(
                f"only the first {eb.MAX_CONTOURS} of {len(v.contours)} contours are in the budget"
            )
        without: dict[str, eb.Figures] = {}
        for name, got in zip(self.modelled, self.work.answers(self._answered), strict=True):
            values = got.values | (eb.against_figures(v.against) if got.same else {})
            if got.blocks is not None and got.blocks != [c.blocks for c in v.contours]:
                # the plan's moves are not the code's: only the whole-program figures compare
                values = {k: x for k, x in values.items() if not k.startswith("contour ")}
            if got.note is not None:
                notes.append(got.note)
            without[name] = values
        return eb.compute(total, self.statuses, without, notes=notes)


class _ForkedOne(Generic[T, R]):
    """``[fn(item)]``, started now in one forked helper, gathered later (as ForkedWork).

    :class:`~camtool.accel.cores.ForkedWork` runs a lone item in this process, when its
    answers are asked for; a process with work of its own meanwhile (a streamed trace)
    gives it a helper of its own (:func:`~camtool.accel.cores.fork_with_pipes`), a copy of
    this process as it is now. Its answer comes back pickled, every bit kept; a helper that
    raised, died or could not start has the item run here, so an error is raised as it
    would be without it. Where ForkedWork would not fork (no ``fork``, one core, in a
    worker process) the item runs here. Leaving it (:meth:`close`) ends the helper.
    """

    def __init__(self, fn: Callable[[T], R], item: T) -> None:
        self.fn, self.item = fn, item
        self.pid: int | None = None
        self.fd: int | None = None
        if not FORK or default_jobs() < 2 or in_worker():
            return

        def run(inbox: int, outbox: int) -> None:
            quiet_crashes()
            signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's to handle
            os.close(inbox)
            write_record(outbox, pickle.dumps(fn(item), protocol=pickle.HIGHEST_PROTOCOL))

        with suppress(OSError):  # no process now: the item runs here
            self.pid, to_child, self.fd = fork_with_pipes(run)
            os.close(to_child)

    def __enter__(self) -> _ForkedOne[T, R]:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def answers(self, done: Callable[[int], None] | None = None) -> list[R]:
        """``[fn(item)]``, from the helper or made here; the helper is ended after.

        ``done``: called with 1 once the answer is in (for a progress report).

        Raises:
            Whatever ``fn`` raises (run here when the helper did not answer).
        """
        record = None
        if self.fd is not None:
            try:
                wait_readable(self.fd)
                record = read_record(self.fd)
            finally:
                self.close()
        answer: R = pickle.loads(record) if record is not None else self.fn(self.item)
        if done is not None:
            done(1)
        return [answer]

    def close(self) -> None:
        """End the helper (idempotent)."""
        if self.fd is not None:
            os.close(self.fd)
            self.fd = None
        if self.pid is not None:
            with suppress(ChildProcessError):
                end_process(self.pid, kill=True)
            self.pid = None


@dataclass(frozen=True)
class _Without:
    """A verification re-simulated with one error source off (:func:`_without`).

    Attributes:
        values: its figures (:func:`camtool.verify.budget.figures`), the distance to the
            drawing left out when ``same``.
        same: its drawing comparison gets exactly the verification's inputs, so its
            figure is the verification's own (:func:`_same_against`).
        blocks: ``rounding`` only: the plan's contours' ``(first, last)`` moves.
        note: why the source could not be compared (then ``values`` is empty).
    """

    values: eb.Figures
    same: bool = False
    blocks: list[tuple[int, int]] | None = None
    note: str | None = None


def _without(inputs: _Inputs, name: str) -> _Without:
    """The verification of ``inputs`` re-simulated with the error source ``name`` off.

    ``rounding`` simulates the unrounded plan instead; when the plan does not simulate
    (not what this machine reads), no figure and a note that says why. The drawing is
    measured again only when the cutting trace differs (:func:`_same_against`). A trace
    of more than :data:`CHUNK_ROWS` rows is streamed, that many rows at a time
    (:func:`_resimulate`).

    Raises:
        CamtoolError: the re-simulation fails (the full model did not).
    """
    program, sources = inputs.program, ALL
    if name == "rounding":
        assert inputs.planned is not None
        program = inputs.planned
    else:
        sources = ALL.without(name)
    chunk_rows = CHUNK_ROWS
    stream = inputs.row_count > chunk_rows
    try:
        dev, along, contours, thin, digest = _resimulate(
            program, inputs.machine, sources, inputs.drawing, chunk_rows if stream else 0
        )
    except CamtoolError as exc:  # the plan is not what this machine reads: say so
        if name != "rounding":
            raise
        return _Without(
            {}, note=f"rounding not compared: the unrounded plan does not simulate ({exc})"
        )
    same = _same_against(inputs, program, digest)  # then the drawing is not measured again
    values = eb.figures(dev, along, contours, None)
    if inputs.drawing is not None and thin is not None and not same:
        values |= eb.distance_figures(  # only its largest distance is a figure
            against_worst(
                thin,
                inputs.drawing,
                inputs.tool_diameter / 2.0,
                nominal=trace_sources._nominal_lines(program) if inputs.findings else (),
                findings=inputs.findings,
            )
        )
    blocks = [c.blocks for c in contours] if name == "rounding" else None
    return _Without(values, same, blocks)


def _resimulate(
    program: Program,
    machine: Machine,
    sources: Sources,
    drawing: Drawing | None,
    chunk_rows: int,
) -> _Streamed:
    """The measures of ``program`` simulated with ``sources`` (the error budget's).

    With ``chunk_rows`` and the compiled kernels, the step simulator's trace is streamed
    (:func:`_stream`: the same figures as the whole trace's, bit for bit; the rms, which
    the budget does not use, is not measured), its rows counted first
    (:func:`~camtool.verify.simulate.count_rows`); else simulated whole and measured by
    :func:`_trace_measures`. With a drawing, the thinned cutting rows and their digest.

    Raises:
        CamtoolError: the simulation fails.
    """
    kernels = compiled() if chunk_rows else None
    if kernels is not None and library().simulator(machine.motion.line) is None:
        for closed_form in (True, False):  # a count the chunks do not repeat: simulated
            block_start = count_rows(program, machine, sources=sources, closed_form=closed_form)
            try:
                got = _stream(
                    program,
                    machine,
                    drawing,
                    chunk_rows,
                    block_start,
                    kernels,
                    sources=sources,
                    rms=False,
                )
            except NotStreamable:
                break
            if got is not None:
                return got[1]
    trace = trace_sources.simulate(program, machine, sources=sources)
    dev, along, contours, thin = _trace_measures(program, trace, cutting=drawing is not None)
    digest = None if drawing is None else _trace_digest(program, trace)
    return dev, along, contours, thin, digest
