"""Arcs split by ``max_arc_deg`` or ``full_circle = "split"`` in a dialect with an arc check.

Each piece must pass the controller's check from where the controller stands when it
starts: the end of the piece before, as written. The writer checked every piece from the
arc's own start instead, and a target file combining the two (a GRBL with ``max_arc_deg =
180``) ended ``camtool post samples/logo.dxf`` with "internal error: ValueError: the arc
start … is not the rounded exact start …". No built-in target combines them, so their code
is unchanged (the goldens hold it).

Expected values: the controller's own rule (:func:`camtool.post.arccheck.arc_error`, the
rule GRBL's ``gcode.c`` and LinuxCNC's interpreter apply, as the dialect's reader applies it
to the code read back) and the exact arcs drawn here.
"""

from __future__ import annotations

import math
import random
from pathlib import Path

import pytest

from camtool.cli.main import main
from camtool.model.machine import Machine
from camtool.model.program import ArcMove, Linear, Move, Program, Rapid
from camtool.post.wordaddress import word_address_dialect

BIG = Machine(name="test bench", steps_per_mm=(1000.0,) * 3, work_area_mm=(-900, -900, 900, 900))
QUANTUM = 0.001
ROOT = Path(__file__).resolve().parents[2]


def arcs(rng: random.Random, count: int) -> tuple[Program, list[tuple[float, float, float]]]:
    """Arcs of every sweep up to full circles, and each one's exact circle (cx, cy, r)."""
    moves: list[Move] = [Rapid(1.0, 2.0)]
    circles = []
    x, y = 1.0, 2.0
    for _ in range(count):
        r = 10 ** rng.uniform(-1.3, 1.7)  # 0.05 to 50 mm
        a0 = rng.uniform(-math.pi, math.pi)
        sweep = rng.choice([rng.uniform(0.1, 2 * math.pi - 0.1), 2 * math.pi])
        sweep *= rng.choice((-1, 1))
        cx, cy = x - r * math.cos(a0), y - r * math.sin(a0)
        if abs(sweep) == 2 * math.pi:
            tx, ty = x, y  # a full circle
        else:
            tx, ty = cx + r * math.cos(a0 + sweep), cy + r * math.sin(a0 + sweep)
        moves.append(ArcMove(tx, ty, cx, cy, sweep < 0, 300.0))
        circles.append((cx, cy, r))
        x, y = tx + rng.uniform(-2, 2), ty + rng.uniform(-2, 2)
        moves.append(Linear(x, y, 300.0))
    return Program(tuple(moves)), circles


@pytest.mark.parametrize("rule", ["grbl", "linuxcnc"])
@pytest.mark.parametrize(
    ("max_deg", "full"), [(90.0, "split"), (180.0, "one-block"), (360.0, "split")]
)
def test_each_piece_passes_from_where_the_piece_before_ends(
    rule: str, max_deg: float, full: str
) -> None:
    post = word_address_dialect(
        {
            "arc_check": rule,
            "max_arc_deg": max_deg,
            "full_circle": full,
            "words": {"XYZIJ": {"decimals": 3, "min_decimals": 0}},
        },
        "toy.toml",
    )
    program, circles = arcs(random.Random(f"{rule}{max_deg}{full}"), 150)
    code = post.emit(program, BIG).code
    assert isinstance(code, str)
    back = post.parse(code)  # the reader refuses an arc the controller would refuse
    pieces = 0
    arc_of = iter(circles)
    circle = None
    for move in back.moves:
        if isinstance(move, Linear) and not isinstance(move, ArcMove):
            circle = None  # the next arc's blocks follow
            continue
        if not isinstance(move, ArcMove):
            continue
        if circle is None:
            circle = next(arc_of)
        pieces += 1
        cx, cy, r = circle  # each block's end lies on the exact arc, rounded to the grid
        assert abs(math.hypot(move.x - cx, move.y - cy) - r) <= QUANTUM
    assert pieces > len(circles)  # arcs were split: the case under test ran


def test_a_grbl_target_file_that_splits_arcs_posts_and_verifies_the_logo(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The case a user met: grbl.toml with ``max_arc_deg = 180``, on ``make demo``'s logo."""
    grbl = (ROOT / "postprocessors" / "grbl" / "grbl.toml").read_text()
    text = grbl.replace('name = "grbl"', 'name = "grbl-180"').replace(
        'arc_check = "grbl"', 'arc_check = "grbl"\nmax_arc_deg = 180.0'
    )
    assert "max_arc_deg = 180.0" in text
    target = tmp_path / "grbl-180.toml"
    target.write_text(text)
    out = tmp_path / "logo.gcode"
    logo = str(ROOT / "samples" / "logo.dxf")
    assert main(["post", logo, "--target", str(target), "-o", str(out)]) == 0
    code = out.read_text()
    assert "internal error" not in capsys.readouterr().err
    assert sum(line.startswith(("G2 ", "G3 ")) for line in code.splitlines()) >= 2
    assert main(["verify", str(out), "--target", str(target)]) == 0  # the arc check passes
