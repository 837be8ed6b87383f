"""Heights as the dialect writes them: refuse an option its rounding turns into another move.

Design notes: docs/internals.md, ``camtool/jobs/heights.py``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

from camtool.model.errors import DialectError, UsageError
from camtool.toolpath.passes import pass_depths

if TYPE_CHECKING:
    from camtool.post.base import Target
    from camtool.toolpath.options import PlanOptions

Write = Callable[[float], float]


def check_heights(target: Target, plan: PlanOptions) -> None:
    """Refuse heights of ``plan`` that ``target`` would write as another move.

    Args:
        target: the target that writes the program.
        plan: the planning options (``depth`` ``None``: nothing to check).

    Raises:
        UsageError: ``--depth``, ``--step-down``, ``--safe-z``, ``--clearance-z`` or
            ``--tab-height`` rounds, in ``target``'s Z words, to the top of the stock,
            to another pass or to the final depth.
    """
    if plan.depth is None or target.post.written_z(0.0, target.machine) is None:
        return

    def write(z: float) -> float:
        try:
            written = target.post.written_z(z, target.machine)
        except DialectError:  # too long for the Z word: not a rounding; the Z travel check
            return z  # (or the writer, naming the block) refuses it
        return 0.0 if written is None else written + 0.0  # -0.0 reads as 0

    step = _resolution(write)
    where = f"{target.name} writes Z in steps of {step:g} mm"
    _check_depth(write, plan, where, step)
    _check_heights_above(write, plan, where, step)
    if plan.tabs > 0:
        _check_tabs(write, plan, where, step)


def _check_depth(write: Write, plan: PlanOptions, where: str, step: float) -> None:
    assert plan.depth is not None
    if write(-plan.depth) >= 0:
        raise UsageError(
            f"--depth {plan.depth:g} mm is written as Z0 ({where}): the cut would be at the "
            f"top of the stock; give --depth {step:g} or more"
        )
    levels = pass_depths(plan.depth, plan.step_down)
    written = [write(z) for z in levels]
    for k, (z, w) in enumerate(zip(levels, written, strict=True)):
        if w >= 0:
            raise UsageError(
                f"--step-down {plan.step_down:g} mm: the first pass is written as Z0 "
                f"({where}): it would cut nothing; give --step-down {step:g} or more"
            )
        if k and w == written[k - 1]:
            raise UsageError(
                f"--step-down {plan.step_down:g} mm: the passes at Z{levels[k - 1]:g} and "
                f"Z{z:g} are both written as Z{w:g} ({where}); give --step-down {step:g} "
                "or more"
            )


def _check_heights_above(write: Write, plan: PlanOptions, where: str, step: float) -> None:
    for flag_name, height in (("--safe-z", plan.safe_z), ("--clearance-z", plan.clearance)):
        if write(height) <= 0:
            raise UsageError(
                f"{flag_name} {height:g} mm is written as Z0 ({where}): rapids would run at "
                f"the top of the stock; give {flag_name} {step:g} or more"
            )


def _check_tabs(write: Write, plan: PlanOptions, where: str, step: float) -> None:
    assert plan.depth is not None
    top = -plan.depth + plan.tab_height
    if write(top) == write(-plan.depth):
        raise UsageError(
            f"--tab-height {plan.tab_height:g} mm is written at the final depth ({where}): "
            f"there would be no tabs and the part would come loose; give --tab-height "
            f"{step:g} or more"
        )
    if write(top) >= 0:
        raise UsageError(
            f"--tab-height {plan.tab_height:g} mm puts the tab top at Z{top:g}, written as Z0 "
            f"({where}); give --tab-height {plan.depth - step:g} or less"
        )


def _resolution(write: Write) -> float:
    """The smallest positive height ``write`` writes as other than 0, mm."""
    low, high = 0.0, 1.0
    while write(high) <= 0 and high < 1e3:
        high *= 10
    for _ in range(60):
        middle = (low + high) / 2
        if write(middle) > 0:
            high = middle
        else:
            low = middle
    return write(high)
