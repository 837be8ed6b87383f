"""The word-address writer's shortcuts write what its full path writes (issue 17).

:class:`~camtool.post.wordaddress_write.BlockWriter` formats a word without a step grid with
its number format directly (:meth:`text`), writes the feed of the block before again
without checking it anew (:meth:`_feed`), keeps the text and value read back of each
coordinate it printed (:meth:`_print`) and keeps the blocks of each arc it conformed to
the controller's check for the same arc again (:meth:`_conformed`). :class:`Reference`
turns them all off: every word goes through the full formatting, every feed through its
checks and every arc through :func:`~camtool.post.arcconform.conform_arc`, as before. On
random programs of rapids, lines and arcs (tiny, huge, full circles, reflex arcs,
helices, feeds that round, numbers over their field) written for every built-in
word-address target and a few dialects of other widths, the code, the warnings and the
errors are the same.
"""

from __future__ import annotations

import math
import random
from typing import Any

from camtool.model.errors import CamtoolError
from camtool.model.machine import Machine
from camtool.model.program import ArcMove, Linear, Move, Program, Rapid
from camtool.model.shapes import Arc, Point
from camtool.post.registry import load_target
from camtool.post.wordaddress import WordAddressPost, word_address_dialect
from camtool.post.wordaddress_write import BlockWriter

BIG = Machine(name="test bench", steps_per_mm=(1000.0,) * 3, work_area_mm=(-900, -900, 900, 900))


class Reference(BlockWriter):
    """The writer without its shortcuts: every text formatted and checked in full."""

    def __init__(self, *args: Any) -> None:
        super().__init__(*args)
        self._formats = {}

    def _feed(self, move: Linear | ArcMove, words: list[str]) -> None:
        self._feed_text = None
        super()._feed(move, words)

    def _print(self, letter: str, value: float) -> tuple[str, float]:
        text = self.text(letter, value)
        return text, self._parses[letter](text)

    def _conformed(self, piece: Arc) -> list[tuple[Point, Point | None]]:
        if self.spec.arc_check == "none":
            return super()._conformed(piece)
        return self._conform(piece)


def written(writer: type[BlockWriter], post: WordAddressPost, program: Program) -> str:
    """The code and warnings ``writer`` gives, or its error."""
    w = writer(post.spec, BIG)
    try:
        code = w.write(program)
    except CamtoolError as exc:
        return f"{type(exc).__name__}: {exc}"
    return code + "\n---\n" + "\n".join(w.warnings)


def random_program(rng: random.Random, z: bool) -> Program:
    moves: list[Move] = []
    x, y = 0.0, 0.0
    scale = 10 ** rng.uniform(-3, 3)
    tiny_feed = rng.random() < 0.05
    for _ in range(rng.randint(1, 40)):
        kind = rng.random()
        tx, ty = x + rng.uniform(-1, 1) * scale, y + rng.uniform(-1, 1) * scale
        zz = rng.choice([None, None, rng.uniform(-5, 5)]) if z else None
        feed = rng.choice([100.0, 100.0, 250.0, 33.333, 0.04 if tiny_feed else 1e7])
        if kind < 0.2:
            moves.append(Rapid(tx, ty, zz))
        elif kind < 0.5:
            moves.append(Linear(tx, ty, feed, zz))
        else:
            r = rng.uniform(0.0001, 1) * scale
            a0, sweep = rng.uniform(-math.pi, math.pi), rng.uniform(-2 * math.pi, 2 * math.pi)
            cx, cy = x - r * math.cos(a0), y - r * math.sin(a0)
            if rng.random() < 0.1:
                tx, ty = x, y  # a full circle
            else:
                tx, ty = cx + r * math.cos(a0 + sweep), cy + r * math.sin(a0 + sweep)
            moves.append(ArcMove(tx, ty, cx, cy, sweep < 0, feed, zz))
        x, y = tx, ty
    if rng.random() < 0.5:  # the same contour again, at another depth where there is Z
        moves += [Rapid(0.0, 0.0), *moves]
    return Program(tuple(moves))


def test_the_shortcuts_write_what_the_full_path_writes() -> None:
    rng = random.Random(17)
    posts = [load_target(name).post for name in ("flashcut", "grbl", "linuxcnc", "valcnc")]
    posts += [
        word_address_dialect(
            {"words": {"XYZIJ": {"decimals": d, "min_decimals": 0}, "F": {"decimals": 0}}},
            "toy.toml",
        )
        for d in (0, 2, 4)
    ]
    for post in posts:
        assert isinstance(post, WordAddressPost)
        for _ in range(150):
            program = random_program(rng, z=post.spec.has("Z"))
            assert written(BlockWriter, post, program) == written(Reference, post, program)
