"""What a calibration fit works on: its parameters, the sheet's observations, the result."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from camtool.calibrate.coupon import Measure
from camtool.model.machine import AXES, Machine


@dataclass(frozen=True)
class Parameter:
    """One fitted number of a machine profile.

    Attributes:
        key: where it lives in the ``[machine]`` table (``"true_steps_per_mm[0]"``,
            ``"backlash.true_um[1]"``, ``"backlash.regions[2].true_um"``).
        label: for people (``"true steps/mm X"``, ``"backlash X in X 0…3.333 mm"``).
        unit: ``"steps/mm"`` or ``"µm"``.
        start: the profile's value, the fit's starting point.
        unit_change: a small typical change (0.1 % of steps/mm, 1 µm of backlash): the
            finite-difference step and the scale of the Jacobian column.
    """

    key: str
    label: str
    unit: str
    start: float
    unit_change: float


@dataclass(frozen=True)
class Observation:
    """A measured value of one coupon measure.

    Attributes:
        measure: what was measured.
        value_mm: the measured value, mm.
        compensation_um: the controller's backlash compensation ``(x, y)`` when the
            feature was cut, µm (``None``: the profile's).
        line: the sheet line it came from (0 when given in code).
    """

    measure: Measure
    value_mm: float
    compensation_um: tuple[float, float] | None = None
    line: int = 0


@dataclass(frozen=True)
class Fitted:
    """A fitted parameter: value and 1-σ uncertainty (``None`` without redundancy)."""

    parameter: Parameter
    value: float
    sigma: float | None


@dataclass(frozen=True)
class Residual:
    """One measurement against the prediction before and after the fit, mm."""

    observation: Observation
    before_mm: float
    after_mm: float

    @property
    def residual_um(self) -> float:
        """Measured − predicted after the fit, µm."""
        return (self.observation.value_mm - self.after_mm) * 1000.0


@dataclass(frozen=True)
class FitResult:
    """What the fit found.

    Attributes:
        target: the target's name.
        fitted: the determined parameters.
        undetermined: each parameter the data cannot determine, with why.
        residuals: every measurement, predicted before and after.
        dof: measurements − fitted parameters.
        overlay: the ``[machine]`` overlay table (fitted keys only).
        iterations: Levenberg–Marquardt iterations run.
        settings: the controller's steps/mm settings to make, one per fitted axis
            (``"$100=252.000"`` where the profile names them, else the profile's
            ``steps_per_mm`` key with the new values).
    """

    target: str
    fitted: tuple[Fitted, ...]
    undetermined: tuple[tuple[Parameter, str], ...]
    residuals: tuple[Residual, ...]
    dof: int
    overlay: Mapping[str, Any] = field(repr=False)
    iterations: int = 0
    settings: tuple[str, ...] = ()

    @property
    def rms_before_um(self) -> float:
        """RMS of measured − predicted with the profile as it was, µm."""
        return _rms([(r.observation.value_mm - r.before_mm) * 1000 for r in self.residuals])

    @property
    def rms_after_um(self) -> float:
        """RMS of measured − predicted with the fitted profile, µm."""
        return _rms([r.residual_um for r in self.residuals])

    def value(self, key: str) -> float:
        """The fitted value of the parameter at ``key``.

        Raises:
            KeyError: that parameter was not determined.
        """
        for f in self.fitted:
            if f.parameter.key == key:
                return f.value
        raise KeyError(key)


def _rms(values: Sequence[float]) -> float:
    return math.sqrt(sum(v * v for v in values) / len(values)) if values else 0.0


JOINT_XY = "true_steps_per_mm[x=y]"
"""Key of the one steps/mm of X and Y together (one screw lead), fitted when the measurements
cannot tell X's from Y's (circles only): Y keeps its ratio to X."""


def joint_xy(machine: Machine) -> Parameter:
    """The steps/mm of X and Y as one parameter (:data:`JOINT_XY`)."""
    x = machine.real_steps_per_mm[0]
    return Parameter(JOINT_XY, "true steps/mm X and Y (one lead)", "steps/mm", x, x * 1e-3)


def parameters(machine: Machine) -> list[Parameter]:
    """The parameters of ``machine``'s profile a coupon can measure, at their current values."""
    real = machine.real_steps_per_mm
    out = []
    for axis in range(3 if machine.has_z else 2):
        name = AXES[axis].upper()
        out.append(
            Parameter(
                f"true_steps_per_mm[{axis}]",
                f"true steps/mm {name}",
                "steps/mm",
                real[axis],
                real[axis] * 1e-3,
            )
        )
    b = machine.backlash
    for axis in range(2):
        name = AXES[axis].upper()
        where = " outside its regions" if any(r.axis == AXES[axis] for r in b.regions) else ""
        out.append(
            Parameter(
                f"backlash.true_um[{axis}]", f"backlash {name}{where}", "µm", b.true_um[axis], 1.0
            )
        )
    for i, r in enumerate(b.regions):
        span = []
        if r.x_mm[0] > -999 or r.x_mm[1] < 999:
            span.append(f"X {r.x_mm[0]:g}…{r.x_mm[1]:g}")
        if r.y_mm[0] > -999 or r.y_mm[1] < 999:
            span.append(f"Y {r.y_mm[0]:g}…{r.y_mm[1]:g}")
        out.append(
            Parameter(
                f"backlash.regions[{i}].true_um",
                f"backlash {r.axis.upper()} in region {i + 1} "
                f"({' '.join(span) or 'everywhere'} mm)",
                "µm",
                r.true_um,
                1.0,
            )
        )
    return out
