"""Arcs conformed ahead in a forked helper: the writer writes what it writes alone (issue 17).

:mod:`camtool.accel.conformahead` forks a helper that predicts the arguments of each arc's
arc check (:func:`~camtool.post.arcconform.conform_arc`) and conforms the arcs from the last
back, while the writer works from the first; the writer takes an answer only for an arc
whose arguments are the key the helper predicted. These tests hold:

- the prediction: on a program whose arcs all go through the usual path, the predicted
  keys are the keys the writer conforms, in order;
- the output: the same code and warnings with the helper, without it, with every answer
  taken, with a helper that dies, and with one whose predictions are all wrong;
- when no helper runs (few distinct arcs, no arc check, a worker process).
"""

from __future__ import annotations

import math
import os
import random
import time
from typing import Any

import pytest

from camtool.accel import conformahead, cores
from camtool.model.machine import Machine
from camtool.model.program import ArcMove, Linear, Move, Program, Rapid
from camtool.post import wordaddress_write
from camtool.post.registry import load_target
from camtool.post.wordaddress import WordAddressPost, word_address_dialect
from camtool.post.wordaddress_write import BlockWriter

BIG = Machine(name="test bench", steps_per_mm=(1000.0,) * 3, work_area_mm=(-900, -900, 900, 900))
ARCS = conformahead.MIN_ARCS + 500


pytestmark = pytest.mark.usefixtures("helpers_on")


@pytest.fixture(autouse=True)
def _helper_alone(monkeypatch: pytest.MonkeyPatch) -> None:
    """The helper without the writer's batch of plain arcs (camtool.post.arcbatch), which
    would answer most arcs first and leave the helper only the others: these tests are of
    the helper's answers (tests/post/test_arcbatch.py runs the two together)."""
    from camtool.post import arcbatch

    monkeypatch.setattr(arcbatch, "applies", lambda writer, program: False)


TOYS: dict[str, dict[str, Any]] = {
    # split arcs, a step grid on X/Y/I/J, absolute centres: arcs the writer splits, words
    # whose text also raises its largest grid change
    "toy-grid": {
        "arc_check": "linuxcnc",
        "max_arc_deg": 90.0,
        "full_circle": "split",
        "arc_centre": "absolute",
        "words": {"XYZIJ": {"decimals": 3, "min_decimals": 0, "grid_mm": 0.002}},
    },
    # 2 decimals: coarser arcs, more of them nudged or split by the check
    "toy-coarse": {"arc_check": "grbl", "words": {"XYZIJ": {"decimals": 2, "min_decimals": 0}}},
}


def post_of(name: str) -> WordAddressPost:
    if name in TOYS:
        return word_address_dialect(TOYS[name], f"{name}.toml")
    post = load_target(name).post
    assert isinstance(post, WordAddressPost)
    return post


def arc_program(rng: random.Random, arcs: int, *, messy: bool) -> Program:
    """``arcs`` arcs of distinct centres with lines, rapids and Z moves between them.

    ``messy``: also full circles, arcs that round away at 3 decimals, reflex arcs and
    moves that change only Z (the arcs the helper leaves to the writer).
    """
    moves: list[Move] = [Rapid(10.0, 10.0, 5.0), Linear(10.0, 10.0, 300.0, -1.0)]
    x, y = 10.0, 10.0
    for k in range(arcs):
        if abs(x) > 400 or abs(y) > 400:
            x, y = 10.0 + k * 1e-3, 10.0  # back near the start, above the stock
            moves += [Rapid(moves[-1].x, moves[-1].y, 5.0), Rapid(x, y), Linear(x, y, 300.0, -1.0)]
        roll = rng.random()
        r = rng.uniform(0.5, 20.0)
        a0 = rng.uniform(-math.pi, math.pi)
        sweep = rng.uniform(0.2, 2.8) * rng.choice((-1, 1))
        if messy and roll < 0.05:
            sweep = 2 * math.pi  # a full circle
        elif messy and roll < 0.08:
            r, sweep = 0.0004, 0.5  # rounds away at 3 decimals
        elif messy and roll < 0.15:
            sweep = rng.uniform(3.3, 6.0) * rng.choice((-1, 1))  # a reflex arc
        cx, cy = x - r * math.cos(a0), y - r * math.sin(a0)
        if sweep == 2 * math.pi:
            tx, ty = x, y
        else:
            tx, ty = cx + r * math.cos(a0 + sweep), cy + r * math.sin(a0 + sweep)
        moves.append(ArcMove(tx, ty, cx, cy, sweep < 0, 300.0))
        x, y = tx, ty
        if rng.random() < 0.2:
            tx, ty = x + rng.uniform(-3, 3), y + rng.uniform(-3, 3)
            moves.append(Linear(tx, ty, 300.0))
            x, y = tx, ty
        if messy and rng.random() < 0.05:
            moves.append(Rapid(x, y, rng.uniform(-2, 2)))  # Z alone: no X or Y word
    return Program(tuple(moves))


def alone(post: WordAddressPost, program: Program, monkeypatch: pytest.MonkeyPatch) -> str:
    """The code and warnings of the writer without a helper."""
    with monkeypatch.context() as m:
        m.setattr(conformahead, "start", lambda writer, program: None)
        return written(post, program)


def written(post: WordAddressPost, program: Program) -> str:
    w = BlockWriter(post.spec, BIG)
    code = w.write(program)
    return code + "\n---\n" + "\n".join(w.warnings)


class Started:
    """Wraps :func:`conformahead.start`: keeps the helper, and waits for it when ``drain``."""

    def __init__(self, drain: bool) -> None:
        self.drain = drain
        self.ahead: conformahead.ConformAhead | None = None
        self.start = conformahead.start

    def __call__(self, writer: BlockWriter, program: Program) -> Any:
        ahead = self.start(writer, program)
        assert ahead is not None, "no helper was started"
        self.ahead = ahead
        if self.drain:  # every answer in before the first block: all of them are taken
            deadline = time.monotonic() + 60.0
            while ahead.fd is not None and time.monotonic() < deadline:
                ahead._read()
                time.sleep(0.002)
            assert ahead.fd is None, "the helper did not finish"
        return ahead


def same_with_helper(
    post: WordAddressPost, program: Program, monkeypatch: pytest.MonkeyPatch, *, drain: bool
) -> conformahead.ConformAhead:
    """Assert that the writer writes the same with its helper as alone; the helper it had."""
    expected = alone(post, program, monkeypatch)
    started = Started(drain)
    monkeypatch.setattr(conformahead, "start", started)
    assert written(post, program) == expected
    assert started.ahead is not None
    return started.ahead


@pytest.mark.parametrize("target", ["grbl", "linuxcnc"])
def test_predicted_keys_are_the_keys_the_writer_conforms(
    target: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    post = post_of(target)
    program = arc_program(random.Random(1), ARCS, messy=False)
    looked: list[tuple[Any, ...]] = []

    class Recording(wordaddress_write.Conformed):
        def __setitem__(self, key: Any, value: Any) -> None:
            looked.append(key)
            super().__setitem__(key, value)

    monkeypatch.setattr(wordaddress_write, "Conformed", Recording)
    alone(post, program, monkeypatch)
    writer = BlockWriter(post.spec, BIG)
    origin = program.origin
    writer.written = (writer._round("X", origin[0]), writer._round("Y", origin[1]))
    steps = zip([origin, *((m.x, m.y) for m in program.moves)], program.moves, strict=False)
    # the prediction goes through moves that write no X or Y
    assert any(not isinstance(m, ArcMove) and writer.z_only(s, m) for s, m in steps)
    calls = conformahead.arc_calls(writer, program)
    predicted = [key for call in calls if (key := conformahead.key_of(writer, call)) is not None]
    assert len(looked) == ARCS  # every arc conformed once, by the usual path
    assert predicted == looked


@pytest.mark.parametrize("target", ["grbl", "linuxcnc", "toy-coarse", "toy-grid"])
def test_every_answer_taken_writes_the_same(target: str, monkeypatch: pytest.MonkeyPatch) -> None:
    post = post_of(target)
    program = arc_program(random.Random(2), ARCS, messy=True)
    ahead = same_with_helper(post, program, monkeypatch, drain=True)
    # the messy arcs are left to the writer, and on toy-grid the arcs it splits in pieces
    assert ahead.taken > (0.3 if target == "toy-grid" else 0.8) * ARCS
    assert ahead.fd is None  # closed


def test_the_helper_and_the_writer_meet_and_write_the_same(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    post = post_of("grbl")
    program = arc_program(random.Random(3), ARCS, messy=True)
    same_with_helper(post, program, monkeypatch, drain=False)


def test_a_helper_that_dies_changes_nothing(monkeypatch: pytest.MonkeyPatch) -> None:
    post = post_of("grbl")
    program = arc_program(random.Random(4), ARCS, messy=True)
    monkeypatch.setattr(conformahead, "_conformed", lambda writer, key: os._exit(3))
    assert same_with_helper(post, program, monkeypatch, drain=True).taken == 0


def test_answers_to_other_arguments_are_not_taken(monkeypatch: pytest.MonkeyPatch) -> None:
    """Predictions one quantum off: every answer is for another arc, and none is taken."""
    post = post_of("grbl")
    program = arc_program(random.Random(5), ARCS, messy=False)
    key_of = conformahead.key_of

    def off(writer: BlockWriter, call: Any) -> Any:
        key = key_of(writer, call)
        return None if key is None else ((key[0][0] + 0.001, key[0][1]), *key[1:])

    monkeypatch.setattr(conformahead, "key_of", off)
    ahead = same_with_helper(post, program, monkeypatch, drain=True)
    assert ahead.taken == 0
    assert not ahead.got and not ahead.raw  # closed: what it sent is let go


def test_no_helper_for_repeated_arcs_or_without_an_arc_check(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    grbl = post_of("grbl")
    few = arc_program(random.Random(6), conformahead.MIN_ARCS // 4, messy=False)
    again = Program(few.moves * 5)  # as many arcs, a quarter of them distinct
    assert sum(isinstance(m, ArcMove) for m in again.moves) > conformahead.MIN_ARCS
    assert conformahead.start(BlockWriter(grbl.spec, BIG), again) is None
    many = arc_program(random.Random(7), ARCS, messy=False)
    flashcut = post_of("flashcut")
    assert flashcut.spec.arc_check == "none"
    assert conformahead.start(BlockWriter(flashcut.spec, BIG), many) is None
    monkeypatch.setattr(cores, "in_worker", lambda: True)
    assert conformahead.start(BlockWriter(grbl.spec, BIG), many) is None
    monkeypatch.setattr(cores, "in_worker", lambda: False)
    monkeypatch.setattr(cores, "default_jobs", lambda: 1)
    assert conformahead.start(BlockWriter(grbl.spec, BIG), many) is None
    monkeypatch.setattr(cores, "default_jobs", lambda: 2)
    ahead = conformahead.start(BlockWriter(grbl.spec, BIG), many)
    assert ahead is not None
    ahead.close()


def test_no_helper_when_no_process_can_be_forked(monkeypatch: pytest.MonkeyPatch) -> None:
    post = post_of("grbl")
    program = arc_program(random.Random(8), ARCS, messy=False)
    expected = alone(post, program, monkeypatch)

    def no_fork() -> int:
        raise BlockingIOError(11, "Resource temporarily unavailable")

    monkeypatch.setattr(os, "fork", no_fork)
    assert conformahead.start(BlockWriter(post.spec, BIG), program) is None
    assert written(post, program) == expected


def test_no_helper_for_a_program_too_big_to_copy_or_when_switched_off(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # the helper walks every move, and the reference counts it touches copy the program's
    # pages into it: above MAX_MOVES the writer conforms its arcs alone (bounded memory)
    grbl = post_of("grbl")
    many = arc_program(random.Random(9), ARCS, messy=False)
    monkeypatch.setattr(conformahead, "MAX_MOVES", len(many.moves) - 1)
    assert conformahead.start(BlockWriter(grbl.spec, BIG), many) is None
    monkeypatch.setattr(conformahead, "MAX_MOVES", len(many.moves))
    monkeypatch.setenv("CAMTOOL_ACCEL", "0")
    assert conformahead.start(BlockWriter(grbl.spec, BIG), many) is None
