"""The G-code reader's plain-line path reads exactly what the lexer and ``run`` read (issue 17).

:func:`camtool.importers.gcode.parse_gcode` executes plain lines (G0-G3, X Y Z I J R F N
words, nothing else) without making word objects; :func:`parse_gcode_slow` lexes every
line and runs it block by block, as every line was read before. On the LinuxCNC example
programs of the corpus and on random programs built from plain and not-quite-plain lines
(duplicates, G91, G20, missing centres, radii off their circle, negative feeds, numbers
out of range, blanks inside words...), both give the same program (compared by ``repr``,
so ``-0.0`` and ``0.0`` differ) with the same warnings, or the same error.
"""

from __future__ import annotations

import math
import pickle
import random
from pathlib import Path

import pytest

from camtool.importers.gcode import parse_gcode, parse_gcode_slow
from camtool.model.errors import CamtoolError

# the fast path against the reference: the accelerated versions on
pytestmark = pytest.mark.usefixtures("accel_on")

CORPUS = Path(__file__).resolve().parents[2] / ".corpus" / "pkg" / "linuxcnc"

LINES = [
    "G0 X0 Y0",
    "G0 X1 Y2 Z5",
    "G0 Z5",
    "g0x0y0z0",
    "G1 X10 Y0 F100",
    "G1 X10.5 Y-3.25",
    "G01 X1. Y.5",
    "G1 Z-1 F50",
    "G1 F0",
    "G1 F-5 X1",
    "F200",
    "X3 Y4",
    "Y7",
    "Z-0.5",
    "G2 X10 Y10 I5 J5",
    "G2 X10 Y0 I5 J0",
    "G3 X0 Y0 I-5 J0",
    "G03 X0 Y0 R5",
    "G2 X20 Y0 R-10",
    "G2 X10 Y0 R1",
    "G2 X10 Y0 R0",
    "G2 X0 Y0 R5",
    "G2 Z-1",
    "G2 X3 Y3",
    "G2 X10 Y0 I5 J0 R5",
    "G2 X10 Y0 I5.3 J0",
    "G2 X10 Y0 I5.003 J0",
    "G2 I5 J0",
    "G2 X0 Y0 I0 J0",
    "R2 X1 Y1",
    "I1 J1",
    "N10 G1 X2 Y2 F100",
    "N10 N20 X1",
    "G1 X1 X2",
    "G1 G0 X1",
    "G0 G0 X1",
    "G4 P1",
    "G90",
    "G91",
    "G90.1",
    "G91.1",
    "G20",
    "G21",
    "G28",
    "G80",
    "G1.0 X1",
    "G1.04 X1",
    "G0.9 X1",
    "M3 S1000",
    "T1 M6",
    "X 1 Y 2",
    "X1 2",
    "G1 X1e3",
    "X" + "9" * 400,
    "X١",
    "X1\fY2",
    "G2 X1 Y1 \u0131-1 J0",
    "G1X1Y2F100",
    "G1 X-",
    "G1 X+.5 Y-.5",
    "G1 X1 .",
    "G1 X1.2.3",
    "GX1",
    "N1 N1 G1 X1",
    "G01.5 X1",
    "G1 X1 Y2 \t",
    "  G1   X1\tY2  ",
    "",
    "(comment)",
    "G1 X1 (c)",
    "; x",
    "/G1 X1",
    "%",
    "M2",
]


def both(text: str) -> tuple[str, str]:
    """``repr`` of what each reader gives ``text`` (the program, or the error)."""
    out = []
    for parse in (parse_gcode, parse_gcode_slow):
        try:
            out.append(repr(parse(text, source="t.ngc")))
        except CamtoolError as exc:
            out.append(f"{type(exc).__name__}: {exc}")
    return out[0], out[1]


def test_random_programs_read_the_same() -> None:
    rng = random.Random(17)
    for _ in range(3000):
        head = rng.choice(["", "G21\n", "G20\n", "G91\n", "G90.1\n", "F100\n", "G21 F100\n"])
        body = [rng.choice(LINES) for _ in range(rng.randint(1, 12))]
        tail = rng.choice(["M2\n", "", "%\n"])
        text = head + "\n".join(body) + "\n" + tail
        fast, slow = both(text)
        assert fast == slow, text


def test_random_numbers_read_the_same() -> None:
    """Plain lines with random numbers: arcs on and off their circle, tiny and huge values."""
    rng = random.Random(171)

    def number() -> str:
        kind = rng.random()
        if kind < 0.1:
            return rng.choice(["0", "-0", "-0.", ".0", "+0", "1e400", "-.5"])
        value = rng.uniform(-50, 50) * 10 ** rng.randint(-3, 2)
        return f"{value:.{rng.randint(0, 6)}f}"

    for _ in range(2000):
        lines = ["G21 G90 F300" if rng.random() < 0.8 else "G20 G90 F12", "G0 X0 Y0"]
        for _ in range(rng.randint(1, 8)):
            code = rng.choice(["G0", "G1", "G2", "G3", ""])
            words = [f"{letter}{number()}" for letter in rng.sample("XYZIJRF", rng.randint(1, 4))]
            if rng.random() < 0.3:
                # from a known start, an arc whose end is on its circle to the printed digits
                sx, sy, i, j = (rng.uniform(-20, 20) for _ in range(4))
                a = rng.uniform(-math.pi, math.pi)
                r = math.hypot(i, j)
                x, y = sx + i + r * math.cos(a), sy + j + r * math.sin(a)
                lines.append(f"G0 X{sx:.4f} Y{sy:.4f}")
                code = rng.choice(["G2", "G3", ""])
                words = [f"X{x:.{rng.randint(2, 5)}f}", f"Y{y:.4f}", f"I{i:.4f}", f"J{j:.4f}"]
                if rng.random() < 0.3:
                    words = [f"X{x:.4f}", f"Y{y:.4f}", f"R{rng.choice([-r, r]):.4f}"]
            lines.append(" ".join([code, *words]).strip())
        text = "\n".join([*lines, "M2"]) + "\n"
        fast, slow = both(text)
        assert fast == slow, text


@pytest.mark.skipif(not CORPUS.exists(), reason="corpus not fetched (make corpus)")
def test_corpus_programs_read_the_same() -> None:
    programs = sorted(CORPUS.rglob("*.ngc"))
    assert len(programs) > 300
    for path in programs:
        data = path.read_bytes()
        try:
            text = data.decode("utf-8-sig")
        except UnicodeDecodeError:
            text = data.decode("latin-1")
        fast, slow = both(text)
        assert fast == slow, path


def test_plain_moves_are_made_as_their_init_makes_them() -> None:
    """The plain reader's moves, made without ``__init__``, equal the dataclass's own."""
    from camtool.importers import gcode_plain as gcode
    from camtool.model.program import ArcMove, Linear, Rapid

    assert gcode._FAST_MOVES  # the model's moves are plain slotted frozen dataclasses
    rng = random.Random(1717)
    values = [0.0, -0.0, 1.5, -2.25, 1e300, math.pi]
    for _ in range(200):
        x, y, cx, cy, feed = (rng.choice([*values, rng.uniform(-9, 9)]) for _ in range(5))
        z = rng.choice([None, -0.0, rng.uniform(-9, 9)])
        contour, cw = rng.randint(0, 5), rng.random() < 0.5
        pairs = [
            (gcode._rapid(x, y, z, contour), Rapid(x, y, z, contour)),
            (gcode._linear(x, y, feed, z, contour), Linear(x, y, feed, z, contour)),
            (
                gcode._arc_move(x, y, cx, cy, cw, feed, z, contour),
                ArcMove(x, y, cx, cy, cw, feed, z, contour),
            ),
        ]
        for fast, made in pairs:
            assert type(fast) is type(made)
            assert repr(fast) == repr(made)  # every field, -0.0 included
            names = type(made).__slots__
            assert [getattr(fast, n) for n in names] == [getattr(made, n) for n in names]
            assert fast == made and hash(fast) == hash(made)
            assert pickle.loads(pickle.dumps(fast)) == made


def test_switched_off_every_line_is_read_the_reference_way(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    from camtool.importers import gcode

    taken: list[int] = []
    plain = gcode._Reader.plain

    def spy(self: object, *args: object) -> bool:
        taken.append(1)
        return plain(self, *args)  # type: ignore[arg-type]

    monkeypatch.setattr(gcode._Reader, "plain", spy)
    program = "G21 G90\nG0 X0 Y0\nG1 X1 Y1 F100\nG2 X2 Y0 I0.5 J-0.5\nM2\n"
    fast = repr(parse_gcode(program, source="p.ngc"))
    assert taken
    monkeypatch.setenv("CAMTOOL_ACCEL", "0")
    taken.clear()
    assert repr(parse_gcode(program, source="p.ngc")) == fast and not taken
