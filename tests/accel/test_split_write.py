"""A long program's second part written in a forked helper: the same code as the writer alone.

:mod:`camtool.accel.splitwrite` forks a helper that writes a program from its middle on,
after writing a stretch before it to reach the writer's state there; the writer takes the
helper's blocks only when its own state at the middle is the one the helper started
from. These tests hold, with the split forced on small programs (:data:`MIN_MOVES` and
:data:`WARM` lowered, :data:`FAR` raised):

- the output: the same code, warnings and block count as the writer alone, on real
  programs of other CAM tools re-posted to each word-address target and on random arcs,
  lines and Z moves, and the helper's part was taken (so the comparison is not empty);
- the refusals: a second part the helper cannot reach the state of (no feed in its
  stretch), a helper that fails, dies, or meets an error (the writer's own error, naming
  its block, as alone), a warning only the helper gave;
- :func:`camtool.accel.later.same`: floats bit for bit.
"""

from __future__ import annotations

import math
import os
import random
import threading
from pathlib import Path
from typing import Any

import pytest

from camtool.accel import later, splitwrite
from camtool.importers.gcode import parse_gcode
from camtool.model.errors import DialectError
from camtool.model.program import Linear, Move, Program, Rapid
from camtool.post.registry import load_target
from camtool.post.wordaddress import WordAddressPost
from camtool.post.wordaddress_write import BlockWriter
from tests.accel.test_conform_ahead import BIG, arc_program

ROOT = Path(__file__).resolve().parents[2]
CORPUS = Path(os.environ.get("CAMTOOL_CORPUS_DIR", ROOT / ".corpus")) / "pkg" / "linuxcnc"
PROGRAMS = {
    "fusion-style-leads.nc": ROOT / "tests" / "data" / "fusion-style-leads.nc",
    **{
        Path(name).name: CORPUS / name
        for name in (
            "usr/share/doc/linuxcnc/examples/sample-configs/sim/craftsman/screens/craftsmancnc.ngc",
            "usr/share/linuxcnc/ncfiles/arcspiral.ngc",
            "usr/share/linuxcnc/ncfiles/cds.ngc",
        )
    },
}
"""Programs other tools wrote: tests/data/README.md says where the first comes from; the
others are the LinuxCNC examples of tests/benchmarks/bench_repost.py (CamBam's engraving, R-format
arcs in inches, pockets), from the corpus (``make corpus``)."""


@pytest.fixture(autouse=True)
def small_split(helpers_on: None, monkeypatch: pytest.MonkeyPatch) -> None:
    """Split programs of a few dozen moves, wherever the tests run."""
    monkeypatch.setattr(splitwrite, "MIN_MOVES", 20)
    monkeypatch.setattr(splitwrite, "WARM", 4)
    monkeypatch.setattr(splitwrite, "FAR", 0.5)


class Joins:
    """Wraps :meth:`splitwrite.Split.join`: what each join answered."""

    def __init__(self, monkeypatch: pytest.MonkeyPatch) -> None:
        self.answers: list[bool] = []
        join = splitwrite.Split.join

        def recording(split: splitwrite.Split, *args: Any) -> bool:
            answer = join(split, *args)
            self.answers.append(answer)
            return answer

        monkeypatch.setattr(splitwrite.Split, "join", recording)


def post_of(name: str) -> WordAddressPost:
    post = load_target(name).post
    assert isinstance(post, WordAddressPost)
    return post


def written(post: WordAddressPost, program: Program) -> str:
    """The code, warnings and block count the writer writes."""
    w = BlockWriter(post.spec, BIG)
    code = w.write(program)
    return f"{code}\n---\n" + "\n".join(w.warnings) + f"\n---\n{w.count}"


def alone(post: WordAddressPost, program: Program, monkeypatch: pytest.MonkeyPatch) -> str:
    with monkeypatch.context() as m:
        m.setattr(splitwrite, "start", lambda writer, program: None)
        return written(post, program)


def split_answers(post: WordAddressPost, program: Program, mp: pytest.MonkeyPatch) -> list[bool]:
    """Assert the writer writes the same split as alone; what its joins answered."""
    expected = alone(post, program, mp)
    joins = Joins(mp)
    assert written(post, program) == expected
    return joins.answers


@pytest.mark.parametrize("name", PROGRAMS)
@pytest.mark.parametrize("target", ["grbl", "linuxcnc", "flashcut"])
def test_real_programs_split_write_the_same(
    name: str, target: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = PROGRAMS[name]
    if not path.exists():
        pytest.skip(f"no {path}: run `make corpus`")
    program = parse_gcode(path.read_text(encoding="latin-1"), source=name)
    post = post_of(target)
    try:
        alone(post, program, monkeypatch)
    except DialectError:
        pytest.skip(f"{target} cannot write {name}")  # then the next test's case holds
    assert split_answers(post, program, monkeypatch) == [True]


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("target", ["grbl", "linuxcnc"])
def test_random_arcs_lines_and_z_moves_split_write_the_same(
    seed: int, target: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    program = arc_program(random.Random(seed), 300, messy=True)
    assert split_answers(post_of(target), program, monkeypatch) == [True]


def lines(n: int, z_every: int = 10) -> list[Move]:
    """``n`` cuts zig-zagging at 300 mm/min, a Z move every ``z_every``."""
    moves: list[Move] = [Rapid(0.0, 0.0, 5.0), Linear(0.0, 0.0, 300.0, -1.0)]
    for k in range(n):
        z = -1.0 - (k // z_every) * 0.1 if k % z_every == 0 else None
        moves.append(Linear(float(k % 7), float(k), 300.0, z))
    return moves


def test_a_state_the_helper_cannot_reach_is_written_by_the_writer(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # the first half cuts at F300; the stretch the helper writes before the middle is
    # rapids: it starts without the feed the writer has written, and its part is not taken
    moves = lines(30)
    moves += [Rapid(float(k), 50.0, 5.0 if k % 2 else 4.0) for k in range(30)]
    moves += [Linear(1.0, 60.0 + k, 300.0) for k in range(40)]
    answers = split_answers(post_of("grbl"), Program(tuple(moves)), monkeypatch)
    assert answers == [False]


def test_a_program_without_a_z_move_near_the_middle_is_not_split(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(splitwrite, "FAR", 0.1)  # its only Z moves are its first two
    moves = [Rapid(0.0, 0.0, 5.0), Linear(0.0, 0.0, 300.0, -1.0)]
    moves += [Linear(float(k % 5), float(k), 300.0) for k in range(200)]
    assert split_answers(post_of("grbl"), Program(tuple(moves)), monkeypatch) == []


def test_an_error_in_the_second_part_names_its_block_as_alone(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # a feed that rounds to F0 near the end: the helper fails, the writer writes the
    # rest itself and gives its own error, counted from the program's first block
    moves = lines(200)
    moves[-5] = Linear(3.0, 300.0, 1e-9)
    post = post_of("grbl")
    with pytest.raises(DialectError) as alone_error:
        alone(post, Program(tuple(moves)), monkeypatch)
    joins = Joins(monkeypatch)
    with pytest.raises(DialectError) as split_error:
        written(post, Program(tuple(moves)))
    assert str(split_error.value) == str(alone_error.value)
    assert "block" in str(alone_error.value)
    assert joins.answers == [False]


def test_a_warning_only_the_helper_gives_is_written_by_the_writer(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # a feed GRBL writes rounded (a warning naming the feed) only in the second half
    moves = lines(200)
    moves[150:] = [Linear(m.x, m.y, 300.04, m.z) for m in moves[150:]]
    post = post_of("grbl")
    assert "written as" in alone(post, Program(tuple(moves)), monkeypatch)
    assert split_answers(post, Program(tuple(moves)), monkeypatch) == [False]


@pytest.mark.parametrize("how", ["raises", "dies", "hangs"])
def test_a_helper_that_fails_changes_nothing(how: str, monkeypatch: pytest.MonkeyPatch) -> None:
    from camtool.accel import cores

    monkeypatch.setattr(cores, "HELPER_PATIENCE_MIN_S", 0.5)  # not the 10 s a user waits

    def fail(*args: Any) -> Any:
        if how == "dies":
            os._exit(3)
        if how == "hangs":
            threading.Event().wait()  # forever: the writer ends it at the deadline
        raise RuntimeError("helper failed")

    monkeypatch.setattr(splitwrite, "_second_part", fail)
    program = Program(tuple(lines(200)))
    assert split_answers(post_of("linuxcnc"), program, monkeypatch) == [False]


def test_switched_off_nothing_is_split(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("CAMTOOL_ACCEL", "0")
    program = Program(tuple(lines(200)))
    assert split_answers(post_of("linuxcnc"), program, monkeypatch) == []


def test_same_compares_floats_bit_for_bit() -> None:
    same = later.same
    assert same({"here": (1.0, 2.0), "last": {"X": "1"}}, {"here": (1.0, 2.0), "last": {"X": "1"}})
    assert not same((0.0, 1.0), (-0.0, 1.0))
    assert not same(math.nan, math.nan)
    assert not same(1, 1.0)
    assert not same({"a": 1}, {"a": 1, "b": 2})
    assert not same([1.0], (1.0,))
