"""The fit recovers parameters it is given, says what it cannot determine, reads sheets strictly."""

from __future__ import annotations

import pytest

from camtool.calibrate.coupon import build_coupon
from camtool.calibrate.fit import UNMEASURED, fit, overlay_toml
from camtool.calibrate.fitdata import Observation
from camtool.calibrate.predict import predict, read_back
from camtool.calibrate.sheet import read_measurements, sheet_csv
from camtool.model.errors import InputError
from camtool.model.machine import machine_from_table, merge_tables
from camtool.post.registry import load_target

TRUE = {"true_steps_per_mm": [252.0, 248.5, 250.0], "backlash": {"true_um": [60.0, 35.0, 0.0]}}


@pytest.fixture(scope="module")
def synthetic():
    """A grbl machine with known errors: its own coupon, simulated, is the measurement."""
    target = load_target("grbl")
    coupon = build_coupon(target)
    read = read_back(coupon, target)
    true = machine_from_table(merge_tables(target.machine.table, TRUE), where="test")
    measured = predict(read, true)
    observations = [Observation(m, measured[m.id]) for m in coupon.measures]
    return target, read, fit(read, target.machine, observations, target="grbl")


def test_fit_recovers_known_steps_and_backlash(synthetic) -> None:
    _, _, result = synthetic
    assert result.value("true_steps_per_mm[0]") == pytest.approx(252.0, rel=2e-4)
    assert result.value("true_steps_per_mm[1]") == pytest.approx(248.5, rel=2e-4)
    assert result.value("true_steps_per_mm[2]") == pytest.approx(250.0, rel=2e-4)
    assert result.value("backlash.true_um[0]") == pytest.approx(60.0, abs=4.0)  # a step is 4 µm
    assert result.value("backlash.true_um[1]") == pytest.approx(35.0, abs=4.0)
    assert result.rms_after_um < 3.0 < result.rms_before_um
    assert all(f.sigma is not None for f in result.fitted)


def test_overlay_round_trips_through_the_machine_loader(synthetic, tmp_path) -> None:
    target, _, result = synthetic
    text = overlay_toml(result, source="measured.csv")
    assert text.startswith("# machine overlay fitted by `camtool calibrate fit -t grbl`")
    path = tmp_path / "m.toml"
    path.write_text(text)
    fitted = load_target("grbl", machine_file=path).machine
    assert fitted.real_steps_per_mm[0] == pytest.approx(result.value("true_steps_per_mm[0]"))
    assert fitted.backlash.true_um[0] == pytest.approx(result.value("backlash.true_um[0]"))
    assert fitted.backlash.compensation_um == target.machine.backlash.compensation_um


def test_nothing_depends_on_an_unmeasured_parameter() -> None:
    target = load_target("grbl")
    coupon = build_coupon(target)
    read = read_back(coupon, target)
    lx = [m for m in coupon.measures if m.id.startswith("LX.")]
    result = fit(read, target.machine, [Observation(m, m.nominal_mm * 1.01) for m in lx])
    undetermined = dict((p.key, why) for p, why in result.undetermined)
    assert undetermined["true_steps_per_mm[1]"] == UNMEASURED
    assert "backlash.true_um[0]" in undetermined  # a one-way move never reverses
    assert result.value("true_steps_per_mm[0]") == pytest.approx(250.0 / 1.01, rel=1e-4)


def _sheet(rows: list[str]) -> str:
    return "id,measured_mm,nominal_mm\n" + "\n".join(rows) + "\n"


@pytest.mark.parametrize(
    ("rows", "message"),
    [
        (["LX.p1,abc,"], r"m\.csv: line 2, column 'measured_mm': 'abc' is not a number"),
        (["LX.p1,nan,"], r"line 2, column 'measured_mm': 'nan' is not a number"),
        (["LX.p1,-1,"], r"line 2, column 'measured_mm'"),
        (["ZZ.p1,1,"], r"line 2, column 'id': unknown measure 'ZZ.p1'"),
        (["LX.p1,15,", "LX.p1,15,"], r"line 3, column 'id': 'LX.p1' repeats line 2"),
        (["LX.p1,15,16"], r"line 2, column 'nominal_mm'.*another coupon"),
    ],
)
def test_bad_sheets_name_file_line_and_column(rows: list[str], message: str) -> None:
    coupon = build_coupon(load_target("grbl"))
    with pytest.raises(InputError, match=message):
        read_measurements(_sheet(rows), coupon, source="m.csv")


def test_a_sheet_without_the_measured_column_is_refused() -> None:
    coupon = build_coupon(load_target("grbl"))
    with pytest.raises(InputError, match=r"line 1: no 'measured_mm' column"):
        read_measurements("id,value\nLX.p1,1\n", coupon, source="m.csv")


def test_the_template_reads_back_empty_and_the_compensation_column_is_kept() -> None:
    target = load_target("pic-mmh")
    coupon = build_coupon(target)
    template = sheet_csv(coupon, target.machine)
    assert read_measurements(template, coupon, source="t.csv") == []
    filled = template.replace("LX.p1,travel", "LX.p1,travel", 1)
    lines = filled.splitlines()
    lines[1] = lines[1].replace(",,204,178", ",0.81,0,0")
    got = read_measurements("\n".join(lines), coupon, source="t.csv")
    assert len(got) == 1 and got[0].value_mm == 0.81 and got[0].compensation_um == (0.0, 0.0)
