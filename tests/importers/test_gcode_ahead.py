"""A long program's later plain lines read ahead in a forked helper: the same program.

:mod:`camtool.importers.gcode_ahead` lets a helper read a program from its middle on, from
nothing known, and the reader take each run of plain lines the helper read where its own
modal values are the run's, bit for bit. These tests force it on small programs
(:data:`MIN_CHARS` lowered) and hold that the program read (moves, line numbers,
commands, warnings, compared by ``repr``: ``-0.0`` is not ``0.0``) or the error is the
one the reader gives alone and the reference reader gives
(:func:`~camtool.importers.gcode.parse_gcode_slow`), on the LinuxCNC example programs
and on random programs of plain and not-quite-plain lines; and that runs were taken
(so the comparison is not empty), or not where the helper cannot know the state.
"""

from __future__ import annotations

import os
import random
import re
import threading
from pathlib import Path
from typing import Any

import pytest

from camtool.importers import gcode_ahead
from camtool.importers.gcode import parse_gcode, parse_gcode_slow
from camtool.importers.gcode_target import Reading
from camtool.model.errors import CamtoolError
from tests.importers.test_gcode_plain import LINES

CORPUS = Path(os.environ.get("CAMTOOL_CORPUS_DIR", Path(__file__).resolve().parents[2] / ".corpus"))
EXAMPLES = [
    CORPUS / "pkg/linuxcnc" / name
    for name in (
        "usr/share/doc/linuxcnc/examples/sample-configs/sim/craftsman/screens/craftsmancnc.ngc",
        "usr/share/linuxcnc/ncfiles/arcspiral.ngc",
        "usr/share/linuxcnc/ncfiles/cds.ngc",
    )
]
"""CamBam's engraving (mm), 1 000 R-format arcs (inch), pockets (inch): the re-post
benchmark's programs (tests/benchmarks/bench_repost.py)."""
END = re.compile(r"^\s*(n\d+\s*)?m0*(2|30)\s*$", re.IGNORECASE)
"""A program end line (removed between the copies)."""


@pytest.fixture(autouse=True)
def small_programs(helpers_on: None, monkeypatch: pytest.MonkeyPatch) -> None:
    """Read ahead in programs of any size, in runs of at most 50 lines, wherever the tests run."""
    monkeypatch.setattr(gcode_ahead, "MIN_CHARS", 1)
    monkeypatch.setattr(gcode_ahead, "RUN_LINES", 50)


class Taken:
    """Counts the runs the reader took from the helper and the runs it read itself."""

    def __init__(self, monkeypatch: pytest.MonkeyPatch) -> None:
        self.taken = self.refused = 0
        take = gcode_ahead.Runs.take

        def counting(runs: gcode_ahead.Runs, reader: Any, number: int) -> Any:
            run = take(runs, reader, number)
            if number in runs.by_first:
                if run is None:
                    self.refused += 1
                else:
                    self.taken += 1
            return run

        monkeypatch.setattr(gcode_ahead.Runs, "take", counting)


def read(text: str, monkeypatch: pytest.MonkeyPatch, *, ahead: bool) -> str:
    """``repr`` of the program ``parse_gcode`` reads (or its error), with or without a helper."""
    with monkeypatch.context() as m:
        if not ahead:
            m.setattr(gcode_ahead, "MIN_CHARS", 10**12)
        try:
            return repr(parse_gcode(text, source="t.ngc"))
        except CamtoolError as exc:
            return f"{type(exc).__name__}: {exc}"


def slow(text: str) -> str:
    try:
        return repr(parse_gcode_slow(text, source="t.ngc"))
    except CamtoolError as exc:
        return f"{type(exc).__name__}: {exc}"


def examples(copies: int, line_end: str = "\n") -> str:
    """The three examples, their ends removed, ``copies`` times, then ``M2``."""
    bodies = []
    for path in EXAMPLES:
        if not path.exists():
            pytest.skip(f"no {path}: run `make corpus`")
        lines = path.read_text(encoding="latin-1").splitlines()
        bodies.append([x for x in lines if not END.match(x) and x.strip() != "%"])
    out = [line for _ in range(copies) for body in bodies for line in body]
    return line_end.join([*out, "M2"]) + line_end


@pytest.mark.parametrize("line_end", ["\n", "\r\n", "\r"])
def test_the_examples_read_the_same_with_their_runs_taken(
    line_end: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    text = examples(3, line_end)
    expected = read(text, monkeypatch, ahead=False)
    taken = Taken(monkeypatch)
    assert read(text, monkeypatch, ahead=True) == expected
    if line_end == "\r":
        assert taken.taken == taken.refused == 0  # no LF to start the helper at
    else:
        assert taken.taken > 10  # the runs after the helper's first: its state is known


def test_single_axis_lines_read_for_a_post_are_read_ahead(monkeypatch: pytest.MonkeyPatch) -> None:
    """A post reads with ``known_start``: the helper, starting mid-program, is positioned.

    Lines naming X alone or Y alone are what a program's first moves may not be (where
    the machine stands decides them); at 55 % of the text the program has long given X
    and Y, so the helper reads them and its runs fit.
    """
    lines = ["G21 G90", "G0 X0 Y0 Z1", "G1 Z-1 F100"]
    lines += [f"G1 X{k % 7 * 0.1:.1f}" if k % 2 else f"G1 Y{k * 0.01:.2f}" for k in range(3000)]
    text = "\n".join([*lines, "M2"]) + "\n"
    posted = Reading(known_start=True)
    with monkeypatch.context() as m:
        m.setattr(gcode_ahead, "MIN_CHARS", 10**12)
        expected = repr(parse_gcode(text, source="t.ngc", reading=posted))
    taken = Taken(monkeypatch)
    assert repr(parse_gcode(text, source="t.ngc", reading=posted)) == expected
    assert taken.taken > 10 and taken.refused <= 1


@pytest.mark.parametrize("units", ["G20", "G21"])
def test_units_and_feed_set_once_at_the_top(units: str, monkeypatch: pytest.MonkeyPatch) -> None:
    # the units and the feed on the program's first lines only: the helper, starting in
    # the middle, takes them from the text before it (a guess), and its runs fit
    lines = [f"{units} G90", "G0 X0 Y0 Z0.1", "G1 Z-0.01 F10"]
    lines += [f"G1 X{k % 7 * 0.1:.1f} Y{k * 0.01:.2f}" for k in range(3000)]
    text = "\n".join([*lines, "M2"]) + "\n"
    expected = read(text, monkeypatch, ahead=False)
    taken = Taken(monkeypatch)
    assert read(text, monkeypatch, ahead=True) == expected == slow(text)
    assert taken.taken > 0


def test_random_programs_read_the_same(monkeypatch: pytest.MonkeyPatch) -> None:
    rng = random.Random(44)
    for _ in range(150):
        head = rng.choice(["", "G21\n", "G20\n", "G91\n", "F100\n", "G21 F100\n"])
        body = [rng.choice(LINES) for _ in range(rng.randint(20, 60))]
        tail = rng.choice(["M2\n", "", "%\n"])
        text = head + "\n".join(body) + "\n" + tail
        assert read(text, monkeypatch, ahead=True) == slow(text), text


@pytest.mark.parametrize("how", ["raises", "dies", "hangs"])
def test_a_helper_that_fails_changes_nothing(how: str, monkeypatch: pytest.MonkeyPatch) -> None:
    from camtool.accel import cores

    monkeypatch.setattr(cores, "HELPER_PATIENCE_MIN_S", 0.5)  # not the 10 s a user waits
    text = examples(2)
    expected = read(text, monkeypatch, ahead=False)

    def fail(self: Any) -> bytes:
        if how == "dies":
            os._exit(3)
        if how == "hangs":
            threading.Event().wait()  # forever: the reader ends it at the deadline
        raise RuntimeError("helper failed")

    monkeypatch.setattr(gcode_ahead.Recorder, "pack", fail)
    taken = Taken(monkeypatch)
    assert read(text, monkeypatch, ahead=True) == expected
    assert taken.taken == taken.refused == 0


def test_switched_off_there_is_no_helper(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("CAMTOOL_ACCEL", "0")
    assert gcode_ahead.start("G0 X0 Y0\n" * 10, lambda position, number: b"") is None


def test_the_state_compared_is_every_value_a_plain_line_reads() -> None:
    # a run fits where STATE is the same: every attribute of the reader the plain path
    # uses must be in it, or be one the reader's run sets itself (its moves, line numbers,
    # last line, contour count) or the notes (written only before the units are seen,
    # where no run is taken)
    import camtool.importers.gcode_plain as plain_module

    source = Path(plain_module.__file__).read_text(encoding="utf-8")
    used = set(re.findall(r"self\.([a-z][a-z_]*)\b(?!\()", source))
    own = {"moves", "lines", "line", "contour", "notes"}
    methods = {name for name in used if callable(getattr(plain_module.PlainLines, name, None))}
    assert used - methods - own <= set(gcode_ahead.STATE), used - methods - own
