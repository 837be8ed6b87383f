"""Compressed SVG (``.svgz``, Inkscape's "Compressed Inkscape SVG", KDE's themes and card
decks): read as the SVG it holds, named by its own file, bombs and damage refused.

The expected drawing is the same SVG's, read uncompressed (gzip is lossless); the bomb and
the damage are written here with Python's gzip.
"""

from __future__ import annotations

import gzip
import subprocess
import sys
from pathlib import Path

import pytest

import camtool.importers as importers
from camtool.importers import read_drawing, read_drawing_bytes
from camtool.jobs.inputs import stdin_kind
from camtool.model.errors import InputError
from tests.importers.svgutil import svg

BODY = (
    '<path d="M 10 10 C 20 0 40 0 50 10 L 50 40 Z" fill="none" stroke="black"/>'
    '<circle cx="70" cy="70" r="12" fill="none" stroke="black"/>'
)
NO_SIZE = 'viewBox="0 0 100 100"'  # no width/height: the importer warns about its units


def _compressed(plain: Path) -> Path:
    packed = plain.with_suffix(".svgz")
    packed.write_bytes(gzip.compress(plain.read_bytes()))
    return packed


def test_an_svgz_reads_as_the_svg_it_holds_and_is_named_by_its_file(tmp_path: Path) -> None:
    plain = svg(tmp_path, BODY, root=NO_SIZE)
    packed = _compressed(plain)
    want, got = read_drawing(plain), read_drawing(packed)
    assert [c.segments for c in got.contours] == [c.segments for c in want.contours]
    assert len(got.contours) == 2
    assert got.source == str(packed)
    assert got.warnings == tuple(w.replace(str(plain), str(packed)) for w in want.warnings)
    assert got.warnings and all(w.startswith(f"{packed}: ") for w in got.warnings)


def test_an_svgz_that_is_not_compressed_is_read_as_plain_svg(tmp_path: Path) -> None:
    plain = svg(tmp_path, BODY)
    named = tmp_path / "plain.svgz"
    named.write_bytes(plain.read_bytes())
    assert len(read_drawing(named).contours) == 2


def test_a_gzip_bomb_is_refused_before_it_is_expanded(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(importers, "MAX_SVGZ_BYTES", 4096)
    plain = svg(tmp_path, BODY + "<!--" + " " * 5000 + "-->")
    with pytest.raises(InputError, match=r"expands to more than 0 MiB once decompressed"):
        read_drawing(_compressed(plain))
    small = svg(tmp_path, BODY, name="small.svg")
    assert len(read_drawing(_compressed(small)).contours) == 2  # under the limit: read


def test_damaged_gzip_data_is_an_input_error_naming_the_file(tmp_path: Path) -> None:
    packed = _compressed(svg(tmp_path, BODY))
    packed.write_bytes(packed.read_bytes()[:40])  # cut short
    with pytest.raises(InputError) as info:
        read_drawing(packed)
    assert str(info.value).startswith(f"{packed}: damaged gzip data")


def test_an_svgz_piped_on_stdin_posts_as_the_file_does(tmp_path: Path) -> None:
    packed = _compressed(svg(tmp_path, BODY))
    data = packed.read_bytes()
    assert stdin_kind(data) == ".svgz"

    def post(source: str, data: bytes | None) -> bytes:
        done = subprocess.run(
            [sys.executable, "-m", "camtool", "post", source, "-t", "grbl", "-o", "-"],
            input=data,
            capture_output=True,
            check=False,
        )
        assert done.returncode == 0, done.stderr
        return done.stdout

    piped, named = post("-", data), post(str(packed), None)
    assert b"<stdin>" in piped.splitlines()[0]
    assert piped.splitlines()[1:] == named.splitlines()[1:]
    assert b"G2" in named or b"G3" in named  # the circle, as arcs


OFF_PAGE = (
    '<rect x="10" y="10" width="20" height="20" fill="none" stroke="black"/>'
    '<rect x="400" y="10" width="20" height="20" fill="none" stroke="black"/>'
)
"""One square on the 100 × 100 mm page, one wholly off it (so the drawing is 410 mm wide)."""


def test_the_note_on_shapes_off_the_page_names_the_input_not_a_temporary_file(
    tmp_path: Path,
) -> None:
    plain = svg(tmp_path, OFF_PAGE)
    note = read_drawing(plain).size_note
    assert note.startswith(f"but {plain}: 1 contour lies wholly outside the 100 × 100 mm page")
    packed = _compressed(plain)
    assert read_drawing(packed).size_note == note.replace(str(plain), str(packed))
    piped = read_drawing_bytes(plain.read_bytes(), suffix=".svg")
    assert piped.size_note == note.replace(str(plain), "<stdin>")


def test_a_refusal_for_size_while_reading_stdin_names_stdin(tmp_path: Path) -> None:
    """The early travel check raises inside the reading of the temporary file: the refusal
    keeps its exit code (1) and names ``<stdin>``."""
    data = svg(tmp_path, OFF_PAGE).read_bytes()
    for piped in (data, gzip.compress(data)):
        done = subprocess.run(
            [sys.executable, "-m", "camtool", "post", "-", "-t", "grbl", "-o", "-"],
            input=piped,
            capture_output=True,
            check=False,
        )
        message = done.stderr.decode()
        assert done.returncode == 1, message
        assert "larger than the 200 × 200 mm travel" in message
        assert "but <stdin>: 1 shape lies wholly outside" in message
        assert "camtool-" not in message and "stdin.svg" not in message
