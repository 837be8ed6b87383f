"""Gradients taken out of the prepared SVG: the drawing read is the same without them.

svgelements reads a gradient and its stops into elements it draws nothing of, and paints a
``url(…)`` black whether the gradient is there or not (``svgvalues.drop_gradients``). So the
expected drawing is the one read with the gradients left in (the function switched off),
on documents drawn here and on real icons of the Tango theme (a Debian package).
"""

from __future__ import annotations

import random
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Any

import pytest

from camtool.importers import svgvalues
from camtool.importers.svg import read_svg
from camtool.importers.svgdoc import prepare
from camtool.model.errors import InputError
from tests.corpus.conftest import CORPUS, load_manifest
from tests.importers.svgutil import svg

TANGO = CORPUS / "pkg/tango-icon-theme/usr/share/icons/Tango/scalable"


def _read(path: Path) -> tuple[Any, ...]:
    """What a user gets of ``path``: contours (source, layer, closed, segments) and warnings."""
    try:
        drawing = read_svg(path)
    except InputError as exc:
        return ("refused", str(exc))
    contours = [(c.source, c.layer, c.closed, c.segments) for c in drawing.contours]
    return (contours, drawing.warnings)


def _read_with_gradients(path: Path, monkeypatch: pytest.MonkeyPatch) -> tuple[Any, ...]:
    with monkeypatch.context() as patch:
        patch.setattr(svgvalues, "drop_gradients", lambda root: 0)
        return _read(path)


def _kinds(data: bytes) -> list[str]:
    return [e.tag.rpartition("}")[2] for e in ET.fromstring(data).iter()]


BODY = (
    '<defs><linearGradient id="stops"><stop offset="0" stop-color="red"/></linearGradient>'
    '<linearGradient id="chain" xlink:href="#stops" x2="1"/>'
    '<radialGradient id="placed"><stop offset="0" stop-color="blue"/></radialGradient>'
    '<linearGradient id="holder"><path id="inside" d="M 0 0 L 30 30"/></linearGradient>'
    '<radialGradient id="animated"><stop offset="0"><animate attributeName="offset"/>'
    "</stop></radialGradient></defs>"
    '<g><linearGradient id="loose"><stop offset="1"/></linearGradient>'
    '<linearGradient id="drawn-in"><path id="in-group" d="M 5 5 L 9 40"/></linearGradient>'
    '<rect id="painted" width="9" height="9" fill="url(#chain)"/>'
    '<rect id="clipped" x="20" width="9" height="9" clip-path="url(#stops)"/>'
    '<rect id="radial" x="40" width="9" height="9" style="fill:url(#animated)"/></g>'
    '<use id="clone" href="#placed"/><use id="clone2" xlink:href="#holder"/>'
)


def test_gradients_with_nothing_drawn_in_them_are_taken_out(tmp_path: Path) -> None:
    """Kept: one a ``<use>`` places (its clone would hold it), and one holding a shape.

    ``drawn-in``'s shape stands where SVG draws none: it goes to the hold first
    (``svgcontent``), and the gradient with it.
    """
    path = svg(tmp_path, BODY)
    kept = _kinds(prepare(path, None).data)
    assert kept.count("linearGradient") + kept.count("radialGradient") == 2
    data = prepare(path, None).data.decode()
    for gone in ('"stops"', '"chain"', '"animated"', '"loose"', '"drawn-in"'):
        assert gone not in data
    for there in ('"placed"', '"holder"', '"in-group"'):
        assert there in data


def test_the_drawing_is_the_one_read_with_the_gradients(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = svg(tmp_path, BODY)
    read = _read(path)
    assert read == _read_with_gradients(path, monkeypatch)
    sources = [c[0] for c in read[0]]
    assert {"rect#painted", "rect#clipped", "rect#radial"} <= set(sources)


@pytest.mark.skipif(load_manifest() is None, reason="no corpus (make corpus)")
def test_tango_icons_read_the_same_without_their_gradients(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Twelve icons with gradients, drawn by the Tango project in Inkscape."""
    icons = sorted(p for p in TANGO.rglob("*.svg") if p.is_file() and not p.is_symlink())
    with_gradients = [p for p in icons if b"Gradient" in p.read_bytes()]
    picked = random.Random(44).sample(with_gradients, 12)
    real = svgvalues.drop_gradients
    dropped: list[int] = []

    def counted(root: ET.Element) -> int:
        dropped.append(real(root))
        return dropped[-1]

    for icon in picked:
        dropped.clear()
        with monkeypatch.context() as patch:
            patch.setattr(svgvalues, "drop_gradients", counted)
            read = _read(icon)
        assert dropped and dropped[0] > 0, icon
        assert read == _read_with_gradients(icon, monkeypatch), icon
