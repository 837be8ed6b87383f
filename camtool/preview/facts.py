"""The facts a preview's title states: part size and estimated machining time.

The time is the best estimate available, and the title says which it is:

- a verification's own time (the machine's timing model over the simulated
  steps, :mod:`camtool.verify.clock`);
- for a program with a target: the same model, run on a step simulation of the
  program (no measurement);
- otherwise the cutting moves at their programmed feeds
  (:meth:`camtool.model.program.Program.cutting_time_s`; rapids not counted).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from camtool.model.program import Program, Rapid
from camtool.model.shapes import BBox

if TYPE_CHECKING:
    from camtool.model.machine import Machine
    from camtool.verify.motion import StepTrace
    from camtool.verify.verifier import Verification


def time_basis(machine: Machine, trace: StepTrace) -> str:
    """How :func:`camtool.verify.clock.block_times_s` timed a trace, in words."""
    if trace.block_time_s is not None:
        return "by the servo simulation"
    model = machine.timing.get("model") if machine.timing else None
    return f"by the {model} timing model" if model else "at programmed feeds"


def machine_time(program: Program, machine: Machine) -> tuple[float, str]:
    """Seconds ``program`` takes on ``machine`` by its timing model, and the basis in words.

    Simulates the steps (no measurement); see :mod:`camtool.verify.clock`.

    Raises:
        CamtoolError: the machine profile is invalid for the simulator.
    """
    from camtool.verify.verifier import block_times, simulate

    trace = simulate(program, machine)
    return float(block_times(trace, program, machine).sum()), time_basis(machine, trace)


def estimated_time(
    program: Program | None, machine: Machine | None, verification: Verification | None
) -> tuple[float, str] | None:
    """The best time estimate (see the module docstring): ``(seconds, basis)`` or ``None``."""
    if verification is not None:
        return verification.time_s, time_basis(verification.machine, verification.trace)
    if program is None or not any(not isinstance(m, Rapid) for m in program.moves):
        return None
    if machine is not None:
        return machine_time(program, machine)
    return program.cutting_time_s(), "at programmed feeds, cuts only"


def duration(seconds: float) -> str:
    """``"0.8 s"``, ``"42 s"``, ``"3 min 12 s"``, ``"2 h 05 min"``."""
    if seconds < 10:
        return f"{seconds:.1f} s"
    whole = round(seconds)
    if whole < 60:
        return f"{whole} s"
    if whole < 3600:
        return f"{whole // 60} min {whole % 60} s"
    minutes = round(seconds / 60)
    return f"{minutes // 60} h {minutes % 60:02d} min"


def length(mm: float) -> str:
    """A length for titles: at most 3 decimals, trailing zeros dropped (``"4.5"``)."""
    text = f"{mm:.3f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def size_text(box: BBox) -> str:
    """``"5 × 4.5 mm"``: width × height of ``box``."""
    return f"{length(box[2] - box[0])} × {length(box[3] - box[1])} mm"
