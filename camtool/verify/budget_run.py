"""The error budget's re-simulations, one per source, in forked workers.

:func:`budget_of` gives a :class:`~camtool.verify.verifier.Verification` its budget; a
verification without a drawing starts its one source early (:class:`EarlyBudget`).
"""

from __future__ import annotations

import dataclasses
import os
import pickle
import signal
from collections.abc import Callable, Sequence
from contextlib import suppress
from dataclasses import dataclass
from functools import cached_property, partial
from typing import TYPE_CHECKING, Generic, TypeVar

import numpy as np

from camtool.accel.cores import (
    FORK,
    ForkedWork,
    default_jobs,
    end_process,
    fork_with_pipes,
    in_worker,
    quiet_crashes,
    read_record,
    wait_readable,
    write_record,
)
from camtool.model.errors import CamtoolError
from camtool.model.machine import Machine
from camtool.model.program import Program
from camtool.model.progress import Progress, Step, no_progress
from camtool.model.shapes import Drawing
from camtool.verify import budget as eb
from camtool.verify import trace_sources
from camtool.verify.chunked import (
    NotStreamable,
    count_rows,
)
from camtool.verify.cutting_thin import (
    CutDigest,
)
from camtool.verify.dda import compiled
from camtool.verify.drawing_compare import (
    against_worst,
    prepare_stream,
)
from camtool.verify.motion import StepTrace, library
from camtool.verify.not_cut import CHAIN_JOIN_MM, FindingLike
from camtool.verify.sources import ALL, SOURCES, Sources
from camtool.verify.streamed import (
    CHUNK_ROWS,
    Streamed,
    measure_trace,
    rapid_mask,
    stream_trace,
)

if TYPE_CHECKING:
    from camtool.verify.verifier import Verification

T = TypeVar("T")
R = TypeVar("R")


class EarlyBudget:
    """A verification's error budget of one source, started before its trace.

    Without a drawing, the budget's re-simulations need only the program, the machine and
    the trace's row count: a streamed trace (:func:`simulate_big`) is told to
    :meth:`start` the one source as soon as its rows are counted, and it runs in a helper
    of its own (:class:`BudgetRun`, ``alongside``) while this process simulates and
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
        joint_mm: float = CHAIN_JOIN_MM,
    ) -> None:
        self.program, self.machine, self.planned = program, machine, planned
        self.tool_diameter, self.findings, self.progress = tool_diameter, findings, progress
        self.joint_mm = joint_mm
        self.run: BudgetRun | None = None
        statuses = trace_sources.source_statuses(program, machine, planned=planned)
        self.one = sum(s.status == "modelled" for s in statuses) == 1 and not (
            trace_sources.follows_program(program, machine, statuses)  # nothing to simulate
        )

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
        inputs = BudgetInputs(
            self.program,
            self.machine,
            None,
            self.planned,
            None,
            self.tool_diameter,
            self.findings,
            rows=rows,
            joint_mm=self.joint_mm,
        )
        self.run = BudgetRun(inputs, True, self.progress, alongside=True)

    def run_for(self, rows: int) -> BudgetRun | None:
        """The run started for a trace of ``rows`` rows (``None``, closed: none, or another)."""
        if self.run is not None and self.run.rows != rows:
            self.close()
        return self.run

    def close(self) -> None:
        """Stop what was started (idempotent)."""
        if self.run is not None:
            self.run.work.close()
            self.run = None


def same_against(v: BudgetInputs, program: Program, digest: bytes | None) -> bool:
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


def trace_digest(program: Program, trace: StepTrace) -> bytes:
    """The :class:`~camtool.verify.cutting_thin.CutDigest` of a whole trace, a chunk at a time."""
    digest = CutDigest(rapid_mask(program))
    points, blocks = trace.carriage_mm, trace.block_of_row
    for lo in range(0, len(points), CHUNK_ROWS):
        digest.add(points[lo : lo + CHUNK_ROWS], blocks[lo : lo + CHUNK_ROWS])
    return digest.digest()


def budget_of(v: Verification, progress: Progress = no_progress) -> eb.ErrorBudget:
    """The error budget of ``v`` (see :attr:`Verification.error_budget`), told to ``progress``."""
    inputs = BudgetInputs(
        v.program,
        v.machine,
        v.trace,
        v.planned,
        v.drawing,
        v.tool_diameter,
        v.findings,
        v.cut_digest,
        joint_mm=v.joint_mm,
    )
    with BudgetRun(inputs, v.budget, progress) as run:
        return run.gather(v)


@dataclass(frozen=True)
class BudgetInputs:
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
    joint_mm: float = CHAIN_JOIN_MM

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
        return trace_digest(self.program, self.trace)


class BudgetRun:
    """The error budget's re-simulations, started in forked workers when it is made.

    The workers (:class:`~camtool.accel.cores.ForkedWork`, one per core) need only the
    verification's inputs and trace, so they can start before all its measures are
    taken (:func:`verify_program` starts them before the drawing comparison, and before
    a streamed trace without a drawing: they need only its row count);
    :meth:`gather` joins their figures with the verification's own. A context manager:
    leaving it stops the workers. ``alongside``: this process has work of its own
    meanwhile (a streamed trace to simulate and measure), so even one source is
    re-simulated in a process of its own (:class:`_ForkedOne`). A program whose trace
    without its one source, ``interpolation``, is the program itself
    (:func:`~camtool.verify.trace_sources.follows_program`, no drawing) is not
    re-simulated: its figures are the program's own
    (:func:`~camtool.verify.trace_sources.ideal_figures`).
    """

    def __init__(
        self, inputs: BudgetInputs, budget: bool, progress: Progress, *, alongside: bool = False
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
        self.exact = (
            self.modelled == ["interpolation"]
            and inputs.drawing is None
            and trace_sources.follows_program(inputs.program, inputs.machine, self.statuses)
        )  # the figures without it are the program's own: nothing to re-simulate
        self.simulated = [] if self.exact else self.modelled
        self._answered(0)
        work = partial(without_source, inputs)
        self.work: ForkedWork[str, Without] | _ForkedOne[str, Without]
        if alongside and len(self.simulated) == 1:
            self.work = _ForkedOne(work, self.simulated[0])
        else:
            self.work = ForkedWork(work, self.simulated, jobs=_jobs(rows))

    def __enter__(self) -> BudgetRun:
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
        if self.exact:
            figures = trace_sources.ideal_figures(v.program, v.contours, along=v.along is not None)
            without["interpolation"] = figures
            self._answered(1)
        for name, got in zip(self.simulated, self.work.answers(self._answered), strict=True):
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


def _jobs(rows: int) -> int | None:
    """Worker processes for re-simulations of a trace of ``rows`` rows (``None``: a core each).

    A re-simulation of more than :data:`CHUNK_ROWS` rows is streamed on two threads of its
    own (:func:`stream_trace`: one simulates the next chunk while the other measures this
    one), but in a worker process on one (:func:`~camtool.accel.cores.ahead` runs there
    in turn). So a long one, of more than :data:`IN_TURN_FROM` rows, takes two cores: on
    two, the sources run one after the other in this process (less wall and CPU time, and
    less memory in all, than a worker each: docs/performance.md). A shorter one, of a few
    chunks, gains little from its second thread: a worker each, started as the
    verification starts, runs beside it (:class:`~camtool.accel.cores.ForkedWork`'s own
    count, ``None``).
    """
    return max(1, default_jobs() // 2) if rows > IN_TURN_FROM else None


IN_TURN_FROM = 16 * CHUNK_ROWS
"""Rows of a trace from which :func:`_jobs` gives each re-simulation two cores (~1 M)."""


@dataclass(frozen=True)
class Without:
    """A verification re-simulated with one error source off (:func:`without_source`).

    Attributes:
        values: its figures (:func:`camtool.verify.budget.figures`), the distance to the
            drawing left out when ``same``.
        same: its drawing comparison gets exactly the verification's inputs, so its
            figure is the verification's own (:func:`same_against`).
        blocks: ``rounding`` only: the plan's contours' ``(first, last)`` moves.
        note: why the source could not be compared (then ``values`` is empty).
    """

    values: eb.Figures
    same: bool = False
    blocks: list[tuple[int, int]] | None = None
    note: str | None = None


def without_source(inputs: BudgetInputs, name: str) -> Without:
    """The verification of ``inputs`` re-simulated with the error source ``name`` off.

    ``rounding`` simulates the unrounded plan instead; when the plan does not simulate
    (not what this machine reads), no figure and a note that says why. The drawing is
    measured again only when the cutting trace differs (:func:`same_against`). A trace
    of more than :data:`CHUNK_ROWS` rows is streamed, that many rows at a time
    (:func:`resimulate`).

    Raises:
        CamtoolError: the re-simulation fails (the full model did not).
    """
    program, sources = inputs.program, ALL
    if name == "rounding":
        assert inputs.planned is not None
        program = inputs.planned
    else:
        sources = ALL.without(name)
        if inputs.drawing is not None:  # its comparison thins by counting rows
            sources = dataclasses.replace(sources, sampled_lines=True)
    chunk_rows = CHUNK_ROWS
    stream = inputs.row_count > chunk_rows
    try:
        dev, along, contours, thin, digest = resimulate(
            program, inputs.machine, sources, inputs.drawing, chunk_rows if stream else 0
        )
    except CamtoolError as exc:  # the plan is not what this machine reads: say so
        if name != "rounding":
            raise
        return Without(
            {}, note=f"rounding not compared: the unrounded plan does not simulate ({exc})"
        )
    same = same_against(inputs, program, digest)  # then the drawing is not measured again
    values = eb.figures(dev, along, contours, None)
    if inputs.drawing is not None and thin is not None and not same:
        values |= eb.distance_figures(  # only its largest distance is a figure
            against_worst(
                thin,
                inputs.drawing,
                inputs.tool_diameter / 2.0,
                nominal=trace_sources._nominal_lines(program) if inputs.findings else (),
                findings=inputs.findings,
                joint_mm=inputs.joint_mm,
            )
        )
    blocks = [c.blocks for c in contours] if name == "rounding" else None
    return Without(values, same, blocks)


def resimulate(
    program: Program,
    machine: Machine,
    sources: Sources,
    drawing: Drawing | None,
    chunk_rows: int,
) -> Streamed:
    """The measures of ``program`` simulated with ``sources`` (the error budget's).

    With ``chunk_rows`` and the compiled kernels, the step simulator's trace is streamed
    (:func:`stream_trace`: the same figures as the whole trace's, bit for bit; the rms, which
    the budget does not use, is not measured), its rows counted first
    (:func:`~camtool.verify.simulate.count_rows`); else simulated whole and measured by
    :func:`measure_trace`. With a drawing, the thinned cutting rows and their digest.

    Raises:
        CamtoolError: the simulation fails.
    """
    kernels = compiled() if chunk_rows else None
    if kernels is not None and library(machine).simulator(machine.motion.line) is None:
        for closed_form in (True, False):  # a count the chunks do not repeat: simulated
            block_start = count_rows(program, machine, sources=sources, closed_form=closed_form)
            try:
                got = stream_trace(
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
    dev, along, contours, thin = measure_trace(program, trace, cutting=drawing is not None)
    digest = None if drawing is None else trace_digest(program, trace)
    return dev, along, contours, thin, digest
