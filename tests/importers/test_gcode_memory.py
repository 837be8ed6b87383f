"""The G-code reader holds no copy of the program's text but the one it is given.

Checked with tracemalloc, with wide margins: what the reader allocates beyond the
program it returns (its transient peak). Before, it kept a list of every line and a
second copy of the text with its line ends made uniform: ~90 bytes a line of 16, 5.7×
the text; now what is left is turning its lists of moves and lines into tuples (~18
bytes a line).
"""

from __future__ import annotations

import tracemalloc

from camtool.importers.gcode import _lines_at, parse_gcode


def _program(lines: int) -> str:
    body = [f"G1 X{i % 97}.{i % 10} Y{i % 89}.5" for i in range(lines)]
    return "G21 G90\nG0 X0 Y0\nF600\n" + "\r\n".join(body) + "\nM2\n"


def _transient(text: str) -> int:
    """Peak allocation of reading ``text`` above what stays (the program), bytes."""
    tracemalloc.start()
    try:
        program = parse_gcode(text, source="big.ngc")
        current, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert len(program.moves) > 0
    return peak - current


def test_reading_holds_no_copy_of_the_lines() -> None:
    small, big = _program(20_000), _program(80_000)
    _transient(small)  # caches and imports first
    lines = 80_000
    transient = _transient(big)
    assert transient < 40 * lines, transient  # bytes a line, beside the program
    assert transient < 2.5 * len(big), (transient, len(big))


def test_lines_are_read_lazily_and_as_split_would() -> None:
    text = "a\r\nb\rc\n\r\nd"
    lines = _lines_at(text, 0)
    assert next(lines) == ("a", False, 3)  # a generator: one line at a time
    assert list(lines) == [("b", False, 5), ("c", False, 7), ("", False, 9), ("d", True, 10)]
    assert list(_lines_at(text, 5)) == [("c", False, 7), ("", False, 9), ("d", True, 10)]
    for sample in ("", "\n", "x", "x\n", "\r\r\n\n\r", "a\n\rb\r\n"):
        split = sample.replace("\r\n", "\n").replace("\r", "\n").split("\n")
        assert [raw for raw, _, _ in _lines_at(sample, 0)] == split
        assert [last for _, last, _ in _lines_at(sample, 0)] == [False] * (len(split) - 1) + [True]
