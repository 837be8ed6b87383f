"""The ideal controller (``interpolation`` off) draws a long line's straight rest with few rows.

What the fewer rows stand for is the controller's own sampling, every sample a row
(:data:`camtool.verify.simulate.IDEAL_SAMPLES_PER_STEP` a step): the expected values
here are that sampling's, made by the same controller with :meth:`_line_shape` answering
"every sample". Past a reversal's take-up the carriage runs straight, so the rows'
polyline must be the samples' one (the take-up's corner where the samples have it) and
the error budget's figures the same.
"""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from camtool.cli.main import main
from camtool.model.machine import Backlash, BacklashRegion, Machine
from camtool.model.program import ArcMove, Linear, Program, Rapid
from camtool.post.registry import load_target
from camtool.verify import budget as eb
from camtool.verify import budget_run
from camtool.verify import simulate as sim
from camtool.verify.chunked import count_rows
from camtool.verify.sources import ALL

WITHOUT = ALL.without("interpolation")
SAMPLES = Path(__file__).resolve().parents[2] / "samples"


def _program() -> Program:
    """Long lines inside pic-mmh's 10 × 7 mm whose take-ups fall inside them or span several.

    X reverses at the start of long lines; Y reverses on a line that moves Y 20 µm (less
    than its backlash), so its take-up goes on into the next, long, line going the same
    way; an arc turns Y 0.5° before its end (14 nm of Y), and the long line after it goes
    on down: Y's take-up, begun in the arc, ends in the line.
    """
    f = 300.0
    tail = math.radians(90.5)
    arc_end = (7.5 + math.cos(tail), 5.0 + math.sin(tail))
    moves = (
        Rapid(1.0, 1.0, contour=1),
        Linear(8.0, 1.5, f, contour=1),
        Linear(1.5, 2.0, f, contour=1),  # X reverses
        Linear(1.51, 1.98, f, contour=1),  # X and Y reverse, Y by less than its backlash
        Linear(8.5, 1.0, f, contour=1),  # Y's take-up goes on here
        Linear(8.5, 5.0, f, contour=1),
        ArcMove(*arc_end, 7.5, 5.0, False, f, contour=1),  # Y turns down at its end
        Linear(2.0, 5.0, f, contour=1),
        Rapid(9.0, 6.0, contour=2),
        Linear(0.5, 0.5, f, contour=2),
    )
    return Program(moves, origin=(0.0, 0.0))


def _machines() -> dict[str, Machine]:
    """pic-mmh's profile (regions, over-compensation) and two backlashes of no compensation."""
    profile = load_target("pic-mmh").machine
    plain = Backlash(true_um=(30.0, 25.0, 0.0), compensation_um=(0.0, 0.0, 0.0))
    under = Backlash(
        true_um=(40.0, 35.0, 0.0),
        compensation_um=(10.0, 0.0, 0.0),
        regions=(BacklashRegion(axis="x", x_mm=(0.0, 5.0), y_mm=(0.0, 7.0), true_um=60.0),),
    )
    return {
        "profile": profile,
        "plain": dataclasses.replace(profile, backlash=plain),
        "regions": dataclasses.replace(profile, backlash=under),
    }


def _every_sample(monkeypatch: pytest.MonkeyPatch) -> None:
    """The ideal controller with every sample of every line a row (the expected values')."""
    monkeypatch.setattr(sim.IdealController, "_line_shape", lambda self, dx, dy, n: (n, 0))


def _traces(monkeypatch: pytest.MonkeyPatch, machine: Machine) -> tuple[Any, Any]:
    """The trace with ``interpolation`` off, fewer rows and every sample (in this order)."""
    program = _program()
    rows = sim.simulate_steps(program, machine, sources=WITHOUT)
    assert np.array_equal(count_rows(program, machine, sources=WITHOUT), rows.block_start)
    with monkeypatch.context() as patch:
        _every_sample(patch)
        samples = sim.simulate_steps(program, machine, sources=WITHOUT)
    return rows, samples


def _off_segment(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    """The largest distance of ``points`` ``(N, 2)`` from the segment ``a → b``, mm."""
    d = b - a
    t = np.clip((points - a) @ d / max(float(d @ d), 1e-300), 0.0, 1.0)
    return float(np.max(np.hypot(*(points - a - t[:, None] * d).T)))


@pytest.mark.parametrize("name", ["profile", "plain", "regions"])
def test_each_move_s_rows_draw_the_polyline_of_its_samples(
    monkeypatch: pytest.MonkeyPatch, name: str
) -> None:
    """Per move, the rows are its first samples, then a straight run that holds the rest.

    Both polylines start at the carriage before the move. Where the rows stop being the
    samples (row ``p``), every later sample and row lies on the segment from there to the
    move's end, to 1e-9 mm: the take-up's corner, if any, is among the samples (a corner
    cut by the rest's 8-step rows would be ~1 µm off on pic-mmh).
    """
    rows, samples = _traces(monkeypatch, _machines()[name])
    assert rows.block_start[-1] * 5 < samples.block_start[-1]  # the point of it
    for b in range(len(rows.block_start) - 1):
        polylines = []
        for trace in (rows, samples):
            lo, hi = int(trace.block_start[b]), int(trace.block_start[b + 1])
            before = trace.carriage_mm[lo - 1 : lo] if lo else np.asarray([_program().origin])
            polylines.append(np.concatenate([before, trace.carriage_mm[lo:hi]]))
        mine, theirs = polylines
        if len(mine) == len(theirs):
            np.testing.assert_allclose(mine, theirs, rtol=0, atol=1e-9)
            continue
        np.testing.assert_allclose(mine[-1], theirs[-1], rtol=0, atol=1e-9)  # the same end
        apart = np.flatnonzero(np.any(np.abs(mine[:-1] - theirs[: len(mine) - 1]) > 1e-9, axis=1))
        p = int(apart[0]) if len(apart) else len(mine) - 1
        assert p >= 2, (name, b)  # the rows start as the samples do
        corner = mine[p - 1]
        assert _off_segment(theirs[p - 1 :], corner, mine[-1]) < 1e-9, (name, b)
        assert _off_segment(mine[p - 1 :], corner, mine[-1]) < 1e-9, (name, b)


@pytest.mark.parametrize("chunk_rows", [0, 4096])
@pytest.mark.parametrize("name", ["profile", "plain", "regions"])
def test_the_budget_without_interpolation_has_the_samples_figures(
    monkeypatch: pytest.MonkeyPatch, name: str, chunk_rows: int
) -> None:
    """The budget's figures with ``interpolation`` off: the samples', to 1e-6 µm.

    Whole (``chunk_rows`` 0) and streamed, when the compiled kernels are there.
    """
    machine, program = _machines()[name], _program()

    def figures() -> eb.Figures:
        dev, along, contours, _, _ = budget_run.resimulate(
            program, machine, WITHOUT, None, chunk_rows
        )
        return eb.figures(dev, along, contours, None)

    got = figures()
    with monkeypatch.context() as patch:
        _every_sample(patch)
        expected = figures()
    assert got.keys() == expected.keys()
    assert got["max deviation"] > 1.0  # the backlash shows
    for key, value in expected.items():
        assert got[key] == pytest.approx(value, abs=1e-6), key


def test_a_budget_against_the_drawing_samples_every_line(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """With a drawing, interpolation off keeps every sample: its comparison thins by count.

    The drawing comparison keeps every k-th cutting row, k read from the trace's first
    rows: rows of two lengths would make its chords cut the corners between moves (the
    demo logo's distance to the drawing without interpolation moved by 0.08 µm). So
    ``post --report`` gives the budget of every sample, figure for figure.
    """
    machine = tmp_path / "lash.toml"
    machine.write_text(
        "[machine.backlash]\ntrue_um = [25.0, 18.0, 0.0]\ncompensation_um = [20.0, 20.0, 0.0]\n"
        "regions = []\n"
    )

    def budget(name: str) -> Any:
        report = tmp_path / f"{name}.json"
        args = ["post", str(SAMPLES / "logo.dxf"), "-t", "pic-mmh", "--fit", "9", "6"]
        args += ["--machine", str(machine), "--report", str(report)]
        assert main([*args, "-o", str(tmp_path / f"{name}.pic")]) == 0, capsys.readouterr().err
        return json.loads(report.read_text())["error_budget"]

    got = budget("rows")
    with monkeypatch.context() as patch:
        _every_sample(patch)
        expected = budget("samples")
    assert any(f["figure"] == "distance to the drawing" for f in got["figures"])
    assert got == expected
