"""Hostile rows of point lists, piped input and dialect programs: linear time, short messages.

Each pattern that reads a row used to try every split of a run of blanks or digits: a row
of a million digits (``1,111…1x``) or blanks kept camtool busy for hours, and a line of
60 000 blanks on standard input 25 s. Each file here is read under a CPU-time bound far
above what it needs (:func:`tests.cpu.cpu_bound`), and every message stays short: a
message quotes a long text by its start and its length (:func:`camtool.model.errors.quoted`),
and the CLI leaves out the middle of any message longer than
:data:`camtool.model.errors.MAX_MESSAGE` characters.
"""

from __future__ import annotations

import io
import sys
from pathlib import Path

import pytest

from camtool.cli.main import main
from camtool.importers.points import holds_rows, read_points
from camtool.model.errors import MAX_MESSAGE, InputError, readable
from tests.cpu import cpu_bound

BOUND_S = 60
SNIFF_BOUND_S = 10
"""For the 64 KiB that camtool looks at to tell a file's kind: a few ms of work."""


@pytest.mark.parametrize(
    ("rows", "what"),
    [
        ("0 0\n1," + "1" * 1_000_000 + "x\n", "(1000001 characters) is not a number"),
        ("x,y\n0,0\n1" + " " * 1_000_000 + "x\n2,2\n", "'x' is not a number"),
        ("0;0\n1;2," + "5" * 1_000_000 + "\n", "has a decimal comma"),
        ("0 0\n1 " + "1" * 1_000_000 + "\n", "(1000000 characters) is out of range"),
    ],
)
def test_a_hostile_row_is_refused_in_linear_time(tmp_path: Path, rows: str, what: str) -> None:
    path = tmp_path / "p.csv"
    path.write_text(rows)
    with pytest.raises(InputError) as info, cpu_bound(BOUND_S):
        read_points(path)
    message = str(info.value)
    assert message.startswith(f"{path}: line ") and what in message
    assert len(message) < 400


def test_a_row_of_a_million_blanks_between_numbers_is_read(tmp_path: Path) -> None:
    path = tmp_path / "p.csv"
    path.write_text("0 0\n5" + " " * 1_000_000 + "5\n")
    with cpu_bound(BOUND_S):
        drawing = read_points(path)
    (contour,) = drawing.contours
    assert [contour.start, *(s.end for s in contour.segments)] == [(0.0, 0.0), (5.0, 5.0)]


def test_piped_input_of_a_letter_and_blanks_is_told_apart_quickly(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    data = ("X" + " " * 60_000 + "Y\n").encode()
    monkeypatch.setattr(sys, "stdin", io.TextIOWrapper(io.BytesIO(data)))
    with cpu_bound(SNIFF_BOUND_S):
        code = main(["post", "-", "-t", "grbl", "-o", str(tmp_path / "o.nc")])
    err = capsys.readouterr().err
    assert code == 3 and "<stdin>: cannot tell what it holds" in err
    assert not (tmp_path / "o.nc").exists()


def test_a_note_of_a_number_and_blanks_is_no_point_list() -> None:
    with cpu_bound(SNIFF_BOUND_S):  # what a batch asks of each .txt beside the drawings
        assert not holds_rows("1" + " " * 60_000 + "x\n")


def test_a_dialect_block_of_a_hundred_thousand_characters_gives_a_short_message(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    program = tmp_path / "p.txt"
    program.write_text("G54;\nG90;\nG00X03000.00Y01400.00;\nG01X" + "1" * 100_000 + "Y0F08;\n")
    with cpu_bound(BOUND_S):
        code = main(["verify", str(program), "-t", "pic-mmh"])
    err = capsys.readouterr().err
    assert code == 3 and f"{program}:4: not a pic-mmh block: 'G01X111" in err
    assert "(100010 characters)" in err and len(err) < 300


def test_a_long_message_keeps_its_start_and_its_end() -> None:
    message = "f.nc:3: " + "x" * 10 * MAX_MESSAGE + " ; do this"
    shown = readable(message)
    assert len(shown) <= MAX_MESSAGE + 60
    assert shown.startswith("f.nc:3: xxx") and shown.endswith("xxx ; do this")
    left_out = len(message) - (MAX_MESSAGE * 2 // 3) - (MAX_MESSAGE // 4)
    assert f" ... ({left_out} characters left out) ... " in shown
    assert readable("short") == "short"


def test_the_cli_shortens_a_long_message_and_keeps_what_to_do(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    drawing = Path(__file__).parents[2] / "samples" / "logo.dxf"
    code = main(["post", str(drawing), "-t", "A" * 20_000, "-o", str(tmp_path / "o.nc")])
    err = capsys.readouterr().err
    assert code != 0 and err.startswith("camtool: error: unknown target 'AAA")
    assert "characters left out" in err and len(err) < MAX_MESSAGE + 100
    assert err.rstrip().endswith("(or a target .toml file)")  # what to do is kept
    assert not (tmp_path / "o.nc").exists()
