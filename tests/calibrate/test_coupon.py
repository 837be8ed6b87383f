"""The coupon: every target writes one that reads back; the sheet lists every measure."""

from __future__ import annotations

import csv
import io

import pytest

from camtool.calibrate import make_coupon
from camtool.calibrate.coupon import build_coupon, u_pattern
from camtool.calibrate.predict import predict, read_back
from camtool.model.errors import UsageError
from camtool.model.machine import machine_from_table, merge_tables
from camtool.model.program import Rapid
from camtool.post.registry import load_target
from tests.targets import TARGETS


@pytest.mark.parametrize("name", TARGETS)
def test_every_target_writes_a_coupon_that_reads_back(name: str) -> None:
    target = load_target(name)
    files = make_coupon(target)
    coupon = files.coupon
    back = target.parse(files.code)
    assert back.moves
    # inside the travel, every feature kept whole by the dialect
    x0, y0, x1, y1 = target.machine.work_area_mm
    bx0, by0, bx1, by1 = coupon.program.bbox()
    assert x0 <= bx0 and y0 <= by0 and bx1 <= x1 and by1 <= y1
    ids = {f.id for f in coupon.features}
    assert {"LX", "LY", "SQ1", "SQ2", "SQ3", "C6", "C4", "C2"} <= ids
    assert ("LZ" in ids) == target.machine.has_z
    # one U pattern per axis and backlash region of the profile (one per axis without regions)
    regions = target.machine.backlash.regions
    for axis in "xy":
        mine = [r for r in regions if r.axis == axis]
        u = [i for i in ids if i.startswith(f"U{axis.upper()}")]
        assert len(u) == max(1, len(mine))
    # the sheet: one CSV row and one Markdown row per measure
    rows = list(csv.DictReader(io.StringIO(files.csv)))
    assert [r["id"] for r in rows] == [m.id for m in coupon.measures]
    assert all(r["measured_mm"] == "" for r in rows)
    for m in coupon.measures:
        assert f"| {m.id} |" in files.markdown


def test_pic_mmh_u_patterns_sit_in_their_regions() -> None:
    target = load_target("pic-mmh")
    coupon = build_coupon(target)
    regions = [r for r in target.machine.backlash.regions]
    for feature in coupon.features:
        if not feature.id.startswith("U"):
            continue
        axis = feature.id[1].lower()
        region = [r for r in regions if r.axis == axis][int(feature.id[-1]) - 1]
        x0, y0, x1, y1 = feature.bbox()
        assert region.contains(x0, y0) and region.contains(x1, y1)


def test_a_perfect_machine_predicts_the_nominal_values() -> None:
    """grbl's profile has no backlash and exact steps: every measure is its nominal value.

    A length is within a step (4 µm); a diameter is a width between two sides, each within a
    step and a chord's sagitta ($12 = 2 µm): 12 µm."""
    target = load_target("grbl")
    coupon = build_coupon(target)
    predicted = predict(read_back(coupon, target), target.machine)
    for m in coupon.measures:
        tol = 0.012 if m.kind == "diameter" else 0.004
        assert predicted[m.id] == pytest.approx(m.nominal_mm, abs=tol)


def test_u_pattern_shows_an_uncompensated_backlash() -> None:
    # analytic: the back line is shorter than the out line by the true backlash (Yanez-07 §5)
    target = load_target("grbl")
    machine = machine_from_table(
        merge_tables(target.machine.table, {"backlash": {"true_um": [120.0, 80.0, 0.0]}}),
        where="test",
    )
    feed = target.default_feed_mm_min
    features = [
        u_pattern("UX", 0, (10, 10), 20, 2, 4, feed),
        u_pattern("UY", 1, (40, 10), 20, 2, 4, feed),
    ]
    from camtool.calibrate.coupon import coupon_from_features

    read = read_back(coupon_from_features(target, features), target)
    p = predict(read, machine)
    assert p["UX.out"] - p["UX.back"] == pytest.approx(0.120, abs=0.004)
    assert p["UY.out"] - p["UY.back"] == pytest.approx(0.080, abs=0.004)
    assert p["UX.out"] == pytest.approx(20.0, abs=0.004)


def test_a_travel_too_small_is_refused_with_the_size_needed() -> None:
    target = load_target("pic-mmh")
    small = machine_from_table(
        merge_tables(target.machine.table, {"work_area_mm": [0.0, 0.0, 1.0, 0.7]}), where="t"
    )
    from dataclasses import replace

    with pytest.raises(UsageError, match=r"too small for a calibration coupon.*--machine"):
        build_coupon(replace(target, machine=small))


@pytest.mark.parametrize("name", ["grbl", "linuxcnc", "valcnc", "i8751", "flashcut"])
def test_a_z_coupon_starts_and_ends_like_every_planned_program(name: str) -> None:
    """toolpath/passes.py's convention: a Z-only rise to clearance (5 mm) where the tool
    stands, XY at clearance, down to safe Z; nothing ever descends by a rapid below the
    rapids' height; the last move leaves the tool at or above clearance."""
    target = load_target(name)
    program = build_coupon(target).program
    first, second, third = program.moves[:3]
    assert (first.x, first.y, first.z) == (*program.origin, 5.0)
    assert second.z is None and third.z == 2.0
    heights = [m.z for m in program.moves if m.z is not None]
    assert heights[-1] >= 5.0
    rapids_down = [m.z for m in program.moves if isinstance(m, Rapid) and m.z is not None]
    assert min(rapids_down) == 2.0


@pytest.mark.parametrize(("name", "rpm"), [("grbl", 1000.0), ("linuxcnc", 12000.0)])
def test_the_spindle_runs_for_the_whole_coupon(name: str, rpm: float) -> None:
    from camtool.model.program import Rapid, Spindle

    program = build_coupon(load_target(name)).program
    spindle = [(i, c) for i, c in program.commands if isinstance(c, Spindle)]
    # it starts once the tool has risen off the stock's top (a Z-only rapid), before any
    # move in X or Y
    assert spindle[0][0] == 1 and spindle[0][1].rpm == rpm and spindle[0][1].direction == "cw"
    rise = program.moves[0]
    assert isinstance(rise, Rapid) and (rise.x, rise.y) == program.origin and rise.z > 0
    assert spindle[-1] == (len(program.moves), Spindle("off"))


def _scale(target, width: float, height: float) -> float:
    """The coupon's scale in a ``width`` x ``height`` mm work area (0: refused as too small)."""
    from dataclasses import replace

    machine = machine_from_table(
        merge_tables(target.machine.table, {"work_area_mm": [0.0, 0.0, width, height]}), where="t"
    )
    try:
        return build_coupon(replace(target, machine=machine)).scale
    except UsageError:
        return 0.0


@pytest.mark.parametrize("name", TARGETS)
def test_a_100_by_70_mm_travel_gets_a_coupon(name: str) -> None:
    """A common small router; pic-mmh's regions (sized for its 10 x 7 mm) stay inside it."""
    assert _scale(load_target(name), 100.0, 70.0) >= 1.0


SIDES = (3.0, 5.0, 7.0, 10.0, 14.0, 20.0, 30.0, 45.0, 70.0, 100.0, 150.0, 220.0, 330.0)


@pytest.mark.parametrize("name", ["grbl", "pic-mmh", "valcnc", "matlab-router"])
def test_the_scale_never_decreases_when_the_travel_grows(name: str) -> None:
    """Property: over a grid of travels, a wider or taller work area never gets a smaller
    coupon (the scale is monotonic non-decreasing in each side), and a travel ten times
    another's gets a larger coupon until the largest (10×)."""
    target = load_target(name)
    grid = {(w, h): _scale(target, w, h) for w in SIDES for h in SIDES}
    for (w, h), s in grid.items():
        i, j = SIDES.index(w), SIDES.index(h)
        if i + 1 < len(SIDES):
            assert s <= grid[(SIDES[i + 1], h)], (w, h)
        if j + 1 < len(SIDES):
            assert s <= grid[(w, SIDES[j + 1])], (w, h)
    squares = [grid[(side, side)] for side in SIDES]
    for small, large in zip(squares, squares[6:], strict=False):
        assert large > small or large == 10 or small == 0
