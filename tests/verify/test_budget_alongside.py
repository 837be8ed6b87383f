"""A streamed verification's one budget source runs beside it; the ideal play compiled.

The error budget of a streamed trace without a drawing needs only the trace's row count:
its one source is forked before the stream (the two peaks of memory in two processes),
and gives the budget of the source re-simulated here, bit for bit. The ideal controller's
carriage (interpolation off) is computed by compiled loops, judged against the numpy
play it replaced.
"""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest

from camtool.accel import cores
from camtool.model.machine import Backlash, BacklashRegion, Machine
from camtool.model.program import ArcMove, Linear, Program, Rapid
from camtool.model.progress import Step
from camtool.post.registry import load_target
from camtool.verify import budget_run, chunked, verifier
from camtool.verify.chunked import ChunkedSimulation, TraceChunk

kernels = pytest.importorskip("camtool.accel.kernels")
pytestmark = [
    pytest.mark.skipif(not cores.FORK, reason="needs fork (Linux)"),
    pytest.mark.usefixtures("accel_on"),  # the accelerated versions only
]


def _lines(count: int = 8) -> Program:
    """Long lines back and forth along X, each a little higher, then an arc: one contour.

    The quarter circle ends 0.04 nm off the circle of its start (as a rounded end does):
    the controller with ``interpolation`` off blends the two radii, so the budget's one
    source is re-simulated (:func:`camtool.verify.trace_sources.follows_program`).
    """
    moves: list[Linear | Rapid | ArcMove] = [Rapid(0.5, 0.5, contour=1)]
    for k in range(count):
        moves.append(Linear(6.0 if k % 2 == 0 else 0.5, 0.5 + 0.137 * (k + 1), 300.0, contour=1))
    x, y = moves[-1].x, moves[-1].y
    moves.append(ArcMove(x + 0.5, y + 0.5002, x, y + 0.5, False, 300.0, contour=1))
    return Program(tuple(moves), origin=(0.0, 0.0))


def _machine(backlash: bool) -> Machine:
    machine = load_target("pic-mmh").machine
    return machine if backlash else dataclasses.replace(machine, backlash=Backlash())


def _verify(machine: Machine, **kw: Any) -> verifier.Verification:
    return verifier.verify_program(
        _lines(), machine, name="pic-mmh", chunk_rows=4096, stream_above=1000, **kw
    )


def _spy(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """Record, in this process, each helper forked and each chunk streamed."""
    events: list[str] = []
    fork = budget_run.fork_with_pipes

    def forked(*args: Any, **kw: Any) -> Any:
        events.append("fork")
        got = fork(*args, **kw)
        events.append(f"pid {got[0]}")
        return got

    real = ChunkedSimulation.chunks

    def chunks(self: ChunkedSimulation) -> Iterator[TraceChunk]:
        for chunk in real(self):
            events.append("chunk")
            yield chunk

    monkeypatch.setattr(budget_run, "fork_with_pipes", forked)
    monkeypatch.setattr(ChunkedSimulation, "chunks", chunks)
    monkeypatch.setattr(budget_run, "default_jobs", lambda: 2)  # a helper even on one core
    return events


def test_one_source_is_forked_before_the_stream_and_gives_the_same_budget(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    machine = _machine(backlash=False)
    monkeypatch.setattr(cores, "default_jobs", lambda: 1)  # the source here, after
    expected = _verify(machine).error_budget
    assert list(expected.without) == ["interpolation"]
    events = _spy(monkeypatch)
    told: list[Step] = []
    v = _verify(machine, budget_now=told.append)
    assert isinstance(v.trace, chunked.StreamedTrace)
    assert "error_budget" in v.__dict__  # computed with the verification
    assert events[0] == "fork" and events.count("fork") == 1
    assert events.count("chunk") > 1  # this process streamed its own trace meanwhile
    assert v.error_budget == expected  # every figure, bit for bit
    assert [(s.done, s.total) for s in told] == [(0, 1)]  # the next source, as it starts


def test_a_helper_that_dies_has_its_source_re_simulated_here(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    machine = _machine(backlash=False)
    monkeypatch.setattr(cores, "default_jobs", lambda: 1)
    expected = _verify(machine).error_budget
    events = _spy(monkeypatch)
    here = os.getpid()
    real = budget_run.without_source

    def dies(inputs: Any, name: str) -> Any:
        if os.getpid() != here:
            os._exit(3)  # the helper, before it answers
        return real(inputs, name)

    monkeypatch.setattr(budget_run, "without_source", dies)
    v = _verify(machine, budget_now=lambda step: None)
    assert events[0] == "fork"
    assert v.error_budget == expected


def test_two_sources_are_re_simulated_once_the_trace_is_measured(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """With backlash (two sources) nothing is forked before the stream: side by side
    after it, as before (three processes on two cores took longer)."""
    machine = _machine(backlash=True)
    monkeypatch.setattr(cores, "default_jobs", lambda: 1)
    expected = _verify(machine).error_budget
    assert list(expected.without) == ["interpolation", "backlash"]
    events = _spy(monkeypatch)
    v = _verify(machine, budget_now=lambda step: None)
    assert "fork" not in events
    assert v.error_budget == expected


def _play_both(
    rows: np.ndarray, cuts: list[int], machine: Machine, origin: tuple[float, float]
) -> tuple[list[np.ndarray], list[np.ndarray]]:
    """The chunks' directions and carriage by the numpy play and by the compiled one."""
    numpy_play = chunked._FloatPlay(origin, machine)
    compiled = chunked._FloatPlayCompiled(origin, machine, kernels)
    got: tuple[list[np.ndarray], list[np.ndarray]] = ([], [])
    for piece in np.split(rows, cuts):
        for out, play in zip(got, (numpy_play, compiled), strict=True):
            signs, carriage = play.chunk(piece)
            out.append(np.concatenate([signs.astype(np.float64), carriage], axis=1))
    return got


@pytest.mark.parametrize("seed", range(6))
def test_the_compiled_ideal_play_is_the_numpy_one(seed: int) -> None:
    """Fractional rows with reversals, standstills, zeros of both signs and equal values,
    in chunks cut anywhere, through bands that change by region: the same bits."""
    rng = np.random.default_rng(seed)
    regions = (
        BacklashRegion(axis="x", x_mm=(-1000.0, 1000.0), y_mm=(-1000.0, 0.0), true_um=150.0),
        BacklashRegion(axis="y", x_mm=(0.0, 1000.0), y_mm=(-1000.0, 1000.0), true_um=90.0),
    )
    machine = dataclasses.replace(
        load_target("pic-mmh").machine,
        backlash=Backlash(
            true_um=(120.0, 80.0, 0.0), compensation_um=(0.0, 0.0, 0.0), regions=regions
        ),
    )
    n = 3000
    rows = np.repeat(rng.normal(0.0, 0.4, (n // 50, 2)), 50, axis=0)  # runs of equal rows
    rows[rng.random((n, 2)) < 0.1] = 0.0
    rows[rng.random((n, 2)) < 0.02] = -0.0
    flip = rng.random(n) < 0.01
    rows[flip] = -rows[flip]
    origin = (float(rng.integers(-500, 500)), float(rng.integers(-500, 500)))
    cuts = sorted(int(c) for c in rng.integers(0, n, 7))
    numpy_chunks, compiled_chunks = _play_both(rows, cuts, machine, origin)
    for a, b in zip(numpy_chunks, compiled_chunks, strict=True):
        assert a.tobytes() == b.tobytes()


def test_an_error_in_the_stream_leaves_no_helper_behind(monkeypatch: pytest.MonkeyPatch) -> None:
    from camtool.verify.trace_measures import TraceStream

    events = _spy(monkeypatch)

    def fails(self: TraceStream, *args: Any, **kw: Any) -> None:
        raise RuntimeError("a chunk that cannot be measured")

    monkeypatch.setattr(TraceStream, "add", fails)
    with pytest.raises(RuntimeError, match="cannot be measured"):
        _verify(_machine(backlash=False), budget_now=lambda step: None)
    assert events[0] == "fork"
    pid = int(events[1].split()[1])
    with pytest.raises(ChildProcessError):  # the helper was ended and waited for
        os.waitpid(pid, os.WNOHANG)


@pytest.mark.parametrize(
    ("cores_here", "rows", "jobs"),
    [(2, 2_600_000, 1), (4, 2_600_000, 2), (2, 440_000, None), (2, 5_000, None)],
)
def test_long_streamed_sources_take_two_cores_each(
    monkeypatch: pytest.MonkeyPatch, cores_here: int, rows: int, jobs: int | None
) -> None:
    """A long streamed re-simulation runs two threads here but one in a worker process, so
    on two cores its sources run here in turn; one of a few chunks (a part's 440 000 rows),
    or not streamed, takes one core (``None``: the workers' own count, a core each)."""
    monkeypatch.setattr(budget_run, "default_jobs", lambda: cores_here)
    assert budget_run.CHUNK_ROWS < 440_000 < budget_run.IN_TURN_FROM < 2_600_000
    assert budget_run._jobs(rows) == jobs
