"""A big program is verified in bounded memory: streamed in chunks, its budget too.

The error budget re-simulates the program once per error source; each re-simulation is
streamed (simulated and measured a chunk of whole moves at a time) like the verification's
own trace, never simulated whole, and gives the budget of the whole-trace path figure for
figure. The sizes are scaled down (a chunk of a few hundred rows) so that the structural
checks run in seconds; the memory checks compare a program with four times as many
contours (tracemalloc's peak, with a wide margin), never a wall clock.
"""

from __future__ import annotations

import json
import tracemalloc
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np
import pytest

from camtool.accel import cores
from camtool.model.program import ArcMove, Linear, Program, Rapid
from camtool.post.registry import load_target
from camtool.verify import budget_run, trace_sources, verifier
from camtool.verify.chunked import ChunkedSimulation, TraceChunk, count_rows
from camtool.verify.simulate import simulate_steps
from camtool.verify.sources import ALL, SOURCES, Sources
from camtool.verify.trace_measures import TraceStream
from tests.verify.programs import TARGETS, mixed_program

# what this file checks is done by the accelerated versions only (docs/architecture.md)
pytestmark = pytest.mark.usefixtures("accel_on")

kernels = pytest.importorskip("camtool.accel.kernels")

SIMULATED = [name for name in SOURCES if name != "rounding"]


def _squares(count: int, side: float = 2.0) -> Program:
    """``count`` closed squares with a rounded corner, each its own contour, in rows."""
    moves: list[Linear | ArcMove | Rapid] = []
    across = int(150.0 // (side + 1.0))
    r = side / 4.0
    for k in range(count):
        x, y = 5.0 + (k % across) * (side + 1.0), 5.0 + (k // across) * (side + 1.0)
        n = k + 1
        moves += [
            Rapid(x, y, contour=n),
            Linear(x + side, y, 300.0, contour=n),
            Linear(x + side, y + side - r, 300.0, contour=n),
            ArcMove(x + side - r, y + side, x + side - r, y + side - r, False, 300.0, contour=n),
            Linear(x, y + side, 300.0, contour=n),
            Linear(x, y, 300.0, contour=n),
        ]
    return Program(tuple(moves), origin=(0.0, 0.0))


@pytest.mark.parametrize("name", TARGETS)
@pytest.mark.parametrize("off", SIMULATED)
def test_a_source_switched_off_streams_the_whole_trace(name: str, off: str) -> None:
    """Each source off: the chunks joined are the whole simulation's rows and carriage.

    With ``interpolation`` off the rows are fractional steps; their carriage is carried
    from chunk to chunk (the motor's running sum, the play), bit for bit.
    """
    machine = load_target(name).machine
    program = mixed_program(1)
    sources = ALL.without(off)
    whole = simulate_steps(program, machine, sources=sources)
    assert np.array_equal(count_rows(program, machine, sources=sources), whole.block_start)
    for chunk in (1, max(1, int(whole.block_start[-1]) // 3)):  # a row, a third of them
        sim = ChunkedSimulation(program, machine, chunk, sources=sources)
        parts = list(sim.chunks())
        assert len(parts) > 1
        for column in ("rows", "carriage_mm", "compensation"):
            joined = np.concatenate([getattr(p, column) for p in parts])
            expected = getattr(whole, column)
            assert joined.dtype == expected.dtype and joined.tobytes() == expected.tobytes()
        for key, value in sim.trace_summary().items():
            expected = getattr(whole, key)
            if isinstance(value, np.ndarray):
                assert np.array_equal(value, expected), key
            else:
                assert value == expected, key


def _spy_chunks(monkeypatch: pytest.MonkeyPatch) -> list[tuple[int, int, Sources]]:
    """Record each chunk's rows, its longest move's rows and its sources."""
    seen: list[tuple[int, int, Sources]] = []
    real = ChunkedSimulation.chunks

    def chunks(self: ChunkedSimulation) -> Iterator[TraceChunk]:
        for chunk in real(self):
            longest = int(np.diff(chunk.block_start).max()) if len(chunk.block_start) > 1 else 0
            seen.append((len(chunk.rows), longest, self.sim.sources))
            yield chunk

    monkeypatch.setattr(ChunkedSimulation, "chunks", chunks)
    return seen


def _spy_whole(monkeypatch: pytest.MonkeyPatch) -> list[Sources]:
    """Record the sources of every whole simulation the verifier asks for."""
    calls: list[Sources] = []
    real: Callable[..., Any] = trace_sources.simulate

    def simulate(program: Program, machine: Any, *, sources: Sources = ALL) -> Any:
        calls.append(sources)
        return real(program, machine, sources=sources)

    monkeypatch.setattr(trace_sources, "simulate", simulate)
    return calls


@pytest.mark.parametrize("name", ["grbl", "pic-mmh"])
def test_the_budget_re_simulates_in_chunks_never_whole(
    name: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A trace over the chunk size: every source re-simulated in chunks, the same budget."""
    machine = load_target(name).machine
    program = _squares(3) if name == "grbl" else mixed_program(2)
    monkeypatch.setattr(cores, "default_jobs", lambda: 1)  # the sources here, one by one
    expected = verifier.verify_program(program, machine, name=name).error_budget  # whole
    assert expected.without  # some sources are modelled
    chunk_rows = 256
    monkeypatch.setattr(budget_run, "CHUNK_ROWS", chunk_rows)
    seen = _spy_chunks(monkeypatch)
    whole = _spy_whole(monkeypatch)
    v = verifier.verify_program(program, machine, name=name)
    assert v.trace.row_count > chunk_rows
    budget = v.error_budget
    assert whole == []  # no source re-simulated whole
    streamed = {sources.off for _, _, sources in seen}
    assert streamed == {(source,) for source in expected.without}
    for rows, longest, _ in seen:  # a chunk: whole moves, at most one past the chunk size
        assert rows < chunk_rows + longest or rows == longest
    assert budget == expected  # every figure, bit for bit


def _budget_peak(program: Program, machine: Any) -> int:
    """tracemalloc's peak while the error budget of ``program`` is computed, bytes."""
    v = verifier.verify_program(program, machine, name="m")
    tracemalloc.start()
    try:
        v.measure_budget()
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_the_budget_peak_does_not_grow_with_the_program(monkeypatch: pytest.MonkeyPatch) -> None:
    """Four times the contours, about the same peak: the budget holds a chunk, not a trace.

    The interpolation source off samples each step four times (float rows); simulated
    whole, the 40 squares' budget held ~4x the 10 squares'.
    """
    machine = load_target("grbl").machine
    monkeypatch.setattr(cores, "default_jobs", lambda: 1)
    monkeypatch.setattr(budget_run, "CHUNK_ROWS", 1024)
    small = _budget_peak(_squares(10, side=4.0), machine)
    big = _budget_peak(_squares(40, side=4.0), machine)
    assert big < 2 * small, (small, big)


def _zigzags(count: int, moves_each: int = 200) -> Program:
    """``count`` contours, each a zig-zag of ``moves_each`` short lines (20 µm, 5 µm up)."""
    moves: list[Linear | ArcMove | Rapid] = []
    for c in range(count):
        x0, y0 = 5.0 + (c % 100) * 1.5, 5.0 + (c // 100) * 1.0
        moves.append(Rapid(x0, y0, contour=c + 1))
        for k in range(moves_each):
            x = x0 + (0.02 if k % 2 == 0 else 0.0)
            moves.append(Linear(round(x, 3), round(y0 + 0.005 * (k + 1), 3), 300.0, contour=c + 1))
    return Program(tuple(moves), origin=(0.0, 0.0))


def _kept_per_move(program: Program, machine: Any) -> float:
    """Bytes a streamed simulation and its measures keep per move, the chunks aside."""
    warm = ChunkedSimulation(_zigzags(1, 4), machine, 512)  # the kernels' first calls
    for _ in warm.chunks():
        pass
    tracemalloc.start()
    try:
        sim = ChunkedSimulation(program, machine, 512)
        for _ in sim.chunks():  # each chunk let go as the next comes
            pass
        summary = sim.trace_summary()
        stream = TraceStream(program, summary["block_start"], summary["start_mm"], kernels)
        kept = tracemalloc.get_traced_memory()[0]
    finally:
        tracemalloc.stop()
    del sim, stream
    return kept / len(program.moves)


def test_a_streamed_verification_keeps_a_few_numbers_per_move() -> None:
    """What a streamed trace keeps per move, besides the program: numbers in arrays.

    The controller's records of each move (rows, logical end, pulses, ...) and where
    each move starts are 8-byte values in arrays; as lists of Python tuples they took
    ~210 bytes a move more (here ~470 bytes a move kept, ~265 now), and a 12 MB
    program's verification 601 MB (482 MB now).
    """
    per_move = _kept_per_move(_zigzags(40), load_target("grbl").machine)
    assert per_move < 350, per_move


@pytest.mark.parametrize("value", [0.25, -0.25, 0.0, -0.0])
@pytest.mark.parametrize("direction", [-1, 0, 1])
def test_an_ideal_line_s_reversals_are_the_row_scan_s(value: float, direction: int) -> None:
    """A column of one value (an ideal line's rows): the same reversals as the scan of rows."""
    from camtool.verify import simulate as sim

    machine = load_target("pic-mmh").machine
    column = np.full(1000, value)
    fast = sim.IdealController(machine, (0.0, 0.0))
    scan = sim.IdealController(machine, (0.0, 0.0))
    fast.direction = [direction, direction]
    scan.direction = [direction, direction]
    got = fast._reversals(column, 0)
    expected = sim.StepController._reversals(scan, column, 0)
    assert [a.tolist() for a in got] == [a.tolist() for a in expected]
    assert [a.dtype for a in got] == [a.dtype for a in expected]
    assert fast.direction == scan.direction


@pytest.mark.parametrize("target", ["grbl", "pic-mmh"])
def test_a_streamed_budget_against_a_drawing_is_the_whole_one(
    target: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Trace and sources streamed, compared with a drawing and with the plan: the same budget.

    The distance to the drawing of a source whose cutting rows are the verification's
    own (the plan's rounding, absorbed by the steps) is told by their digest.
    """
    from camtool.model.shapes import Arc, Contour, Drawing, Line

    machine = load_target(target).machine
    c = [(1.0, 1.0), (5.0, 1.0), (5.0, 4.0), (1.0, 4.0)]
    outline = Contour(tuple(Line(c[i], c[(i + 1) % 4]) for i in range(4)), True)
    hole = Contour((Arc((4.0, 2.5), (4.0, 2.5), (3.0, 2.5), False),), True)
    drawing = Drawing((hole, outline))
    moves = (
        Rapid(3.75, 2.5, contour=1),
        ArcMove(3.75, 2.5, 3.0, 2.5, False, 300.0, contour=1),
        Rapid(0.75, 0.75, contour=2),
        Linear(5.25, 0.75, 300.0, contour=2),
        Linear(5.25, 4.25, 300.0, contour=2),
        Linear(0.75, 4.25, 300.0, contour=2),
        Linear(0.75, 0.75, 300.0, contour=2),
    )
    program = Program(moves, origin=(0.0, 0.0))
    planned = Program(
        tuple(
            m if isinstance(m, Rapid | ArcMove) else Linear(m.x + 1e-7, m.y, 300.0, contour=2)
            for m in moves
        ),
        origin=(0.0, 0.0),
    )
    monkeypatch.setattr(cores, "default_jobs", lambda: 1)

    def budget(**kw: Any) -> Any:
        v = verifier.verify_program(
            program,
            machine,
            name=target,
            against=drawing,
            tool_diameter=0.5,
            planned=planned,
            **kw,
        )
        return v, v.error_budget

    whole, expected = budget()
    assert whole.cut_digest is None  # a whole trace: its digest made when needed
    assert "distance to the drawing" in expected.total and "rounding" in expected.without
    monkeypatch.setattr(budget_run, "CHUNK_ROWS", 97)
    v, got = budget(chunk_rows=97, stream_above=10)
    assert v.cut_digest is not None and v.trace.row_count > 97
    assert got == expected


def _peak_per_move(program: Program, measure: Callable[[], object]) -> float:
    """tracemalloc's peak while ``measure()`` runs, bytes a move of ``program``."""
    measure()  # its imports and first calls
    tracemalloc.start()
    try:
        measure()
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    return peak / len(program.moves)


def test_the_nominal_moves_are_built_without_a_row_object_a_move() -> None:
    """The ends are views of the moves' starts (16 bytes a move), the rest six floats a move,
    and no tuple of them beside: a 12 MB program's 616 000 moves peaked 93 MB over a table
    of ten floats a move (a list of tuples, ~230 bytes a move); 64 bytes a move now."""
    from camtool.verify.deviations import move_starts, nominal_arrays

    program = _zigzags(40)
    assert _peak_per_move(program, lambda: nominal_arrays(program)) < 90
    starts = move_starts(program)
    nominal = nominal_arrays(program, starts)
    assert np.shares_memory(nominal["x1"], starts.xy)  # given the starts, not made again
    ends = np.array([(m.x, m.y) for m in program.moves])
    assert np.array_equal(nominal["x1"], ends[:, 0]) and np.array_equal(nominal["y1"], ends[:, 1])
    assert nominal["x0"][0] == program.origin[0] and nominal["y0"][1] == ends[0, 1]


def test_capped_feeds_are_named_by_reason_not_a_message_a_move() -> None:
    """Every move of a program fed over GRBL's maximum rate (F600 > $110 = 500) is capped;
    the warning names the lines once per feed. A message and a tuple per capped move, the
    feeds and flags as lists and each per-block array copied twice peaked ~355 bytes a move
    (a 12 MB program's verify 650 → 760 MB); ~130 now, all in arrays of numbers."""
    from camtool.verify.clock import timing_warnings

    machine = load_target("grbl").machine
    base = _zigzags(40)
    moves = tuple(m if isinstance(m, Rapid) else Linear(m.x, m.y, 600.0) for m in base.moves)
    program = Program(moves, origin=base.origin, lines=range(10, 10 + len(moves)))
    trace = simulate_steps(program, machine)
    warnings = timing_warnings(trace, program, machine)
    assert len(warnings) == 1 and "feed 600 mm/min is over the maximum rate 500" in warnings[0]
    assert warnings[0].startswith("lines 11, 12, 13, 14, 15, 16, 17, 18 and ")
    assert _peak_per_move(program, lambda: timing_warnings(trace, program, machine)) < 200


def test_the_report_text_is_joined_without_a_piece_object_each() -> None:
    """The JSON report of many contours: ``json.dumps(indent=2)`` keeps each of its pieces
    (a key, a number, a comma: tens of bytes of object each) until it joins them; joined
    8 192 at a time the peak is the report's dict and text (8.9x the text before, 5.9x
    now; a 12 MB program's report of 61 600 contours took its verify 516 -> 681 MB)."""
    from camtool.jobs.pipeline import report_json

    v = verifier.verify_program(
        _zigzags(300, 4), load_target("grbl").machine, name="grbl", budget=False
    )
    text = report_json(v)
    assert text == json.dumps(json.loads(text), indent=2, ensure_ascii=True) + "\n"
    tracemalloc.start()
    try:
        report_json(v)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 7.4 * len(text), peak / len(text)
