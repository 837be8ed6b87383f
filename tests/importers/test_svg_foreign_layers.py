"""Layers of SVGs written by Adobe Illustrator and CorelDRAW: the root's groups, by name.

Both write each layer as a ``<g>`` child of the ``<svg>`` element, named by its ``id``; a
character an id cannot hold is written ``_xHHHH_`` (``Layer_x0020_1`` is CorelDRAW's
"Layer 1"), and Illustrator adds ``data-name`` with the name as typed where it differs.
The file's prolog comment names the writer. Expected layer names are read off the
files' own text; a file without such a comment has no layers but Inkscape's.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from camtool.importers import read_drawing
from camtool.importers.options import ImportOptions
from camtool.model.errors import InputError

ILLUSTRATOR = (
    '<?xml version="1.0" encoding="utf-8"?>\n'
    "<!-- Generator: Adobe Illustrator 27.0.0, SVG Export Plug-In . SVG Version: 6.00 "
    "Build 0)  -->\n"
)
COREL = '<?xml version="1.0" encoding="UTF-8" standalone="no"?>\n<!-- Creator: CorelDRAW X8 -->\n'
BODY = (
    '<g id="Cut_x0020_outside" data-name="Cut outside">'
    '<rect x="10" y="10" width="60" height="40" fill="none" stroke="#000"/></g>'
    '<g id="Engrave"><circle cx="40" cy="30" r="5" fill="none" stroke="#000"/></g>'
    '<g id="Layer_x0020_2"><metadata id="CorelCorpID_0Corel-Layer"/>'
    '<path d="M 20 60 L 80 60" fill="none" stroke="#000"/></g>'
)
CORPUS = Path(os.environ.get("CAMTOOL_CORPUS_DIR", Path(__file__).resolve().parents[2] / ".corpus"))
KIG = CORPUS / "pkg/breeze-icon-theme/usr/share/icons/breeze/apps/48/kig.svg"
"""Breeze's kig icon, written by Adobe Illustrator 10: layers ``Layer_2`` (empty) and
``Layer_1`` (every path)."""


def _file(tmp_path: Path, prolog: str, stamp: str = "") -> Path:
    path = tmp_path / "part.svg"
    path.write_text(
        f'{prolog}<svg version="1.1" xmlns="http://www.w3.org/2000/svg" '
        f'xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape" {stamp} '
        f'width="100mm" height="100mm" viewBox="0 0 100 100">{BODY}</svg>',
        encoding="utf-8",
    )
    return path


def _layers(path: Path, *wanted: str) -> list[str]:
    drawing = read_drawing(path, ImportOptions(layers=wanted or None))
    return sorted(c.layer for c in drawing.contours)


@pytest.mark.parametrize("prolog", [ILLUSTRATOR, COREL])
def test_the_roots_groups_are_the_layers_by_their_names(tmp_path: Path, prolog: str) -> None:
    path = _file(tmp_path, prolog)
    assert _layers(path) == ["Cut outside", "Engrave", "Layer 2"]
    assert _layers(path, "Engrave") == ["Engrave"]
    # by the name as typed, by the id as written, by the id's characters written back
    assert _layers(path, "Cut outside") == ["Cut outside"]
    assert _layers(path, "Cut_x0020_outside") == ["Cut outside"]
    assert _layers(path, "Layer 2", "Layer_x0020_2") == ["Layer 2"]


def test_an_unknown_layer_lists_the_foreign_layers(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"no layer named 'Cut'; its layers are .*'Engrave'"):
        _layers(_file(tmp_path, ILLUSTRATOR), "Cut")


def test_groups_are_no_layers_in_other_files(tmp_path: Path) -> None:
    plain = _file(tmp_path, '<?xml version="1.0"?>\n')
    assert set(_layers(plain)) == {"0"}
    with pytest.raises(InputError, match="it has no Inkscape layers"):
        _layers(plain, "Engrave")
    # Illustrator's file saved again by Inkscape: its groups are groups there
    saved = _file(tmp_path, ILLUSTRATOR, 'inkscape:version="1.2.2 (b0a8486541, 2022-12-01)"')
    assert set(_layers(saved)) == {"0"}


def test_a_hidden_foreign_layer_is_skipped_with_a_warning(tmp_path: Path) -> None:
    path = _file(tmp_path, ILLUSTRATOR)
    path.write_text(path.read_text().replace('<g id="Engrave">', '<g id="Engrave" display="none">'))
    drawing = read_drawing(path)
    assert sorted({c.layer for c in drawing.contours}) == ["Cut outside", "Layer 2"]
    assert any("layer 'Engrave' is hidden" in w for w in drawing.warnings)
    assert _layers(path, "Engrave") == ["Engrave"]


@pytest.mark.skipif(not KIG.is_file(), reason="corpus not fetched (make corpus)")
def test_an_illustrator_icon_s_layers() -> None:
    root = ET.parse(KIG).getroot()
    groups = [(e.get("id"), len(list(e.iter()))) for e in root if e.tag.endswith("}g")]
    assert groups[0] == ("Layer_2", 1)  # the file's own text: an empty first layer
    assert groups[1][0] == "Layer_1"
    everything = read_drawing(KIG)
    assert {c.layer for c in everything.contours} == {"Layer_1"}
    chosen = read_drawing(KIG, ImportOptions(layers=("Layer_1",)))
    assert len(chosen.contours) == len(everything.contours)
    with pytest.raises(InputError, match="nothing to cut in the selected layers"):
        read_drawing(KIG, ImportOptions(layers=("Layer_2",)))


def test_an_id_escape_no_xml_name_can_hold_stays_as_written(tmp_path: Path) -> None:
    # a NUL, a lone surrogate and a non-character cannot be in an XML attribute: kept as
    # written (the layer name is an attribute camtool sets), the rest written back
    path = tmp_path / "part.svg"
    groups = "".join(
        f'<g id="{ident}"><rect x="{10 + 20 * i}" y="10" width="5" height="5" fill="none" '
        'stroke="#000"/></g>'
        for i, ident in enumerate(["A_x0000_b", "C_xD800__x0029_", "E_xFFFF_", "F_x00E9_"])
    )
    path.write_text(
        f'{ILLUSTRATOR}<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" '
        f'viewBox="0 0 100 100">{groups}</svg>',
        encoding="utf-8",
    )
    assert _layers(path) == ["A_x0000_b", "C_xD800_)", "E_xFFFF_", "F\u00e9"]
