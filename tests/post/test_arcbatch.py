"""Plain arcs conformed in arrays give conform_arc's own blocks (issue 44).

:mod:`camtool.post.arcbatch` answers, a chunk of arcs at a time, the arcs whose rounded
centre plainly passes the arc check; the writer takes an answer only for its exact
arguments. These tests hold:

- every answer is what :func:`~camtool.post.arcconform.conform_arc` returns for the same
  arguments (the reference: the scalar shortcut and search), on random arcs of every kind
  the writer meets, and on arcs built to sit on each limit of the shortcut and of GRBL's
  float32 check; and it answers nearly every arc the scalar shortcut answers;
- its grid indices are :meth:`Grid.index`'s, on the floats next to decimal halves too;
- the writer writes the same code with it and without it (``CAMTOOL_ACCEL=0``), and with
  it most arcs are answered by it.
"""

from __future__ import annotations

import math
import random

import numpy as np
import pytest

import camtool.post.arcconform as arcconform
from camtool.model.errors import CamtoolError
from camtool.post import arcbatch
from camtool.post.arccheck import GRBL_TOLERANCE_MM, LINUXCNC_TOLERANCE_MM, MARGIN_MM
from camtool.post.arcconform import SHORTCUT_MAX_MM, conform_arc
from camtool.post.registry import load_target
from tests.accel.test_conform_ahead import BIG, arc_program, post_of
from tests.post.test_arccheck_shortcut import _arc

Point = tuple[float, float]
Key = tuple[Point, Point, Point, bool, Point]


def _reference_blocks(key: Key, rule: str, quantum: float) -> object:
    written, end, centre, clockwise, exact_start = key
    try:
        pieces = conform_arc(
            written, end, centre, clockwise, rule=rule, quantum_mm=quantum, exact_start=exact_start
        )
    except (CamtoolError, ValueError) as exc:
        return f"{type(exc).__name__}: {exc}"
    return [(p.end, p.centre) for p in pieces]


def _plain_by_scalar_shortcut(key: Key, rule: str, quantum: float) -> bool:
    """Whether the scalar shortcut alone settles the arc (its answer: one block)."""
    written, end, centre, clockwise, exact_start = key
    grid = arcconform.Grid.of(quantum)
    s, e, c = grid.indices(written), grid.indices(end), grid.indices(centre)
    if s == e or math.dist(end, centre) == 0.0:
        return False
    ref = arcconform._reference(written, end, centre, clockwise, exact_start)
    solver = arcconform.Solver(grid, rule, clockwise, centre)
    return arcconform.plainly_passes(solver, s, e, c, ref) and solver._accepted(s, e, c)


def _check(keys: list[Key], rule: str, quantum: float) -> tuple[int, int]:
    """Assert every answer is conform_arc's; (answers, arcs the scalar shortcut settles)."""
    grid = arcconform.Grid.of(quantum)
    answers = arcbatch.plain_blocks(grid, rule, keys)
    assert len(answers) == len(keys)
    answered = scalar = 0
    for key, blocks in zip(keys, answers, strict=True):
        scalar += _plain_by_scalar_shortcut(key, rule, quantum)
        if blocks is None:
            continue
        answered += 1
        assert blocks == _reference_blocks(key, rule, quantum), (key, rule, quantum)
    return answered, scalar


@pytest.mark.parametrize("rule", ["grbl", "linuxcnc"])
def test_every_answer_on_random_arcs_is_conform_arcs_own(rule: str) -> None:
    rng = np.random.default_rng(44 if rule == "grbl" else 4444)
    by_quantum: dict[float, list[Key]] = {}
    for _ in range(3000):
        start, exact_start, end, centre, clockwise, q = _arc(rng)
        by_quantum.setdefault(q, []).append((start, end, centre, clockwise, exact_start))
    answered = scalar = 0
    for q, keys in by_quantum.items():
        a, s = _check(keys, rule, q)
        if arcconform.Grid.of(q).decimals is None:
            assert a == 0  # 0.0254 mm: grid values are not k / 10**d, no answers
            continue
        answered, scalar = answered + a, scalar + s
    assert answered > 1000  # not vacuous: most arcs are plain
    assert answered >= 0.99 * scalar  # and nearly every one the scalar shortcut settles


def _around(rng: random.Random, radius: float, gap: float, q: float, sweep: float) -> Key:
    """An arc of ``radius`` whose exact start lies ``gap`` mm further out than its end."""
    centre = (rng.uniform(-500, 500), rng.uniform(-500, 500))
    a0 = rng.uniform(-math.pi, math.pi)
    clockwise = sweep < 0
    start = (centre[0] + (radius + gap) * math.cos(a0), centre[1] + (radius + gap) * math.sin(a0))
    end = (centre[0] + radius * math.cos(a0 + sweep), centre[1] + radius * math.sin(a0 + sweep))
    grid = arcconform.Grid.of(q)
    return (grid.point(grid.indices(start)), end, centre, clockwise, start)


@pytest.mark.parametrize("rule", ["grbl", "linuxcnc"])
@pytest.mark.parametrize("quantum", [0.001, 0.01, 0.1])
def test_answers_on_the_limits_are_conform_arcs_own(rule: str, quantum: float) -> None:
    """Start radii on each side of the rule's tolerance (less the margin), radii from a
    quantum to the shortcut's ceiling, sweeps from a hair to a full turn."""
    rng = random.Random(f"{rule}{quantum}")
    tolerance = (GRBL_TOLERANCE_MM if rule == "grbl" else LINUXCNC_TOLERANCE_MM) - MARGIN_MM
    gaps = [0.0, tolerance, -tolerance, 0.001 * 0.5 - MARGIN_MM]
    gaps += [g + d for g in (tolerance, -tolerance) for d in (-1e-9, -1e-12, 1e-12, 1e-9)]
    radii = [quantum, 3 * quantum, 0.5, 7.0, 250.0, SHORTCUT_MAX_MM * 0.999, SHORTCUT_MAX_MM]
    sweeps = [1e-7, 1e-4, 0.3, math.pi / 2, math.pi - 1e-9, math.pi + 1e-9, 6.0, 2 * math.pi - 1e-6]
    keys = [
        _around(rng, radius, gap, quantum, sweep * sign)
        for radius in radii
        for gap in gaps
        for sweep in sweeps
        for sign in (1, -1)
    ]
    answered, scalar = _check(keys, rule, quantum)
    print(f"{rule} {quantum}: {answered} answered, the scalar shortcut {scalar}, of {len(keys)}")
    assert answered >= 0.9 * scalar > 0


def test_no_answer_for_numbers_that_are_no_arc() -> None:
    grid = arcconform.Grid.of(0.001)
    ok: Key = ((1.0, 2.0), (3.0, 4.0), (3.0, 2.0), True, (1.0, 2.0))
    keys: list[Key] = [
        ok,
        ((1.0, 2.0), (3.0, 4.0), (math.nan, 2.0), True, (1.0, 2.0)),
        ((1.0, 2.0), (math.inf, 4.0), (3.0, 2.0), True, (1.0, 2.0)),
        ((1.0, 2.0), (3.0, 2.0), (3.0, 2.0), True, (1.0, 2.0)),  # radius 0
        ((1.0, 2.0), (1.0, 2.0), (3.0, 2.0), True, (1.0, 2.0)),  # ends print the same
        ((1.0, 2.0), (3.0, 4.0), (3.0, 2.0), True, (1.002, 2.0)),  # start not its rounding
        ((1.0004, 2.0), (3.0, 4.0), (3.0, 2.0), True, (1.0004, 2.0)),  # start off the grid
    ]
    answers = arcbatch.plain_blocks(grid, "grbl", keys)
    assert answers[0] == _reference_blocks(ok, "grbl", 0.001)
    assert answers[1:] == [None] * (len(keys) - 1)


@pytest.mark.parametrize("quantum", [0.001, 0.01, 0.1, 0.0001, 1e-6])
def test_grid_indices_in_arrays_are_grid_index(quantum: float) -> None:
    grid = arcconform.Grid.of(quantum)
    assert grid.decimals is not None  # the grids the batch works on
    rng = np.random.default_rng(5)
    values = [0.0, -0.0, 0.0005, -0.0005, 2.675, -2.675, 1.0005, 0.0015, 1e16, -1e15]
    values += [float(v) for v in rng.uniform(-2000, 2000, 2000)]
    halves = [(int(k) + 0.5) * quantum for k in rng.integers(-(10**13), 10**13, 300)]
    halves += [(int(k) + 0.5) * quantum for k in rng.integers(-(10**6), 10**6, 300)]
    values += [math.nextafter(h, t) for h in halves for t in (-math.inf, math.inf)] + halves
    values += [2.0**50 * quantum, 2.0**52 * quantum]
    pairs = np.array(values + values[:1] if len(values) % 2 else values).reshape(-1, 2)
    got = arcbatch._indices(grid, pairs)
    big = arcbatch._BIG_INDEX
    for (a, b), (ka, kb) in zip(pairs.tolist(), got.tolist(), strict=True):
        want = [k if abs(k) < big else big for k in (grid.index(a), grid.index(b))]
        assert [ka, kb] == want, (a, b)


@pytest.mark.parametrize("target", ["grbl", "linuxcnc", "toy-coarse", "toy-grid"])
def test_the_writer_writes_the_same_with_and_without_it(
    target: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    from camtool.accel import conformahead, splitwrite
    from camtool.post.wordaddress_write import BlockWriter

    monkeypatch.setattr(conformahead, "start", lambda *_: None)  # the batch alone
    monkeypatch.setattr(splitwrite, "start", lambda *_: None)
    post = post_of(target)
    program = arc_program(random.Random(target), 1500, messy=True)
    taken = []
    real_take = arcbatch.ArcBatch.take

    def take(self: arcbatch.ArcBatch, key: Key) -> object:
        found = real_take(self, key)
        taken.append(found is not None)
        return found

    monkeypatch.setattr(arcbatch.ArcBatch, "take", take)

    def written() -> str:
        w = BlockWriter(post.spec, BIG)
        code = w.write(program)
        return code + "\n---\n" + "\n".join(w.warnings)

    monkeypatch.setenv("CAMTOOL_ACCEL", "1")
    fast = written()
    print(f"{target}: {sum(taken)} of {len(taken)} lookups answered")
    if target == "toy-grid":  # a 0.002 mm grid is no 10**-d one: the writer alone
        assert not taken
    else:  # most arcs answered by the batch (fewer at 2 decimals, where more are nudged)
        assert sum(taken) > (0.6 if target == "toy-coarse" else 0.8) * 1500
    monkeypatch.setenv("CAMTOOL_ACCEL", "0")
    taken.clear()
    assert written() == fast
    assert not taken  # switched off: no batch at all


@pytest.mark.usefixtures("helpers_on")
@pytest.mark.parametrize("target", ["grbl", "toy-coarse"])
def test_with_the_helper_too_the_writer_writes_the_same(
    target: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The helper (camtool.accel.conformahead) leaves the batch's arcs to the writer and
    conforms the others; with every answer of both in before the first block, the code is
    the code of the writer alone."""
    from camtool.accel import conformahead
    from tests.accel.test_conform_ahead import Started, written

    post = post_of(target)
    program = arc_program(random.Random(f"both {target}"), conformahead.MIN_ARCS + 500, messy=True)
    with monkeypatch.context() as m:
        m.setenv("CAMTOOL_ACCEL", "0")
        expected = written(post, program)
    started = Started(drain=True)
    monkeypatch.setattr(conformahead, "start", started)
    assert written(post, program) == expected
    assert started.ahead is not None
    # the helper answered only arcs the batch leaves: the arcs that take the search
    assert 0 < started.ahead.taken < 0.3 * conformahead.MIN_ARCS
    # and it was told of every lookup, the batch's too: it knows where the writer is
    assert started.ahead.looks > conformahead.MIN_ARCS


def test_no_batch_where_it_would_not_pay(monkeypatch: pytest.MonkeyPatch) -> None:
    """Repeated arcs (the writer reuses their blocks), too many moves to keep a prediction
    of, no arc check, a grid that is not 10**-d mm, or the switch off: no batch."""
    from camtool.model.program import Linear, Program
    from camtool.post.wordaddress_write import BlockWriter

    monkeypatch.setenv("CAMTOOL_ACCEL", "1")
    program = arc_program(random.Random(7), 300, messy=False)
    writer = BlockWriter(post_of("grbl").spec, BIG)
    assert arcbatch.applies(writer, program)
    repeated = Program(program.moves * 11)  # 300 distinct arcs in more than 3 000 moves
    assert not arcbatch.applies(writer, repeated)
    padded = Program(program.moves + (Linear(1.0, 1.0, 300.0),) * arcbatch.MAX_MOVES)
    assert not arcbatch.applies(writer, padded)
    assert not arcbatch.applies(BlockWriter(post_of("toy-grid").spec, BIG), program)
    assert not arcbatch.applies(BlockWriter(load_target("flashcut").post.spec, BIG), program)
    monkeypatch.setenv("CAMTOOL_ACCEL", "0")
    assert not arcbatch.applies(writer, program)
