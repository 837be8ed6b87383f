"""LWPOLYLINEs and SPLINEs written without subclass markers are read by their group codes.

Small DXF writers (the gear template generator behind many woodworkers' gear drawings,
JavaScript and Python DXF writers) write only an ENTITIES section, and their LWPOLYLINEs
as flat lists of group codes with no ``100 AcDbEntity`` / ``100 AcDbPolyline``
markers. LibreCAD reads them; ezdxf refuses them in normal and in recover mode, so
camtool puts the markers in first. The drawings here are ezdxf's own files with
the markers (and the header) taken out, so the expected geometry is ezdxf's evaluation
of the intact file, not camtool's.
"""

from __future__ import annotations

import math
from pathlib import Path

import ezdxf
import pytest
from ezdxf import path as ezpath
from shapely.geometry import LineString, Point

from camtool.importers.dxf import read_dxf
from camtool.importers.dxf_subclass import with_subclass_markers
from camtool.model.errors import InputError
from tests.shapes import write_dxf


def _part(msp: object) -> None:
    msp.add_lwpolyline(  # type: ignore[attr-defined]
        [(0, 0, 0, 0, 0), (40, 0, 0, 0, 0.5), (40, 20, 0, 0, 0), (0, 20, 0, 0, 0)],
        format="xyseb",
        close=True,
        dxfattribs={"layer": "CUT", "color": 1},
    )
    msp.add_spline(  # type: ignore[attr-defined]
        [(5, 5), (15, 15), (25, 5), (35, 15)], dxfattribs={"layer": "CURVE"}
    )


def _flat(intact: Path, *, header: bool) -> Path:
    """``intact``'s ENTITIES section with no ``100`` marker, handle or owner.

    ``header``: keep a HEADER section of ``$ACADVER`` and ``$INSUNITS`` (mm); without
    it the file is an ENTITIES section only, as the gear template generator writes.
    """
    lines = intact.read_text().splitlines()
    pairs = [(lines[i].strip(), lines[i + 1]) for i in range(0, len(lines) - 1, 2)]
    start = pairs.index(("2", "ENTITIES"))
    end = pairs.index(("0", "ENDSEC"), start)
    body = [(c, v) for c, v in pairs[start + 1 : end] if c not in ("100", "5", "330")]
    version = [("9", "$ACADVER"), ("1", "AC1015"), ("9", "$INSUNITS"), ("70", "4")]
    head = [("0", "SECTION"), ("2", "HEADER"), *version, ("0", "ENDSEC")] if header else []
    tags = [("999", "written without subclass markers"), *head, ("0", "SECTION")]
    tags += [("2", "ENTITIES"), *body, ("0", "ENDSEC"), ("0", "EOF")]
    out = intact.with_name(("headed-" if header else "flat-") + intact.name)
    out.write_text("".join(f"{c}\n{v}\n" for c, v in tags))
    return out


def _expected(intact: Path) -> dict[str, LineString]:
    """ezdxf's own evaluation of each entity of the intact file, by layer."""
    doc = ezdxf.readfile(intact)
    return {
        e.dxf.layer: LineString([(v.x, v.y) for v in ezpath.make_path(e).flattening(0.0005)])
        for e in doc.modelspace()
    }


@pytest.mark.parametrize("header", [False, True], ids=["entities-only", "with-header"])
def test_entities_without_markers_read_as_the_intact_file(tmp_path: Path, header: bool) -> None:
    intact = write_dxf(tmp_path / "part.dxf", _part)
    flat = _flat(intact, header=header)
    with pytest.raises(ezdxf.DXFStructureError):
        ezdxf.readfile(flat)  # what camtool met: ezdxf alone refuses the file
    drawing = read_dxf(flat)
    expected = _expected(intact)
    assert sorted(c.layer for c in drawing.contours) == ["CURVE", "CUT"]
    for contour in drawing.contours:
        path = expected[contour.layer]
        points = contour.points(0.0005)
        assert max(path.distance(Point(p)) for p in points) < 0.002, contour.layer
        assert contour.length == pytest.approx(path.length, abs=0.01)
        assert contour.closed == (contour.layer == "CUT")


def test_the_repair_is_said(tmp_path: Path) -> None:
    flat = _flat(write_dxf(tmp_path / "part.dxf", _part), header=False)
    drawing = read_dxf(flat)
    damaged = [w for w in drawing.warnings if "damaged DXF file" in w]
    assert len(damaged) == 1
    assert "missing 'AcDbPolyline' subclass in LWPOLYLINE" in damaged[0]
    assert any("no units" in w for w in drawing.warnings)  # no header: the unit is unsaid


def test_a_decimal_comma_in_such_a_file_is_refused_at_its_own_line(tmp_path: Path) -> None:
    flat = _flat(write_dxf(tmp_path / "part.dxf", _part), header=False)
    lines = flat.read_text().splitlines()
    at = next(i for i in range(0, len(lines), 2) if lines[i] == "20" and lines[i + 1] == "20.0")
    lines[at + 1] = "20,5"
    flat.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError) as info:
        read_dxf(flat)
    assert f"near line {at + 2}: '20,5' of a LWPOLYLINE" in str(info.value)


def test_entities_with_markers_and_other_entities_are_left_as_they_are(tmp_path: Path) -> None:
    intact = write_dxf(tmp_path / "part.dxf", _part)
    data = intact.read_bytes()
    assert with_subclass_markers(data).data == data
    flat = _flat(intact, header=True).read_bytes()
    marked = with_subclass_markers(flat)
    assert dict(marked.counts) == {"LWPOLYLINE": 1, "SPLINE": 1}
    assert len(marked.inserted) == 2 * 2 * 2  # two markers of two lines in each entity
    assert marked.data.count(b"$ACADVER") == 1  # the file's own version is kept


def test_a_file_that_says_r12_but_holds_lwpolylines_is_read_as_r2000(tmp_path: Path) -> None:
    """``$ACADVER AC1009`` (R12, which has no LWPOLYLINE) with a marker-less LWPOLYLINE.

    The bulge 0.5 from (20, 0) to (20, 10) is an arc of 4·atan(0.5) rad on a 6.25 mm
    radius (chord 10 mm), its sagitta 2.5 mm: the closed outline is 20 + 11.591 + 20 +
    10 mm long and reaches x = 22.5 (analysis).
    """
    tags = ["0", "SECTION", "2", "HEADER", "9", "$ACADVER", "1", "AC1009", "9", "$INSUNITS"]
    tags += ["70", "4", "0", "ENDSEC", "0", "SECTION", "2", "ENTITIES", "0", "LWPOLYLINE"]
    tags += ["8", "CUT", "90", "4", "70", "1", "10", "0", "20", "0", "10", "20", "20", "0"]
    tags += ["42", "0.5", "10", "20", "20", "10", "10", "0", "20", "10", "0", "ENDSEC"]
    path = tmp_path / "r12.dxf"
    path.write_text("\n".join([*tags, "0", "EOF"]) + "\n")
    (outline,) = read_dxf(path).contours
    arc = 6.25 * 4 * math.atan(0.5)
    assert outline.closed and outline.layer == "CUT"
    assert outline.length == pytest.approx(50.0 + arc, abs=1e-6)
    assert max(x for x, _ in outline.points(0.0001)) == pytest.approx(22.5, abs=1e-3)
