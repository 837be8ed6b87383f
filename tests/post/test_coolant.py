"""Coolant (a laser's air assist) survives a re-post where the target has the codes.

``M8`` is flood coolant in RS-274, and the air assist of a laser program (LightBurn and
LaserGRBL write it around each layer): camtool read it and every other coolant code as
"ignored", with a warning, and wrote none. GRBL 1.1 runs ``M8``/``M9`` (``M7`` only in builds
with ``ENABLE_M7``), LinuxCNC all three. The judge is LinuxCNC's ``rs274``: the coolant calls
it makes between the moves, for the original and for camtool's program.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from camtool.importers import gcode
from camtool.model.program import Coolant, Linear, Program, Rapid
from camtool.post.registry import load_target
from tests.corpus.test_rs274 import needs_rs274, rs274
from tests.targets import post_cli

PROGRAM = (
    "G21 G90\nM3 S1000\nM8\nG0 X1 Y1\nG1 X5 F300\nM7\nG1 Y5\nM9\nG1 X1\nM8\nG1 Y1\nM9\nM5\nM2\n"
)
CALL = re.compile(r"(FLOOD_ON|FLOOD_OFF|MIST_ON|MIST_OFF|STRAIGHT_FEED|STRAIGHT_TRAVERSE)\(")


def _calls(program: Path) -> list[str]:
    """rs274's coolant calls and moves of ``program``, in order."""
    done = rs274(program)
    assert done.returncode == 0, done.stderr
    return [m[1] for line in done.stdout.splitlines() if (m := CALL.search(line))]


@pytest.mark.parametrize("plain", [True, False])
def test_m7_m8_m9_are_read_before_the_next_move(plain: bool) -> None:
    program = gcode._parse(PROGRAM, "t.ngc", plain=plain)
    coolant = [(i, c) for i, c in program.commands if isinstance(c, Coolant)]
    assert coolant == [
        (0, Coolant("flood")),
        (2, Coolant("mist")),
        (3, Coolant("off")),
        (4, Coolant("flood")),
        (5, Coolant("off")),
    ]
    assert not any("coolant" in w for w in program.warnings)


@pytest.mark.parametrize(("target", "codes"), [("grbl", "M8 M9"), ("linuxcnc", "M7 M8 M9")])
def test_written_and_read_back(target: str, codes: str) -> None:
    loaded = load_target(target)
    moves = (Rapid(0.0, 0.0), Linear(1.0, 0.0, 100.0), Linear(1.0, 1.0, 100.0))
    commands = ((0, Coolant("mist")), (1, Coolant("flood")), (3, Coolant("off")))
    result = loaded.post.emit(Program(moves, commands=commands), loaded.machine)
    lines = str(result.code).splitlines()
    written = [line for line in lines if line in ("M7", "M8", "M9")]
    assert written == [c for c in ("M7", "M8", "M9") if c in codes.split()]
    back = loaded.post.parse(result.code)
    kept = tuple((i, c) for i, c in commands if ("M7" in codes or c.state != "mist"))
    assert tuple((i, c) for i, c in back.commands if isinstance(c, Coolant)) == kept
    dropped = [w for w in result.warnings if "coolant command(s)" in w]
    assert len(dropped) == ("M7" not in codes)


def test_pic_mmh_drops_it_with_a_warning() -> None:
    loaded = load_target("pic-mmh")
    moves = (Rapid(0.0, 0.0), Linear(1.0, 0.0, 5.0))  # 5 mm/min: F50 of its feed table
    commands = ((0, Coolant("flood")), (2, Coolant("off")))
    result = loaded.post.emit(Program(moves, commands=commands), loaded.machine)
    assert "M08" not in str(result.code)
    (warning,) = [w for w in result.warnings if "coolant" in w]
    assert "dropped" in warning and "(2 times)" in warning


@needs_rs274
def test_linuxcnc_re_post_switches_the_coolant_where_the_original_did(tmp_path: Path) -> None:
    original = tmp_path / "coolant.ngc"
    original.write_text(PROGRAM)
    out = tmp_path / "out.ngc"
    done = post_cli(original, "linuxcnc", out)
    assert done.returncode == 0, done.stderr
    want = _calls(original)
    assert want.count("FLOOD_ON") == 2 and want.count("MIST_ON") == 1
    assert _calls(out) == want
