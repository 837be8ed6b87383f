"""G43/G49 read for a target that applies tool length offsets (LinuxCNC's ``G43 H<n>``).

The linuxcnc dialect writes ``G43 H<n>`` right after each change to tool ``n``, and nowhere
else. A program read for it must have its offsets there: a G43 anywhere else (no change
before it, another tool's H, a move between) would be lost, and a Z after a G49 that
cancelled one would keep the offset: in both the tool stands a tool length off (rs274's
``USE_TOOL_LENGTH_OFFSET`` shows it: tests/corpus/test_rs274.py). Both readers, the
plain-line path and the lexer, give the same answers. Read for any other target, Z is read
as written, with the warning, as before.
"""

from __future__ import annotations

import pytest

from camtool.importers import gcode
from camtool.model.errors import InputError
from camtool.model.program import ToolChange

HEAD = "G21 G90 G17\n"
CUT = "G0 X0 Y0 Z5\nG1 Z-1 F100\nG1 X10\nG0 Z5\n"


def _both(text: str) -> list[object]:
    """The program read for a target with length offsets by both readers (the same)."""
    got = [gcode._parse(text, "p.ngc", plain=plain, length_offsets=True) for plain in (True, False)]
    assert got[0] == got[1]
    return [c for _, c in got[0].commands]


def _refused(text: str, match: str) -> None:
    for plain in (True, False):
        with pytest.raises(InputError, match=match):
            gcode._parse(text, "p.ngc", plain=plain, length_offsets=True)


def test_the_offset_the_dialect_writes_after_a_change_is_read() -> None:
    for g43 in ("G43 H2", "G43"):  # without H: the tool in the spindle (LinuxCNC)
        commands = _both(HEAD + f"T2 M6\n{g43}\n" + CUT + "M2\n")
        assert commands == [ToolChange(2)]
    # CAMotics' cameo.nc: an XY rapid between the change and G43 H1 Z2 (Z not yet moved)
    cameo = HEAD + "T1 M6\nG00 X-75. Y-93.703 M03\nG43H1 Z2. M8\nG01 Z-6. F300\nM2\n"
    assert ToolChange(1) in _both(cameo)


@pytest.mark.parametrize(
    ("program", "match"),
    [
        (HEAD + "G43 H1\n" + CUT, r"p.ngc:2: G43 H1 .* put T1 M6 right before it"),
        (HEAD + "T1 M6\nG43 H2\n" + CUT, r"p.ngc:3: G43 H2 .* right after the change to T1"),
        (HEAD + "T1 M6\nG0 X0 Y0 Z5\nG43 H1\n" + CUT, r"p.ngc:4: G43 H1 .* before any Z move"),
    ],
)
def test_an_offset_the_dialect_would_not_write_is_refused(program: str, match: str) -> None:
    _refused(program + "M2\n", match)


def test_a_z_after_the_offset_is_cancelled_is_refused() -> None:
    program = HEAD + "T1 M6\nG43 H1\n" + CUT + "G49\n"
    _refused(program + "G0 Z20\nM2\n", r"p.ngc:9: Z20 after G49 \(line 8\)")
    _refused(program + "G0 X1 Y1 Z20\nM2\n", r"p.ngc:9: Z20 after G49")
    assert _both(program + "G0 X1 Y1\nM2\n") == [ToolChange(1)]  # XY: no length in it
    assert _both(HEAD + "G49\n" + CUT + "M2\n") == []  # no offset on: nothing cancelled


def test_other_targets_read_z_as_written_with_the_warning() -> None:
    text = HEAD + "G43 H1\n" + CUT + "G49\nG0 Z20\nM2\n"
    for plain in (True, False):
        program = gcode._parse(text, "p.ngc", plain=plain)
        assert any("G43 tool length offset assumed 0" in w for w in program.warnings)
        assert any("G49 (tool length offset off) read as a no-op" in w for w in program.warnings)
        assert program.moves[-1].z == 20.0
