"""How a DXF entity is drawn: colour and linetype resolved as the DXF reference says.

Expected colours are ezdxf's own ACI table (:func:`ezdxf.colors.aci2rgb`, the AutoCAD
palette): 1 red, 3 green, 5 blue; BYLAYER takes the layer's, BYBLOCK the INSERT's, a true
colour (group 420) wins over the ACI number.
"""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any

import ezdxf
import pytest

from camtool.importers import read_drawing
from camtool.importers.options import ImportOptions
from camtool.jobs.pipeline import post_drawing
from camtool.model.errors import InputError
from camtool.model.program import Linear
from camtool.post.registry import load_target
from camtool.toolpath.options import PlanOptions


def _doc() -> Any:
    doc = ezdxf.new("R2010", setup=True)
    doc.header["$INSUNITS"] = 4
    doc.layers.add("RED", color=1)
    doc.layers.add("AXES", color=3, linetype="CENTER")
    return doc


def test_colours_and_linetypes_resolve_through_layer_and_block(tmp_path: Path) -> None:
    doc = _doc()
    msp = doc.modelspace()
    msp.add_line((0, 0), (1, 0), dxfattribs={"layer": "RED"})  # BYLAYER: red
    msp.add_line((0, 1), (1, 1), dxfattribs={"layer": "RED", "color": 5})  # blue
    line = msp.add_line((0, 2), (1, 2), dxfattribs={"layer": "RED"})
    line.rgb = (10, 20, 30)  # a true colour wins
    msp.add_line((0, 3), (1, 3), dxfattribs={"layer": "AXES"})  # CENTER by layer
    msp.add_line((0, 4), (1, 4), dxfattribs={"layer": "RED", "linetype": "DASHED"})
    block = doc.blocks.new("B")
    block.add_line((0, 0), (1, 0), dxfattribs={"color": 0, "linetype": "BYBLOCK"})
    msp.add_blockref("B", (0, 5), dxfattribs={"layer": "RED", "color": 3, "linetype": "HIDDEN"})
    path = tmp_path / "styles.dxf"
    doc.saveas(path)
    got = {round(c.start[1]): (c.colour, c.linetype) for c in read_drawing(path).contours}
    assert got == {
        0: ("#ff0000", ""),
        1: ("#0000ff", ""),
        2: ("#0a141e", ""),
        3: ("#00ff00", "CENTER"),
        4: ("#ff0000", "DASHED"),
        5: ("#00ff00", "HIDDEN"),
    }


def _linetype_of_a_line(doc: Any, linetype: str, tmp_path: Path) -> str:
    """The linetype camtool reads for one LINE drawn in ``linetype`` in ``doc``."""
    doc.modelspace().add_line((0, 0), (1, 0), dxfattribs={"linetype": linetype})
    path = tmp_path / "line.dxf"
    doc.saveas(path)
    (contour,) = read_drawing(path).contours
    return str(contour.linetype)


def test_a_linetype_whose_pattern_is_solid_is_continuous(tmp_path: Path) -> None:
    doc = _doc()
    doc.linetypes.add("K5LT_SOLID", pattern=[0.0], description="solid")
    assert _linetype_of_a_line(doc, "K5LT_SOLID", tmp_path) == ""


def test_a_complex_linetype_with_gaps_is_not_continuous(tmp_path: Path) -> None:
    """AutoCAD's ``ltypeshp.lin`` linetypes carry text or shapes in their gaps (``GAS_LINE``
    ``----GAS----``: QCAD's ``DrawCSV_Ltype_test.dxf`` uses it); ezdxf's simplified pattern
    of such a linetype is empty, its pattern groups (49) still hold the gaps."""
    doc = _doc()
    doc.linetypes.add(
        "GASLINE",
        pattern='A,.5,-.2,["GAS",STANDARD,S=.1,U=0.0,X=-0.1,Y=-.05],-.25',
        description="Gas line ----GAS----GAS----",
        length=0.95,
    )
    assert not doc.linetypes.get("GASLINE").simplified_line_pattern()
    assert _linetype_of_a_line(doc, "GASLINE", tmp_path) == "GASLINE"


def _without_patterns(text: str) -> str:
    """DXF ``text`` with its LTYPE entries' pattern groups (3, 72, 73, 40, 49, 74) taken out,
    as dxflib writes them (ezdxf writes no such entry)."""
    lines = text.splitlines()
    kept: list[str] = []
    record = ""
    for code, value in zip(lines[::2], lines[1::2], strict=True):
        if code.strip() == "0":
            record = value.strip()
        elif record == "LTYPE" and code.strip() in ("3", "72", "73", "40", "49", "74"):
            continue
        kept += [code, value]
    return "\n".join(kept) + "\n"


def test_a_linetype_entry_without_a_pattern_is_judged_by_its_name(tmp_path: Path) -> None:
    """dxflib (QCAD's DXF library) writes LTYPE entries with a name and no pattern groups
    (QCAD's own ``libraries/default/Mechanics/M4_c.dxf``: ``DASHDOT`` on its axes); CAD
    programs and ezdxf's drawing add-on draw those by their name, so a ``DASHDOT`` is a
    centre line, not continuous, and a name of no dashed family stays continuous."""
    doc = ezdxf.new("R2000")
    doc.header["$INSUNITS"] = 4
    for name in ("DASHDOT", "PLAIN"):
        doc.linetypes.add(name, pattern=[10.0, 6.0, -2.0, 0.0, -2.0])
    msp = doc.modelspace()
    msp.add_line((0, 0), (1, 0), dxfattribs={"linetype": "DASHDOT"})
    msp.add_line((0, 1), (1, 1), dxfattribs={"linetype": "PLAIN"})
    path = tmp_path / "dxflib.dxf"
    text = io.StringIO()
    doc.write(text)
    path.write_text(_without_patterns(text.getvalue()))
    assert len(ezdxf.readfile(path).linetypes.get("DASHDOT").pattern_tags) == 0
    got = {round(c.start[1]): c.linetype for c in read_drawing(path).contours}
    assert got == {0: "DASHDOT", 1: ""}


def _crossed_square(tmp_path: Path) -> Path:
    doc = _doc()
    msp = doc.modelspace()
    msp.add_lwpolyline([(0, 0), (20, 0), (20, 20), (0, 20)], close=True)
    msp.add_line((-5, 10), (25, 10), dxfattribs={"layer": "AXES"})  # a centre line across
    path = tmp_path / "crossed.dxf"
    doc.saveas(path)
    return path


def test_a_centre_line_is_never_cut_by_default(tmp_path: Path) -> None:
    drawing = read_drawing(_crossed_square(tmp_path))
    job = post_drawing(drawing, load_target("grbl"), PlanOptions(depth=1.0))
    cuts = [m for m in job.program.moves if isinstance(m, Linear) and m.z is None]
    assert cuts and all(m.y in (0, 20) or m.x in (0, 20) for m in cuts)
    (note,) = [w for w in job.warnings if "layer 'AXES'" in w]
    assert note.startswith("not cut: 1 contour(s) on layer 'AXES' (linetype CENTER")
    assert note.endswith("(post --layers AXES, or a job operation that selects it)")


def test_a_drawing_all_in_a_dash_dot_linetype_names_the_option_that_cuts_it(
    tmp_path: Path,
) -> None:
    """dxf2gcode's DEMO.DXF draws everything on layer 0 in linetype STRICHPUNKT (dash-dot):
    all construction by the rule, so nothing to cut; the message names the option, which
    then cuts it."""
    doc = _doc()
    doc.linetypes.add("STRICHPUNKT", [10.0, 6.0, -2.0, 0.0, -2.0])
    doc.layers.get("0").dxf.linetype = "STRICHPUNKT"
    doc.modelspace().add_lwpolyline([(0, 0), (20, 0), (20, 20), (0, 20)], close=True)
    path = tmp_path / "Layer 0 only.dxf"
    doc.saveas(path)
    with pytest.raises(InputError) as err:
        post_drawing(read_drawing(path), load_target("grbl"), PlanOptions(depth=1.0))
    assert "nothing to cut: every contour is construction" in str(err.value)
    assert "(post --layers 0, or a job operation that selects it)" in str(err.value)
    job = post_drawing(
        read_drawing(path), load_target("grbl"), PlanOptions(depth=1.0), layers=("0",)
    )
    assert max(m.x for m in job.program.moves) == 20


def test_a_centre_line_named_by_its_layer_is_cut(tmp_path: Path) -> None:
    drawing = read_drawing(_crossed_square(tmp_path))
    job = post_drawing(drawing, load_target("grbl"), PlanOptions(depth=1.0), layers=("axes",))
    assert any(isinstance(m, Linear) and (m.x, m.y) == (25, 10) for m in job.program.moves)


# Names from real drawings: Autodesk Inventor's ISO/ANSI layers (the Voron build plate:
# its sheet's border, title block, section and break lines), the AIA layer standard's
# annotation group, a bare CENTERLINE layer and a sheet's bare border (LibreCAD's library),
# Inventor's flat-pattern layers of bend lines and centre marks (its export's layer map),
# a laser panel generator's ORIGIN crosshair (CUT, SCORE, TEXT, ORIGIN layers on GitHub).
@pytest.mark.parametrize(
    "layer",
    [
        "DIMENSIONS",
        "Construction",
        "Hilfslinien",
        "CENTERLINE",
        "Center Mark (ISO)",
        "Centerline (ISO)",
        "A-ANNO-NOTE",
        "Title - Kova (ANSI)",
        "Guides",
        "Border - Kova (ANSI)",
        "Border (ANSI)",
        "Section Line - Kova (ANSI)",
        "Break Line (ISO)",
        "Hatch (ISO)",
        "border",
        "IV_BEND",
        "IV_ARC_CENTERS",
        "IV_TANGENT",
        "IV_FEATURE_PROFILES_DOWN",
        "Bend Lines",
        "TITLEBLOCK",
        "Sheet Border",
        "ORIGIN",
        "Datum",
    ],
)
def test_a_construction_layer_is_left_out(tmp_path: Path, layer: str) -> None:
    doc = _doc()
    msp = doc.modelspace()
    msp.add_lwpolyline([(0, 0), (20, 0), (20, 20), (0, 20)], close=True)
    msp.add_lwpolyline([(30, 0), (40, 0), (40, 10)], dxfattribs={"layer": layer})
    path = tmp_path / "c.dxf"
    doc.saveas(path)
    job = post_drawing(read_drawing(path), load_target("grbl"), PlanOptions(depth=1.0))
    assert max(m.x for m in job.program.moves) == 20
    assert any(f"on layer {layer!r} (a construction layer" in w for w in job.warnings)


# Parts named with a word that alone would name construction: a cabinet's centre drawer
# (an Inkscape layer of a laser-cut drawer set), OpenSCAD's example009 fan (one layer per
# extruded part), a CNC build's axis plate and guide rail, and text exploded to curves on
# layer TEXT, as camtool's warning about TEXT entities advises.
@pytest.mark.parametrize(
    "layer",
    [
        "Center_Drawer",
        "fan_side_center",
        "X_Axis_Plate",
        "Guide_Rail",
        "TEXT",
        "Border_Panel",
        "Hatch_Cover",
        "Section_A",
        "IV_OUTER_PROFILE",
        "IV_INTERIOR_PROFILES",
        "Bend_Bracket",
        "Bike_Frame",
        "Origin_Plate",
    ],
)
def test_a_part_layer_named_with_a_construction_word_is_cut(tmp_path: Path, layer: str) -> None:
    doc = _doc()
    msp = doc.modelspace()
    msp.add_lwpolyline([(0, 0), (20, 0), (20, 20), (0, 20)], close=True)
    msp.add_lwpolyline(
        [(30, 0), (40, 0), (40, 10), (30, 10)], close=True, dxfattribs={"layer": layer}
    )
    path = tmp_path / "p.dxf"
    doc.saveas(path)
    job = post_drawing(read_drawing(path), load_target("grbl"), PlanOptions(depth=1.0))
    assert max(m.x for m in job.program.moves if m.x is not None) == 40
    assert not any("not cut" in w for w in job.warnings)


def test_inspect_lists_layers_colours_linetypes_and_construction() -> None:
    from camtool.importers.lint import StyleCount, inspect_drawing

    root = Path(__file__).resolve().parents[2]
    report = inspect_drawing(root / "samples" / "part.dxf")
    # samples/make_samples.py: layers HOLES red (ACI 1), CENTER cyan (ACI 4) with the
    # CENTER linetype, four circles, ten centre lines
    assert StyleCount("HOLES", "#ff0000", "", 4, 0, 4) in report.styles
    assert StyleCount("CENTER", "#00ffff", "CENTER", 0, 10, 0) in report.styles
    (construction,) = [f for f in report.findings if f.kind == "construction"]
    assert construction.message.startswith("10 contour(s) on layer 'CENTER' (linetype CENTER)")
    assert report.to_json()["styles"][0] == {  # type: ignore[index]
        "layer": "CENTER",
        "colour": "#00ffff",
        "linetype": "CENTER",
        "closed": 0,
        "open": 10,
        "circles": 0,
        "points": 0,
    }


def _greek_r12(tmp_path: Path) -> Path:
    """An R12 file (code page ANSI_1252) with Greek layer names, which ezdxf writes in the
    ``\\U+xxxx`` notation, as AutoCAD does: a centre line on ΟΣΕΣ (linetype CENTER by
    layer) across a circle on ΚΥΚΛΟΣ."""
    doc = ezdxf.new("R12", setup=True)
    doc.layers.add("ΟΣΕΣ", linetype="CENTER")
    doc.layers.add("ΚΥΚΛΟΣ")
    msp = doc.modelspace()
    msp.add_line((-5, 10), (25, 10), dxfattribs={"layer": "ΟΣΕΣ"})
    msp.add_circle((10, 10), 5, dxfattribs={"layer": "ΚΥΚΛΟΣ"})
    path = tmp_path / "greek.dxf"
    doc.saveas(path)
    assert b"\\U+039" in path.read_bytes()  # the notation, not the letters
    return path


def test_an_r12_layer_name_in_unicode_notation_is_read_as_the_cad_program_shows_it(
    tmp_path: Path,
) -> None:
    from camtool.importers.options import ImportOptions

    path = _greek_r12(tmp_path)
    drawing = read_drawing(path)
    assert sorted((c.layer, c.linetype) for c in drawing.contours) == [
        ("ΚΥΚΛΟΣ", ""),
        ("ΟΣΕΣ", "CENTER"),  # its layer's linetype found under the decoded name
    ]
    (circle,) = read_drawing(path, ImportOptions(layers=("κυκλοσ",))).contours
    assert circle.layer == "ΚΥΚΛΟΣ"
    job = post_drawing(drawing, load_target("grbl"), PlanOptions(depth=1.0))
    cuts = [m for m in job.program.moves if isinstance(m, Linear) and m.z is None]
    assert not cuts  # the circle is cut as arcs; the centre line is not cut at all
    (note,) = [w for w in job.warnings if "ΟΣΕΣ" in w]
    assert note.startswith("not cut: 1 contour(s) on layer 'ΟΣΕΣ' (linetype CENTER")


def _flagged(tmp_path: Path, flag: str, linetype: str = "BYLAYER") -> Path:
    """A 20 mm square on layer ``PART`` and a LINE across it on layer ``AID``, flagged so.

    ``flag``: ``"librecad"`` gives ``AID`` the extended data LibreCAD writes for a
    construction layer (application ``LibreCad``, 1070 = 1, as its DXF filter's
    ``writeLayers`` does); ``"librecad-0"`` the same with 0; ``"no-plot"`` clears the
    layer's plot flag (group 290 = 0); ``""`` leaves it plain.
    """
    doc = _doc()
    doc.appids.add("LibreCad")
    aid = doc.layers.add("AID")
    if flag.startswith("librecad"):
        aid.set_xdata("LibreCad", [(1070, 0 if flag.endswith("-0") else 1)])
    elif flag == "no-plot":
        aid.dxf.plot = 0
    msp = doc.modelspace()
    msp.add_lwpolyline(
        [(0, 0), (20, 0), (20, 20), (0, 20)], close=True, dxfattribs={"layer": "PART"}
    )
    msp.add_line((-5, 10), (25, 10), dxfattribs={"layer": "AID", "linetype": linetype})
    path = tmp_path / f"flag-{flag or 'plain'}.dxf"
    doc.saveas(path)
    return path


@pytest.mark.parametrize(
    ("flag", "phrase"),
    [("librecad", "a LibreCAD construction layer"), ("no-plot", "a layer that does not plot")],
)
@pytest.mark.parametrize("linetype", ["BYLAYER", "CONTINUOUS", "DASHED"])
def test_a_layer_the_drawing_flags_as_not_the_part_is_left_out(
    tmp_path: Path, flag: str, phrase: str, linetype: str
) -> None:
    """The line across the square would cut it in two: the flag is the layer's, so it
    holds whatever line the entity is drawn in; naming the layer cuts it."""
    path = _flagged(tmp_path, flag, linetype)
    text = path.read_text()
    if flag == "librecad":  # the group codes as LibreCAD writes them, after the layer's own
        assert "1001\nLibreCad\n1070\n1\n" in text
    job = post_drawing(read_drawing(path), load_target("grbl"), PlanOptions(depth=1.0))
    fed = [(m.x, m.y) for m in job.program.moves if isinstance(m, Linear)]
    assert min(x for x, _ in fed) == 0 and max(x for x, _ in fed) == 20
    assert not any(y == 10 for _, y in fed)
    assert any(f"on layer 'AID' ({phrase}: construction, not the part" in w for w in job.warnings)
    named = post_drawing(
        read_drawing(path, ImportOptions(layers=("PART", "AID"))),
        load_target("grbl"),
        PlanOptions(depth=1.0),
        layers=("PART", "AID"),
    )
    assert {(m.x, m.y) for m in named.program.moves if isinstance(m, Linear)} >= {
        (-5, 10),
        (25, 10),
    }


@pytest.mark.parametrize("flag", ["", "librecad-0"])
def test_a_plain_layer_is_cut(tmp_path: Path, flag: str) -> None:
    """A plotted layer, or LibreCAD's data with 0 (its filter sets construction only on 1)."""
    job = post_drawing(
        read_drawing(_flagged(tmp_path, flag)), load_target("grbl"), PlanOptions(depth=1.0)
    )
    fed = {(m.x, m.y) for m in job.program.moves if isinstance(m, Linear)}
    assert {(-5, 10), (25, 10)} <= fed
