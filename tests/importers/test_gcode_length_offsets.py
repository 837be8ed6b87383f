"""G43/G49 read for a target that applies tool length offsets (LinuxCNC's ``G43 H<n>``).

The linuxcnc dialect writes ``G43 H<n>`` right after each change to tool ``n``. A program
read for it keeps its own offsets: a G43 there is the change's; a change with no G43 says
so (the target writes none there, and the offset in force stays); any other G43 (no change
before it, another tool's H, after a Z move) and a G49 that cancels one are
:class:`LengthOffset` commands written where the program had them. Dropped, the tool stood
a tool length off (rs274's ``USE_TOOL_LENGTH_OFFSET`` shows it: tests/corpus/test_rs274.py).
Both readers, the plain-line path and the lexer, give the same answers. Read for any other
target, Z is read as written, with the warning, as before.
"""

from __future__ import annotations

import pytest

from camtool.importers import gcode
from camtool.importers.gcode_target import Reading
from camtool.model.errors import InputError
from camtool.model.program import LengthOffset, Linear, Program, Rapid, ToolChange
from camtool.post.registry import load_target

HEAD = "G21 G90 G17\n"
CUT = "G0 X0 Y0 Z5\nG1 Z-1 F100\nG1 X10\nG0 Z5\n"


def _both(text: str) -> list[tuple[int, object]]:
    """``(before move, command)`` read for a target with length offsets, by both readers."""
    got = [
        gcode._parse(text, "p.ngc", plain=plain, reading=Reading(length_offsets=True))
        for plain in (True, False)
    ]
    assert got[0] == got[1]
    return list(got[0].commands)


def test_the_offset_the_dialect_writes_after_a_change_is_the_change_s() -> None:
    for g43 in ("G43 H2", "G43"):  # without H: the tool in the spindle (LinuxCNC)
        assert _both(HEAD + f"T2 M6\n{g43}\n" + CUT + "M2\n") == [(0, ToolChange(2))]
    # CAMotics' cameo.nc: an XY rapid between the change and G43 H1 Z2 (Z not yet moved)
    cameo = HEAD + "T1 M6\nG00 X-75. Y-93.703 M03\nG43H1 Z2. M8\nG01 Z-6. F300\nM2\n"
    assert (0, ToolChange(1)) in _both(cameo)


@pytest.mark.parametrize(
    ("program", "expected"),
    [
        # LinuxCNC's cds.ngc: G43 H1 with no tool change in the program
        (HEAD + "G43 H1\n" + CUT, [(0, LengthOffset(1))]),
        (
            HEAD + "T1 M6\nG43 H2\n" + CUT,
            [(0, ToolChange(1, length_offset=False)), (0, LengthOffset(2))],
        ),
        (
            HEAD + "T1 M6\nG0 X0 Y0 Z5\nG43 H1\n" + CUT,
            [(0, ToolChange(1, length_offset=False)), (2, LengthOffset(1))],
        ),
    ],
)
def test_an_offset_elsewhere_is_kept_where_it_was(program: str, expected: list[object]) -> None:
    assert _both(program + "M2\n") == expected


def test_a_cancelled_offset_is_kept_cancelled() -> None:
    program = HEAD + "T1 M6\nG43 H1\n" + CUT + "G49\nG0 Z20\nM2\n"
    # the first G0 X0 Y0 Z5 is two moves (Z, then XY: the start was only assumed)
    assert _both(program) == [(0, ToolChange(1)), (5, LengthOffset(None))]
    assert _both(HEAD + "G49\n" + CUT + "M2\n") == []  # no offset on: nothing cancelled


def test_a_change_without_its_offset_says_so() -> None:
    """The target then writes no G43 after it: the offset in force stays, as it ran."""
    text = HEAD + "T2 M6\nG43 H2\n" + CUT + "T3 M6\n" + CUT + "M2\n"
    assert [c for _, c in _both(text)] == [ToolChange(2), ToolChange(3, length_offset=False)]
    for plain in (True, False):  # for other targets the offset does not apply
        program = gcode._parse(text, "p.ngc", plain=plain)
        assert [c for _, c in program.commands] == [ToolChange(2), ToolChange(3)]


def test_g43_without_h_before_any_change_is_refused() -> None:
    for plain in (True, False):
        with pytest.raises(InputError, match=r"p.ngc:2: G43 without H before any tool change"):
            gcode._parse(
                HEAD + "G43\n" + CUT + "M2\n",
                "p.ngc",
                plain=plain,
                reading=Reading(length_offsets=True),
            )


def test_other_targets_read_z_as_written_with_the_warning() -> None:
    text = HEAD + "G43 H1\n" + CUT + "G49\nG0 Z20\nM2\n"
    for plain in (True, False):
        program = gcode._parse(text, "p.ngc", plain=plain)
        assert any("G43 tool length offset assumed 0" in w for w in program.warnings)
        assert any("G49 (tool length offset off) read as a no-op" in w for w in program.warnings)
        assert program.commands == ()


def test_linuxcnc_writes_each_offset_and_its_reader_reads_the_changes_back() -> None:
    target = load_target("linuxcnc")
    moves = (Rapid(1.0, 1.0, 5.0), Linear(1.0, 1.0, 100.0, -1.0), Linear(5.0, 1.0, 100.0))
    for flag in (True, False):
        change = ToolChange(3, length_offset=flag)
        program = Program(moves, commands=((0, change),))
        code = target.post.emit(program, target.machine).code
        assert ("G43 H3" in code) == flag
        back = target.post.parse(code, source="out.ngc")
        assert [c for _, c in back.commands if isinstance(c, ToolChange)] == [change]
    program = Program(moves, commands=((1, LengthOffset(2)), (3, LengthOffset(None))))
    lines = target.post.emit(program, target.machine).code.splitlines()
    body = [line for line in lines if not line.startswith("(")]
    assert body.index("G43 H2") < body.index("G1 Z-1.000 F100") < body.index("G49")


def test_a_target_without_offsets_refuses_one() -> None:
    from camtool.model.errors import DialectError

    moves = (Rapid(1.0, 1.0), Linear(2.0, 1.0, 100.0))
    program = Program(moves, commands=((1, LengthOffset(2)),))
    for name in ("grbl", "pic-mmh", "i8751"):
        target = load_target(name)
        with pytest.raises(DialectError, match="tool length offset G43 H2"):
            target.post.emit(program, target.machine)


def test_an_offset_after_the_change_s_own_is_kept_in_order() -> None:
    """G43 H1, G49, G43 H1 after T1 M6: the second G43 is not the change's (it follows a G49)."""
    text = HEAD + "T1 M6\nG43 H1\nG49\nG43 H1\n" + CUT + "M2\n"
    assert [c for _, c in _both(text)] == [ToolChange(1), LengthOffset(None), LengthOffset(1)]
    text = HEAD + "T1 M6\nG43 H2\nG43 H1\n" + CUT + "M2\n"
    expected = [ToolChange(1, length_offset=False), LengthOffset(2), LengthOffset(1)]
    assert [c for _, c in _both(text)] == expected


def test_a_program_of_many_changes_and_offsets_is_read() -> None:
    """A hostile program: 20 000 tool changes, each with its G43, and moves between (each G43
    looks only at the moves since the one before, not back to the change)."""
    block = "T{n} M6\nG43 H{n}\nG0 X1 Y1 Z5\nG1 Z-1 F100\nG1 X2\n"
    text = HEAD + "".join(block.format(n=n % 99 + 1) for n in range(20_000)) + "M2\n"
    program = gcode._parse(text, "p.ngc", plain=True, reading=Reading(length_offsets=True))
    changes = [c for _, c in program.commands if isinstance(c, ToolChange)]
    assert len(changes) == 20_000 and all(c.length_offset for c in changes)
