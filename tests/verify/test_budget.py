"""The error budget by source and the errors along the path (issue 16, part A)."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path

import numpy as np
import pytest

from camtool.cli.main import main
from camtool.model.machine import Backlash
from camtool.model.program import ArcMove, Linear, Program, Rapid
from camtool.post.registry import load_target
from camtool.verify.budget import NOTE
from camtool.verify.report import report_dict, seconds_6, summary_lines
from camtool.verify.sources import ALL, SOURCES
from camtool.verify.trace_sources import simulate
from camtool.verify.verifier import verify_code, verify_program

# what this file checks is done by the accelerated versions only (docs/architecture.md)
pytestmark = pytest.mark.usefixtures("accel_on")

D_MM = 10.0
DIAMETER = "contour 1 diameter error"


def _circle10() -> Program:
    """A ø10 mm CCW circle about (10, 10) mm, inside the flashcut's 20 × 35 mm."""
    return Program((Rapid(15, 10, contour=1), ArcMove(15, 10, 10, 10, False, 3.0, contour=1)))


def test_budget_scale_share_of_a_circle_is_d_times_k_minus_1() -> None:
    """Yanez-07 R14: the app assumes 1.9 µm/step, the machine makes 1.88 µm.

    Without backlash the carriage with the scale on is the carriage with it off
    times k = nominal/true steps/mm (same motor rows), and a least-squares circle
    scales with it: total = k·(D + e_off) − D, so the scale's difference is exactly
    (k − 1)·(D + e_off) ≈ D·(k − 1) = −105.3 µm.
    """
    target = load_target("flashcut")
    machine = dataclasses.replace(target.machine, backlash=Backlash())
    v = verify_program(_circle10(), machine, name="flashcut")
    b = v.error_budget
    k = machine.steps_per_mm[0] / machine.real_steps_per_mm[0]
    e_off = b.without["scale"][DIAMETER]
    assert b.difference("scale", DIAMETER) == pytest.approx(
        (k - 1.0) * (D_MM * 1000.0 + e_off), abs=1e-6
    )
    assert D_MM * 1000.0 * (k - 1.0) == pytest.approx(-105.26, abs=0.01)
    assert b.difference("scale", DIAMETER) == pytest.approx(-105.26, abs=1.0)
    assert b.dominant(DIAMETER) == "scale"
    assert "backlash" not in b.without  # the profile has none now: absent, not 0
    status = {s.name: s.status for s in b.sources}
    assert status == {
        "interpolation": "modelled",
        "chords": "modelled",
        "scale": "modelled",
        "backlash": "absent",
        "dynamics": "modelled",
        "rounding": "unknown",
    }


def test_issue_example_scale_dominates_while_overshoot_partly_cancels_it() -> None:
    """The flashcut profile as shipped: the scale (−105 µm) dominates the ø10 circle's
    diameter error; the timer overshoot pushes the other way, so the total is smaller."""
    v = verify_program(_circle10(), load_target("flashcut").machine, name="flashcut")
    b = v.error_budget
    total = b.total[DIAMETER]
    assert b.dominant(DIAMETER) == "scale"
    assert b.difference("scale", DIAMETER) == pytest.approx(-105.3, abs=2.0)
    assert b.difference("dynamics", DIAMETER) > 0  # overshoot: the other axis over-steps
    assert -105.3 < total < 0
    text = b.dominant_text(DIAMETER)
    assert text is not None and text.startswith(f"{DIAMETER}: dominant steps/mm scale (")
    lines = "\n".join(summary_lines(v))
    assert "sources do not add" in lines and "not known from the code alone" in lines
    report = report_dict(v)["error_budget"]
    assert report["note"] == NOTE and "do not add" in report["note"]
    row = next(r for r in report["figures"] if r["figure"] == DIAMETER)
    assert row["dominant"] == "scale"
    assert row["difference_um"]["scale"] == pytest.approx(
        row["total_um"] - row["without_um"]["scale"], abs=1e-3
    )
    assert [s["source"] for s in report["sources"]] == list(SOURCES)


def test_rounding_is_known_with_the_plan_and_zero_when_the_plan_is_the_code() -> None:
    target = load_target("pic-mmh")
    program = target.post.parse(U_CODE, source="u.pic")
    v = verify_program(program, target.machine, name="pic-mmh", planned=program)
    b = v.error_budget
    assert {s.name: s.status for s in b.sources}["rounding"] == "modelled"
    assert all(b.difference("rounding", f) == 0.0 for f in b.total)
    # the GMM profile has no true steps/mm and its DDA models no dynamics
    assert {s.name: s.status for s in b.sources}["scale"] == "absent"
    assert {s.name: s.status for s in b.sources}["dynamics"] == "absent"


def test_ideal_controller_follows_lines_and_native_arcs_exactly() -> None:
    """Interpolation off: no staircase and no rounding to steps, so (without backlash)
    every point lies on its programmed line or arc."""
    target = load_target("pic-mmh")
    machine = dataclasses.replace(target.machine, backlash=Backlash())
    program = Program(
        (
            Rapid(1.0, 1.0, contour=1),
            Linear(3.0001, 2.2, 0.8, contour=1),
            ArcMove(2.0001, 2.2, 2.5001, 2.2, True, 0.8, contour=1),
        )
    )
    full = verify_program(program, machine, name="pic-mmh")
    off = full.error_budget.without["interpolation"]
    assert full.deviation.max_um > 0.05  # the DDA and DSM staircases: about a step (0.14 µm)
    assert off["max deviation"] < 1e-6
    trace = simulate(program, machine, sources=ALL.without("interpolation"))
    end = trace.carriage_mm[-1]
    assert math.dist(end, (2.0001, 2.2)) < 1e-9  # no rounding of the end to whole steps


# UNAM-GMM §5.2: the U pattern (two 2.5 mm lines along X joined by a 1 mm line); on the
# return leg an uncompensated X backlash of 190 µm (Tabla 13, figure A) is taken up by the
# motor while the carriage stands, so the leg ends 190 µm short of X = 1.
U_CODE = (
    "G54;\nG90;\nG00X01000.00Y01000.00;\nG01X03500.00Y01000.00F08;\n"
    "G01X03500.00Y02000.00F08;\nG01X01000.00Y02000.00F08;\n"
)
U_OVERLAY = (
    "[machine.backlash]\ntrue_um = [190.0, 0.0, 0.0]\ncompensation_um = [0.0, 0.0, 0.0]\n"
    "regions = []\n"
)


def _u_verification() -> object:
    target = load_target("pic-mmh")
    lash = Backlash(true_um=(190.0, 0.0, 0.0), compensation_um=(0.0, 0.0, 0.0))
    machine = dataclasses.replace(target.machine, backlash=lash)
    return verify_code(U_CODE, dataclasses.replace(target, machine=machine), source="u.pic")


def test_u_pattern_shortfall_is_the_uncompensated_backlash() -> None:
    v = _u_verification()
    assert v.deviation.max_um < 1.0  # blind: the carriage never leaves the path
    assert v.along is not None
    # 190 µm within a step of the rounded start and end (140 nm) and the band in steps
    assert v.along.shortfall_um == pytest.approx(190.0, abs=0.2)
    assert v.along.shortfall_at_mm == pytest.approx((1.0, 2.0))
    assert v.program.line_of(v.along.shortfall_block) == 6
    assert v.along.block_end_um == pytest.approx(190.0, abs=0.2)
    assert v.along.contour_end_um[0] == pytest.approx(190.0, abs=0.2)
    assert v.max_error_um == pytest.approx(v.along.shortfall_um)
    assert v.over_limit(50.0) is not None
    b = v.error_budget
    assert b.dominant("shortfall along the path") == "backlash"
    assert b.without["backlash"]["shortfall along the path"] < 0.2
    report = report_dict(v)
    assert report["shortfall_um"]["at"]["line"] == 6
    assert report["max_error_um"] == pytest.approx(190.0, abs=0.2)
    assert report["contours"][0]["end_error_um"] == pytest.approx(190.0, abs=0.2)


def test_u_pattern_fails_max_error_at_the_cli(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, lash = tmp_path / "u.pic", tmp_path / "lash.toml"
    code.write_text(U_CODE)
    lash.write_text(U_OVERLAY)
    report = tmp_path / "r.json"
    args = ["verify", str(code), "-t", "pic-mmh", "--machine", str(lash), "--report", str(report)]
    assert main([*args, "--max-error-um", "50"]) == 4
    err = capsys.readouterr().err
    assert "shortfall max 190.0" in err and "exceeds --max-error-um 50" in err
    data = json.loads(report.read_text())
    assert data["shortfall_um"]["max"] == pytest.approx(190.0, abs=0.2)
    assert data["error_budget"]["dominant"].startswith("shortfall along the path: dominant")
    assert main([*args, "--max-error-um", "200"]) == 0


def test_no_budget_skips_the_resimulation(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, report = tmp_path / "u.pic", tmp_path / "r.json"
    code.write_text(U_CODE)
    args = ["verify", str(code), "-t", "pic-mmh", "--no-budget", "--report", str(report)]
    assert main(args) == 0
    assert "error budget skipped: switched off (--no-budget)" in capsys.readouterr().err
    budget = json.loads(report.read_text())["error_budget"]
    assert (
        budget["skipped"] == "switched off (--no-budget)"
        and budget["figures"][0]["without_um"] == {}
    )


def test_pic_mmh_warns_about_the_166_hz_cap_by_line() -> None:
    """UNAM-GMM §2.4/§4.9: f = d·F/60 at d = 1e6/140 steps/mm; F13 = 1.3 mm/min asks
    154.8 Hz (under 166 Hz), F14 = 1.4 mm/min asks 166.7 Hz (capped)."""
    target = load_target("pic-mmh")
    code = (
        "G54;\nG90;\nG00X01000.00Y01000.00;\nG01X02000.00Y01000.00F13;\n"
        "G01X02000.00Y02000.00F14;\nG01X01000.00Y02000.00F20;\n"
    )
    v = verify_code(code, target, source="fast.pic")
    capped = [w for w in v.warnings if "step-rate cap" in w]
    assert len(capped) == 2  # one per feed: F14 on line 5, F20 on line 6
    assert capped[0].startswith("line 5: feed 1.4 mm/min asks 166.7 Hz")
    assert "166 Hz" in capped[0] and "UNAM-GMM" in capped[0]
    assert capped[1].startswith("line 6: feed 2 mm/min asks 238.1 Hz")
    assert not any("line 4" in w for w in capped)


def test_trapezoid_warns_when_a_feed_is_over_the_maximum_rate() -> None:
    target = load_target("linuxcnc")
    rate = float(target.machine.timing["max_rate_mm_min"])
    program = Program((Rapid(1, 1, contour=1), Linear(5, 1, rate * 2, contour=1)))
    v = verify_program(program, target.machine, name="linuxcnc")
    assert any(
        w.startswith("move 2: feed") and f"maximum rate {rate:g} mm/min" in w for w in v.warnings
    )


def test_time_s_keeps_six_significant_digits() -> None:
    """Munoz-22: ValCNC takes 166.667 µs per DDA iteration, so 7 steps take 1.167 ms."""
    assert seconds_6(7 * 166.667e-6) == pytest.approx(7 * 166.667e-6, rel=1e-5)
    assert seconds_6(0.0007352941) == 0.000735294  # 6 significant digits
    assert seconds_6(172.5123456) == 172.512  # 6 significant digits, 3 decimals
    assert seconds_6(12345.67891) == 12345.679  # never fewer than 3 decimals
    assert seconds_6(0.0) == 0.0
    target = load_target("valcnc")
    step = 1.0 / target.machine.steps_per_mm[0]
    program = Program((Linear(7 * step, 0.0, 100.0, contour=1),))
    v = verify_program(program, target.machine, name="valcnc")
    assert int(np.abs(v.trace.block_steps).sum()) == 7
    time_s = report_dict(v)["time_s"]
    assert time_s == pytest.approx(v.time_s, rel=1e-5) and time_s != 0.001


def test_every_contour_has_its_end_error() -> None:
    """Two U patterns (UNAM-GMM §5.2), each ending 190 µm short on its return leg."""
    target = load_target("pic-mmh")
    lash = Backlash(true_um=(190.0, 0.0, 0.0), compensation_um=(0.0, 0.0, 0.0))
    machine = dataclasses.replace(target.machine, backlash=lash)
    moves: list[Linear | Rapid] = []
    for n, y in enumerate((1.0, 4.0), start=1):
        moves += [
            Rapid(1.0, y, contour=n),
            Linear(3.5, y, 0.8, contour=n),
            Linear(3.5, y + 1.0, 0.8, contour=n),
            Linear(1.0, y + 1.0, 0.8, contour=n),
        ]
    v = verify_program(Program(tuple(moves)), machine, name="pic-mmh")
    assert v.along is not None and len(v.along.contour_end_um) == 2
    # the second U starts with a +X move after the first ended moving −X: its first leg
    # takes up the play (190 µm short at its start), its return leg ends 190 µm short again
    assert v.along.contour_end_um == pytest.approx((190.0, 190.0), abs=0.2)


def test_measure_budget_tells_each_source_it_re_simulates() -> None:
    """One ``budget`` step per modelled source, before it, in order; the same budget.

    The flashcut profile as shipped models five sources for the circle: interpolation,
    chords (an arc cut in chords), the steps/mm scale (1.9 assumed, 1.88 µm real),
    backlash (654 µm true, Yanez-07) and dynamics (the timer); the rounding is unknown
    from code alone. So five steps, ``done`` 0 to 4 of 5.
    """
    from camtool.model.progress import Step

    machine = load_target("flashcut").machine
    told: list[Step] = []
    v = verify_program(_circle10(), machine, name="flashcut")
    got = v.measure_budget(told.append)
    assert [(s.stage, s.done, s.total) for s in told] == [("budget", i, 5) for i in range(5)]
    assert [s.name for s in told] == [SOURCES[n] for n in got.without]
    assert v.error_budget is got  # computed once
    again = verify_program(_circle10(), machine, name="flashcut").error_budget
    assert got == again
    assert v.measure_budget(told.append) is got and len(told) == 5  # not re-simulated


def test_measure_budget_tells_nothing_when_the_budget_is_off() -> None:
    from camtool.model.progress import Step

    told: list[Step] = []
    v = verify_program(_circle10(), load_target("flashcut").machine, name="fc", budget=False)
    assert v.measure_budget(told.append).skipped is not None
    assert told == []


def test_the_budget_made_in_workers_is_the_one_made_here(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    """The sources re-simulated in forked workers, one per core, give the same budget.

    The reference is the budget made in this process, one source after the other (one
    job); the workers' pids show the five sources were re-simulated elsewhere.
    """
    import os

    from camtool.accel import cores
    from camtool.verify import budget_run, verifier

    if not cores.FORK:
        pytest.skip("forked workers: Linux only")
    machine = load_target("flashcut").machine
    monkeypatch.setattr(cores, "default_jobs", lambda: 1)
    here = verify_program(_circle10(), machine, name="flashcut").error_budget
    pids = tmp_path / "pids"
    measure = budget_run.without_source

    def noted(v: verifier.Verification, name: str) -> object:
        with pids.open("a") as note:
            note.write(f"{os.getpid()}\n")
        return measure(v, name)

    monkeypatch.setattr(budget_run, "without_source", noted)
    monkeypatch.setattr(cores, "default_jobs", lambda: 2)
    there = verify_program(_circle10(), machine, name="flashcut").error_budget
    assert there == here and len(here.without) == 5
    made_by = pids.read_text().split()
    assert len(made_by) == 5 and str(os.getpid()) not in made_by


def test_a_budget_asked_for_now_is_the_budget_asked_for_later() -> None:
    """``budget_now``: made while the program is measured, told as measure_budget tells it."""
    from camtool.model.progress import Step

    machine = load_target("flashcut").machine
    later = verify_program(_circle10(), machine, name="flashcut")
    told_later: list[Step] = []
    expected = later.measure_budget(told_later.append)
    told: list[Step] = []
    now = verify_program(_circle10(), machine, name="flashcut", budget_now=told.append)
    assert "error_budget" in now.__dict__  # made before verify_program returned
    assert now.error_budget == expected
    assert [(s.stage, s.done, s.total, s.name) for s in told] == [
        (s.stage, s.done, s.total, s.name) for s in told_later
    ]
    off = verify_program(_circle10(), machine, budget=False, budget_now=told.append)
    assert off.error_budget.skipped == "switched off (--no-budget)" and len(told) == 5


def test_a_budget_that_fails_now_fails_when_asked_for(monkeypatch: pytest.MonkeyPatch) -> None:
    """A re-simulation that fails does not stop the verification; asking for the budget does."""
    from camtool.model.errors import InputError
    from camtool.verify import budget_run

    def fails(inputs: object, name: str) -> object:
        raise InputError(f"{name} cannot be simulated")

    monkeypatch.setattr(budget_run, "without_source", fails)
    machine = load_target("flashcut").machine
    v = verify_program(_circle10(), machine, name="flashcut", budget_now=lambda step: None)
    assert v.deviation.max_um > 0 and "error_budget" not in v.__dict__
    with pytest.raises(InputError, match="interpolation cannot be simulated"):
        v.error_budget  # noqa: B018 - asked for: it fails as it always did
