"""A re-posted program's G28 returns are written for GRBL and LinuxCNC, not dropped.

Fusion 360's posts begin ``G28 G91 Z0`` / ``G90``: the tool rises to the stored position
before the first XY rapid, and again before each tool change and at the end. camtool read
it as a :class:`~camtool.model.program.Home` command and dropped it for every target, with
a warning, so the re-posted program's first rapid ran at whatever height the tool had been
left (on the stock, after touching off Z). Both controllers run RS-274's ``G28``
(GRBL 1.1 gcode.c; LinuxCNC), so the targets now write it as RS-274 does. The judge is
LinuxCNC's ``rs274``: the original and the re-posted program make the same moves, the
returns' traverses included.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from camtool.model.errors import ParseError
from camtool.model.program import Home, Linear, Program, Rapid
from camtool.post.registry import load_target
from camtool.post.wordaddress_read import BlockReader
from tests.corpus.test_rs274 import ROUND_MM, canon_moves, needs_rs274, rs274
from tests.targets import post_cli

FUSION = """%
(1001)
(T1  D=3 CR=0 - flat end mill)
G90 G94
G17
G21
G28 G91 Z0.
G90
(2D Contour1)
T1 M6
S5000 M3
G54
G0 X-5 Y0
G43 Z15. H1
G0 Z5.
G1 Z-1. F300.
G1 X50. F1000.
G2 X60. Y10. I0. J10.
G1 Y50.
G0 Z15.
G28 G91 Z0.
G90
G28 G91 X0. Y0.
G90
M5
M30
%
"""


@pytest.mark.parametrize("target", ["grbl", "linuxcnc"])
def test_returns_are_written_and_read_back(target: str) -> None:
    moves = (Rapid(0.0, 0.0, 5.0), Linear(10.0, 0.0, 100.0, z=-1.0), Rapid(10.0, 0.0, 5.0))
    moves += (Rapid(20.0, 20.0, 5.0), Rapid(0.0, 0.0, 5.0))
    commands = ((0, Home("Z")), (3, Home("Z")), (4, Home("XY")), (5, Home("XYZ")))
    loaded = load_target(target)
    post = loaded.post
    code = str(post.emit(Program(moves, commands=commands), loaded.machine).code)
    lines = [line for line in code.splitlines() if not line.startswith("(")]
    first = lines.index("G91 G28 Z0.000")
    assert lines[first + 1] == "G90" and lines[first + 2] == "G0 Z5.000"
    # the Z the return left unknown is written again, though the program's Z is unchanged
    again = lines.index("G91 G28 Z0.000", first + 1)
    assert lines[again + 1] == "G90" and "Z5.000" in " ".join(lines[again + 2 : again + 4])
    assert "G91 G28 X0.000 Y0.000" in lines and "G28" in lines
    back = post.parse(code)
    assert [c for c in back.commands if isinstance(c[1], Home)] == list(commands)


@pytest.mark.parametrize(
    "block", ["G28 Z0.000", "G91 G28", "G91 G28 Z1.000", "G91 G28 Z0.000 F100"]
)
def test_the_strict_reader_takes_the_writers_returns_only(block: str) -> None:
    """(Another program's G28 forms are read by the RS-274 reader, as before.)"""
    reader = BlockReader(load_target("grbl").post.spec, "t.gcode")
    with pytest.raises(ParseError, match="G28"):
        reader.read(f"G21 G90 G94 G17\n{block}\nG90\nG0 X1.000 Y1.000 Z1.000\nM2\n")


@needs_rs274
@pytest.mark.parametrize("target", ["grbl", "linuxcnc"])
def test_a_fusion_program_re_posted_moves_as_it_did(target: str, tmp_path: Path) -> None:
    original = tmp_path / "1001.nc"
    original.write_text(FUSION)
    out = tmp_path / f"1001-{target}.ngc"
    done = post_cli(original, target, out)
    assert done.returncode == 0, done.stderr
    assert "G28-style" not in done.stderr  # nothing dropped
    want, got = rs274(original), rs274(out)
    assert want.returncode == 0 and got.returncode == 0, (want.stderr, got.stderr)
    a, b = canon_moves(want.stdout), canon_moves(got.stdout)
    assert [kind for kind, _ in a] == [kind for kind, _ in b]
    for (_, p), (_, q) in zip(a, b, strict=True):
        assert max(abs(u - v) for u, v in zip(p, q, strict=True)) <= ROUND_MM
    # the first move of both is the return's rise, before any XY rapid
    assert a[0][0] == "rapid" and a[0][1][:2] == (0.0, 0.0)
