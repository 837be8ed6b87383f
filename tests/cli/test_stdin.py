"""Standard input as a user pipes it: told by its content, named ``<stdin>``, nothing lost.

A pipeline (``cat logo.svg | camtool post - -t grbl``) gives no file name, so the kind
comes from the bytes (:func:`camtool.jobs.inputs.stdin_kind`). The expected kinds are the
files' own endings, from their authors (LibreCAD, Inkscape, LinuxCNC, the Tango icons);
the programs posted from stdin must be the ones the same file posts, byte for byte but
for the header's name of the source.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from camtool.jobs.inputs import PROGRAM_SUFFIXES, stdin_kind
from camtool.model.errors import InputError
from tests.corpus.conftest import CORPUS

ROOT = Path(__file__).resolve().parents[2]
SAMPLES = ROOT / "samples"
KNOWN = {".dxf": ".dxf", ".svg": ".svg", ".m": ".m", ".csv": ".csv"} | {
    s: ".nc" for s in PROGRAM_SUFFIXES
}


def camtool(args: list[str], data: bytes) -> subprocess.CompletedProcess[bytes]:
    return subprocess.run(
        [sys.executable, "-m", "camtool", *args], input=data, capture_output=True, check=False
    )


def _third_party() -> list[Path]:
    """Every DXF, SVG and G-code program of the corpus that holds a byte."""
    found = [
        p
        for p in sorted((CORPUS / "pkg").rglob("*"))
        if p.suffix.lower() in KNOWN and p.is_file() and p.stat().st_size > 0
    ]
    return found


def test_real_files_are_told_by_their_content() -> None:
    files = _third_party()
    if not files:
        pytest.skip("no corpus: run `python tests/corpus/fetch_corpus.py` (make corpus)")
    wrong = []
    for path in files:
        try:
            kind = stdin_kind(path.read_bytes())
        except InputError as exc:
            kind = f"refused: {exc}"
        if kind != KNOWN[path.suffix.lower()]:
            wrong.append((path.relative_to(CORPUS).as_posix(), kind))
    kinds = {KNOWN[p.suffix.lower()] for p in files}
    assert {".dxf", ".svg", ".nc"} <= kinds  # LibreCAD, Inkscape/Tango, LinuxCNC
    assert wrong == []


@pytest.mark.parametrize(
    ("text", "kind"),
    [
        ("  0\nSECTION\n  2\nHEADER\n", ".dxf"),
        ("999\ndxfrw 0.6.3\n  0\nSECTION\n", ".dxf"),  # LibreCAD's comment first
        ("\ufeff<?xml version='1.0'?>\n<svg/>", ".svg"),
        ("%\nO1001 (PART)\nG90\n", ".nc"),  # a Fanuc post: the reader refuses the O
        ("(header)\n; note\nN10 G21\n", ".nc"),
        ("/ G0 X1\n", ".nc"),  # block delete
        ("#<depth> = -1\nG1 Z#<depth>\n", ".nc"),  # LinuxCNC named parameter
        ("o<sub> sub\nG0 X1\no<sub> endsub\n", ".nc"),
        ("x 10 y 5\n", ".nc"),  # spaces inside words are G-code's
        ("(only a comment)\n", ".nc"),
        ("% comment\nxy = [1 2; 3 4];\n", ".m"),
        ("x,y\n1,2\n", ".csv"),
        ("X Y Z\n1 2 0\n", ".csv"),
        ("# points\n1;2\n", ".csv"),
        ("# 1st stroke\n1 2\n3 4\n", ".csv"),  # a comment, not LinuxCNC's #1
        ("-1.5\t2\n", ".csv"),
        # headers of units or quotes (read_points takes them): a comma is no G-code
        ("X (in),Y (in)\n0,0\n", ".csv"),
        ('"x","y"\n"0","1"\n', ".csv"),
        ("x1,y1\n0,0\n", ".csv"),
        ("G1 X1 Y1 (a, b)\n", ".nc"),  # a comma in a comment
        ("sep=;\nx;y\n0;0\n", ".csv"),  # Excel's separator line, no Matlab assignment
    ],
)
def test_kinds_from_their_first_lines(text: str, kind: str) -> None:
    assert stdin_kind(text.encode()) == kind


@pytest.mark.parametrize("text", ["", " \n\n", "hello world\n", "x y\nnot numbers\n"])
def test_what_cannot_be_told_is_refused(text: str) -> None:
    with pytest.raises(InputError, match=r"<stdin>: (empty input|cannot tell what it holds)"):
        stdin_kind(text.encode())


def test_binary_dxf_sentinel() -> None:
    assert stdin_kind(b"AutoCAD Binary DXF\r\n\x1a\x00" + bytes(range(256))) == ".dxf"


def _header_free(code: bytes) -> bytes:
    """The program without its first line (the header naming the source)."""
    return code.split(b"\n", 1)[1]


@pytest.mark.parametrize("sample", ["logo.dxf", "star.csv"])
def test_a_drawing_from_stdin_posts_as_the_file(sample: str) -> None:
    path = SAMPLES / sample
    piped = camtool(["post", "-", "-t", "grbl"], path.read_bytes())
    named = camtool(["post", str(path), "-t", "grbl"], b"")
    assert piped.returncode == 0 == named.returncode, piped.stderr
    assert piped.stdout.startswith(b"(camtool ") and b"<stdin>" in piped.stdout.split(b"\n")[0]
    assert _header_free(piped.stdout) == _header_free(named.stdout)


def test_an_svg_from_stdin_is_read_as_svg(tmp_path: Path) -> None:
    svg = b'<svg xmlns="http://www.w3.org/2000/svg" width="20mm" height="10mm" '
    svg += b'viewBox="0 0 20 10"><rect x="2" y="2" width="10" height="5"/></svg>'
    (tmp_path / "r.svg").write_bytes(svg)
    piped = camtool(["post", "-", "-t", "grbl"], svg)
    named = camtool(["post", str(tmp_path / "r.svg"), "-t", "grbl"], b"")
    assert piped.returncode == 0, piped.stderr
    assert b"X12.000" in piped.stdout and b"Y8.000" in piped.stdout  # y flipped: 10 - 2
    assert _header_free(piped.stdout) == _header_free(named.stdout)


def test_a_program_on_stdin_is_refused_not_guessed() -> None:
    """pic-mmh's code (fixed-width µm words) looks like G-code: read so, it would be 1000×."""
    pic = b"G54;\nG90;\nG00X03000.00Y01400.00;\nG01X03600.00Y01400.00F08;\nM30;\n"
    for args, remedy in (
        (["post", "-", "-t", "grbl"], b"if it is RS-274 G-code, save it as FILE.nc"),
        (["preview", "-", "-o", "-"], b"give --target NAME to draw it"),
        (["inspect", "-"], b"this needs a drawing"),
    ):
        done = camtool(args, pic)
        assert done.returncode == 3 and done.stdout == b""
        assert b"<stdin>: holds a program, which camtool does not read from stdin" in done.stderr
        assert remedy in done.stderr


def test_preview_draws_a_drawing_from_stdin() -> None:
    done = camtool(["preview", "-", "-o", "-"], (SAMPLES / "logo.dxf").read_bytes())
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith(b"<svg ") and done.stdout.rstrip().endswith(b"</svg>")


def test_inspect_reads_stdin() -> None:
    done = camtool(["inspect", "-"], (SAMPLES / "logo.dxf").read_bytes())
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith(b"<stdin>\n") and b"contours: 5" in done.stdout


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="needs /dev/full")
def test_a_file_that_cannot_be_written_is_never_said_written() -> None:
    done = camtool(["post", str(SAMPLES / "logo.dxf"), "-t", "grbl", "-o", "/dev/full"], b"")
    assert done.returncode == 1
    assert b"/dev/full: cannot write (no space left on device)" in done.stderr
    assert b"wrote" not in done.stderr
