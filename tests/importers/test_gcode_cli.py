"""Real programs through the CLI: comments, program ends, truncation, absurd numbers.

Each class of problem (issues 13 §4 and 14) is run as a user runs camtool
(``camtool.cli.main.main`` returns the exit code): 0 with a warning, or 3 with a message
that names the file and the line.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from camtool.cli.main import main

GRBL_SQUARE = (
    "G21 G90 G17 (mm, absolute, XY)\n"
    "G0 X0.000 Y0.000 ; to the start\n"
    "(the square)\n"
    "G1 X10.000 Y0.000 F300 (first side; slow)\n"
    "G1 X10.000 Y10.000\n"
    "M2 (end)\n"
)


def run(argv: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def write(tmp_path: Path, name: str, text: str) -> str:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8", newline="")
    return str(path)


# -- comments: every standard form, also in the grbl/linuxcnc dialect readers ------------


@pytest.mark.parametrize("target", ["grbl", "linuxcnc"])
def test_verify_reads_comments_the_way_the_controller_does(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], target: str
) -> None:
    # camtool's own blocks with "( )" and ";" comments added by hand: both controllers skip
    # them (GRBL protocol.c, LinuxCNC close_and_downcase), so verify reads the program.
    code, _, err = run(
        ["verify", write(tmp_path, "square.gcode", GRBL_SQUARE), "-t", target], capsys
    )
    assert code == 0, err
    assert "contour 1" in err


def test_verify_refuses_a_nested_comment_naming_the_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    text = GRBL_SQUARE.replace("(the square)", "(the (square))")
    code, _, err = run(["verify", write(tmp_path, "bad.gcode", text), "-t", "grbl"], capsys)
    assert code == 3
    assert "bad.gcode:3: nested comment" in err


def test_valcnc_reader_still_refuses_comments(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # The ValCNC firmware reads no comments (Munoz-22 S004-R04): the reader must not skip them.
    path = write(tmp_path, "v.ngc", "G00X0Y0\nG01X1Y1(cut)\n")
    code, _, err = run(["verify", path, "-t", "valcnc"], capsys)
    assert code == 3
    assert "v.ngc:2:" in err


def test_post_reads_msg_print_semicolon_and_percent(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    text = (
        "%\n"
        "(MSG, cutting the square)\n"
        "(PRINT, part #1; first op)\n"
        "G21 G90 G17 G94 G40 G49 G80 G54 ; the usual safety line\n"
        "G64 P0.01 Q0.01\n"
        "G0 X0 Y0\n"
        "G1 X10 F300\n"
        "G1 Y10\n"
        "%\n"
    )
    code, out, err = run(["post", write(tmp_path, "p.ngc", text), "-t", "grbl"], capsys)
    assert code == 0, err
    assert "G1 X10.000 Y10.000" in out
    # one warning per converted code, none for the comments or the '%' delimiters
    for fragment in ("G40 (cutter", "G49 (tool length", "G64 path blending"):
        assert sum(fragment in line for line in err.splitlines()) == 1, fragment
    # the program's own work offset, which GRBL has, is written as it chose it
    assert "G54" in out.splitlines() and "G54 work offset" not in err
    assert "truncated" not in err  # the closing '%' ends the program


def test_g54_1_is_refused_naming_the_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = write(tmp_path, "p.ngc", "G21\nG54.1 P3\nG1 X1 F10\nM2\n")
    code, _, err = run(["post", path, "-t", "grbl"], capsys)
    assert code == 3
    assert "p.ngc:2: G54.1 (extended work offsets" in err


# -- nothing to cut -------------------------------------------------------------------------


def test_post_of_a_rapid_only_program_is_an_input_error(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = write(tmp_path, "r.ngc", "G21 G90\nG0 X0 Y0\nG0 X10 Y10\nM2\n")
    code, out, err = run(["post", path, "-t", "grbl"], capsys)
    assert (code, out) == (3, "")
    assert "r.ngc: no cutting move (G1, G2, G3): the program only moves in rapids" in err


@pytest.mark.parametrize(
    ("text", "what"),
    [
        ("G21 G90 G17\nG0 X0.000 Y0.000\nG0 X10.000 Y10.000\nM2\n", "only 2 rapid move(s)"),
        ("G21 G90 G17\nM2\n", "no move"),
    ],
)
def test_verify_of_code_with_nothing_to_cut_says_so(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], text: str, what: str
) -> None:
    # not: "internal error: ValueError: bbox of nothing"
    code, _, err = run(["verify", write(tmp_path, "r.gcode", text), "-t", "grbl"], capsys)
    assert code == 3
    assert f"r.gcode: no cutting move in the code ({what}): nothing to verify" in err


@pytest.mark.parametrize("text", ["", " \n\t\n"])
def test_verify_of_an_empty_file_says_it_is_empty(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], text: str
) -> None:
    code, _, err = run(["verify", write(tmp_path, "r.gcode", text), "-t", "grbl"], capsys)
    assert code == 3
    assert "r.gcode: empty file (nothing but blanks): nothing to verify" in err
    assert "internal error" not in err


@pytest.mark.parametrize("text", ["", "\n\n  \t\r\n"])
def test_empty_drawing_file_is_an_input_error(
    text: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, _, err = run(["post", write(tmp_path, "e.ngc", text), "-t", "grbl"], capsys)
    assert code == 3
    assert "e.ngc: empty file (nothing but blanks); export the program again" in err


def test_a_program_of_comments_only_has_no_move(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Not empty: it has lines, none of them a move (UGS's comment fixture is such a file)."""
    text = "; Empty command with comment\n(Another empty command with comment)\n\nG0 ; c\nG1 (c)\n"
    code, _, err = run(["post", write(tmp_path, "c.ngc", text), "-t", "grbl"], capsys)
    assert code == 3
    assert "c.ngc: no move (G0, G1, G2, G3) found" in err


# -- truncated programs (issue 14) ----------------------------------------------------------


def test_program_without_end_is_read_with_a_warning(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = write(tmp_path, "t.ngc", "G21\nG0 X0 Y0\nG1 X10 F100\nG1 Y10\n")
    code, out, err = run(["post", path, "-t", "grbl"], capsys)
    assert code == 0
    assert "G1 X10.000 Y10.000" in out
    assert "t.ngc:4: no M2/M30 (nor a closing '%'): the file may be truncated" in err


def test_complete_last_block_without_end_of_line_is_fine(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = write(tmp_path, "t.ngc", "G21\nG0 X0 Y0\nG1 X10 F100\nM30")
    code, _, err = run(["post", path, "-t", "grbl"], capsys)
    assert code == 0
    assert "truncated" not in err


@pytest.mark.parametrize("cut", ["X12.", "X-", "X", "X 1 2 ."])
def test_last_line_cut_mid_number_is_an_error(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], cut: str
) -> None:
    path = write(tmp_path, "t.ngc", f"G21\nG0 X0 Y0\nG1 X10 F100\nG1 Y10 {cut}")
    code, out, err = run(["post", path, "-t", "grbl"], capsys)
    assert (code, out) == (3, "")
    assert f"t.ngc:4: the file ends in the middle of a word ('{cut.replace(' ', '')}'" in err
    assert "incomplete" in err


def test_same_words_with_an_end_of_line_are_not_cut(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # "X12." followed by an end of line is a complete RS-274 number (12.0)
    path = write(tmp_path, "t.ngc", "G21\nG0 X0 Y0\nG1 X10 F100\nG1 Y10 X12.\n")
    code, out, _ = run(["post", path, "-t", "grbl"], capsys)
    assert code == 0
    assert "X12.000 Y10.000" in out


# -- absurd numbers -------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("number", "message"),
    [
        ("1" + "0" * 400, "is out of range"),  # 1e400: a float would be inf
        ("100000000000000000000", "is out of range"),  # 1e20 mm
        ("1000000000", "is out of range"),  # the limit itself
        ("1e308", "exponent"),  # E is not part of a G-code number
        ("nan", "is not followed by a number"),
        ("inf", "is not followed by a number"),
    ],
)
@pytest.mark.parametrize("target", ["valcnc", "grbl"])
def test_absurd_numbers_in_gcode_are_refused_naming_the_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], number: str, message: str, target: str
) -> None:
    path = write(tmp_path, "h.ngc", f"G21 G90\nG0 X0 Y0\nG1 X{number} Y0 F100\nM2\n")
    code, out, err = run(["post", path, "-t", target], capsys)
    assert (code, out) == (3, "")
    assert "h.ngc:3:" in err and message in err
    assert "internal error" not in err and len(err) < 400


# -- the first positioning stays explicit ---------------------------------------------------


@pytest.mark.parametrize(
    ("first", "expected"),
    [
        # rising: Z first, then the XY the program gave; plunging: XY first, then Z
        ("G0 X0 Y0 Z5", ["G0 Z5.000", "G0 X0.000 Y0.000"]),
        ("G0 X0 Y0 Z-1", ["G0 X0.000 Y0.000", "G0 Z-1.000"]),
    ],
)
def test_a_first_move_to_x0_y0_keeps_its_xy_when_reposted(
    first: str, expected: list[str], tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # regression: "G0 X0 Y0 Z5" was re-posted as "G0 Z5": the XY positioning was lost and
    # the next plunge went down wherever the machine stood
    path = write(tmp_path, "p.ngc", f"G21 G90\n{first}\nG1 Z-1 F100\nG1 X10 F300\nM2\n")
    code, out, _ = run(["post", path, "-t", "grbl"], capsys)
    assert code == 0
    moves = [b for b in out.splitlines() if b.startswith(("G0 ", "G1 "))]
    assert moves[:2] == expected
