"""Fit a machine profile to measured coupon features by least squares.

Design notes: docs/internals.md, ``camtool/calibrate/fit.py``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from camtool.calibrate.fitdata import (
    JOINT_XY,
    FitResult,
    Fitted,
    Observation,
    Parameter,
    Residual,
    joint_xy,
    parameters,
)
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
MAX_CORRECTION = 0.2
"""The largest steps/mm correction a fit accepts by default (fitted / profile − 1, ±20 %): a
mis-set steps/mm of a real machine is a few %; more is a wrong unit, scale or driver setting."""
ROW_RATIO = 3.0
"""A measured value more than this many times its nominal value (or less than its inverse)
is a unit or typing mistake, refused before the fit."""
UNMEASURED = "not measured by this sheet (no filled-in row depends on it)"
UNEXPLAINED_MM = 0.25
"""A residual (measured − predicted by the fitted machine) over this, mm, and over
:data:`UNEXPLAINED_SHARE` of its nominal, is a row the fitted machine does not explain: a
misread or misplaced measurement, or an effect the model has not (Yanez-07 §6.2's ø10 circle,
0.9 mm under size at P = 20 ms). The thesis tables' rows fit within 0.1 mm (Munoz-22 §5.2's
± 0.09 mm scatter per revolution)."""
UNEXPLAINED_SHARE = 0.02
"""See :data:`UNEXPLAINED_MM`: 2 % of the nominal length."""


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
    max_correction: float = MAX_CORRECTION,
) -> FitResult:
    """Fit ``machine``'s parameters to ``observations`` of the read-back coupon ``read``.

    Args:
        read: the coupon's features as the target reads them
            (:func:`~camtool.calibrate.predict.read_back`); every feature of the coupon,
            so that a refusal can name the rows that would determine a parameter.
        machine: the profile to start from (its ``table`` is what the overlay goes over).
        observations: the measurements.
        target: the target's name, for the result.
        only: fit only the parameters this accepts (the others are held at the profile's
            values, said so in the result).
        max_correction: the largest accepted ``|fitted / profile − 1|`` of a steps/mm.

    Raises:
        InputError: no observation; a row that looks like another unit; parameters the
            rows depend on but cannot tell apart (names the rows that would); a backlash
            the rows put below 0; a steps/mm correction over ``max_correction``; or the
            profile cannot be simulated.
    """
    if not observations:
        raise InputError("no measured value to fit: fill in the 'measured_mm' column of the sheet")
    _check_rows(observations)
    everything = parameters(machine)
    candidates = [p for p in everything if only is None or only(p)]
    undetermined: list[tuple[Parameter, str]] = [
        (p, "held at the profile's value (not fitted: --hold)")
        for p in everything
        if p not in candidates
    ]
    model = _Model(read, machine, observations, candidates)
    start = np.array([p.start for p in candidates])
    y = np.array([o.value_mm for o in observations])
    before = model(start)
    first = len(undetermined)
    jac = _jacobian(model, start, before, candidates, undetermined)
    keep, confounded = _determined(jac, candidates, undetermined)
    if only is None or only(joint_xy(machine)):
        keep, jac, confounded = _joint_if_needed(
            model, jac, candidates, keep, confounded, undetermined, machine
        )
        start = np.array([p.start for p in candidates])
    _refuse_confounded(confounded, candidates, jac, read, machine, observations)
    theta, pred, iterations, sigmas, jac_k = _solve(model, start, keep, y, jac)
    # a parameter no row depended on at the profile may matter at the fitted values
    full = start.copy()
    full[keep] = theta
    woken = _woken(model, full, pred, candidates, undetermined[first:])
    if woken:
        undetermined[first:] = [(p, why) for p, why in undetermined[first:] if p not in woken]
        jac = _jacobian(model, full, pred, candidates)
        keep, confounded = _determined(jac, candidates, undetermined)
        _refuse_confounded(confounded, candidates, jac, read, machine, observations)
        theta, pred, iterations, sigmas, jac_k = _solve(model, full, keep, y, jac)
    params = [candidates[k] for k in keep]
    _check_backlash_sign(params, theta, y - pred, jac_k, observations, machine)
    _check_correction(params, theta, max_correction)
    dof = len(y) - len(params)
    fitted = []
    for p, v, sd in zip(params, theta, sigmas, strict=True):
        if _loose(p, float(v), sd):
            undetermined.append(
                (
                    p,
                    "not determined by these measurements (it came out "
                    f"{_value_text(p, float(v))} ± {_value_text(p, sd or 0.0)}: they hardly "
                    "constrain it; the others were fitted with it free)",
                )
            )
        else:
            fitted.append(Fitted(p, float(v), sd))
    residuals = tuple(
        Residual(o, float(b), float(a)) for o, b, a in zip(observations, before, pred, strict=True)
    )
    kept = [f.parameter for f in fitted]
    overlay = overlay_table(machine, kept, [f.value for f in fitted])
    return FitResult(
        target or machine.name,
        tuple(fitted),
        tuple(undetermined),
        residuals,
        dof,
        overlay,
        iterations,
        _settings(machine, kept, overlay),
    )


def _solve(
    model: _Model,
    start: np.ndarray,
    keep: list[int],
    y: np.ndarray,
    jac: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, int, list[float | None], np.ndarray]:
    """Levenberg–Marquardt over the parameters ``keep``: values, prediction, iterations, σ, J."""
    full = start.copy()
    params = [model.params[k] for k in keep]

    def run(values: np.ndarray) -> np.ndarray:
        full[keep] = values
        return model(full)

    if not params:
        return start[keep], model(start), 0, [], np.zeros((len(y), 0))
    theta, pred, iterations, jac_k = _levenberg_marquardt(run, start[keep], y, jac[:, keep], params)
    return theta, pred, iterations, _sigmas(jac_k, y - pred, len(y) - len(params)), jac_k


def _loose(p: Parameter, value: float, sigma: float | None) -> bool:
    """Whether ``sigma`` exceeds :data:`LOOSE_SIGMA` of the parameter's size."""
    size = max(abs(p.start), abs(value), 10 * p.unit_change)
    return sigma is not None and sigma / size > LOOSE_SIGMA


def _woken(
    model: _Model,
    theta: np.ndarray,
    at: np.ndarray,
    candidates: Sequence[Parameter],
    undetermined: Sequence[tuple[Parameter, str]],
) -> list[Parameter]:
    """The unmeasured candidates on which a row depends at ``theta`` (the fitted values)."""
    out = []
    for p, why in undetermined:
        if why != UNMEASURED or p not in candidates:
            continue
        k = candidates.index(p)
        step = theta.copy()
        step[k] += p.unit_change
        try:
            moved = np.max(np.abs(model(step) - at), initial=0.0)
        except CamtoolError:
            continue
        if moved >= SENSITIVITY_MM:
            out.append(p)
    return out


def _check_rows(observations: Sequence[Observation]) -> None:
    """Refuse a row whose value is far from its nominal: another unit, or a typing mistake."""
    for o in observations:
        ratio = o.value_mm / o.measure.nominal_mm if o.measure.nominal_mm > 0 else 1.0
        if 1 / ROW_RATIO <= ratio <= ROW_RATIO:
            continue
        where = f"line {o.line}, " if o.line else ""
        raise InputError(
            f"{where}{o.measure.id}: measured {fmt_num(o.value_mm, 4)} for a nominal of "
            f"{fmt_num(o.measure.nominal_mm, 4)} mm ({_factor_text(ratio)} it): "
            f"{_unit_cause(ratio)}; the measured_mm column is in millimetres"
        )


def _factor_text(ratio: float) -> str:
    return f"{ratio:.4g} times" if ratio >= 1 else f"1/{1 / ratio:.4g} of"


def _unit_cause(ratio: float) -> str:
    """The likely mistake behind values ``ratio`` times what a right sheet would hold."""
    for factor, cause in (
        (1000.0, "the values look like µm"),
        (1 / 25.4, "the values look like inches"),
        (0.001, "the values look like metres"),
        (10.0, "the values look like 0.1 mm units"),
        (0.1, "the values look like cm"),
        (25.4, "the values look like mm measured on an inch nominal"),
    ):
        if abs(ratio / factor - 1) < 0.05:
            return cause
    power = round(math.log2(ratio)) if ratio > 0 else 0
    if power and abs(ratio / 2.0**power - 1) < 0.05:
        n = 2 ** abs(power)
        typed = "doubled" if power > 0 else "halved, a radius for a diameter"
        return (
            f"the values look {n}× too {'large' if power > 0 else 'small'} ({typed}), or a "
            f"driver's microstepping is set {n}× off (fix that first)"
        )
    return "a typing mistake or another unit"


def _check_correction(params: Sequence[Parameter], theta: np.ndarray, limit: float) -> None:
    """Refuse a steps/mm correction beyond ``limit``, naming the likely cause."""
    for p, v in zip(params, (float(t) for t in theta), strict=True):
        if p.unit != "steps/mm" or abs(v / p.start - 1) <= limit:
            continue
        ratio = p.start / v  # how much longer the machine moves than it should
        raise InputError(
            f"{p.label} came out {_value_text(p, v)} steps/mm against the profile's "
            f"{_value_text(p, p.start)}: a correction of {(v / p.start - 1) * 100:+.1f} %, "
            f"beyond the ±{limit * 100:g} % a mis-set steps/mm explains; the machine moves "
            f"{_factor_text(ratio)} the nominal distances: {_unit_cause(ratio)}; if the machine "
            "really is that far off (a wrong lead, pulley or steps_per_mm in the profile), "
            "correct the profile's steps_per_mm first, or give --max-correction "
            f"{math.ceil(abs(v / p.start - 1) * 100 + 1)}"
        )


def _check_backlash_sign(
    params: Sequence[Parameter],
    theta: np.ndarray,
    residual: np.ndarray,
    jac: np.ndarray,
    observations: Sequence[Observation],
    machine: Machine,
) -> None:
    """Refuse a backlash held at 0 that the rows put clearly below 0.

    The fit keeps a backlash >= 0; at that bound the unconstrained linearised estimate
    (J at the fitted values) says how far below 0 the rows want it: more than 3 σ and more
    than a motor step (or 2 µm) means the rows contradict the model (swapped or mistyped
    rows, or a wrong compensation column), and the other parameters would absorb it.
    """
    if jac.size == 0:
        return
    scaled = jac * np.array([p.unit_change for p in params])
    delta_scaled, *_ = np.linalg.lstsq(scaled, residual, rcond=None)
    delta = delta_scaled * np.array([p.unit_change for p in params])
    dof = len(residual) - len(params)
    sigmas = _sigmas(jac, residual - jac @ delta, dof)
    for k, p in enumerate(params):
        if p.unit != "µm" or theta[k] > 1e-9:
            continue
        estimate = float(theta[k] + delta[k])
        axis = _backlash_axis(p, machine)
        floor = max(3 * (sigmas[k] or 0.0), 1000.0 / machine.real_steps_per_mm[axis], 2.0)
        if estimate >= -floor:
            continue
        rows = [o for o, d in zip(observations, jac[:, k], strict=True) if abs(d) > 1e-9]
        shown = ", ".join(
            f"{o.measure.id} {fmt_num(o.value_mm, 4)} mm" + (f" (line {o.line})" if o.line else "")
            for o in rows[:6]
        )
        sigma = f" ± {_value_text(p, sigmas[k] or 0.0)}" if sigmas[k] is not None else ""
        raise InputError(
            f"{p.label} comes out negative, {_value_text(p, estimate)}{sigma} µm: a backlash is "
            f">= 0, so these rows contradict the model ({shown}): a line cut after a reversal "
            "is longer than the compensation on the sheet can make it; check for swapped or "
            "mistyped rows (out/back), and that the compensation columns hold what each "
            "feature was cut with"
        )


def _backlash_axis(p: Parameter, machine: Machine) -> int:
    """The axis (0 = X, 1 = Y) of a backlash parameter, from its key."""
    index = int(p.key.split("[")[1].split("]")[0])
    if p.key.startswith("backlash.regions"):
        return AXES.index(machine.backlash.regions[index].axis)
    return index


def _settings(
    machine: Machine, fitted: Sequence[Parameter], overlay: Mapping[str, Any]
) -> tuple[str, ...]:
    """The controller settings that make the machine move true distances (fitted axes only)."""
    keys = {p.key for p in fitted}
    axes = [a for a in range(3) if f"true_steps_per_mm[{a}]" in keys]
    if JOINT_XY in keys:
        axes = sorted({0, 1, *axes})
    if not axes:
        return ()
    true = overlay["true_steps_per_mm"]
    if machine.steps_per_mm_settings:
        return tuple(
            machine.steps_per_mm_settings[a].replace("{}", fmt_num(true[a], 3)) for a in axes
        )
    new = [true[a] if a in axes else machine.steps_per_mm[a] for a in range(3)]
    return (f"steps_per_mm = {_array(new)}",)


def _refuse_confounded(
    confounded: Sequence[tuple[int, list[int]]],
    candidates: Sequence[Parameter],
    jac: np.ndarray,
    read: Sequence[ReadBack],
    machine: Machine,
    observations: Sequence[Observation],
) -> None:
    """Refuse parameters the rows depend on but cannot tell apart, naming the missing rows."""
    if not confounded:
        return
    k, partners = confounded[0]
    group = [k, *partners]
    labels = " and ".join(candidates[i].label for i in group)
    rows = sorted(
        {o.measure.id for i in group for o, d in zip(observations, jac[:, i], strict=True) if d}
    )
    missing = _rows_that_depend(read, machine, observations, [candidates[i] for i in group])
    measure = f"fill in {_ids_text(missing)} too" if missing else "add a feature that does"
    raise InputError(
        f"the sheet cannot tell {labels} apart: the filled-in rows that depend on them "
        f"({_ids_text(rows)}) change the same way with each, so fitting one would move the "
        f"other's error into it. To fit them, {measure}; or hold the profile's values "
        f"(--hold {'backlash' if candidates[k].unit == 'µm' else 'steps'}, said so in the "
        "overlay); or leave those rows empty"
    )


def _rows_that_depend(
    read: Sequence[ReadBack],
    machine: Machine,
    observations: Sequence[Observation],
    params: Sequence[Parameter],
) -> list[str]:
    """The coupon's rows not filled in on which any of ``params`` acts (at the profile)."""
    taken = {o.measure.id for o in observations}
    others = [Observation(m, m.nominal_mm) for r in read for m in r.feature.measures]
    others = [o for o in others if o.measure.id not in taken]
    if not others:
        return []
    model = _Model(read, machine, others, params)
    start = np.array([p.start for p in params])
    at = model(start)
    jac = _jacobian(model, start, at, params, [])
    moved = np.max(np.abs(jac * np.array([p.unit_change for p in params])), axis=1)
    return [o.measure.id for o, d in zip(others, moved, strict=True) if d >= SENSITIVITY_MM]


def _ids_text(ids: Sequence[str]) -> str:
    """Row ids grouped by feature: ``LY.p1…p10, UY.out, UY.back``."""
    groups: dict[str, list[str]] = {}
    for i in ids:
        feature, _, measure = i.partition(".")
        groups.setdefault(feature, []).append(measure)
    parts = []
    for feature, names in groups.items():
        if len(names) > 3:
            parts.append(f"{feature}.{names[0]}…{names[-1]}")
        else:
            parts += [f"{feature}.{n}" for n in names]
    return ", ".join(parts)


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
    confounded: list[tuple[int, list[int]]],
    undetermined: list[tuple[Parameter, str]],
    machine: Machine,
) -> tuple[list[int], np.ndarray, list[tuple[int, list[int]]]]:
    """Keep X's and Y's steps/mm, or fit them as one (:data:`JOINT_XY`) if only that is determined.

    Appends the joint parameter to ``candidates`` (and a column to the model) when it is used;
    then neither is confounded any more.
    """
    xy = [
        k
        for k, p in enumerate(candidates)
        if p.key in ("true_steps_per_mm[0]", "true_steps_per_mm[1]")
    ]
    kept = [k for k in xy if k in keep]
    if len(kept) == 2 or len(xy) < 2 or not any(k in xy for k, _ in confounded):
        return keep, jac, confounded
    joint = joint_xy(machine)
    ratio = candidates[xy[1]].start / candidates[xy[0]].start
    column = jac[:, xy[0]] + jac[:, xy[1]] * ratio
    others = [k for k in keep if k not in xy]
    rest = [(k, partners) for k, partners in confounded if k not in xy]
    candidates.append(joint)
    model.params.append(joint)
    trial_jac = np.hstack([jac, column[:, None]])
    order = [*others, len(candidates) - 1]
    ok, sub_confounded = _determined(
        trial_jac[:, order], [candidates[k] for k in order], [], report=False
    )
    if len(ok) != len(order) or sub_confounded:
        model.params.pop()
        candidates.pop()
        return keep, jac, confounded
    for k in xy:
        undetermined.append(
            (
                candidates[k],
                "not determined alone by these measurements (only with the other "
                "axis: fitted as one lead, see 'X and Y', Y keeping its ratio to X)",
            )
        )
    return sorted(order), trial_jac, rest


def _determined(
    jac: np.ndarray,
    params: Sequence[Parameter],
    undetermined: list[tuple[Parameter, str]],
    *,
    report: bool = True,
) -> tuple[list[int], list[tuple[int, list[int]]]]:
    """The parameters the measurements determine, and those they cannot tell apart.

    Returns the indices kept, and for each confounded parameter its index with the kept
    indices whose columns share its rows. An unmeasured parameter goes to
    ``undetermined`` (:data:`UNMEASURED`; when ``report``).
    """
    refused = {p.key for p, _ in undetermined}
    scaled = jac * np.array([p.unit_change for p in params])
    keep: list[int] = []
    confounded: list[tuple[int, list[int]]] = []
    for k, p in enumerate(params):
        if p.key in refused:
            continue
        if np.max(np.abs(scaled[:, k]), initial=0.0) < SENSITIVITY_MM:
            if report:
                undetermined.append((p, UNMEASURED))
            continue
        trial = [*keep, k]
        cols = scaled[:, trial] / np.linalg.norm(scaled[:, trial], axis=0)
        r = np.linalg.qr(cols, mode="r")
        pivots = np.abs(np.diag(r))
        if len(trial) > len(jac) or pivots.min() < PIVOT_RATIO * pivots.max():
            rows = np.abs(scaled[:, k]) >= SENSITIVITY_MM
            partners = [j for j in keep if np.any(np.abs(scaled[rows, j]) >= SENSITIVITY_MM)]
            confounded.append((k, partners))
            continue
        keep.append(k)
    return keep, confounded


def _levenberg_marquardt(
    run: Callable[[np.ndarray], np.ndarray],
    theta: np.ndarray,
    y: np.ndarray,
    jac: np.ndarray,
    params: Sequence[Parameter],
) -> tuple[np.ndarray, np.ndarray, int, np.ndarray]:
    """Minimise Σ (y − run(θ))²; returns θ, the prediction, the iterations and the Jacobian."""
    unit = np.array([p.unit_change for p in params])
    lower = np.array([0.0 if p.unit == "µm" else p.start / 10 for p in params])
    upper = np.array([1e5 if p.unit == "µm" else p.start * 10 for p in params])
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
            step = np.linalg.lstsq(h + lam * np.diag(np.diag(h)), g, rcond=None)[0]
            trial = np.clip(theta + step * unit, lower, upper)  # backlash >= 0, in RANGES
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
    lines += [f"  {line}" for line in caution_lines(result)]
    lines += [f"  {line}" for line in setting_lines(result)]
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


def unexplained(result: FitResult) -> list[Residual]:
    """The rows the fitted machine does not explain (:data:`UNEXPLAINED_MM`), worst first."""
    rows = [
        r
        for r in result.residuals
        if abs(r.residual_um)
        > 1000.0 * max(UNEXPLAINED_MM, UNEXPLAINED_SHARE * r.observation.measure.nominal_mm)
    ]
    return sorted(rows, key=lambda r: -abs(r.residual_um))


def caution_lines(result: FitResult) -> list[str]:
    """A caution, said before the settings, naming the rows :func:`unexplained` finds (or none)."""
    rows = unexplained(result)
    if not rows:
        return []
    named = ", ".join(
        f"{r.observation.measure.id} ({fmt_num(r.residual_um / 1000.0, 3)} mm)" for r in rows[:6]
    )
    more = f" and {len(rows) - 6} more" if len(rows) > 6 else ""
    return [
        f"caution: {len(rows)} of {len(result.residuals)} row(s) differ from the fitted machine "
        f"by more than {fmt_num(UNEXPLAINED_MM, 2)} mm and {UNEXPLAINED_SHARE * 100:g} % of "
        f"their nominal: {named}{more}; measure them again (a misread vernier, a row on the "
        "wrong line), or they show what the model has not (feed, timing, a loose part): the "
        "values fitted here rest on them too"
    ]


def setting_lines(result: FitResult) -> list[str]:
    """What to change so that the machine cuts true sizes (empty when no steps/mm was fitted)."""
    if not result.settings:
        return []
    where = (
        "the controller's setting"
        if not result.settings[0].startswith("steps_per_mm =")
        else "the profile's (the firmware's) value"
    )
    return [
        f"to cut true sizes, change {where}: {'  '.join(result.settings)}",
        "(the overlay describes the machine as it is set now: after the change, drop its "
        "true_steps_per_mm and cut the coupon again to check)",
    ]


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
        head.append(f"# not fitted: {p.label}: {why}; the profile's {_value_text(p, p.start)}")
    head += [f"# {line}" for line in caution_lines(result)]
    head += [f"# {line}" for line in setting_lines(result)]
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
