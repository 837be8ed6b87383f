"""FreeCAD's grbl post writes ``K0.000`` on every arc in the XY plane (FreeCAD issue 19417).

GRBL 1.1 takes the word and ignores it (gcode.c clears I, J and K of an arc alike);
LinuxCNC refuses it ("K word given for arc in xy plane"). A zero offset off the plane
changes no arc on either, so camtool reads it as GRBL does, says so once, and writes the
arc without it. A K other than 0 there is still refused: controllers disagree on it. The
judge is LinuxCNC's ``rs274``: it refuses the original, and runs the program without its
K words to the same moves as camtool's re-post.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from camtool.importers.gcode import read_gcode
from camtool.model.errors import InputError
from tests.corpus.test_rs274 import ROUND_MM, canon_moves, needs_rs274, rs274
from tests.targets import repost_cli

# The shape of FreeCAD's grbl_post output: an outside profile with rounded corners.
FREECAD_GRBL = """(Exported by FreeCAD)
(Post Processor: grbl_post)
(Begin preamble)
G17 G90
G21
(Begin operation: Profile)
M3 S18000
G54
G0 Z5.000
G0 X40.000 Y23.000
G0 Z3.000
G1 X40.000 Y23.000 Z-1.500 F200.000
G2 X43.000 Y20.000 Z-1.500 I0.000 J-3.000 K0.000 F400.000
G1 X43.000 Y0.000 Z-1.500 F400.000
G2 X40.000 Y-3.000 Z-1.500 I-3.000 J0.000 K0.000 F400.000
G1 X0.000 Y-3.000 Z-1.500 F400.000
G2 X-3.000 Y0.000 Z-1.500 I0.000 J3.000 K0.000 F400.000
G1 X-3.000 Y20.000 Z-1.500 F400.000
G2 X0.000 Y23.000 Z-1.500 I3.000 J0.000 K0.000 F400.000
G1 X40.000 Y23.000 Z-1.500 F400.000
G0 Z5.000
(Begin postamble)
M5
G17 G90
M2
"""


def test_k0_on_xy_arcs_is_read_as_grbl_reads_it(tmp_path: Path) -> None:
    path = tmp_path / "profile.nc"
    path.write_text(FREECAD_GRBL)
    program = read_gcode(path)
    assert (
        f"{path}:13: K0.000 on an arc in the XY plane (G17) ignored: a zero offset off the "
        "plane, which GRBL ignores too (LinuxCNC refuses it) (4 times)"
    ) in program.warnings
    without = tmp_path / "without.nc"
    without.write_text(FREECAD_GRBL.replace(" K0.000", ""))
    assert read_gcode(without).moves == program.moves


@pytest.mark.parametrize(
    ("block", "word"),
    [("G17 G2 X3 Y0 I1 J0 K0.5", "K0.5"), ("G18 G2 X2 Z2 I0 K1 J-1", "J-1")],
)
def test_an_offset_off_the_plane_other_than_zero_is_refused(
    tmp_path: Path, block: str, word: str
) -> None:
    path = tmp_path / "t.nc"
    path.write_text(f"G21 G90\nG0 X1 Y0 Z1\n{block} F100\nM2\n")
    with pytest.raises(InputError, match=f"t.nc:3: {word}: an arc in the"):
        read_gcode(path)


@needs_rs274
@pytest.mark.parametrize("target", ["grbl", "linuxcnc"])
def test_a_freecad_grbl_program_re_posted_moves_as_it_did(target: str, tmp_path: Path) -> None:
    original, out = repost_cli(tmp_path, "profile.nc", FREECAD_GRBL, target)
    refused = rs274(original)
    assert "K word given for arc in xy plane" in refused.stdout + refused.stderr
    without = tmp_path / "without.nc"
    without.write_text(FREECAD_GRBL.replace(" K0.000", ""))
    want, got = rs274(without), rs274(out)
    assert want.returncode == 0 and got.returncode == 0, (want.stderr, got.stderr)
    a, b = canon_moves(want.stdout), canon_moves(got.stdout)
    assert [kind for kind, _ in a] == [kind for kind, _ in b]
    assert [kind for kind, _ in b].count("arc") == 4
    for (_, p), (_, q) in zip(a, b, strict=True):
        assert max(abs(u - v) for u, v in zip(p, q, strict=True)) <= ROUND_MM
