"""The fit fed the theses' own measurements recovers the theses' own conclusions.

Every measured number below is copied from docs/references.md (table and line
cited); every expected value is the thesis's conclusion or arithmetic on its numbers, never
camtool's output. The scatter each prediction is held to is the thesis's own, stated where it
is used.
"""

from __future__ import annotations

import statistics
from dataclasses import replace

import pytest

from camtool.calibrate.coupon import (
    Feature,
    circle,
    coupon_from_features,
    long_move,
    long_move_z,
    rectangle,
    u_pattern,
)
from camtool.calibrate.fit import UNMEASURED, fit
from camtool.calibrate.fitdata import JOINT_XY, FitResult, Observation
from camtool.calibrate.predict import ReadBack, predict, read_back
from camtool.model.errors import InputError
from camtool.model.machine import Machine, machine_from_table, merge_tables
from camtool.post.base import Target
from camtool.post.registry import load_target

STEPS_000 = 1 / 0.00014  # 140 nm/step, UNAM-GMM §2.1


def _with(machine: Machine, overlay: dict) -> Machine:
    return machine_from_table(merge_tables(machine.table, overlay), where="test")


def _read(target: Target, features: list[Feature]) -> tuple[ReadBack, ...]:
    return read_back(coupon_from_features(target, features), target)


def _by_id(result: FitResult) -> dict[str, tuple[float, float, float]]:
    return {
        r.observation.measure.id: (r.observation.value_mm, r.before_mm, r.after_mm)
        for r in result.residuals
    }


# --- UNAM-GMM ------------------------------------------------------------------------------------

# Tabla 13 (UNAM-GMM §5.2, L2387-L2423): (region row, experimental length mm, backlash µm).
# The U pattern's first line is cut after the approach: its length is the "experimental" one;
# the second loses the backlash: experimental − backlash (the thesis's own definition: "la
# diferencia de las longitudes de las dos rectas"). Cut without compensation (the compensation
# 192.5/168.5 µm was derived from this table).
TABLA_13_X = [(0.8, 2.509, 190.0), (3.2, 2.503, 201.0), (5.6, 2.502, 187.0)]  # H1, H2, H3
TABLA_13_Y = [(1.0, 1.205, 152.0), (4.4, 1.203, 180.0), (7.8, 1.199, 173.0)]  # V1, V2, V3
# The thesis's own scatter of nominally equal lines: the spread of the three first-line lengths.
SPREAD_13_X_UM = (2.509 - 2.502) * 1000  # 7 µm
SPREAD_13_Y_UM = (1.205 - 1.199) * 1000  # 6 µm


@pytest.fixture(scope="module")
def pic() -> Target:
    return load_target("pic-mmh")


@pytest.fixture(scope="module")
def tabla_13(pic: Target) -> FitResult:
    feed, a = pic.default_feed_mm_min, 0.31
    features, observations = [], []
    for axis, rows in ((0, TABLA_13_X), (1, TABLA_13_Y)):
        for i, (where, experimental, backlash_um) in enumerate(rows, start=1):
            start = (3.75, where) if axis == 0 else (where, 2.9)
            length = 2.5 if axis == 0 else 1.2
            f = u_pattern(f"U{'XY'[axis]}-{i}", axis, start, length, 0.5, a, feed)
            features.append(f)
            out, back = f.measures
            observations += [
                Observation(out, experimental, (0.0, 0.0)),
                Observation(back, experimental - backlash_um / 1000, (0.0, 0.0)),
            ]
    return fit(_read(pic, features), pic.machine, observations, target="pic-mmh")


def test_tabla_13_recovers_the_backlash_of_every_region(tabla_13: FitResult) -> None:
    regions = [r[2] for r in TABLA_13_X] + [r[2] for r in TABLA_13_Y]
    for i, thesis_um in enumerate(regions):
        fitted = tabla_13.value(f"backlash.regions[{i}].true_um")
        spread = SPREAD_13_X_UM if i < 3 else SPREAD_13_Y_UM
        assert abs(fitted - thesis_um) <= spread, (i, fitted, thesis_um)
    # the mean the thesis compensated with first: 192.5 (X) and 168.5 (Y), ±0.5 (its rounding)
    x = statistics.mean(tabla_13.value(f"backlash.regions[{i}].true_um") for i in range(3))
    y = statistics.mean(tabla_13.value(f"backlash.regions[{i}].true_um") for i in range(3, 6))
    assert x == pytest.approx(192.5, abs=0.5 + SPREAD_13_X_UM / 3)
    assert y == pytest.approx(168.5, abs=0.5 + SPREAD_13_Y_UM / 3)
    # the global value outside the regions: no U pattern lies there
    assert {p.key for p, _ in tabla_13.undetermined} >= {"backlash.true_um[0]"}
    # every line predicted within the thesis's scatter of equal lines
    for r in tabla_13.residuals:
        spread = SPREAD_13_X_UM if r.observation.measure.axis == 0 else SPREAD_13_Y_UM
        assert abs(r.residual_um) <= spread
    assert all(f.sigma is not None and f.sigma < 15 for f in tabla_13.fitted)


def test_tabla_14_contradicts_tabla_13(pic: Target) -> None:
    """Tabla 14's squares, cut with 192.5/168.5 µm compensation, came out up to 16 µm short in X.

    Tabla 13's regional backlash is at most 201 µm in X, so under 192.5 µm of compensation no
    square anywhere can lose more than 201 − 192.5 = 8.5 µm of its X edge. The thesis measured
    Dx = 2.489 and 2.484 mm (11 and 16 µm short, L2436-L2479) and raised the compensation to
    204 µm, above every X backlash Tabla 13 found: the two tables cannot both hold.
    """
    machine = _with(pic.machine, {"backlash": {"compensation_um": [192.5, 168.5, 0.0]}})
    feed, a = pic.default_feed_mm_min, 0.31
    squares = [
        rectangle(f"S{i}{j}", (x, y), (2.5, 2.5), a, feed)
        for i, x in enumerate((0.5, 3.5, 6.8))  # corners in V1, V2, V3
        for j, y in enumerate((0.4, 2.45, 4.7))  # edges in H1, H2, H3
    ]
    predicted = predict(_read(pic, squares), machine)
    shortfall_um = [(2.5 - predicted[f"{s.id}.dx"]) * 1000 for s in squares]
    bound_um = 201.0 - 192.5
    assert max(shortfall_um) <= bound_um + 0.5  # + half a step of rounding
    measured_dx = (2.489, 2.484, 2.497)  # Tabla 14
    assert [round((2.5 - d) * 1000) for d in measured_dx if (2.5 - d) * 1000 > bound_um] == [11, 16]
    assert max(r[2] for r in TABLA_13_X) < 192.5 + 11.5  # the new 204 µm exceeds 201


# Tabla 15 (UNAM-GMM §6.3, L2528-L2594): mean diameters and sample σ of 8 diameters, cut
# clockwise with 204/178 µm compensation.
TABLA_15 = [(6.0, 5.958, 0.035), (4.0, 3.982, 0.022), (2.0, 1.991, 0.020)]


@pytest.fixture(scope="module")
def circles(pic: Target) -> tuple[tuple[ReadBack, ...], list[Observation]]:
    feed, a = pic.default_feed_mm_min, 0.31
    rings = [circle(f"C{d:g}", (5.0, 3.5), d, a, feed) for d, _, _ in TABLA_15]
    observations = [
        Observation(ring.measures[2], mean, (204.0, 178.0))
        for ring, (_, mean, _) in zip(rings, TABLA_15, strict=True)
    ]
    return _read(pic, rings), observations


@pytest.fixture(scope="module")
def tabla_15(pic: Target, circles: tuple[tuple[ReadBack, ...], list[Observation]]) -> FitResult:
    read, observations = circles
    return fit(read, pic.machine, observations, target="pic-mmh")


def test_tabla_15_circles_fit_one_screw_lead(tabla_15: FitResult) -> None:
    by_id = _by_id(tabla_15)
    # before: the nominal 140 nm step predicts ~6/4/2 mm: the measured circles are 42/18/9 µm
    # smaller (UNAM-GMM §6.3 [derived]: mean diameter errors −42, −18, −9 µm)
    for (d, _, sigma), expected_um in zip(TABLA_15, (42, 18, 9), strict=True):
        measured, before, after = by_id[f"C{d:g}.mean"]
        assert (before - measured) * 1000 == pytest.approx(expected_um, abs=1.5)
        # after: within the thesis's own scatter, the standard error of its mean of 8 diameters
        assert abs(after - measured) <= sigma / 8**0.5
    # the circles cannot tell X's lead from Y's: one lead for both
    lead = tabla_15.value(JOINT_XY)
    undetermined = {p.key for p, _ in tabla_15.undetermined}
    assert {"true_steps_per_mm[0]", "true_steps_per_mm[1]"} <= undetermined
    # a finer step than 140 nm: 0.497 mm per output revolution (3584 steps) instead of 0.502
    assert 7170 < lead < 7205
    assert 3584 / lead == pytest.approx(0.4987, abs=0.0015)


def test_the_issue_lead_of_7168_steps_per_mm_brings_o4_and_o2_within_5_um(
    pic: Target, circles: tuple[tuple[ReadBack, ...], list[Observation]]
) -> None:
    read, observations = circles
    # a 0.5 mm screw: 28 steps × 128 / 0.5 mm = 7168 steps/mm (UNAM-GMM §2.1 [derived])
    machine = _with(pic.machine, {"true_steps_per_mm": [7168.0, 7168.0, STEPS_000]})
    machine = _with(machine, {"backlash": {"compensation_um": [204.0, 178.0, 0.0]}})
    predicted = predict(read, machine)
    gaps = [abs(predicted[o.measure.id] - o.value_mm) * 1000 for o in observations]
    # the issue says "within 4 µm"; the verifier finds ø4 4.4 µm and ø2 2.2 µm off (the
    # compensation overshoot at the quadrants adds to the pure scale)
    assert gaps[1] <= 5 and gaps[2] <= 4
    assert 15 < gaps[0] < 25  # ø6 stays ~21 µm off: 7168 is not the least-squares lead


# --- Yanez-07 ------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def flashcut() -> Target:
    return load_target("flashcut")


@pytest.fixture(scope="module")
def rectangle_10x5(flashcut: Target) -> tuple[FitResult, Machine, tuple[ReadBack, ...]]:
    """Yanez-07 §6.1 (L1568-L1570): the 10 × 5 rectangle measured 9.897 × 4.906 mm."""
    feed = flashcut.default_feed_mm_min
    rect = rectangle("R", (3.0, 3.0), (10.0, 5.0), 1.0, feed)
    ring = circle("C10", (10.0, 22.0), 10.0, 1.0, feed)
    read = _read(flashcut, [rect, ring])
    # start from the application's own constant, 1.9 µm (Yanez-07 §4.5), as a user would
    nominal = _with(flashcut.machine, {"true_steps_per_mm": list(flashcut.machine.steps_per_mm)})
    observations = [Observation(rect.measures[0], 9.897), Observation(rect.measures[1], 4.906)]
    # each edge depends on its axis's steps/mm and backlash alike: the thesis put the whole
    # shortfall on the step size (R14), i.e. it held the backlash; the fit does so only if told
    with pytest.raises(InputError, match=r"cannot tell backlash X and true steps/mm X apart"):
        fit(read[:1], nominal, observations, target="flashcut")
    result = fit(read[:1], nominal, observations, target="flashcut", only=lambda p: p.unit != "µm")
    return result, nominal, read


def test_seed_001_rectangle_finds_the_1_88_um_step(
    rectangle_10x5: tuple[FitResult, Machine, tuple[ReadBack, ...]],
) -> None:
    result, _, _ = rectangle_10x5
    step_x = 1000 / result.value("true_steps_per_mm[0]")
    step_y = 1000 / result.value("true_steps_per_mm[1]")
    # R14: 5263 steps × 1.88 µm = 9.894 mm ≈ 9.897 measured; the thesis's own implied steps of
    # this part are 1.880 and 1.864 µm (Yanez-07 §6.1 [INFERENCE]), both below the 1.9 assumed
    assert step_x == pytest.approx(1.880, abs=0.002)
    assert step_y == pytest.approx(1.864, abs=0.002)
    # two measurements, two parameters: no residual variance, so no σ; backlash not separable
    assert result.dof == 0 and all(f.sigma is None for f in result.fitted)
    assert {"backlash.true_um[0]", "backlash.true_um[1]"} <= {p.key for p, _ in result.undetermined}


def test_seed_001_circle_stays_unexplained(
    flashcut: Target, rectangle_10x5: tuple[FitResult, Machine, tuple[ReadBack, ...]]
) -> None:
    """The ø10 circle came out 9.004 × 9.123 mm at P = 20 ms (L1612); nothing the coupon fits
    explains a 0.9 mm undersize (the thesis does not either, Yanez-07 §6.2)."""
    result, nominal, read = rectangle_10x5
    fitted = _with(nominal, dict(result.overlay))
    for machine in (flashcut.machine, fitted):
        predicted = predict(read[1:], machine)
        assert predicted["C10.h"] - 9.004 > 0.7
        assert predicted["C10.v"] - 9.123 > 0.6


# --- Munoz-22 ------------------------------------------------------------------------------------

# Tables 14-16 (Munoz-22 §5.2, L1647-L1682): position after each of ten 8 mm moves, mm.
TABLE_16_X = [8.08, 16.19, 24.23, 32.29, 40.35, 48.41, 56.53, 64.61, 72.70, 80.76]
TABLE_15_Y = [8.09, 16.19, 24.23, 32.28, 40.36, 48.48, 56.60, 64.71, 72.75, 80.86]
TABLE_14_Z = [8.05, 16.09, 24.21, 32.20, 40.29, 48.44, 56.52, 64.57, 72.61, 80.60]
# The thesis's own stated scatter per revolution: (8.00 ± 0.08) X, ± 0.09 Y, ± 0.06 Z (L1656-L1690)
PLUS_MINUS = {0: 0.08, 1: 0.09, 2: 0.06}


@pytest.fixture(scope="module")
def valcnc() -> FitResult:
    target = load_target("valcnc")
    feed, a = target.default_feed_mm_min, 2.0
    features = [
        long_move("LX", 0, (20.0, 20.0), 8.0, a, feed),
        long_move("LY", 1, (10.0, 40.0), 8.0, a, feed),
        long_move_z("LZ", (150.0, 150.0), 8.0, a, feed),
    ]
    observations = [
        Observation(m, v)
        for f, values in zip(features, (TABLE_16_X, TABLE_15_Y, TABLE_14_Z), strict=True)
        for m, v in zip(f.measures, values, strict=True)
    ]
    return fit(_read(target, features), target.machine, observations, target="valcnc")


def test_seed_004_finds_the_scale_of_each_axis(valcnc: FitResult) -> None:
    scale = [25.0 / valcnc.value(f"true_steps_per_mm[{a}]") for a in range(3)]
    # the thesis's mean travel per revolution (its end point over 10 moves: 8.076, 8.086,
    # 8.060 mm) within its own ± per revolution
    for axis, end in enumerate((80.76, 80.86, 80.60)):
        assert 8.0 * scale[axis] == pytest.approx(end / 10, abs=PLUS_MINUS[axis])
    assert scale[1] == pytest.approx(80.86 / 80, abs=0.0005)
    # every position predicted within the thesis's ± per revolution; Z's own data depart up to
    # 0.072 mm from any straight line (Munoz-22 §5.3 [derived]), more than its stated ± 0.06
    scatter = {**PLUS_MINUS, 2: 0.072}
    for r in valcnc.residuals:
        assert abs(r.residual_um) / 1000 <= scatter[r.observation.measure.axis]
    assert all(f.sigma is not None for f in valcnc.fitted)


def test_seed_004_never_measured_backlash(valcnc: FitResult) -> None:
    # only + moves (Munoz-22 §5.3: "Not tested: backlash"): nothing depends on it
    reasons = dict((p.key, why) for p, why in valcnc.undetermined)
    assert reasons["backlash.true_um[0]"] == UNMEASURED


def test_observations_keep_their_compensation(pic: Target) -> None:
    # the same U pattern cut with and without compensation predicts different back lines
    f = u_pattern("U", 0, (3.75, 0.8), 2.5, 0.5, 0.31, 0.8)
    read = _read(pic, [f])
    off = predict(read, _with(pic.machine, {"backlash": {"compensation_um": [0.0, 0.0, 0.0]}}))
    assert off["U.out"] - off["U.back"] == pytest.approx(0.190, abs=0.0002)  # H1: 190 µm
    on = predict(read, pic.machine)
    assert on["U.back"] - on["U.out"] == pytest.approx(0.014, abs=0.0002)  # 204 − 190 over
    assert replace(f).id == "U"


def test_the_theses_rows_are_all_explained(
    valcnc: FitResult, tabla_13: FitResult, tabla_15: FitResult
) -> None:
    """No row of Munoz-22's tables 14-16 or UNAM-GMM's tablas 13 and 15 draws a caution."""
    from camtool.calibrate.fit import unexplained

    for result in (valcnc, tabla_13, tabla_15):
        worst = max(abs(r.residual_um) for r in result.residuals)
        assert not unexplained(result), worst
        assert worst < 100.0  # within 0.1 mm, as the threshold's note says
