"""Fit a machine profile to measured coupon features by least squares.

The model is the verifier itself: for a candidate parameter vector θ the coupon's features are
simulated on the target's profile with θ laid over it (:func:`camtool.model.machine.merge_tables`)
and measured as the sheet says (:func:`camtool.calibrate.predict.predict`). The fit minimises
Σ (measured − predicted(θ))² with Levenberg–Marquardt (Marquardt 1963), the Jacobian by forward
differences of the simulation.

Parameters (what a profile models that a coupon can determine):

- ``true_steps_per_mm`` X, Y (and Z on a machine with Z): the steps the mechanics really make
  per mm (Yanez-07 R14: 1.9 µm assumed, 1.88 µm real; Munoz-22 §5.3: 80.86 mm for 80);
- the true backlash per axis, ``backlash.true_um`` X, Y, and per region where the profile has
  regions (``backlash.regions[i].true_um``, UNAM-GMM Tabla 13).

The compensation is the controller's setting, not a property of the mechanics: it is not fitted
but taken from each measurement row (the setting the feature was cut with).

A parameter on which no measurement depends, or whose effect the others already explain (its
scaled Jacobian column is near-dependent: a small pivot of the QR factorisation), is "not
determined by these measurements" and left out of the fit and the overlay. Uncertainties are
1 σ from the covariance s²·(JᵀJ)⁻¹, with s² = Σr²/(m − n) the residual variance (none when
m = n).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from camtool.calibrate.coupon import Measure
from camtool.calibrate.predict import ReadBack, predict
from camtool.model.errors import CamtoolError, InputError
from camtool.model.machine import AXES, Machine, machine_from_table, merge_tables
from camtool.model.units import fmt_num

MAX_ITERATIONS = 30
PIVOT_RATIO = 0.02
"""A QR pivot (of unit columns) below this marks a parameter the others already explain: its
column is within about 1° of their span, so its σ would be 50 times what it is alone."""
LOOSE_SIGMA = 0.25
"""A fitted value whose 1-σ uncertainty exceeds this fraction of its size is reported as not
determined and the fit is run again without it (a backlash of 125 ± 75 µm tells nothing)."""
SENSITIVITY_MM = 1e-7
"""A parameter whose unit change moves no measurement by more than this (mm) is not measured."""


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
    """

    target: str
    fitted: tuple[Fitted, ...]
    undetermined: tuple[tuple[Parameter, str], ...]
    residuals: tuple[Residual, ...]
    dof: int
    overlay: Mapping[str, Any] = field(repr=False)
    iterations: int = 0

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


def overlay_table(
    machine: Machine, params: Sequence[Parameter], values: Sequence[float]
) -> dict[str, Any]:
    """The ``[machine]`` overlay that sets ``params`` to ``values`` (and nothing else).

    Arrays are written whole (an overlay replaces an array): the other entries keep the
    profile's values.
    """
    overlay: dict[str, Any] = {}
    real = list(machine.real_steps_per_mm)
    true_um = list(machine.backlash.true_um)
    regions = [
        {"axis": r.axis, "x_mm": list(r.x_mm), "y_mm": list(r.y_mm), "true_um": r.true_um}
        for r in machine.backlash.regions
    ]
    touched: set[str] = set()
    for p, v in zip(params, (float(v) for v in values), strict=True):
        if p.key == JOINT_XY:
            real[1] = v * real[1] / real[0]
            real[0] = v
            touched.add("steps")
            continue
        index = int(p.key.split("[")[1].split("]")[0])
        if p.key.startswith("true_steps_per_mm"):
            real[index] = v
            touched.add("steps")
        elif p.key.startswith("backlash.true_um"):
            true_um[index] = v
            touched.add("true_um")
        else:
            regions[index]["true_um"] = v
            touched.add("regions")
    if "steps" in touched:
        overlay["true_steps_per_mm"] = real
    backlash: dict[str, Any] = {}
    if "true_um" in touched:
        backlash["true_um"] = true_um
    if "regions" in touched:
        backlash["regions"] = regions
    if backlash:
        overlay["backlash"] = backlash
    return overlay


class _Model:
    """Predicted measurements as a function of the parameter vector (local to one fit)."""

    def __init__(
        self,
        read: Sequence[ReadBack],
        machine: Machine,
        observations: Sequence[Observation],
        params: Sequence[Parameter],
    ) -> None:
        self.machine, self.params = machine, list(params)
        self.observations = observations
        groups: dict[tuple[float, float] | None, list[int]] = {}
        for i, o in enumerate(observations):
            groups.setdefault(o.compensation_um, []).append(i)
        by_feature = {r.feature.id: r for r in read}
        self.groups = []
        for comp, rows in groups.items():
            wanted = {observations[i].measure.id.split(".")[0] for i in rows}
            self.groups.append((comp, rows, [by_feature[f] for f in by_feature if f in wanted]))
        self.runs = 0

    def machine_for(self, values: Any, comp: tuple[float, float] | None) -> Machine:
        table = merge_tables(self.machine.table, overlay_table(self.machine, self.params, values))
        if comp is not None:
            z = self.machine.backlash.compensation_um[2]
            table = merge_tables(table, {"backlash": {"compensation_um": [comp[0], comp[1], z]}})
        return machine_from_table(table, where="the calibration fit")

    def __call__(self, values: Any) -> np.ndarray:
        self.runs += 1
        out = np.empty(len(self.observations))
        for comp, rows, features in self.groups:
            predicted = predict(features, self.machine_for(values, comp))
            for i in rows:
                out[i] = predicted[self.observations[i].measure.id]
        return out


def fit(
    read: Sequence[ReadBack],
    machine: Machine,
    observations: Sequence[Observation],
    *,
    target: str = "",
    only: Callable[[Parameter], bool] | None = None,
) -> FitResult:
    """Fit ``machine``'s parameters to ``observations`` of the read-back coupon ``read``.

    Args:
        read: the coupon's features as the target reads them
            (:func:`~camtool.calibrate.predict.read_back`).
        machine: the profile to start from (its ``table`` is what the overlay goes over).
        observations: the measurements.
        target: the target's name, for the result.
        only: fit only the parameters this accepts (the others keep the profile's values).

    Raises:
        InputError: no observation, or the profile cannot be simulated.
    """
    if not observations:
        raise InputError("no measured value to fit: fill in the 'measured_mm' column of the sheet")
    candidates = [p for p in parameters(machine) if only is None or only(p)]
    model = _Model(read, machine, observations, candidates)
    start = np.array([p.start for p in candidates])
    y = np.array([o.value_mm for o in observations])
    before = model(start)
    undetermined: list[tuple[Parameter, str]] = []
    jac = _jacobian(model, start, before, candidates, undetermined)
    keep = _determined(jac, candidates, undetermined)
    if only is None or only(joint_xy(machine)):
        keep, jac = _joint_if_needed(model, jac, candidates, keep, undetermined, machine)
        start = np.array([p.start for p in candidates])
    while True:
        params = [candidates[k] for k in keep]
        theta, pred, iterations, sigmas = _solve(model, start, keep, y, jac, params, before)
        loose = _loosest(params, theta, sigmas)
        if loose is None:
            break
        k = keep.pop(loose)
        undetermined.append(
            (
                candidates[k],
                "not determined by these measurements (it came out "
                f"{_value_text(candidates[k], theta[loose])} ± "
                f"{_value_text(candidates[k], sigmas[loose] or 0.0)}: they hardly constrain it)",
            )
        )
    dof = len(y) - len(params)
    fitted = tuple(Fitted(p, float(v), s) for p, v, s in zip(params, theta, sigmas, strict=True))
    residuals = tuple(
        Residual(o, float(b), float(a)) for o, b, a in zip(observations, before, pred, strict=True)
    )
    return FitResult(
        target or machine.name,
        fitted,
        tuple(undetermined),
        residuals,
        dof,
        overlay_table(machine, params, [float(v) for v in theta]),
        iterations,
    )


def _solve(
    model: _Model,
    start: np.ndarray,
    keep: list[int],
    y: np.ndarray,
    jac: np.ndarray,
    params: list[Parameter],
    before: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, int, list[float | None]]:
    """Levenberg–Marquardt over the parameters ``keep``: values, prediction, iterations, σ."""
    full = start.copy()

    def run(values: np.ndarray) -> np.ndarray:
        full[keep] = values
        return model(full)

    if not params:
        return start[keep], before, 0, []
    theta, pred, iterations, jac_k = _levenberg_marquardt(run, start[keep], y, jac[:, keep], params)
    return theta, pred, iterations, _sigmas(jac_k, y - pred, len(y) - len(params))


def _loosest(params: list[Parameter], theta: np.ndarray, sigmas: list[float | None]) -> int | None:
    """The parameter whose σ is largest against its size, if over :data:`LOOSE_SIGMA`, else None."""
    worst, index = LOOSE_SIGMA, None
    for k, (p, v, s) in enumerate(zip(params, theta, sigmas, strict=True)):
        size = max(abs(p.start), abs(float(v)), 10 * p.unit_change)
        if s is not None and s / size > worst:
            worst, index = s / size, k
    return index


def _jacobian(
    model: _Model,
    theta: np.ndarray,
    at: np.ndarray,
    params: Sequence[Parameter],
    refused: list[tuple[Parameter, str]] | None = None,
) -> np.ndarray:
    """Forward-difference Jacobian ``(m, n)`` (mm per parameter unit).

    A parameter the motion model refuses (a simulator that raises on a backlash) gets a zero
    column and, when ``refused`` is given, its reason there.
    """
    jac = np.zeros((len(at), len(theta)))
    for k, p in enumerate(params):
        step = theta.copy()
        step[k] += p.unit_change
        try:
            jac[:, k] = (model(step) - at) / p.unit_change
        except CamtoolError as exc:
            if refused is not None:
                refused.append((p, f"the motion model does not take it ({exc})"))
    return jac


def _joint_if_needed(
    model: _Model,
    jac: np.ndarray,
    candidates: list[Parameter],
    keep: list[int],
    undetermined: list[tuple[Parameter, str]],
    machine: Machine,
) -> tuple[list[int], np.ndarray]:
    """Keep X's and Y's steps/mm, or fit them as one (:data:`JOINT_XY`) if only that is determined.

    Appends the joint parameter to ``candidates`` (and a column to the model) when it is used.
    """
    xy = [
        k
        for k, p in enumerate(candidates)
        if p.key in ("true_steps_per_mm[0]", "true_steps_per_mm[1]")
    ]
    kept = [k for k in xy if k in keep]
    unmeasured = {p.key for p, why in undetermined if "none depends" in why}
    if len(kept) == 2 or len(xy) < 2 or any(candidates[k].key in unmeasured for k in xy):
        return keep, jac
    joint = joint_xy(machine)
    ratio = candidates[xy[1]].start / candidates[xy[0]].start
    column = jac[:, xy[0]] + jac[:, xy[1]] * ratio
    others = [k for k in keep if k not in xy]
    candidates.append(joint)
    model.params.append(joint)
    trial_jac = np.hstack([jac, column[:, None]])
    sub_undetermined: list[tuple[Parameter, str]] = []
    order = [*others, len(candidates) - 1]
    ok = _determined(trial_jac[:, order], [candidates[k] for k in order], sub_undetermined)
    if len(ok) != len(order):
        model.params.pop()
        candidates.pop()
        return keep, jac
    undetermined[:] = [
        (p, why)
        for p, why in undetermined
        if p.key not in ("true_steps_per_mm[0]", "true_steps_per_mm[1]")
    ]
    for k in xy:
        undetermined.append(
            (
                candidates[k],
                "not determined alone by these measurements (only with the other "
                "axis: fitted as one lead, see 'X and Y')",
            )
        )
    return sorted([*others, len(candidates) - 1]), trial_jac


def _determined(
    jac: np.ndarray, params: Sequence[Parameter], undetermined: list[tuple[Parameter, str]]
) -> list[int]:
    """Indices of the parameters the measurements determine; the others go to ``undetermined``."""
    refused = {p.key for p, _ in undetermined}
    scaled = jac * np.array([p.unit_change for p in params])
    keep: list[int] = []
    for k, p in enumerate(params):
        if p.key in refused:
            continue
        if np.max(np.abs(scaled[:, k]), initial=0.0) < SENSITIVITY_MM:
            undetermined.append((p, "not determined by these measurements (none depends on it)"))
            continue
        trial = [*keep, k]
        cols = scaled[:, trial] / np.linalg.norm(scaled[:, trial], axis=0)
        r = np.linalg.qr(cols, mode="r")
        pivots = np.abs(np.diag(r))
        if len(trial) > len(jac) or pivots.min() < PIVOT_RATIO * pivots.max():
            undetermined.append(
                (
                    p,
                    "not determined by these measurements (the other parameters explain the "
                    "same measurements; measure a feature that tells them apart)",
                )
            )
            continue
        keep.append(k)
    return keep


def _levenberg_marquardt(
    run: Callable[[np.ndarray], np.ndarray],
    theta: np.ndarray,
    y: np.ndarray,
    jac: np.ndarray,
    params: Sequence[Parameter],
) -> tuple[np.ndarray, np.ndarray, int, np.ndarray]:
    """Minimise Σ (y − run(θ))²; returns θ, the prediction, the iterations and the Jacobian."""
    unit = np.array([p.unit_change for p in params])
    lower = np.array([0.0 if p.unit == "µm" else 1e-3 * p.start for p in params])
    pred = run(theta)
    cost = float(np.sum((y - pred) ** 2))
    lam = 1e-3
    iterations = 0
    while iterations < MAX_ITERATIONS:
        iterations += 1
        a = jac * unit  # scaled columns: mm per unit change
        g = a.T @ (y - pred)
        h = a.T @ a
        while True:
            step = np.linalg.solve(h + lam * np.diag(np.diag(h)), g)
            trial = np.maximum(theta + step * unit, lower)  # backlash >= 0, steps/mm > 0
            trial_pred = run(trial)
            trial_cost = float(np.sum((y - trial_pred) ** 2))
            if trial_cost <= cost or lam > 1e8:
                break
            lam *= 10.0
        if trial_cost > cost:
            break
        small = np.all(np.abs(step) < 1e-4) or cost - trial_cost <= 1e-12 * max(cost, 1e-30)
        theta, pred, cost = trial, trial_pred, trial_cost
        lam = max(lam / 10.0, 1e-9)
        if small:
            break
        jac = _jacobian_of(run, theta, pred, params)
    return theta, pred, iterations, _jacobian_of(run, theta, pred, params)


def _jacobian_of(
    run: Callable[[np.ndarray], np.ndarray],
    theta: np.ndarray,
    at: np.ndarray,
    params: Sequence[Parameter],
) -> np.ndarray:
    jac = np.zeros((len(at), len(theta)))
    for k, p in enumerate(params):
        step = theta.copy()
        step[k] += p.unit_change
        jac[:, k] = (run(step) - at) / p.unit_change
    return jac


def _sigmas(jac: np.ndarray, residual: np.ndarray, dof: int) -> list[float | None]:
    """1-σ uncertainties: sqrt of the diagonal of s²(JᵀJ)⁻¹, s² = Σr²/dof; ``None`` if dof = 0."""
    n = jac.shape[1]
    if dof <= 0 or n == 0:
        return [None] * n
    s2 = float(np.sum(residual**2)) / dof
    cov = s2 * np.linalg.pinv(jac.T @ jac)
    return [float(math.sqrt(max(cov[k, k], 0.0))) for k in range(n)]


# --- output -------------------------------------------------------------------------------------


def _value_text(p: Parameter, value: float) -> str:
    return fmt_num(value, 3 if p.unit == "steps/mm" else 1)


def summary_lines(result: FitResult) -> list[str]:
    """The fit for people: each fitted value ± 1 σ, what was not determined, each residual."""
    m = len(result.residuals)
    lines = [
        f"fitted {len(result.fitted)} parameter(s) of {result.target} to {m} measurement(s) "
        f"({result.dof} degree(s) of freedom, {result.iterations} iteration(s))"
    ]
    for f in result.fitted:
        p = f.parameter
        sigma = (
            "± n/a (as many measurements as parameters)"
            if f.sigma is None
            else (f"± {_value_text(p, f.sigma)}")
        )
        lines.append(
            f"  {p.label}: {_value_text(p, f.value)} {sigma} {p.unit} "
            f"(profile: {_value_text(p, p.start)})"
        )
    for p, why in result.undetermined:
        lines.append(f"  {p.label}: {why}; left at {_value_text(p, p.start)} {p.unit}")
    lines.append(
        f"  residuals (measured - predicted), µm: rms {fmt_num(result.rms_before_um, 1)} before, "
        f"{fmt_num(result.rms_after_um, 1)} after"
    )
    for r in result.residuals:
        o = r.observation
        lines.append(
            f"    {o.measure.id}: measured {fmt_num(o.value_mm, 4)} mm, predicted "
            f"{fmt_num(r.before_mm, 4)} before, {fmt_num(r.after_mm, 4)} after, "
            f"residual {fmt_num(r.residual_um, 1)} µm"
        )
    return lines


def overlay_toml(result: FitResult, *, source: str) -> str:
    """The ``--machine`` overlay file: the fitted keys under ``[machine]``, with a header.

    The header names the target, the measurement file and each fitted value with its
    uncertainty; it holds no date (the same data give the same bytes).
    """
    head = [
        f"# machine overlay fitted by `camtool calibrate fit -t {result.target}` from {source}",
        f"# ({len(result.residuals)} measurements, {result.dof} degrees of freedom, "
        f"residual rms {fmt_num(result.rms_after_um, 1)} µm). Use: --machine THIS_FILE",
    ]
    for f in result.fitted:
        sigma = "n/a" if f.sigma is None else _value_text(f.parameter, f.sigma)
        head.append(
            f"# fitted: {f.parameter.label} = {_value_text(f.parameter, f.value)} ± {sigma} "
            f"{f.parameter.unit}"
        )
    for p, why in result.undetermined:
        head.append(f"# not fitted: {p.label}: {why}")
    body = ["[machine]"]
    o = result.overlay
    if "true_steps_per_mm" in o:
        body.append(f"true_steps_per_mm = {_array(o['true_steps_per_mm'])}")
    backlash = o.get("backlash", {})
    if "true_um" in backlash:
        body += ["", "[machine.backlash]", f"true_um = {_array(backlash['true_um'])}"]
    for region in backlash.get("regions", []):
        body += [
            "",
            "[[machine.backlash.regions]]",
            f'axis = "{region["axis"]}"',
            f"x_mm = {_array(region['x_mm'])}",
            f"y_mm = {_array(region['y_mm'])}",
            f"true_um = {_num(region['true_um'])}",
        ]
    return "\n".join([*head, *body]) + "\n"


def _num(value: float) -> str:
    text = repr(round(float(value), 6))
    return "0.0" if text == "-0.0" else text


def _array(values: Sequence[float]) -> str:
    return "[" + ", ".join(_num(v) for v in values) + "]"
