"""Every cut of a re-posted program runs at the spindle speed (a laser's power) it had.

A laser program (LaserGRBL, LightBurn) keeps ``M4`` on and changes the power with ``S`` from
one move to the next, ``S0`` for a move that must not burn. camtool read ``S0`` as "no speed"
and wrote a bare ``M4``: the controller kept the power before it, and the move burned. The
judge is LinuxCNC's ``rs274``: the speed and the spindle state in force at each feed move of
the original and of camtool's program, from its canonical calls. A new speed of the turning
spindle is written in the next motion block, where the laser program had it.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from camtool.importers import gcode
from camtool.importers.gcode import read_gcode
from camtool.model.program import Spindle
from tests.corpus.test_rs274 import needs_rs274, rs274
from tests.targets import repost_cli

LASER = "G21 G90\nM4\nG0 X10 Y10\nG1 X20 S500 F1000\nG1 Y20 S300\nG1 X10 S0\nG1 Y10 S800\nM5\nM2\n"
CALL = re.compile(r"(SET_SPINDLE_SPEED|START_SPINDLE_\w+|STOP_SPINDLE_TURNING|STRAIGHT_FEED)\(")
SPEED = re.compile(r"SET_SPINDLE_SPEED\(\d+, ([-\d.]+)\)")


def _speeds_at_cuts(program: Path) -> list[tuple[bool, float]]:
    """(spindle on, speed) in force at each STRAIGHT_FEED of rs274's reading of ``program``."""
    done = rs274(program)
    assert done.returncode == 0, done.stderr
    on, speed, out = False, 0.0, []
    for line in done.stdout.splitlines():
        call = CALL.search(line)
        if call is None:
            continue
        name = call[1]
        if name == "SET_SPINDLE_SPEED":
            found = SPEED.search(line)
            assert found is not None
            speed = float(found[1])
        elif name.startswith("START_SPINDLE"):
            on = True
        elif name == "STOP_SPINDLE_TURNING":
            on = False
        else:
            out.append((on, speed))
    return out


@pytest.mark.parametrize("plain", [True, False])
def test_s0_while_on_is_a_speed_and_a_bare_m4_none(plain: bool) -> None:
    """Both readers (the plain-line path and the lexer): ``M4`` with no S yet has no speed
    (``None``: the controller's stays); ``S0`` is the speed 0."""
    program = gcode._parse("G21\nM4\nG1 X1 S0 F100\nM2\n", "laser.ngc", plain=plain)
    assert program.commands[:2] == ((0, Spindle("ccw")), (0, Spindle("ccw", 0.0)))
    bare, s0 = program.commands[0][1], program.commands[1][1]
    assert isinstance(bare, Spindle) and bare.rpm is None
    assert isinstance(s0, Spindle) and s0.rpm == 0.0


@needs_rs274
@pytest.mark.parametrize("target", ["grbl", "linuxcnc"])
def test_a_laser_program_burns_each_move_at_its_own_power(target: str, tmp_path: Path) -> None:
    original, out = repost_cli(tmp_path, "laser.ngc", LASER, target)
    want = _speeds_at_cuts(original)
    assert want == [(True, 500.0), (True, 300.0), (True, 0.0), (True, 800.0)]
    assert _speeds_at_cuts(out) == want
    # each new power in its motion block, as the laser program had it: GRBL in laser mode
    # runs on through them, where an "M4 S300" block of its own stops the motion
    cuts = [line for line in out.read_text().splitlines() if line.startswith("G1")]
    assert [line.split()[-1] for line in cuts] == ["S500", "S300", "S0", "S800"]
    assert not any(line.startswith("M4 S") for line in out.read_text().splitlines())
    assert read_gcode(out).commands  # and camtool reads its own program back
