"""The work offset a program selects, kept when re-posted for a target that has it.

A program that says ``G55`` runs in the second work offset; written without it, the
controller runs it in whichever offset is active (G54 after power-up) and cuts elsewhere.
For a target whose dialect lists the code (``work_offsets``: LinuxCNC's G54 … G59.3,
GRBL's G54 … G59) the reader keeps it as a :class:`WorkOffset` command and the writer
writes it before the first move; for any other it is read as the part zero, with the
warning, as before. The judge of what LinuxCNC selects is rs274's ``SET_G5X_OFFSET(2, …)``
(tests/corpus/test_rs274.py).
"""

from __future__ import annotations

import pytest

from camtool.importers import gcode
from camtool.importers.gcode_target import Reading
from camtool.model.errors import DialectError
from camtool.model.program import Linear, Program, Rapid, WorkOffset
from camtool.post.registry import load_target

TEXT = "G21 G90 G17 G55\nG0 X0 Y0 Z5\nG1 Z-1 F100\nG1 X10\nG0 Z5\nG55\nM2\n"
GRBL = ("G54", "G55", "G56", "G57", "G58", "G59")


@pytest.mark.parametrize("plain", [True, False])
def test_the_selected_offset_is_kept_for_a_target_that_has_it(plain: bool) -> None:
    program = gcode._parse(TEXT, "p.ngc", plain=plain, reading=Reading(work_offsets=GRBL))
    assert program.commands == ((0, WorkOffset("G55")),)  # once, before the first move
    assert not any("G55 work offset" in w for w in program.warnings)
    other = gcode._parse(
        TEXT.replace("G55", "G59.1"), "p.ngc", plain=plain, reading=Reading(work_offsets=GRBL)
    )
    assert other.commands == ()  # GRBL has no G59.1: the part zero, with the warning
    assert any("G59.1 work offset assumed 0" in w for w in other.warnings)
    bare = gcode._parse(TEXT, "p.ngc", plain=plain)
    assert bare.commands == () and any("G55 work offset assumed 0" in w for w in bare.warnings)


@pytest.mark.parametrize("name", ["grbl", "linuxcnc"])
def test_the_writer_selects_it_before_the_first_move(name: str) -> None:
    target = load_target(name)
    assert "G55" in target.post.work_offsets
    moves = (Rapid(1.0, 1.0, 5.0), Linear(1.0, 1.0, 100.0, -1.0))
    program = Program(moves, commands=((0, WorkOffset("G55")),))
    code = target.post.emit(program, target.machine).code
    body = [line for line in code.splitlines() if not line.startswith(("(", ";"))]
    first_move = next(i for i, line in enumerate(body) if line.startswith("G0 "))
    assert body.index("G55") < first_move
    back = target.post.parse(code, source="out.ngc")  # its own reader reads it back
    assert back.moves == target.post.parse(code.replace("G55\n", ""), source="o.ngc").moves


def test_a_target_without_the_offset_refuses_it() -> None:
    moves = (Rapid(1.0, 1.0), Linear(2.0, 1.0, 100.0))
    for name, code in (("grbl", "G59.1"), ("pic-mmh", "G55"), ("i8751", "G55")):
        target = load_target(name)
        program = Program(moves, commands=((0, WorkOffset(code)),))
        with pytest.raises(DialectError, match=f"cannot select the work offset {code}"):
            target.post.emit(program, target.machine)
