"""The verifier: emitted code → program → simulated machine → measured error.

:func:`verify_code` reads code with the target's own reader (so rounding and
field widths are part of the prediction), :func:`verify_program` simulates a
program on a machine profile and measures the result (see
:mod:`camtool.verify.simulate` and :mod:`camtool.verify.metrics`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from camtool.errors import UsageError
from camtool.geometry import Drawing
from camtool.machine import Machine
from camtool.program import Dwell, Home, Program, Rapid
from camtool.verify.metrics import (
    Against,
    ContourMeasure,
    Deviation,
    against_drawing,
    deviation,
    measure_contours,
)
from camtool.verify.simulate import StepTrace, simulate_steps

if TYPE_CHECKING:
    from camtool.post.base import Target
    from camtool.toolpath.plan import PlanReport

SMALL_PART_MM = 1.0
"""Parts under this size suffer most from compensations (seed-000 §5.3, S000-19)."""
MAX_COMPENSATIONS_SMALL = 16
"""Compensations above which a small part is warned about (the puma: 15-16; the logo: 45)."""


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

        The largest of the deviation from the nominal path and, when a drawing
        was given, the machined edge's distance from it and its overcut.
        """
        worst = self.deviation.max_um
        if self.against is not None:
            worst = max(worst, self.against.max_um, self.against.overcut_um)
        return worst


def verify_code(
    code: str | bytes,
    target: Target,
    *,
    source: str = "<code>",
    against: Drawing | None = None,
    tool_diameter: float = 0.0,
) -> Verification:
    """Read ``code`` with ``target``'s reader and verify it on ``target``'s machine.

    Raises:
        ParseError: the code is not valid in the target's dialect (names the line).
    """
    program = target.post.parse(code, source=source)
    return verify_program(
        program, target.machine, name=target.name, against=against, tool_diameter=tool_diameter
    )


def verify_program(
    program: Program,
    machine: Machine,
    *,
    name: str = "",
    against: Drawing | None = None,
    tool_diameter: float = 0.0,
) -> Verification:
    """Simulate ``program`` on ``machine`` and measure the machined error.

    Args:
        program: moves in mm as the controller reads them.
        machine: the machine profile.
        name: the target name for the report.
        against: the drawing to compare the machined edge with (same coordinates).
        tool_diameter: tool diameter, mm; the machined edge is the trace swept by
            half of it (0: a scribing point, or a path on the line).

    Raises:
        UsageError: a negative tool diameter, or an inconsistent machine profile.
        DialectError: the program does not fit the machine (:func:`check_area`).
    """
    if tool_diameter < 0:
        raise UsageError(f"tool diameter must be >= 0 mm, got {tool_diameter!r}")
    placement = check_area(program, machine)
    if machine.motion.line == "servo":
        from camtool.verify.simulate_servo import simulate_servo

        trace = simulate_servo(program, machine)
    else:
        trace = simulate_steps(program, machine)
    points, blocks = trace.carriage_mm, trace.block_of_row
    dev = deviation(points, blocks, program)
    contours = tuple(measure_contours(points, trace.block_start, trace.start_mm, program))
    compared = None
    if against is not None:
        rapid = np.asarray([isinstance(m, Rapid) for m in program.moves], dtype=bool)
        cutting = ~rapid[blocks] if len(blocks) else np.zeros(0, dtype=bool)
        runs = np.cumsum(~cutting)[cutting]  # a new id after every rapid row
        compared = against_drawing(points[cutting], against, tool_diameter / 2.0, runs=runs)
    times = block_times(trace, program, machine)
    return Verification(
        target=name or machine.name,
        program=program,
        machine=machine,
        trace=trace,
        deviation=dev,
        contours=contours,
        against=compared,
        block_time_s=times,
        warnings=tuple(dict.fromkeys((*_warnings(program, trace), *placement))),
    )


def check_area(program: Program, machine: Machine) -> tuple[str, ...]:
    """The rule ``post`` applies (:func:`camtool.post.base.check_placement`), on read code.

    Work coordinates: the toolpath must fit the travel (warnings where work zero needs
    care); machine coordinates: every move inside the work area, named by its line.

    Raises:
        DialectError: the program cannot run on ``machine`` (with the remedy).
    """
    from camtool.post.base import check_placement, check_work_area

    for index, (start, move) in enumerate(program.steps()):
        line = program.line_of(index)
        where = f"line {line}" if line is not None else f"move {index + 1}"
        check_work_area(start, move, machine, where, program)
    return check_placement(program, machine)


def block_times(trace: StepTrace, program: Program, machine: Machine) -> np.ndarray:
    """Estimated time of each move, s (the machine's timing model)."""
    from camtool.verify.clock import block_times_s

    return block_times_s(trace, program, machine)


def _warnings(program: Program, trace: StepTrace) -> list[str]:
    out = list(program.warnings)
    homes = sum(isinstance(c, Home) for _, c in program.commands)
    if homes:
        out.append(
            f"{homes} return(s) to machine zero (G28) not simulated: machine zero is not "
            "the part zero, so the move after each is simulated from where the one before ended"
        )
    box = program.bbox(cutting_only=True)
    size = max(box[2] - box[0], box[3] - box[1])
    if trace.compensations > MAX_COMPENSATIONS_SMALL and size < SMALL_PART_MM:
        out.append(
            f"{trace.compensations} backlash compensations on a part of {size:.3f} mm: parts "
            f"under {SMALL_PART_MM:g} mm fail after about {MAX_COMPENSATIONS_SMALL} "
            "(seed-000 §5.3); try --order mirror or fewer reversals"
        )
    return out


def summary_lines(v: Verification) -> list[str]:
    """A one-screen text summary of a verification (for stderr)."""
    t = v.trace
    steps = t.block_steps.sum(axis=0) if len(t.block_steps) else np.zeros(3, dtype=np.int64)
    lines = [
        f"verified {len(v.program.moves)} moves on {v.target} ({v.machine.name})",
        f"  steps x {steps[0]}, y {steps[1]}, z {steps[2]}; "
        f"{int((~t.compensation).sum())} iterations",
        f"  reversals x {t.reversals[0]}, y {t.reversals[1]}; "
        f"{t.compensations} compensations ({int(t.compensation.sum())} steps)",
        f"  deviation from the path: max {v.deviation.max_um:.2f} µm at "
        f"({v.deviation.at_mm[0]:.4f}, {v.deviation.at_mm[1]:.4f}) mm, "
        f"rms {v.deviation.rms_um:.2f} µm",
    ]
    for c in v.contours:
        ex, ey = c.size_error_um
        text = f"  contour {c.number}: size error {ex:+.1f} x {ey:+.1f} µm"
        if c.closure_um is not None:
            text += f", closure gap ({c.closure_um[0]:+.1f}, {c.closure_um[1]:+.1f}) µm"
        if c.circle is not None:
            text += f", diameter {c.circle[1]:.4f} mm (nominal {c.circle[0]:.4f})"
        lines.append(text)
        if len(lines) > 14:
            lines.append(f"  ... {len(v.contours) - c.number} more contours in the report")
            break
    if v.against is not None:
        lines.append(
            f"  against the drawing: max {v.against.max_um:.2f} µm, rms {v.against.rms_um:.2f} µm, "
            f"overcut {v.against.overcut_um:.2f} µm"
        )
    lines.append(f"  estimated time {v.time_s:.1f} s")
    return lines


def report_dict(v: Verification, plan: PlanReport | None = None) -> dict[str, Any]:
    """The verify report (keys of ../shared/DESIGN.md, plus details), JSON-ready.

    ``plan``, what planning found when the code was planned in the same run, goes
    under the ``plan`` key (:meth:`camtool.toolpath.plan.PlanReport.to_json`).
    """
    from camtool.verify.report import build_report

    report = build_report(v)
    if plan is not None:
        report["plan"] = plan.to_json()
    return report
