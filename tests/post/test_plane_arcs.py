"""G18/G19 arcs re-posted: kept on the targets that have the planes, chords on the others.

The judge of the kept arcs is LinuxCNC's ``rs274``: its canonical arcs of the input and of
camtool's grbl and linuxcnc programs agree to the 3 decimals written (GRBL takes the
planes as LinuxCNC does: ``gcode.c`` sets ZX to axis_0 Z, axis_1 X, linear Y, and YZ to
Y, Z, linear X). On a target without planes every written point of the chords — the
corners of a Z-then-XY staircase too — lies within ``--tolerance`` of the true arc,
computed here from the program's own numbers, and the arc ends where it ends.
"""

from __future__ import annotations

import dataclasses
import itertools
import math
import re
from pathlib import Path

import pytest

from camtool.cli.main import main
from camtool.importers.gcode import parse_gcode
from camtool.jobs.pipeline import post_program
from camtool.model.errors import InputError
from camtool.model.program import Linear, PlaneArc, Rapid, Stop
from camtool.post.registry import load_target
from camtool.post.wordaddress_spec import load_spec
from tests.importers.test_gcode_planes import LEADS, needs_rs274, rs274_arcs

ROUND_MM = 0.0005 + 1e-9  # 3 decimals

# one lead-in of each plane, as Fusion 360 writes them: (G-code, plane, centre in the
# plane's (first, second) axes, radius, clockwise, start (x, y, z), end (x, y, z))
LEAD_IN_ZX = (
    "G18 G2 X-0.8 Z-0.5 I0.4 K0 F600",
    "zx",
    (-0.1, -0.8),
    0.4,
    True,
    (-1.2, 2.6, -0.1),
    (-0.8, 2.6, -0.5),
)
HELIX_YZ = (
    "G19 G3 X-0.5 Y3.4 Z-0.1 J0.4 K0 F600",
    "yz",
    (3.0, -0.1),
    0.4,
    False,
    (-1.2, 2.6, -0.1),
    (-0.5, 3.4, -0.1),
)


def program_with(block: str) -> str:
    return (
        f"G21 G90 G17\nG0 X-1.2 Y2.6\nG0 Z1\nG1 Z-0.1 F300\n{block}\nG1 X2 F600\nG0 Z5\nG17\nM2\n"
    )


@needs_rs274
@pytest.mark.parametrize("target", ["grbl", "linuxcnc"])
def test_the_planes_stay_arcs_on_grbl_and_linuxcnc(target: str, tmp_path: Path) -> None:
    out = tmp_path / f"out.{target}"
    assert main(["post", str(LEADS), "-t", target, "-o", str(out)]) == 0
    text = out.read_text()
    assert text.count("G18 G") == 5 and text.count("G19 G") == 3  # one block per arc
    theirs, ours = rs274_arcs(LEADS), rs274_arcs(out)
    assert [p for p, _ in ours] == [p for p, _ in theirs]
    for k, ((plane, a), (_, b)) in enumerate(zip(theirs, ours, strict=True)):
        assert b == pytest.approx(a, abs=ROUND_MM), f"arc {k} in {plane}"


@pytest.mark.parametrize("target", ["grbl", "linuxcnc"])
def test_a_new_feed_reaches_the_plane_arcs(target: str) -> None:
    program = parse_gcode(program_with(LEAD_IN_ZX[0]), source="t.ngc")
    code = post_program(program, load_target(target), feed_mm_min=123.0).result.code
    assert isinstance(code, str)
    (arc_block,) = [line for line in code.splitlines() if line.startswith("G18")]
    # the plunge before it set F123 (modal): the arc's F600 is gone with the others
    assert arc_block == "G18 G2 X-0.800 Z-0.500 I0.400 K0.000"
    assert set(re.findall(r"F[0-9.]+", code)) == {"F123"}


@pytest.mark.parametrize("target", ["grbl", "linuxcnc"])
def test_the_code_after_a_plane_arc_is_back_in_xy_with_its_motion_code(target: str) -> None:
    program = parse_gcode(program_with(LEAD_IN_ZX[0]), source="t.ngc")
    code = post_program(program, load_target(target)).result.code
    assert isinstance(code, str)
    lines = code.splitlines()
    k = next(i for i, line in enumerate(lines) if line.startswith("G18"))
    assert lines[k + 1] == "G17" and lines[k + 2].startswith("G1 X2.000")


def distance_to_arc(
    p: tuple[float, float], centre: tuple[float, float], radius: float, a0: float, sweep: float
) -> float:
    """Distance (mm) from ``p`` to the arc from angle ``a0`` turning ``sweep`` rad."""
    angle = math.atan2(p[1] - centre[1], p[0] - centre[0])
    along = (angle - a0) % (2 * math.pi) if sweep > 0 else (a0 - angle) % (2 * math.pi)
    if along <= abs(sweep):
        return abs(math.dist(p, centre) - radius)
    ends = [
        (centre[0] + radius * math.cos(a), centre[1] + radius * math.sin(a))
        for a in (a0, a0 + sweep)
    ]
    return min(math.dist(p, e) for e in ends)


@pytest.mark.parametrize("case", [LEAD_IN_ZX, HELIX_YZ], ids=["zx-lead-in", "yz-helix"])
@pytest.mark.parametrize(("target", "tolerance"), [("flashcut", 0.01), ("flashcut", 0.002)])
def test_without_planes_every_written_point_is_within_the_tolerance(
    case: tuple, target: str, tolerance: float, tmp_path: Path
) -> None:
    block, plane, centre, radius, clockwise, start, end = case
    source = tmp_path / "in.nc"
    source.write_text(program_with(block))
    out = tmp_path / "out.nc"
    assert (
        main(["post", str(source), "-t", target, "-o", str(out), "--tolerance", str(tolerance)])
        == 0
    )
    written = load_target(target).parse(out.read_text(), source="out")
    a, b, lin = {"zx": (2, 0, 1), "yz": (1, 2, 0)}[plane]
    a0 = math.atan2(start[b] - centre[1], start[a] - centre[0])
    a1 = math.atan2(end[b] - centre[1], end[a] - centre[0])
    sweep = (a1 - a0) % (2 * math.pi)
    sweep = sweep - 2 * math.pi if clockwise else sweep
    # the written path, point by point, from the arc's start to its end
    here, z, path = (0.0, 0.0), None, []
    for move in written.moves:
        z = move.z if move.z is not None else z
        here = (move.x, move.y)
        path.append((here[0], here[1], z))
    first = path.index(start)
    last = path.index(end, first)
    chords = path[first : last + 1]
    assert len(chords) > 4  # chords, not one line
    quantum = 0.0005 * math.sqrt(2)  # flashcut writes 3 decimals
    for p, q in itertools.pairwise(chords):
        for t in (0.0, 0.25, 0.5, 0.75):
            point = tuple(pi + (qi - pi) * t for pi, qi in zip(p, q, strict=True))
            in_plane = (point[a], point[b])
            assert distance_to_arc(in_plane, centre, radius, a0, sweep) <= tolerance + quantum
            # the linear axis in step with the angle (a helix), within the same tolerance
            angle = math.atan2(in_plane[1] - centre[1], in_plane[0] - centre[0])
            turned = ((angle - a0) if sweep > 0 else (a0 - angle)) % (2 * math.pi)
            expected = start[lin] + (end[lin] - start[lin]) * min(turned / abs(sweep), 1.0)
            assert (
                abs(point[lin] - expected)
                <= tolerance + quantum + abs(end[lin] - start[lin]) * tolerance / radius
            )


@pytest.mark.parametrize("target", ["flashcut", "valcnc"])
def test_without_planes_the_chords_are_said_and_the_program_verifies(
    target: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "out.nc"
    assert main(["post", str(LEADS), "-t", target, "-o", str(out), "--tolerance", "0.01"]) == 0
    err = capsys.readouterr().err
    assert f"{target} has no arcs in the ZX and YZ planes (G18/G19): 8 such arc(s)" in err
    assert "G18" not in out.read_text() and "G19" not in out.read_text()
    assert main(["verify", str(out), "-t", target]) == 0


@pytest.mark.parametrize("target", ["grbl", "linuxcnc"])
def test_verify_reads_the_plane_arcs_as_their_chords(target: str, tmp_path: Path) -> None:
    out = tmp_path / "out.nc"
    assert main(["post", str(LEADS), "-t", target, "-o", str(out)]) == 0
    program = load_target(target).parse(out.read_text(), source="out")
    arcs = [c for _, c in program.commands if isinstance(c, PlaneArc)]
    assert len(arcs) == 8 and {a.plane for a in arcs} == {"zx", "yz"}
    assert main(["verify", str(out), "-t", target]) == 0
    assert main(["verify", str(LEADS), "-t", target]) == 0


def test_an_arc_too_small_to_print_is_written_as_its_chords_with_a_warning() -> None:
    program = parse_gcode(
        "G21 G90\nG0 X0 Y0\nG0 Z0\nG18 G2 X0.0006 Z-0.0006 I0.0003 K0 F100\nG1 X1\nM2\n",
        source="t.ngc",
    )
    result = load_target("grbl").emit(program)
    assert "G18" not in str(result.code)
    assert any("arc(s) in the ZX or YZ plane" in w for w in result.warnings)


def test_a_target_without_z_gets_the_chords_flattened_not_an_xy_arc() -> None:
    program = parse_gcode(program_with(LEAD_IN_ZX[0]), source="t.ngc")
    job = post_program(program, load_target("pic-mmh"), feed_mm_min=5.0)
    assert not any(isinstance(c, PlaneArc) for _, c in job.program.commands)
    assert all(isinstance(m, Rapid | Linear) for m in job.program.moves)
    assert any("pic-mmh has no arcs in the ZX and YZ planes" in w for w in job.program.warnings)


def test_a_target_without_z_gets_equal_chords_not_a_z_staircase() -> None:
    # No Z is written, so no Z-then-XY staircase: the quarter circle of radius 0.4 needs
    # n = ceil(θ / (2 acos(1 - tol / r))) equal chords for a sagitta within tol.
    program = parse_gcode(program_with(LEAD_IN_ZX[0]), source="t.ngc")
    program = dataclasses.replace(program, tolerance_mm=0.001)
    job = post_program(program, load_target("pic-mmh"), feed_mm_min=5.0)
    radius, tol = LEAD_IN_ZX[3], 0.001
    chords = math.ceil((math.pi / 2) / (2 * math.acos(1 - tol / radius)))
    said = [w for w in job.program.warnings if "ZX and YZ planes" in w]
    assert said and f"written as {chords} straight chords within" in said[0]


def test_a_dialect_with_planes_needs_k_a_helix_and_the_rs274_reader() -> None:
    ok = {"words": {"XYZIJK": {}}, "helix": True, "rs274": True, "planes": True}
    assert load_spec(ok, "m.toml").planes
    with pytest.raises(InputError, match="need Z, I, J and K words; K missing"):
        load_spec({**ok, "words": {"XYZIJ": {}}}, "m.toml")
    with pytest.raises(InputError, match="need helix = true and rs274 = true"):
        load_spec({**ok, "rs274": False}, "m.toml")
    with pytest.raises(InputError, match="a K word is written only in the ZX and YZ planes"):
        load_spec({**ok, "planes": False}, "m.toml")


def test_a_plane_arc_whose_chords_were_changed_is_written_as_its_chords() -> None:
    program = parse_gcode(program_with(LEAD_IN_ZX[0]), source="t.ngc")
    ((index, arc),) = [(i, c) for i, c in program.commands if isinstance(c, PlaneArc)]
    stop = (index + 3, Stop())  # a stop among the chords: the arc cannot stand for them
    changed = dataclasses.replace(
        program, commands=tuple(sorted((*program.commands, stop), key=lambda c: c[0]))
    )
    assert program.has_chords_of(index, arc) and not changed.has_chords_of(index, arc)
    code = str(load_target("grbl").emit(changed).code)
    assert "G18" not in code and "M0" in code
    lines = code.splitlines()
    assert lines.index("M0") == lines.index("G1 Z-0.100 F300") + 4  # after 3 chords
