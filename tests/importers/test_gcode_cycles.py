"""Canned drilling cycles read from another CAM's program move as LinuxCNC moves them.

G81, G82, G83 and G73 with G98/G99, sticky R, Z and Q, a series that begins below or above
the R plane: the reader's moves are LinuxCNC's ``rs274`` canonical moves of the same file
(the judge), and the program re-posted for grbl and linuxcnc runs to the same moves again.
A zero-length traverse (LinuxCNC's rise to the R plane where the tool already is) moves
nothing and is left out of both sides.
"""

from __future__ import annotations

import random
from pathlib import Path

import pytest

from camtool.importers.gcode import read_gcode
from camtool.model.errors import InputError
from camtool.model.program import DrillCycle, Dwell
from tests.corpus.test_rs274 import ROUND_MM, canon_moves, needs_rs274, planned_moves, rs274
from tests.targets import repost_cli

Canon = list[tuple[str, tuple[float, ...]]]


def _moving(moves: Canon) -> Canon:
    """``moves`` without those that end where the one before ended."""
    out: Canon = []
    here: tuple[float, ...] | None = None
    for kind, numbers in moves:
        if numbers[:3] != here:
            out.append((kind, numbers))
        here = numbers[:3]
    return out


def _same(a: Canon, b: Canon) -> None:
    a, b = _moving(a), _moving(b)
    assert [kind for kind, _ in a] == [kind for kind, _ in b], (a, b)
    for (_, p), (_, q) in zip(a, b, strict=True):
        assert max(abs(u - v) for u, v in zip(p, q, strict=True)) <= ROUND_MM, (p, q)


def _program(rng: random.Random) -> str:
    """A random program of cycle series: each its cycle, retract mode, start height, holes."""
    lines = ["G21 G90 G17", "G0 X0 Y0 Z10", "F120"]
    for _ in range(rng.randint(1, 3)):
        code = rng.choice(["G81", "G82", "G83", "G73"])
        r = rng.choice([1.0, 2.5])
        start = rng.choice([r + 8.0, r - 0.5, r])  # above, below and at the R plane
        lines.append(f"G0 X{rng.randint(-20, 20)} Y{rng.randint(-20, 20)} Z{start:g}")
        extra = {"G82": f" P{rng.choice([0.5, 1])}", "G83": " Q0.7", "G73": " Q0.6"}.get(code, "")
        mode = rng.choice(["G98", "G99"])
        bottom = -rng.choice([1.0, 2.3, 3.1])
        x, y = rng.randint(-30, 30), rng.randint(-30, 30)
        lines.append(f"{mode} {code} X{x} Y{y} Z{bottom:g} R{r:g}{extra}")
        for _ in range(rng.randint(0, 3)):  # the series goes on: X and Y only, or a new Z
            x, y = rng.randint(-30, 30), rng.randint(-30, 30)
            z = f" Z{-rng.choice([0.5, 1.5]):g}" if rng.random() < 0.3 else ""
            lines.append(f"X{x} Y{y}{z}")
        lines.append("G80")
    lines += ["G0 Z10", "M2"]
    return "\n".join(lines) + "\n"


@needs_rs274
@pytest.mark.parametrize("seed", range(6))
def test_random_cycles_read_as_rs274_runs_them(seed: int, tmp_path: Path) -> None:
    path = tmp_path / f"cycles{seed}.ngc"
    path.write_text(_program(random.Random(seed)))
    done = rs274(path)
    assert done.returncode == 0, done.stderr
    program = read_gcode(path)
    _same(canon_moves(done.stdout), planned_moves(program.moves))
    cycles = [c for _, c in program.commands if isinstance(c, DrillCycle)]
    assert cycles and sum(c.moves for c in cycles) <= len(program.moves)


@needs_rs274
@pytest.mark.parametrize("target", ["grbl", "linuxcnc"])
def test_cycles_re_posted_move_as_they_did(target: str, tmp_path: Path) -> None:
    text = _program(random.Random(100))
    original, out = repost_cli(tmp_path, "cycles.ngc", text, target)
    want, got = rs274(original), rs274(out)
    assert want.returncode == 0 and got.returncode == 0, (want.stderr, got.stderr)
    _same(canon_moves(want.stdout), canon_moves(got.stdout))


def test_g82_dwells_at_the_bottom_and_the_sticky_words_carry_on(tmp_path: Path) -> None:
    path = tmp_path / "g82.ngc"
    path.write_text("G21 G90\nG0 X0 Y0 Z5\nF100\nG99 G82 X1 Y1 Z-2 R1 P0.5\nX3\nG80\nM2\n")
    program = read_gcode(path)
    dwells = [(i, c) for i, c in program.commands if isinstance(c, Dwell)]
    assert [c.seconds for _, c in dwells] == [0.5, 0.5]
    for index, _ in dwells:  # each after its feed to the bottom
        assert program.moves[index - 1].z == -2.0
    assert (program.moves[-1].x, program.moves[-1].y, program.moves[-1].z) == (3.0, 1.0, 1.0)


@pytest.mark.parametrize(
    ("blocks", "message"),
    [
        ("G81 X1 Y1 Z-1", "G81 needs R"),
        ("G81 X1 Y1 R1", "G81 needs Z"),
        ("G83 X1 Y1 Z-1 R1", "G83 needs Q"),
        ("G82 X1 Y1 Z-1 R1", "G82 needs P"),
        ("G83 X1 Y1 Z-1 R1 Q0", "peck Q0 must be above 0"),
        ("G81 X1 Y1 Z2 R1", "bottom Z2 is not below R1"),
        ("G81 X1 Y1 Z-1 R1 L3", "L3 is a repeat"),
        ("G91 G81 X1 Y1 Z-1 R1", "G81 in G91 is not read"),
        ("G18 G81 X1 Y1 Z-1 R1", "G81 in the ZX or YZ plane"),
        ("G98 G81 X1 Y1 Z-1 R1\nG99 X2", "changes between G98 and G99"),
        ("G85 X1 Y1 Z-1 R1", "G85 is a canned cycle"),
    ],
)
def test_what_is_not_read_is_refused_naming_the_line(blocks: str, message: str) -> None:
    from camtool.importers.gcode import parse_gcode

    with pytest.raises(InputError, match=message) as info:
        parse_gcode(f"G21 G90\nG0 X0 Y0 Z5\nF100\n{blocks}\nG80\nM2\n", source="c.ngc")
    assert "c.ngc:4" in str(info.value) or "c.ngc:5" in str(info.value)


def test_a_cycles_x_y_is_never_read_as_a_straight_cut() -> None:
    """The plain-line path must not take a series' ``X Y`` line as a G1 (it drills)."""
    from camtool.importers.gcode import parse_gcode

    text = "G21 G90\nG0 X0 Y0 Z5\nF100\nG81 X1 Y1 Z-1 R1\n" + "".join(
        f"X{k} Y1\n" for k in range(2, 400)
    )
    program = parse_gcode(text + "G80\nM2\n", source="c.ngc")
    assert sum(isinstance(c, DrillCycle) for _, c in program.commands) == 399
    assert min(m.z for m in program.moves if m.z is not None) == -1.0


_UNSTATED = "G21 G90\nG0 X0 Y0 Z5\nF100\nG81 X1 Y1 Z-1 R1\nX3\nG80\nM2\n"
"""Two holes from Z5 with neither G98 nor G99 in the program."""


def test_a_cycle_without_g98_or_g99_returns_to_its_start_height_and_says_so() -> None:
    """G98 (the series' start height, Z5 here, above R1) is the higher return, the one Fanuc
    and Haas controls start in; the warning says so and names the first line."""
    from camtool.importers.gcode import parse_gcode

    program = parse_gcode(_UNSTATED, source="c.ngc")
    after_bottom = [program.moves[i + 1].z for i, m in enumerate(program.moves[:-1]) if m.z == -1.0]
    assert after_bottom == [5.0, 5.0]
    (warning,) = [w for w in program.warnings if "G98" in w]
    assert warning.startswith("c.ngc:4: G81 with neither G98 nor G99 given")
    assert warning.endswith("(2 times)")
    stated = parse_gcode(_UNSTATED.replace("G81", "G99 G81"), source="c.ngc")
    assert not [w for w in stated.warnings if "G98" in w]
    assert [stated.moves[i + 1].z for i, m in enumerate(stated.moves[:-1]) if m.z == -1.0] == [
        1.0,
        1.0,
    ]


@needs_rs274
def test_linuxcnc_starts_in_g99_as_the_warning_says(tmp_path: Path) -> None:
    """The warning's claim, judged by LinuxCNC's own interpreter: without G98/G99 its
    holes return to the R plane (Z1), not to Z5."""
    path = tmp_path / "unstated.ngc"
    path.write_text(_UNSTATED)
    done = rs274(path)
    assert done.returncode == 0, done.stderr
    moves = _moving(canon_moves(done.stdout))
    after_bottom = [moves[i + 1][1][2] for i, (_, p) in enumerate(moves[:-1]) if p[2] == -1.0]
    assert after_bottom == [1.0, 1.0]
