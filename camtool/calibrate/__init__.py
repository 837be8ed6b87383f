"""Calibration: a coupon that measures what a machine profile models, and a least-squares fit.

Design notes: docs/internals.md, ``camtool/calibrate/__init__.py``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from camtool.model.errors import InputError, UsageError

if TYPE_CHECKING:
    from camtool.calibrate.coupon import Coupon
    from camtool.calibrate.fitdata import FitResult
    from camtool.post.base import Target


@dataclass(frozen=True)
class CouponFiles:
    """What ``camtool calibrate coupon`` writes.

    Attributes:
        coupon: the coupon (features and program).
        code: the program in the target's dialect (``bytes`` for a binary one).
        markdown: the sheet to print (:func:`camtool.calibrate.sheet.sheet_markdown`).
        csv: the template to fill in (:func:`camtool.calibrate.sheet.sheet_csv`).
        warnings: what the post-processor said.
    """

    coupon: Coupon
    code: str | bytes
    markdown: str
    csv: str
    warnings: tuple[str, ...]


def make_coupon(
    target: Target, *, code_name: str = "the coupon program", csv_name: str = "coupon.csv"
) -> CouponFiles:
    """The default coupon of ``target``, posted and read back through it, and its sheet.

    Raises:
        UsageError: the travel is too small for a coupon.
        DialectError: the target cannot write a feature or does not keep it.
    """
    from camtool.calibrate.coupon import build_coupon
    from camtool.calibrate.predict import read_back
    from camtool.calibrate.sheet import sheet_csv, sheet_markdown

    coupon = build_coupon(target)
    result = target.emit(coupon.program)
    target.parse(result.code, source=code_name)  # the coupon reads back with the target's reader
    read_back(coupon, target)  # and every feature keeps its strokes
    return CouponFiles(
        coupon,
        result.code,
        sheet_markdown(coupon, target.machine, code=code_name, csv=csv_name),
        sheet_csv(coupon, target.machine),
        result.warnings,
    )


HOLD = {"steps": "steps/mm", "backlash": "µm"}
"""What ``--hold`` keeps at the profile's values: the steps/mm or the backlash parameters."""


def fit_sheet(
    target: Target,
    text: str,
    *,
    source: str,
    hold: tuple[str, ...] = (),
    max_correction: float = 0.2,
) -> FitResult:
    """Fit ``target``'s profile to a filled-in sheet of its default coupon.

    Args:
        target: the target (its profile is the start).
        text: the sheet CSV.
        source: the sheet's name, for messages.
        hold: kinds of parameters held at the profile's values (keys of :data:`HOLD`).
        max_correction: the largest accepted steps/mm correction, a fraction (0.2: ±20 %).

    Raises:
        UsageError: an unknown ``hold`` kind, or ``max_correction`` not in (0, 10].
        InputError: the sheet is not valid (names ``source``, line and column), holds no
            measured value, is of another coupon, or its values cannot be trusted
            (:func:`camtool.calibrate.fit.fit`; prefixed with ``source``).
    """
    from camtool.calibrate.coupon import build_coupon
    from camtool.calibrate.fit import fit
    from camtool.calibrate.predict import read_back
    from camtool.calibrate.sheet import read_measurements

    unknown = sorted(set(hold) - set(HOLD))
    if unknown:
        raise UsageError(f"--hold {unknown[0]!r}: hold one of {', '.join(HOLD)}")
    if not 0 < max_correction <= 10:
        raise UsageError(f"--max-correction {max_correction * 100:g}: give a % in (0, 1000]")
    units = {HOLD[h] for h in hold}
    coupon = build_coupon(target)
    observations = read_measurements(text, coupon, source=source)
    try:
        return fit(
            read_back(coupon, target),
            target.machine,
            observations,
            target=target.name,
            only=(lambda p: p.unit not in units) if units else None,
            max_correction=max_correction,
        )
    except InputError as exc:
        raise InputError(f"{source}: {exc}") from None
