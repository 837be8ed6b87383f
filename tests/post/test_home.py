"""A re-posted program's returns (G28, G30, G53 G0 Z0) are written for GRBL and LinuxCNC.

Fusion 360's posts begin ``G28 G91 Z0`` / ``G90``: the tool rises to the stored position
before the first XY rapid, and again before each tool change and at the end; Haas-style
posts retract with ``G53 G0 Z0.``. Dropped, such a return would leave the next rapid at
whatever height the tool had (on the stock, after touching off Z). Both controllers run
RS-274's returns (GRBL 1.1 gcode.c; LinuxCNC), so those targets write them as RS-274 does;
a target that cannot is refused where the move after a return on Z needs its height. The
judge is LinuxCNC's ``rs274``: the original and the re-posted program make the same moves,
the returns' traverses included.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from camtool.model.errors import ParseError
from camtool.model.program import Home, Linear, Program, Rapid
from camtool.post.registry import load_target
from camtool.post.wordaddress_read import BlockReader
from tests.corpus.test_rs274 import ROUND_MM, canon_moves, needs_rs274, rs274
from tests.targets import post_cli, repost_cli

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
    "block",
    [
        *("G28 Z0.000", "G91 G28", "G91 G28 Z1.000", "G91 G28 Z0.000 F100"),
        *("G53 G1 Z0.000", "G53 G0", "G91 G53 G0 Z0.000"),
    ],
)
def test_the_strict_reader_takes_the_writers_returns_only(block: str) -> None:
    """(Another program's G28 and G53 forms are read by the RS-274 reader.)"""
    reader = BlockReader(load_target("grbl").post.spec, "t.gcode")
    with pytest.raises(ParseError, match="G53" if "G53" in block else "G28"):
        reader.read(f"G21 G90 G94 G17\n{block}\nG90\nG0 X1.000 Y1.000 Z1.000\nM2\n")


def _same_moves(original: Path, posted: Path) -> list[tuple[str, tuple[float, ...]]]:
    """``rs274``'s moves of both programs: the same kinds, the same points (±``ROUND_MM``)."""
    want, got = rs274(original), rs274(posted)
    assert want.returncode == 0 and got.returncode == 0, (want.stderr, got.stderr)
    a, b = canon_moves(want.stdout), canon_moves(got.stdout)
    assert [kind for kind, _ in a] == [kind for kind, _ in b]
    for (_, p), (_, q) in zip(a, b, strict=True):
        assert max(abs(u - v) for u, v in zip(p, q, strict=True)) <= ROUND_MM
    return b


@needs_rs274
@pytest.mark.parametrize("target", ["grbl", "linuxcnc"])
def test_a_fusion_program_re_posted_moves_as_it_did(target: str, tmp_path: Path) -> None:
    original, out = repost_cli(tmp_path, "1001.nc", FUSION, target)
    a = _same_moves(original, out)  # every return written: none dropped
    # the first move of both is the return's rise, before any XY rapid
    assert a[0][0] == "rapid" and a[0][1][:2] == (0.0, 0.0)


HAAS = """%
O01001 (PART)
(T1 D=6. CR=0. - ZMIN=-3. - FLAT END MILL)
G90 G94 G17 G40 G49 G80
G21
G53 G0 Z0.
T1 M6
S8000 M3
G54
G0 X-5. Y0.
G43 Z15. H1
G0 Z5.
G1 Z-1. F300.
G1 X50. F1000.
G2 X60. Y10. I0. J10.
G0 Z15.
G53 G0 Z0.
M5
G53 G0 X0. Y0.
M30
%
"""
"""A Haas-style post (Fusion 360's "G53" safe retracts): a program number, G53 retracts."""


@needs_rs274
@pytest.mark.parametrize("target", ["grbl", "linuxcnc"])
def test_a_haas_style_program_re_posted_moves_as_it_did(target: str, tmp_path: Path) -> None:
    """The program number is read as no words, the G53 retracts as returns."""
    original, out = repost_cli(tmp_path, "1001.nc", HAAS, target)
    lines = out.read_text().splitlines()
    assert lines.count("G53 G0 Z0.000") == 2 and "G53 G0 X0.000 Y0.000" in lines
    b = _same_moves(original, out)
    assert b[0][0] == "rapid" and b[0][1][2] == 0.0  # machine zero first (G54 at 0)


CARBIDE = """(Design File: plate.c2d)
(stockMin:0.00mm, 0.00mm, -12.70mm)
(stockMax:50.00mm, 50.00mm, 0.00mm)
G90
G21
(Move to safe Z to avoid workholding)
G53G0Z-5.000
M05
(TOOL/MILL,3.18, 0.00, 0.00, 0.00)
M6T1
M03S18000
(PREPARE  Contour 1)
G0X10.490Y14.186Z5.080
G1Z-1.270F254.0
G3X8.967Y14.919I-1.523J-1.217F1016.0
G1X20.000Y20.000
G0Z5.080
M05
G53G0Z-5.000
G0X0.000Y0.000
M02
"""
"""Carbide Create's GRBL post: every retract to a safe height is ``G53G0Z-5.000``, a rapid
to 5 mm below machine zero (Z homes up on a Shapeoko), in machine coordinates."""


@needs_rs274
@pytest.mark.parametrize("target", ["grbl", "linuxcnc"])
def test_a_carbide_create_program_re_posted_moves_as_it_did(target: str, tmp_path: Path) -> None:
    """The G53 retracts are kept at their machine coordinate: rs274 moves the same."""
    original, out = repost_cli(tmp_path, "plate.nc", CARBIDE, target)
    lines = out.read_text().splitlines()
    assert lines.count("G53 G0 Z-5.000") == 2
    b = _same_moves(original, out)
    assert b[0][0] == "rapid" and b[0][1][2] == -5.0  # G54 at 0: machine Z -5 first
    back = load_target(target).post.parse(out.read_text())
    homes = [c for _, c in back.commands if isinstance(c, Home)]
    assert homes == [Home("Z", "G53", (-5.0,))] * 2


G30_MIDWAY = """G21 G90
G0 Z5
G0 X0 Y0
G1 Z-1 F100
G1 X10 F300
G91 G30 Z0
G90
G0 X20 Y20
G1 Z-1
G1 X30
G0 Z5
M2
"""
"""A cut, the return to the G30 position on Z, a rapid that gives X and Y only, a cut."""

RETURNS = {"G28": "G91 G28 Z0\nG90\n", "G30": "G91 G30 Z0\nG90\n", "G53": "G53 G0 Z0.\n"}
"""Each return on Z as programs write it: G53's is Haas-style posts' (and Fusion 360's)."""


def _midway(code: str) -> str:
    """:data:`G30_MIDWAY` with the return ``code`` (:data:`RETURNS`)."""
    return G30_MIDWAY.replace(RETURNS["G30"], RETURNS[code])


@needs_rs274
@pytest.mark.parametrize(("code", "written"), [("G30", "G91 G30 Z0.000"), ("G53", "G53 G0 Z0.000")])
@pytest.mark.parametrize("target", ["grbl", "linuxcnc"])
def test_a_g30_or_g53_return_is_written_as_such_and_moves_as_it_did(
    code: str, written: str, target: str, tmp_path: Path
) -> None:
    """Written again as such: without it the rapid after it would run at Z-1, through the
    part."""
    original, out = repost_cli(tmp_path, f"{code}.nc", _midway(code), target)
    text = out.read_text()
    assert written in text.splitlines() and "G28" not in text
    back = load_target(target).post.parse(text)
    assert [c for _, c in back.commands if isinstance(c, Home)] == [Home("Z", code)]
    b = _same_moves(original, out)
    # rs274's G30 position (its parameters) and machine zero (G54 at 0) are Z0 here: the XY
    # rapid runs at Z0, not at Z-1
    rapid = next(p for kind, p in b if kind == "rapid" and p[:2] == (20.0, 20.0))
    assert rapid[2] == 0.0


@pytest.mark.parametrize("rapid", ["G0 X20 Y20", "G0 X20 Y20 Z5"])
@pytest.mark.parametrize("code", ["G28", "G30", "G53"])
@pytest.mark.parametrize("target", ["valcnc", "i8751"])
def test_a_dropped_return_with_moves_after_it_is_refused(
    rapid: str, code: str, target: str, tmp_path: Path
) -> None:
    """valcnc and i8751 write no return: the XY rapid after it would run at Z-1, or rise
    from Z-1 on a slant through the part (``G00X20Y20Z5`` from there)."""
    original = tmp_path / f"{code}.nc"
    text = _midway(code).replace("G0 X20 Y20", rapid)
    original.write_text(text)
    out = tmp_path / f"{code}.{target}"
    done = post_cli(original, target, out)
    assert done.returncode == 1, done.stdout
    line = text.splitlines().index(rapid) + 1
    assert f"line {line}:" in done.stderr and f"{code} return on Z" in done.stderr
    assert "Z-1" in done.stderr and "Traceback" not in done.stderr
    assert not out.exists()


@pytest.mark.parametrize("tail", ["G0 Z5\nG0 X20 Y20\nM2\n", "M2\n"])
def test_a_dropped_return_followed_by_a_z_or_by_the_end_is_written(
    tail: str, tmp_path: Path
) -> None:
    """Written without it, the next move gives its own height, or there is none."""
    original = tmp_path / "end.nc"
    original.write_text(
        "G21 G90\nG0 Z5\nG0 X0 Y0\nG1 Z-1 F100\nG1 X10 F300\nG91 G28 Z0\nG90\n" + tail
    )
    out = tmp_path / "end.valcnc"
    done = post_cli(original, "valcnc", out)
    assert done.returncode == 0, done.stderr
    assert "G28/G30/G53 return(s) to a machine position dropped" in done.stderr
    lines = out.read_text().splitlines()
    after = lines[lines.index("G01X10Y0") + 1 :]
    assert after == (["G00Z5", "G00X20Y20"] if "X20" in tail else [])


def test_pic_mmh_writes_g28_as_machine_zero_and_never_a_g30_or_g53_as_it() -> None:
    """pic-mmh's ``G28Z0;`` is machine zero; it has no second stored position, no G53."""
    moves = (Rapid(0.0, 0.0), Linear(1.0, 0.0, 5.0), Rapid(0.5, 0.5))  # no Z word
    loaded = load_target("pic-mmh")
    for code, written in (("G28", ["G28Z0;"]), ("G30", []), ("G53", [])):
        home: Home = Home("Z", code)  # type: ignore[arg-type]
        program = Program(moves, commands=((3, home),))
        result = loaded.emit(program)
        blocks = str(result.code).splitlines()
        assert [b for b in blocks if b.startswith("G28")] == written
