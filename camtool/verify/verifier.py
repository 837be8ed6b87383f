"""The verifier: emitted code → program → simulated machine → measured error → report.

Design notes: docs/internals.md, ``camtool/verify/verifier.py``.
"""

from __future__ import annotations

from collections.abc import Sequence
from contextlib import ExitStack, suppress
from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING

import numpy as np

from camtool.model.errors import CamtoolError, InputError, UsageError
from camtool.model.machine import Machine
from camtool.model.program import Dwell, Program, Rapid
from camtool.model.progress import Progress, Step, no_progress
from camtool.model.shapes import Drawing
from camtool.model.units import fmt_num
from camtool.verify import budget as eb
from camtool.verify import report
from camtool.verify.budget_run import BudgetInputs, BudgetRun, EarlyBudget, budget_of
from camtool.verify.clock import timing_warnings
from camtool.verify.contour_measures import ContourMeasure
from camtool.verify.deviations import Deviation
from camtool.verify.drawing_compare import (
    Against,
    prepare_comparison,
)
from camtool.verify.motion import StepTrace
from camtool.verify.not_cut import CHAIN_JOIN_MM, FindingLike
from camtool.verify.path_shortfall import AlongPath
from camtool.verify.streamed import (
    CHUNK_ROWS,
    STREAM_ROWS,
    compare_drawing,
    measure_trace,
    simulate_big,
)

if TYPE_CHECKING:
    from camtool.post.base import Target


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
            program and the drawing do not overlap; a job's program), else ``None``; then
            ``against`` is ``None`` and no limit can be judged against it.
        along: the programmed path seen from the trace (the shortfall, the
            error at every move's end), ``None`` for a verification built by hand.
        planned: the unrounded plan the code was written from, when at hand
            (the ``rounding`` source of the error budget), else ``None``.
        budget: whether :attr:`error_budget` re-simulates (``False``: ``--no-budget``).
        drawing: the drawing given to compare with (the budget measures it again).
        tool_diameter: the tool diameter the drawing was compared with, mm.
        findings: the plan's findings the drawing was compared with.
        joint_mm: the distance within which the plan joined contour ends, mm (the
            drawing's contours are grouped into its chains at it).
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
    joint_mm: float = CHAIN_JOIN_MM

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
        return budget_of(self)

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
            self.__dict__["error_budget"] = budget_of(self, progress)
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
        not compared (:attr:`against_skipped`) fails: it cannot pass unjudged.
        """
        skipped = [p.label for p in self.parts if p.verification.against_skipped is not None]
        if self.against_skipped is not None or skipped:
            where = f" of {', '.join(skipped)}" if skipped else ""
            return (
                f"--max-error-um {limit_um:g} cannot be judged: the drawing{where} was not "
                "compared (see the warning above)"
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
    joint_mm: float = CHAIN_JOIN_MM,
    progress: Progress = no_progress,
) -> Verification:
    """Read ``code`` with ``target``'s reader and verify it on ``target``'s machine.

    ``findings`` are the plan's, ``joint_mm`` its joint distance, ``planned`` the unrounded
    plan, ``budget`` the error budget switch and ``budget_now`` when it is computed, and
    ``progress`` where a long one is (see :func:`verify_program`).

    Raises:
        ParseError: the code is not valid in the target's dialect (names the line).
        InputError: the code is empty or holds no cutting move (nothing to verify).
        DialectError: the program does not fit the machine; the message starts with
            ``source`` (:func:`check_area`).
    """
    if not code or code.isspace():
        raise InputError(f"{source}: empty file (nothing but blanks): nothing to verify")
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
        joint_mm=joint_mm,
        progress=progress,
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
    joint_mm: float = CHAIN_JOIN_MM,
    progress: Progress = no_progress,
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
            features it reported as impossible with this tool are measured apart from
            the rest of the drawing (:func:`camtool.verify.not_cut.not_cut_groups`).
        joint_mm: the distance within which the plan joined contour ends, mm
            (:attr:`camtool.toolpath.plan.PlanReport.joint_mm`): the drawing's contours
            are grouped into the plan's chains at it.
        planned: the unrounded plan ``program`` was emitted from, in the same
            coordinates (the error budget's ``rounding`` source), or ``None``.
        budget: compute the error budget when it is asked for
            (:attr:`Verification.error_budget`); ``False`` skips it.
        chunk_rows: rows simulated and measured at a time when the trace is streamed.
        stream_above: a trace of more rows than this is streamed (:func:`simulate_big`).
        source: the file the program was read from, named in the messages of
            :func:`check_area` (``""``: the line alone).
        budget_now: compute the error budget now, told to this progress callback as
            :meth:`Verification.measure_budget` tells it: its sources are re-simulated
            in forked workers while this process measures the trace (the same budget).
            A budget that fails is left to be computed, and to fail, when it is asked for.
        progress: told the rows of a streamed trace as they are measured (``simulating``)
            and the start of the drawing comparison (``comparing``).

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
    reposted = planned is None or planned.from_code  # not planned here from a drawing
    placement = report.check_area(program, machine, source, reposted=reposted)
    skipped = None if against is None else report._no_overlap(program, against, tool_diameter / 2.0)
    drawing = against if skipped is None else None
    with ExitStack() as stack:  # leaving it stops the budget's workers, if any
        early = None  # one source forked as soon as the rows are counted
        if budget_now is not None and budget and drawing is None:
            early = EarlyBudget(
                program, machine, planned, tool_diameter, findings, budget_now, joint_mm
            )
            stack.callback(early.close)
        streaming = None if early is None else early.start
        trace, streamed = simulate_big(
            program,
            machine,
            drawing,
            chunk_rows,
            stream_above,
            streaming=streaming,
            progress=progress,
        )
        run = None if early is None else early.run_for(trace.row_count)
        if budget_now is not None and streamed is None and run is None:  # forked now
            if budget and drawing is not None:
                prepare_comparison(drawing)  # loaded once here, not once per worker
            inputs = BudgetInputs(
                program,
                machine,
                trace,
                planned,
                drawing,
                tool_diameter,
                findings,
                joint_mm=joint_mm,
            )
            run = stack.enter_context(BudgetRun(inputs, budget, budget_now))
        dev, along, contours, thin, digest = streamed or (
            *measure_trace(program, trace, cutting=drawing is not None),
            None,
        )
        compared = None
        if thin is not None and drawing is not None:
            progress(Step("comparing", 0, thin.rows))
            compared = compare_drawing(program, thin, drawing, tool_diameter, findings, joint_mm)
        warnings = [*report._warnings(program, trace), *([skipped] if skipped else [])]
        warnings += timing_warnings(trace, program, machine)
        v = Verification(
            target=name or machine.name,
            program=program,
            machine=machine,
            trace=trace,
            deviation=dev,
            contours=contours,
            against=compared,
            block_time_s=report.block_times(trace, program, machine),
            warnings=tuple(dict.fromkeys((*warnings, *placement))),
            against_skipped=skipped,
            along=along,
            planned=planned,
            budget=budget,
            drawing=drawing,
            tool_diameter=tool_diameter,
            findings=tuple(findings),
            joint_mm=joint_mm,
            cut_digest=digest,
        )
        if run is not None:
            with suppress(CamtoolError):  # then asked for, it is computed (and fails) again
                v.__dict__["error_budget"] = run.gather(v)  # cached_property's own slot
    return v
