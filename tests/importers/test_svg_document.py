"""SVG importer documents: page units, Inkscape layers, visibility, use, skipped kinds, errors.

Files written by Inkscape 1.2.2 are in tests/data (tests/data/README-svg.md says how).
"""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

from camtool.importers import read_drawing, read_drawing_bytes
from camtool.importers.options import ImportOptions
from camtool.importers.svg import read_svg
from camtool.model.construction import is_construction
from camtool.model.errors import InputError, UsageError
from camtool.model.shapes import Arc
from tests.importers.svgutil import (
    DATA,
    HALF,
    assert_arc,
    one,
    svg,
    true_curve,
    two_sided_error,
    vertices,
)

# ------------------------------------------------------------------ units and page


@pytest.mark.parametrize(
    ("root", "mm_per_unit"),
    [
        ('width="10mm" height="10mm" viewBox="0 0 100 100"', 0.1),
        ('width="2in" height="2in" viewBox="0 0 2 2"', 25.4),
        ('width="1cm" height="1cm" viewBox="0 0 1 1"', 10.0),
        ('width="72pt" height="72pt" viewBox="0 0 72 72"', 25.4 / 72),
        ('width="6pc" height="6pc" viewBox="0 0 1 1"', 25.4),
        ('width="96px" height="96px" viewBox="0 0 96 96"', 25.4 / 96),
        ('width="96" height="96"', 25.4 / 96),
        ('width="50mm" height="20mm"', 25.4 / 96),  # no viewBox: user units are px
    ],
)
def test_units(tmp_path: Path, root: str, mm_per_unit: float) -> None:
    drawing = read_svg(
        svg(tmp_path, '<path d="M 0 0 L 1 0 L 1 1" fill="none" stroke="red"/>', root)
    )
    a, b, c = vertices(one(drawing))
    assert b[0] - a[0] == pytest.approx(mm_per_unit, rel=1e-12)
    assert c[1] - b[1] == pytest.approx(-mm_per_unit, rel=1e-12)  # Y flipped
    assert drawing.warnings == ()


def test_width_10mm_viewbox_100_is_scale_0_1_with_page_flip(tmp_path: Path) -> None:
    root = 'width="10mm" height="20mm" viewBox="0 0 100 200"'
    contour = one(read_svg(svg(tmp_path, '<path d="M 0 0 L 100 0 L 100 200"/>', root)))
    assert np.allclose(vertices(contour), [(0, 20), (10, 20), (10, 0)], rtol=0, atol=1e-12)


def test_viewbox_offset_and_preserve_aspect_ratio(tmp_path: Path) -> None:
    # page 200 x 100 mm, viewBox 50 x 50 from (10, 10): meet -> 2 mm/unit, centred in x
    root = 'width="200mm" height="100mm" viewBox="10 10 50 50"'
    contour = one(read_svg(svg(tmp_path, '<path d="M 10 10 L 60 60"/>', root)))
    assert np.allclose(vertices(contour), [(50, 100), (150, 0)], rtol=0, atol=1e-12)
    root_none = root + ' preserveAspectRatio="none"'
    contour = one(read_svg(svg(tmp_path, '<path d="M 10 10 L 60 60"/>', root_none)))
    assert np.allclose(vertices(contour), [(0, 100), (200, 0)], rtol=0, atol=1e-12)
    root_slice = root + ' preserveAspectRatio="xMinYMin slice"'
    contour = one(read_svg(svg(tmp_path, '<path d="M 10 10 L 60 60"/>', root_slice)))
    assert np.allclose(vertices(contour), [(0, 100), (200, -100)], rtol=0, atol=1e-12)


def test_one_size_missing_is_taken_from_the_viewbox(tmp_path: Path) -> None:
    root = 'width="50mm" viewBox="0 0 100 200"'
    contour = one(read_svg(svg(tmp_path, '<path d="M 0 0 L 100 200"/>', root)))
    assert np.allclose(vertices(contour), [(0, 100), (50, 0)], rtol=0, atol=1e-12)


@pytest.mark.parametrize(
    ("root", "warning"),
    [
        ('viewBox="0 0 96 96"', "no width/height; user units taken as px (1/96 in)"),
        ("", "no width/height; user units taken as px (1/96 in)"),
        (
            'width="100%" height="100%" viewBox="0 0 96 96"',
            "relative size width='100%' x height='100%'",
        ),
        # react-icons: the icon is as large as the text around it (CSS Values 4 §6.1)
        (
            'width="1em" height="1em" viewBox="0 0 96 96"',
            "relative size width='1em' x height='1em'",
        ),
        (
            'width="2ex" height="5vh" viewBox="0 0 96 96"',
            "relative size width='2ex' x height='5vh'",
        ),
    ],
)
def test_no_absolute_size_means_px_with_a_warning(tmp_path: Path, root: str, warning: str) -> None:
    drawing = read_svg(svg(tmp_path, '<path d="M 0 0 L 96 0"/>', root))
    a, b = vertices(one(drawing))
    assert b[0] - a[0] == pytest.approx(25.4, rel=1e-12)
    assert len(drawing.warnings) == 1
    assert warning in drawing.warnings[0]


# ------------------------------------------------------------------ layers, visibility


def test_inkscape_layers_name_the_contours(tmp_path: Path) -> None:
    drawing = read_svg(DATA / "inkscape-layers.svg")
    assert [(c.source, c.layer) for c in drawing.contours] == [
        ("rect#plate", "Cut"),
        ("circle#hole", "Cut"),
        ("ellipse#oval", "Engrave"),
        ("path#wave", "Engrave"),
    ]


def test_select_one_layer(tmp_path: Path) -> None:
    drawing = read_svg(DATA / "inkscape-layers.svg", ImportOptions(layers=("Engrave",)))
    assert [c.layer for c in drawing.contours] == ["Engrave", "Engrave"]
    by_id = read_svg(DATA / "inkscape-layers.svg", ImportOptions(layers=("layer1",)))
    assert [c.source for c in by_id.contours] == ["rect#plate", "circle#hole"]


def test_unknown_layer_lists_the_layers() -> None:
    with pytest.raises(InputError) as err:
        read_svg(DATA / "inkscape-layers.svg", ImportOptions(layers=("Cut", "Nope")))
    assert str(err.value) == (
        f"{DATA / 'inkscape-layers.svg'}: no layer named 'Nope'; "
        "its layers are 'Cut', 'Engrave', 'Guides'"
    )


def test_layers_asked_of_a_file_without_layers(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="no layer named 'Cut'; it has no Inkscape layers"):
        read_svg(svg(tmp_path, HALF), ImportOptions(layers=("Cut",)))


def test_hidden_layer_is_skipped_with_a_warning_and_read_when_named() -> None:
    path = DATA / "inkscape-layers.svg"
    drawing = read_svg(path)
    assert "Guides" not in {c.layer for c in drawing.contours}
    assert f"{path}: layer 'Guides' is hidden and was skipped; name it with --layers to cut it" in (
        drawing.warnings
    )
    guides = read_svg(path, ImportOptions(layers=("Guides",)))
    assert [(c.source, c.layer) for c in guides.contours] == [("path#guide", "Guides")]
    assert vertices(guides.contours[0]) == [(0, 20), (60, 20)]


def test_a_hidden_layer_a_job_names_is_read_with_the_others() -> None:
    """Inkscape 1.2.2's file: a job's operation naming 'guides' (any case) shows the layer."""
    path = DATA / "inkscape-layers.svg"
    everything = {c.layer for c in read_svg(path).contours}
    drawing = read_svg(path, ImportOptions(shown=("guides",)))
    assert {c.layer for c in drawing.contours} == everything | {"Guides"}
    assert not any("hidden" in w for w in drawing.warnings)


def test_sublayer_selection_and_innermost_layer_name(tmp_path: Path) -> None:
    body = (
        '<g inkscape:groupmode="layer" inkscape:label="Top" style="display:none">'
        '<path id="a" d="M 0 0 L 1 0"/>'
        '<g inkscape:groupmode="layer" inkscape:label="Sub"><path id="b" d="M 0 0 L 2 0"/></g>'
        "</g>"
        '<path id="c" d="M 0 0 L 3 0"/>'
    )
    path = svg(tmp_path, body)
    sub = read_svg(path, ImportOptions(layers=("Sub",)))
    assert [(c.source, c.layer) for c in sub.contours] == [("path#b", "Sub")]
    top = read_svg(path, ImportOptions(layers=("Top",)))
    assert [(c.source, c.layer) for c in top.contours] == [("path#a", "Top"), ("path#b", "Sub")]
    everything = read_svg(path)
    assert [(c.source, c.layer) for c in everything.contours] == [("path#c", "0")]


def test_every_layer_of_a_repeated_label_is_selected(tmp_path: Path) -> None:
    """Inkscape keeps ids unique but not labels: a sublayer "Cut" in each part's layer.
    ``--layers Cut`` selects both, not only the last one."""
    body = (
        '<g inkscape:groupmode="layer" id="l1" inkscape:label="Part A">'
        '<g inkscape:groupmode="layer" id="l2" inkscape:label="Cut"><path id="a" d="M 0 0 L 1 0"/>'
        '</g><g inkscape:groupmode="layer" id="l3" inkscape:label="Engrave">'
        '<path id="b" d="M 0 0 L 2 0"/></g></g>'
        '<g inkscape:groupmode="layer" id="l4" inkscape:label="Part B">'
        '<g inkscape:groupmode="layer" id="l5" inkscape:label="Cut"><path id="c" d="M 0 0 L 3 0"/>'
        "</g></g>"
    )
    path = svg(tmp_path, body)
    cut = read_svg(path, ImportOptions(layers=("Cut",)))
    assert [(c.source, c.layer) for c in cut.contours] == [("path#a", "Cut"), ("path#c", "Cut")]
    by_id = read_svg(path, ImportOptions(layers=("l5", "Engrave")))
    assert [c.source for c in by_id.contours] == ["path#b", "path#c"]


def test_librecad_layers_name_the_contours_and_its_construction_layers_are_not_cut(
    tmp_path: Path,
) -> None:
    """LibreCAD's "Export as MakerCAM SVG" (lc_makercamsvg.cpp, LibreCAD 2.2) writes each
    layer as ``<g lc:layername=… lc:is_construction=…>`` in its own namespace, and a frozen
    one (when asked to) with ``style="display: none;"``."""
    layer = '<g lc:layername="{}" lc:is_locked="false" lc:is_construction="{}" {}fill="none" '
    layer += 'stroke="black" stroke-width="1">{}</g>'
    body = (
        layer.format("0", "false", "", '<path id="plate" d="M10,40 L90,40 L90,10 L10,10 Z"/>')
        + layer.format("holes", "false", "", '<circle id="hole" cx="20" cy="25" r="3"/>')
        + layer.format("helper", "true", "", '<line id="axis" x1="0" y1="25" x2="100" y2="25"/>')
        + layer.format("off", "false", 'style="display: none;" ', '<circle cx="5" cy="5" r="1"/>')
    )
    root = 'xmlns:lc="https://librecad.org" width="100mm" height="50mm" viewBox="0 0 100 50"'
    path = svg(tmp_path, body, root=root)
    drawing = read_svg(path)
    assert [(c.source, c.layer, c.linetype) for c in drawing.contours] == [
        ("path#plate", "0", ""),
        ("circle#hole", "holes", ""),
        ("line#axis", "helper", "CONSTRUCTION"),
    ]
    assert is_construction(drawing.contours[2])
    assert f"{path}: layer 'off' is hidden and was skipped; name it with --layers to cut it" in (
        drawing.warnings
    )
    holes = read_svg(path, ImportOptions(layers=("holes",)))
    assert [c.source for c in holes.contours] == ["circle#hole"]


def test_display_none_and_visibility_hidden_are_skipped(tmp_path: Path) -> None:
    body = (
        "<style>.off { display: none }</style>"
        '<path id="inline" d="M 0 0 L 1 0" style="display:none"/>'
        '<path id="attr" d="M 0 0 L 1 0" display="none"/>'
        '<path id="css" d="M 0 0 L 1 0" class="off"/>'
        '<g style="display:none"><path id="child" d="M 0 0 L 1 0" style="display:inline"/></g>'
        '<path id="ghost" d="M 0 0 L 1 0" visibility="hidden"/>'
        '<g style="visibility:hidden">'
        '<path id="shown" d="M 0 0 L 1 0" style="visibility:visible"/></g>'
        '<path id="kept" d="M 0 0 L 1 0"/>'
    )
    drawing = read_svg(svg(tmp_path, body))
    assert [c.source for c in drawing.contours] == ["path#shown", "path#kept"]
    assert drawing.warnings == (f"{tmp_path / 't.svg'}: skipped 1 element with visibility:hidden",)


@pytest.mark.parametrize("where", ["end", "marker", "group"])
def test_a_style_sheet_hides_what_it_selects_wherever_it_stands(tmp_path: Path, where: str) -> None:
    """CSS applies a sheet to the whole document; svgelements only to what follows it."""
    sheet = "<style>.off { display: none } #gone { visibility: hidden }</style>"
    shapes = '<path id="a" d="M 0 0 L 1 0" class="off"/><path id="gone" d="M 0 0 L 1 0"/>'
    shapes += '<path id="kept" d="M 0 0 L 1 0"/>'
    body = {
        "end": shapes + sheet,
        "marker": shapes + f'<defs><marker id="m">{sheet}</marker></defs>',
        "group": f"<g>{shapes}<g>{sheet}</g></g>",
    }[where]
    drawing = read_svg(svg(tmp_path, body))
    assert [c.source for c in drawing.contours] == ["path#kept"]


def test_important_and_upper_case_hide_as_css_says(tmp_path: Path) -> None:
    """CSS property names and keywords ignore case and the white space around them;
    ``!important`` only ranks a declaration."""
    body = (
        "<style>.off { DISPLAY: None ! IMPORTANT }</style>"
        '<path id="a" d="M 0 0 L 1 0" style="display:none !important"/>'
        '<path id="b" d="M 0 0 L 1 0" style="Visibility: HIDDEN"/>'
        '<path id="c" d="M 0 0 L 1 0" class="off"/>'
        '<path id="d" d="M 0 0 L 1 0" display="None"/>'
        '<path id="d2" d="M 0 0 L 1 0" display="none "/>'  # white space is not the value
        '<path id="v2" d="M 0 0 L 1 0" visibility="\thidden"/>'
        '<path id="e" d="M 0 0 L 1 0" style="fill:NONE;stroke:none !important"/>'
        '<path id="kept" d="M 0 0 L 1 0" style="fill:url(#Grad);stroke:currentColor"/>'
    )
    drawing = read_svg(svg(tmp_path, body))
    assert [c.source for c in drawing.contours] == ["path#kept"]


def test_inherit_takes_the_parents_value_as_css_says(tmp_path: Path) -> None:
    """``inherit``, ``unset`` and ``revert`` give an inherited property the parent's value,
    ``initial`` its initial one (CSS Cascade 4 §7.3), never a colour of their own; a style
    declaration outranks the attribute, as a style sheet's rule does."""
    body = (
        "<style>.k { stroke: INHERIT }</style>"
        '<g fill="none" stroke="none"><path id="f" d="M 0 0 L 9 0 L 9 9 Z" fill="inherit"/>'
        '<path id="s" d="M 0 0 L 9 0" stroke="inherit"/>'
        '<path id="k" class="k" d="M 0 0 L 9 0" stroke="red"/>'  # the rule's none wins
        '<path id="u" d="M 0 1 L 9 1" style="stroke: unset"/>'
        '<path id="r" d="M 0 2 L 9 2" style="stroke: revert"/>'
        '<path id="i" d="M 0 3 L 9 3" style="stroke: initial" stroke="red"/>'  # none
        '<path id="black" d="M 0 4 L 9 4 L 9 9 Z" style="fill: initial"/></g>'
        '<g visibility="hidden" stroke="black"><path id="v" d="M 0 5 L 9 5" '
        'visibility="inherit"/><path id="vu" d="M 0 6 L 9 6" style="visibility: unset"/>'
        '<path id="shown" d="M 0 7 L 9 7" style="visibility: initial"/></g>'
        '<g fill="none" stroke="#0000ff" stroke-dasharray="4 2">'
        '<path id="dash" d="M 0 9 L 9 9" stroke-dasharray="inherit"/>'
        '<path id="blue" d="M 0 8 L 9 8" style="stroke: inherit" stroke="green"/></g>'
    )
    drawing = read_svg(svg(tmp_path, body))
    got = [(c.source, c.colour, c.linetype) for c in drawing.contours]
    assert got == [
        ("path#black", "#000000", ""),
        ("path#shown", "#000000", ""),
        ("path#dash", "#0000ff", "DASHED"),
        ("path#blue", "#0000ff", "DASHED"),
    ]


@pytest.mark.parametrize(
    ("dasharray", "linetype"),
    [
        ("4 2", "DASHED"),
        ("0 4", "DASHED"),  # dots: zero-length dashes, 4 apart
        ("5 10 15", "DASHED"),  # odd: repeated, 5 10 15 5 10 15
        ("40 0", ""),  # no gap: a line
        ("4 0 6", "DASHED"),  # repeated, 4 0 6 4 0 6: gaps 0, 4 and 6
        ("4 0 6 0", ""),  # dashes of 4 and 6, no gap
        ("0 0", ""),  # a sum of zero draws as none (SVG 2 §13.5.5)
        ("20 40 -20", ""),  # a negative length: invalid, ignored
        ("none", ""),
    ],
)
def test_a_stroke_is_dashed_only_where_its_dash_array_has_gaps(
    tmp_path: Path, dasharray: str, linetype: str
) -> None:
    """resvg's ``painting/stroke-dasharray`` tests (``negative-values``, ``zero-sum``,
    ``n-0``) render these as a solid line; a solid line is the part, cut by default."""
    body = f'<path id="p" d="M 0 0 L 9 0" stroke="red" stroke-dasharray="{dasharray}"/>'
    (contour,) = read_svg(svg(tmp_path, body)).contours
    assert contour.linetype == linetype


SHAPER = (
    '<svg xmlns="http://www.w3.org/2000/svg" '
    'xmlns:shaper="http://www.shapertools.com/namespaces/shaper" viewBox="0 0 200 100" '
    'width="200mm" height="100mm">'
    # a sheet-layout tool's sheet border and a group of guides: not the part
    '<rect id="sheet" x="0" y="0" width="200" height="100" fill="none" stroke="blue" '
    'shaper:cutType="guide"/>'
    '<g shaper:cutType="GUIDE"><path id="centre" d="M 100 0 L 100 100" stroke="#0068FF"/></g>'
    '<rect id="part" x="20" y="20" width="60" height="40" fill="black" stroke="black" '
    'shaper:cutType="outside"/></svg>'
)


def test_a_shaper_origin_guide_is_construction_and_not_cut(tmp_path: Path) -> None:
    """Shaper Origin's ``shaper:cutType="guide"`` (Shaper Tools' export, sheet-layout tools
    writing their sheet's border so) marks a line that is not cut: read as the linetype
    GUIDE, construction, which a job cuts only when an operation names it. Posted, the
    part alone is cut: a 60 x 40 mm rectangle at (20, 40)-(80, 80) mm, Y up."""
    path = tmp_path / "sheet.svg"
    path.write_text(SHAPER, encoding="utf-8")
    drawing = read_svg(path)
    got = [(c.source, c.linetype) for c in drawing.contours]
    assert got == [("rect#sheet", "GUIDE"), ("path#centre", "GUIDE"), ("rect#part", "")]
    from camtool.cli.main import main

    out = tmp_path / "sheet.ngc"
    assert main(["post", str(path), "-t", "linuxcnc", "-o", str(out)]) == 0
    xy = [
        (float(x), float(y)) for x, y in re.findall(r"G1 X(-?[\d.]+) Y(-?[\d.]+)", out.read_text())
    ]
    assert xy and {x for x, _ in xy} <= {20.0, 80.0} and {y for _, y in xy} <= {40.0, 80.0}


@pytest.mark.parametrize(
    ("attribute", "layer", "linetype"),
    [
        ('shaper:cutType="outside"', "shaper outside", ""),
        ('shaper:pathType="exterior"', "shaper outside", ""),  # Shaper's Fusion 360 add-in
        ('shaper:pathType="interior"', "shaper inside", ""),
        ('shaper:cutType="onLine"', "shaper online", ""),
        ('shaper:cutType="Pocket"', "shaper pocket", ""),
        ('shaper:pathType="guide"', "0", "GUIDE"),
        ('shaper:cutType="sideways"', "0", ""),  # no cut type camtool knows: as without
        # the depth, in mm, when cutDepth gives it with a unit (0.25 in = 6.35 mm)
        ('shaper:cutType="pocket" shaper:cutDepth="6.0mm"', "shaper pocket 6mm", ""),
        ('shaper:cutType="inside" shaper:cutDepth="0.25in"', "shaper inside 6.35mm", ""),
        ('shaper:pathType="exterior" shaper:cutDepth="1.2 cm"', "shaper outside 12mm", ""),
        ('shaper:cutType="pocket" shaper:cutDepth="15"', "shaper pocket", ""),  # no unit
        ('shaper:cutType="online" shaper:cutDepth="0"', "shaper online", ""),
    ],
)
def test_shaper_s_cut_types_name_the_layer(
    tmp_path: Path, attribute: str, layer: str, linetype: str
) -> None:
    """A Shaper cut type names the layer of a shape in no Inkscape layer (a job selects by
    it); an Inkscape layer keeps its name."""
    ns = 'xmlns:shaper="http://www.shapertools.com/namespaces/shaper"'
    body = f'<rect x="10" y="10" width="20" height="10" stroke="black" {attribute}/>'
    root = f'{ns} width="100mm" height="100mm" viewBox="0 0 100 100"'
    (contour,) = read_svg(svg(tmp_path, body, root=root)).contours
    assert (contour.layer, contour.linetype) == (layer, linetype)
    in_layer = f'<g inkscape:groupmode="layer" inkscape:label="Cuts">{body}</g>'
    assert read_svg(svg(tmp_path, in_layer, root=root)).contours[0].layer == "Cuts"


def test_layers_picks_the_layers_camtool_names_shapes_outside_inkscape_layers(
    tmp_path: Path,
) -> None:
    """``--layers`` takes the layers ``camtool inspect`` lists for shapes in no Inkscape
    layer (``0``, a Shaper cut type's), as a job's operations do: the pocket alone, or the
    guides the construction warning says ``--layers 0`` cuts; an unknown one is refused
    naming those there are, and a mix with Inkscape layers is refused."""
    path = tmp_path / "sheet.svg"
    path.write_text(SHAPER, encoding="utf-8")
    picked = read_svg(path, ImportOptions(layers=("shaper outside",))).contours
    assert [c.source for c in picked] == ["rect#part"]
    guides = read_svg(path, ImportOptions(layers=("0",))).contours
    assert [c.source for c in guides] == ["rect#sheet", "path#centre"]
    with pytest.raises(InputError, match="no layer named 'shaper pocket'; its layers are '0'"):
        read_svg(path, ImportOptions(layers=("shaper pocket",)))
    with pytest.raises(InputError, match=r"--layers names Inkscape layers \('Cuts'\) and the"):
        read_svg(path, ImportOptions(layers=("Cuts", "0")))


def test_a_paint_that_is_no_colour_is_ignored_as_css_says(tmp_path: Path) -> None:
    """An invalid ``fill``/``stroke`` declaration is ignored (CSS Syntax 3), so the parent's
    paint applies; keywords are read in any case and with white space around them."""
    body = (
        '<g fill="none" stroke="none" color="#ff0000">'
        '<path id="name" d="M 0 0 L 9 0" stroke="notacolour"/>'
        '<path id="hex" d="M 0 1 L 9 1" stroke="#12"/>'
        '<path id="words" d="M 0 2 L 9 2" stroke="dark blue"/>'
        '<path id="style" d="M 0 3 L 9 3" style="stroke: bogus" stroke="blue"/>'  # attribute
        '<path id="spaced" d="M 0 4 L 9 4" stroke="  none  "/>'
        '<path id="current" d="M 0 5 L 9 5" stroke="CURRENTCOLOR"/>'
        '<path id="icc" d="M 0 6 L 9 6" stroke="#00ff00 icc-color(acmecmyk, 0.1, 0.2)"/>'
        '<path id="css4" d="M 0 7 L 9 7" style="stroke:rebeccapurple"/></g>'
    )
    drawing = read_svg(svg(tmp_path, body))
    got = [(c.source, c.colour) for c in drawing.contours]
    assert got == [
        ("path#style", "#0000ff"),
        ("path#current", "#ff0000"),
        ("path#icc", "#00ff00"),
        ("path#css4", "#663399"),
    ]


@pytest.mark.parametrize(
    ("rule", "named"),
    [
        ("/* a comment { } */ g + path { display : none !important }", r"g \+ path"),
        # a structural pseudo-class selects in a still picture as anywhere
        ("g > path:first-child { visibility: hidden }", "g > path:first-child"),
        ("path:not(:hover) { display: none }", r"path:not\(:hover\)"),
        ("path[id=a] { opacity: 0% }", r"path\[id=a\]"),
    ],
)
def test_a_rule_that_hides_through_a_selector_camtool_cannot_apply_is_refused(
    tmp_path: Path, rule: str, named: str
) -> None:
    body = (
        f"<style>{rule}</style>"
        '<g><path id="a" d="M 0 0 L 1 0"/><path id="kept" d="M 0 0 L 1 0"/></g>'
    )
    with pytest.raises(InputError, match=rf"t\.svg: the <style> rule '{named}' hides"):
        read_svg(svg(tmp_path, body))


def test_rules_that_hide_nothing_still_are_named(tmp_path: Path) -> None:
    """A pseudo-class of the user's actions, a pseudo-element or a print style hides nothing
    in a still picture: read, with a warning."""
    body = (
        "<style>@font-face { font-family: Sans; src: url(s.woff) }"
        " a:hover path { display: none } @media print { .x { display: none } }"
        " path::selection { opacity: 0 }"
        " path[id=y] { stroke: red }</style>"
        '<path id="x" class="x" d="M 0 0 L 1 0"/><g><path id="y" d="M 0 0 L 1 0"/></g>'
    )
    drawing = read_svg(svg(tmp_path, body))
    assert [c.source for c in drawing.contours] == ["path#x", "path#y"]
    assert drawing.warnings == (
        f"{tmp_path / 't.svg'}: 4 <style> rule(s) not applied ('a:hover path', '@media print', "
        "'path::selection' ...): camtool applies types, .class, #id, :root and their descendants; "
        "what they style is read without them",
    )


def test_style_sheets_cascade_as_css_says(tmp_path: Path) -> None:
    """Which declaration wins, by CSS Cascading 4 section 6 and Selectors 3 section 9.

    Each expectation is what a browser shows: an ``!important`` rule above an inline style,
    an inline style above a rule, ``#id`` above ``.class`` whatever their order, a rule above
    a presentation attribute, the later of two equal rules, descendant and child selectors.
    """
    body = (
        "<style>.off { display: none !important } .a { display: none } #b { display: inline }"
        " rect.c { display: none } .d { display: inline } .d { display: none }"
        " g.hidden path { display: none } g > path.e { visibility: hidden }"
        " #f { display: none !important }</style>"
        '<path id="important" class="off" d="M 0 0 L 1 0" style="display:inline"/>'
        '<path id="inline" class="a" d="M 0 0 L 1 0" style="display:inline"/>'
        '<path id="b" class="a" d="M 0 0 L 1 0"/>'
        '<rect id="attr" class="c" display="inline" width="1" height="1"/>'
        '<path id="later" class="d" d="M 0 0 L 1 0"/>'
        '<g class="hidden"><g><path id="descendant" d="M 0 0 L 1 0"/></g></g>'
        '<g><path id="child" class="e" d="M 0 0 L 1 0"/></g>'
        '<g><a><path id="grandchild" class="e" d="M 0 0 L 1 0"/></a></g>'
        '<path id="f" d="M 0 0 L 1 0" style="display:inline !important"/>'
    )
    drawing = read_svg(svg(tmp_path, body))
    assert [c.source for c in drawing.contours] == [
        "path#inline",
        "path#b",
        "path#grandchild",
        "path#f",
    ]


def _colours(tmp_path: Path, body: str) -> list[tuple[str, str]]:
    """``(source, colour)`` of each contour read from an SVG of ``body``."""
    return [(c.source, c.colour) for c in read_svg(svg(tmp_path, body)).contours]


def test_a_comment_in_a_style_attribute_is_white_space(tmp_path: Path) -> None:
    """CSS comments may stand anywhere white space may (CSS Syntax 3 §4.3.2): resvg's
    ``structure/style-attribute/comments`` fills its square green; a ``display:none``
    followed by a comment still hides its shape, which is then not cut."""
    body = (
        '<rect id="hidden" width="9" height="9" style="display:none/* off */"/>'
        '<rect id="hidden2" width="9" height="9" style="/* a */ display : none"/>'
        '<rect id="green" width="9" height="9" style="/*text*/fill:green/*text*/"/>'
    )
    assert _colours(tmp_path, body) == [("rect#green", "#008000")]


def test_a_style_sheet_in_another_language_is_not_applied(tmp_path: Path) -> None:
    """A ``<style>`` whose ``type`` is not ``text/css`` is ignored (SVG 1.1 §6.16; resvg's
    ``structure/style/invalid-type``): the shape keeps its own fill."""
    body = (
        '<style type="no-a-css">.fil { fill: red; display: none }</style>'
        '<style type=" TEXT/CSS ">.blue { fill: blue }</style>'
        '<rect id="r" class="fil" width="9" height="9" fill="green"/>'
        '<rect id="b" class="blue" width="9" height="9"/>'
    )
    assert _colours(tmp_path, body) == [("rect#r", "#008000"), ("rect#b", "#0000ff")]


def test_a_group_a_rule_makes_transparent_hides_its_children(tmp_path: Path) -> None:
    """Group opacity multiplies: a child's own ``opacity:1`` under a group at 0 shows nothing."""
    body = (
        "<style>.gone { opacity: 0 } .seen { stroke: #FF0000 }</style>"
        '<g class="gone"><path id="a" d="M 0 0 L 1 0" style="opacity:1"/></g>'
        '<g class="seen"><path id="kept" d="M 0 0 L 1 0"/></g>'
    )
    assert _colours(tmp_path, body) == [("path#kept", "#ff0000")]


ILLUSTRATOR = """<?xml version="1.0" encoding="utf-8"?>
<!DOCTYPE svg PUBLIC "-//W3C//DTD SVG 1.1//EN" "http://www.w3.org/Graphics/SVG/1.1/DTD/svg11.dtd" [
    <!ENTITY ns_extend "http://ns.adobe.com/Extensibility/1.0/">
    <!ENTITY ns_ai "http://ns.adobe.com/AdobeIllustrator/10.0/">
]>
<svg version="1.1" xmlns:x="&ns_extend;" xmlns:i="&ns_ai;" xmlns="http://www.w3.org/2000/svg"
     xmlns:xlink="http://www.w3.org/1999/xlink" x="0px" y="0px" width="120px" height="90px"
     viewBox="0 0 120 90" xml:space="preserve">
<style type="text/css">
    .st2{fill:none;stroke:#0A1F44;stroke-width:3;stroke-miterlimit:10;}
</style>
<switch>
    <foreignObject requiredExtensions="&ns_ai;" x="0" y="0" width="1" height="1">
        <i:pgfRef  xlink:href="#adobe_illustrator_pgf">
        </i:pgfRef>
    </foreignObject>
    <g i:extraneous="self">
        <rect id="art" x="10" y="10" class="st2" width="50" height="30"/>
    </g>
    <g><rect id="fallback" x="70" y="10" width="10" height="10"/></g>
</switch>
</svg>
"""
"""An Adobe Illustrator export (its DOCTYPE, entities, ``<switch>`` and ``<foreignObject>``
as Illustrator 2020 writes them), with a fallback group added after the artwork."""


def test_a_switch_shows_its_first_child_that_applies(tmp_path: Path) -> None:
    path = tmp_path / "ai.svg"
    path.write_text(ILLUSTRATOR)
    drawing = read_svg(path)
    assert [c.source for c in drawing.contours] == ["rect#art"]
    assert drawing.warnings[-1] == (
        f"{path}: skipped 1 child(ren) of <switch> elements with shapes (a <switch> shows "
        "only its first child that applies)"
    )


def test_a_use_of_another_files_element_is_named(tmp_path: Path) -> None:
    body = (
        '<use xlink:href="parts.svg#gear" x="5"/><use href=""/>'
        '<defs><use id="d" href="x.svg#y"/></defs><path id="kept" d="M 0 0 L 1 0"/>'
    )
    drawing = read_svg(svg(tmp_path, body))
    assert [c.source for c in drawing.contours] == ["path#kept"]
    assert (
        f"{tmp_path / 't.svg'}: skipped 1 <use> of another file's element" in (drawing.warnings[0])
    )


def test_a_switch_a_use_places_shows_its_first_child(tmp_path: Path) -> None:
    body = (
        '<defs><switch id="s"><path id="a" d="M 0 0 L 1 0"/><path id="b" d="M 0 5 L 1 5"/>'
        '</switch></defs><use id="u" xlink:href="#s" x="1"/>'
    )
    drawing = read_svg(svg(tmp_path, body))
    assert [c.source for c in drawing.contours] == ["use#u > path#a"]


def test_a_switch_by_language_is_refused(tmp_path: Path) -> None:
    body = (
        '<switch><path id="fr" systemLanguage="fr" d="M 0 0 L 1 0"/>'
        '<path id="other" d="M 0 0 L 2 0"/></switch>'
    )
    with pytest.raises(InputError, match=r"shows path#fr or another child by the viewer's lang"):
        read_svg(svg(tmp_path, body))


def test_a_switch_passes_over_what_is_not_a_rendered_element(tmp_path: Path) -> None:
    """resvg's structure/switch/non-SVG-child.svg: an unknown ``<random>`` (or a
    ``<title>``) is not what a switch shows; the first rendered child is (it was dropped)."""
    body = (
        '<switch><random id="r"/><title>t</title><path id="shown" d="M 0 0 L 1 0"/>'
        '<path id="other" d="M 0 0 L 2 0"/></switch>'
    )
    drawing = read_svg(svg(tmp_path, body))
    assert [c.source for c in drawing.contours] == ["path#shown"]


def test_conditions_outside_a_switch_apply_too(tmp_path: Path) -> None:
    """SVG 1.1 §5.8.2: an element whose conditions fail is not rendered, switch or not
    (resvg's structure/systemLanguage/on-svg.svg renders nothing)."""
    body = (
        '<path id="ext" requiredExtensions="http://example.org/x" d="M 0 0 L 1 0"/>'
        '<clipPath id="c" systemLanguage="ru"><rect width="1" height="1"/></clipPath>'
        '<path id="kept" d="M 0 0 L 2 0"/>'
    )
    drawing = read_svg(svg(tmp_path, body))
    assert [c.source for c in drawing.contours] == ["path#kept"]
    assert any(
        "skipped 1 element(s) with shapes that require extensions" in w for w in (drawing.warnings)
    )
    body = '<g systemLanguage="ru"><path id="ru" d="M 0 0 L 1 0"/></g><path d="M 0 0 L 2 0"/>'
    with pytest.raises(InputError, match=r"g\[1\] is shown only to viewers whose language"):
        read_svg(svg(tmp_path, body))


# ------------------------------------------------------------------ use, skipped constructs


def test_use_places_a_definition_and_names_both(tmp_path: Path) -> None:
    body = (
        '<defs><path id="d1" d="M 0 0 L 10 0"/></defs><use id="u1" xlink:href="#d1" x="5" y="7"/>'
    )
    drawing = read_svg(svg(tmp_path, body))
    contour = one(drawing)
    assert vertices(contour) == [(5, 93), (15, 93)]
    assert contour.source == "use#u1 > path#d1"
    assert drawing.warnings == ()  # the <use> places all the <defs> holds


@pytest.mark.parametrize(
    ("defs", "warned"),
    [
        ('<path id="d1" d="M 0 0 L 10 0"/><path id="d2" d="M 0 0 L 0 10"/>', True),  # d2
        ('<g><path d="M 0 0 L 10 0"/></g>', True),  # a group nothing places
        ('<text id="t">hi</text>', True),
        (
            '<linearGradient id="g"><stop offset="0"/></linearGradient>'
            '<marker id="m"><path d="M 0 0 L 1 1"/></marker>'
            '<clipPath id="c"><rect width="5" height="5"/></clipPath>'
            '<pattern id="p" width="2" height="2"><rect width="1" height="1"/></pattern>'
            '<filter id="f"/><style>path { stroke: black }</style>',
            False,  # what an Inkscape file's <defs> holds: the drawing is the same without it
        ),
    ],
)
def test_a_defs_is_warned_of_when_it_holds_a_shape_no_use_places(
    tmp_path: Path, defs: str, warned: bool
) -> None:
    body = f'<defs>{defs}</defs><use xlink:href="#d1" x="5"/><path d="M 0 0 L 1 1" stroke="red"/>'
    warnings = read_svg(svg(tmp_path, body)).warnings
    said = [w for w in warnings if "<defs>" in w]
    expected = "skipped 1 <defs> element (definitions are cut only where a <use> places them)"
    assert said == ([f"{tmp_path / 't.svg'}: {expected}"] if warned else [])


@pytest.mark.parametrize(
    ("body", "warning"),
    [
        (
            '<text x="1" y="1">hi</text><text>2</text>',
            "skipped 2 <text> elements (convert text to paths",
        ),
        (
            '<flowRoot><flowRegion><rect width="9" height="9"/></flowRegion>'
            "<flowPara>x</flowPara></flowRoot>",
            "skipped 1 <text> element",
        ),
        (
            '<image width="5" height="5" href="data:image/png;base64,AAAA"/>',
            "skipped 1 <image> element (raster images",
        ),
        (
            '<mask id="m"><rect width="5" height="5"/></mask>',
            "skipped 1 <mask> element (a mask is not cut: what it hides is checked where it is "
            "used)",
        ),
        (  # a <use> a copy of a symbol brings (it was placed before its symbol's own <use>
            # was replaced) is not replaced: camtool/importers/svgmasks.py
            '<use href="#t"/><symbol id="t"><use href="#s" width="9" height="9"/></symbol>'
            '<symbol id="s" viewBox="0 0 1 1"><path d="M 0 0 L 1 1"/></symbol>',
            "skipped 1 <use> element (a <use> of a <symbol> with a viewBox is not supported",
        ),
        (  # symbols nothing places, in and out of <defs> (a viewer draws neither)
            '<symbol id="a"><path d="M 0 0 L 1 0"/></symbol>'
            '<defs><symbol id="b"><path d="M 0 0 L 1 1"/></symbol></defs>',
            "skipped 2 <symbol> elements (no <use> places them, and a symbol is drawn and cut "
            "only where one does)",
        ),
    ],
)
def test_skipped_constructs_warn_once_per_kind(tmp_path: Path, body: str, warning: str) -> None:
    drawing = read_svg(svg(tmp_path, body + HALF))
    assert [c.source for c in drawing.contours] == [drawing.contours[0].source]  # only HALF
    assert isinstance(drawing.contours[0].segments[0], Arc)
    assert len(drawing.warnings) == 1
    assert drawing.warnings[0].startswith(f"{tmp_path / 't.svg'}: {warning}")


def test_text_and_images_a_use_places_are_counted_once_per_use(tmp_path: Path) -> None:
    """A logo kept as a <symbol> with a raster image and a caption, placed twice: a viewer
    shows two images and two captions, none of which camtool cuts, so the warnings count
    them (they were silent when only the drawn tree was walked)."""
    body = (
        '<symbol id="logo"><image width="5" height="5" href="data:image/png;base64,AAAA"/>'
        '<text x="1" y="1">ACME</text><path d="M 0 0 L 1 0"/></symbol>'
        '<defs><g id="tag"><text>2</text></g><use id="again" href="#tag"/></defs>'
        '<use href="#logo" x="3" y="4"/><use href="#logo" x="13" y="4"/><use href="#tag"/>'
        '<use href="#again" x="5"/>'  # a <use> of a <use>: its text shows too
    )
    drawing = read_svg(svg(tmp_path, body))
    assert len(drawing.contours) == 2  # the symbol's path, placed twice
    name = tmp_path / "t.svg"
    assert f"{name}: skipped 4 <text> elements (convert text to paths" in "\n".join(
        drawing.warnings
    )
    assert f"{name}: skipped 2 <image> elements (raster images" in "\n".join(drawing.warnings)


def test_the_markers_a_viewer_draws_are_counted(tmp_path: Path) -> None:
    """SVG 1.1 §11.6: the marker properties inherit, ``none`` or an empty marker draws none,
    and only paths, lines, polylines and polygons get markers."""
    body = (
        '<marker id="arrow"><path d="M 0 0 L 2 1 L 0 2 Z"/></marker><marker id="empty"/>'
        '<g marker-end="url(#arrow)"><path d="M 10 10 L 30 10"/>'  # inherits: drawn
        '<path d="M 10 20 L 30 20" style="marker-end:none"/>'
        '<rect x="1" y="1" width="2" height="2"/></g>'  # a rect has no markers
        '<path d="M 10 30 L 30 30" marker-start="url(#empty)"/>'
        '<line x1="0" y1="50" x2="9" y2="50" stroke="red" style="marker:url(#arrow)"/>'  # drawn
    )
    drawing = read_svg(svg(tmp_path, body))
    assert len(drawing.contours) == 5  # the shapes themselves, no marker's
    assert drawing.warnings == (
        f"{tmp_path / 't.svg'}: skipped the markers of 2 shapes (a viewer draws the shapes of "
        "its markers at its vertices; camtool cuts the shape only: Inkscape's Path > Stroke "
        "to Path makes them paths)",
    )


def test_the_shapes_a_pattern_fills_are_counted(tmp_path: Path) -> None:
    """matplotlib's hatched bars: the bar is filled with a ``<pattern>`` of lines, which a
    viewer draws and camtool does not cut. ``fill`` inherits (SVG 1.1 §11.3), a ``style``
    outranks the attribute, a pattern without children draws its ``href``'s (§13.3), a
    ``<line>`` has no fill, and a pattern's own shapes are not drawn where they stand. As
    Chromium draws this file: a pattern with no children anywhere in its chain is no paint
    server (its fallback paints), one whose children draw nothing paints nothing."""
    body = (
        '<defs><pattern id="h" width="4" height="4" patternUnits="userSpaceOnUse">'
        '<path d="M 0 4 L 4 0" stroke="black"/></pattern>'
        '<pattern id="alias" href="#h"/><pattern id="empty" width="4" height="4"/>'
        '<pattern id="blank" width="4" height="4"><g/></pattern></defs>'
        '<rect x="0" y="0" width="10" height="10" fill="url(#h)"/>'  # filled: counted
        '<g fill="url(#alias)"><circle cx="20" cy="5" r="4"/>'  # inherits through the alias
        '<circle cx="30" cy="5" r="4" style="fill:red"/>'  # its own fill outranks the group's
        '<line x1="0" y1="20" x2="9" y2="20" stroke="red"/></g>'  # no inside to fill
        '<rect x="40" y="0" width="5" height="5" fill="url(#empty) red"/>'  # red: cut
        '<rect x="60" y="0" width="5" height="5" fill="url(#blank) red"/>'  # paints nothing
        '<rect x="50" y="0" width="5" height="5" fill="red" style="fill:url(#h) none"/>'
        '<defs><rect id="r" width="2" height="2" fill="url(#h)"/></defs>'
        '<use href="#r" x="70"/><use href="#r" x="80"/>'  # a viewer draws the stripes twice
    )
    drawing = read_svg(svg(tmp_path, body))
    assert len(drawing.contours) == 8  # the outlines, not the pattern's lines nor rect x=60
    assert drawing.warnings == (
        f"{tmp_path / 't.svg'}: skipped the pattern fill of 5 shapes (a viewer fills them "
        "with the pattern's lines or shapes; camtool cuts the outline only: Inkscape's "
        "Object > Pattern > Pattern to Objects makes them shapes)",
        f"{tmp_path / 't.svg'}: skipped 1 element with neither fill nor stroke",  # x=60
    )


def test_symbol_without_viewbox_is_placed(tmp_path: Path) -> None:
    body = '<symbol id="s"><path d="M 0 0 L 1 0"/></symbol><use href="#s" x="3" y="4"/>'
    assert vertices(one(read_svg(svg(tmp_path, body)))) == [(3, 96), (4, 96)]


def test_a_symbol_library_is_refused_naming_its_symbols(tmp_path: Path) -> None:
    """Inkscape's symbol libraries (Debian's inkscape-open-symbols) hold ``<symbol>``s and
    nothing that places one: a viewer shows an empty page, and the refusal says why."""
    body = (
        '<defs><symbol id="a"><path d="M 0 0 L 1 0"/></symbol></defs>'
        '<symbol id="b"><circle cx="2" cy="2" r="1"/></symbol>'
        '<symbol id="c"><rect width="1" height="1"/></symbol>'
        '<use href="#b"/>'  # b is placed, so it is cut
    )
    assert len(read_svg(svg(tmp_path, body)).contours) == 1
    library = body.replace('<use href="#b"/>', "")
    with pytest.raises(InputError, match=r"nothing to cut; .*\(skipped 3 <symbol> elements "):
        read_svg(svg(tmp_path, library))


def test_links_and_nested_svg_viewports(tmp_path: Path) -> None:
    body = (
        '<a href="#x"><path d="M 0 0 L 10 0" transform="translate(1 1)"/></a>'
        '<svg x="10" y="10" width="20" height="20" viewBox="0 0 2 2"><path d="M 0 0 L 1 0"/></svg>'
    )
    link, nested = read_svg(svg(tmp_path, body)).contours
    assert vertices(link) == [(1, 99), (11, 99)]
    assert vertices(nested) == [(10, 90), (20, 90)]  # 10 mm per unit inside the inner viewport


def test_path_without_data_draws_nothing(tmp_path: Path) -> None:
    drawing = read_svg(svg(tmp_path, '<path id="empty"/><path d=""/>' + HALF))
    assert [c.source for c in drawing.contours] == ["path[3]"]


def test_element_labels_count_in_document_order(tmp_path: Path) -> None:
    body = '<path d="M 0 0 L 1 0"/><g><path id="named" d="M 0 0 L 2 0"/><path d="M 0 0 L 3 0"/></g>'
    drawing = read_svg(svg(tmp_path, body))
    assert [c.source for c in drawing.contours] == ["path[1]", "path#named", "path[3]"]


# ------------------------------------------------------------------ files written by Inkscape


def test_inkscape_saved_shapes(tmp_path: Path) -> None:
    # tests/data/README-svg.md: Inkscape 1.2.2 re-saved inkscape-source.svg (60 x 40 mm page)
    drawing = read_svg(DATA / "inkscape-layers.svg")
    plate, hole, oval, wave = drawing.contours
    assert plate.bbox() == pytest.approx((5, 5, 55, 35))
    assert [isinstance(s, Arc) for s in plate.segments].count(True) == 4
    (circle,) = hole.segments
    assert_arc(circle, (15.0, 20.0), 5.0, True)
    assert oval.bbox() == pytest.approx((32, 16, 48, 24), abs=1e-9)
    assert wave.start == (28.0, 10.0) and wave.end == (52.0, 10.0)
    assert f"{DATA / 'inkscape-layers.svg'}: skipped 1 <text> element" in drawing.warnings[1]


def test_inkscape_object_to_path_plain_svg(tmp_path: Path) -> None:
    # Inkscape wrote the circle as four 'a' commands and the rounded corners as Béziers
    tol = 0.001
    drawing = read_svg(DATA / "inkscape-paths-plain.svg", ImportOptions(tolerance=tol))
    plate, hole, oval, wave = drawing.contours
    assert {c.layer for c in drawing.contours} == {"0"}  # plain SVG drops inkscape:groupmode
    (circle,) = hole.segments
    arc = assert_arc(circle, (15.0, 20.0), 5.0, True)
    assert arc.is_full_circle
    d = (
        "m 9,5 h 42 c 2.216,0 4,1.784 4,4 v 22 c 0,2.216 -1.784,4 -4,4 H 9 "
        "C 6.784,35 5,33.216 5,31 V 9 C 5,6.784 6.784,5 9,5 Z"
    )  # path#plate as Inkscape wrote it; the page is 40 mm high with viewBox 0 0 60 40
    curve = true_curve(d, lambda xy: np.column_stack([xy[:, 0], 40.0 - xy[:, 1]]), 20001)
    there, back = two_sided_error([plate], curve)
    assert max(there, back) <= tol + 1e-6
    saved = read_svg(DATA / "inkscape-layers.svg")
    for a, b in zip(drawing.contours, saved.contours, strict=True):
        assert a.bbox() == pytest.approx(b.bbox(), abs=0.01)  # the 0.554 corner Béziers
    # the ellipse and the untouched Bézier wave give the same contours either way
    assert oval.segments == saved.contours[2].segments
    assert wave.segments == saved.contours[3].segments


def test_svg_bytes_from_stdin_are_named_stdin() -> None:
    data = (DATA / "inkscape-layers.svg").read_bytes()
    drawing = read_drawing_bytes(data, suffix=".svg", options=ImportOptions(layers=("Cut",)))
    assert drawing.source == "<stdin>"
    with pytest.raises(InputError, match=r"^<stdin>: no layer named 'X'"):
        read_drawing_bytes(data, suffix=".svg", options=ImportOptions(layers=("X",)))


def test_read_drawing_dispatches_svg() -> None:
    drawing = read_drawing(DATA / "inkscape-layers.svg", ImportOptions(layers=("Cut",)))
    assert [c.source for c in drawing.contours] == ["rect#plate", "circle#hole"]


# ------------------------------------------------------------------ bad input


@pytest.mark.parametrize(
    ("body", "message"),
    [
        (
            '<path id="p" d="M 0 0 L 10"/>',
            "path#p: bad path data: command 'L' takes a multiple of 2 numbers, got 1",
        ),
        ('<path d="M 0 0 X 5 5"/>', "path[1]: bad path data: unknown command 'X' at character 6"),
        ('<path d="L 5 5"/>', "path[1]: bad path data: path data must start with M or m, not 'L'"),
        ('<path d="M 0 0 A 5 5 0 2 1 9 9"/>', "bad path data: arc flag must be 0 or 1, got '2'"),
        ('<path d="M 0 0 L 1 1 Z 5"/>', "bad path data: command 'Z' takes no numbers, got 1"),
        ('<path d="M 0 0 L 1 #"/>', "bad path data: cannot read a number at character 10"),
        (
            '<g id="g" transform="rotate(abc)"><path d="M0 0 L1 1"/></g>',
            "g#g: bad transform 'rotate(abc)'",
        ),
        ('<path transform="spin(3)" d="M0 0 L1 1"/>', "unknown transform function 'spin'"),
        ('<path transform="scale(1 2 3)" d="M0 0 L1 1"/>', "scale() takes 1 or 2 numbers, got 3"),
        ('<circle r="abc"/>', "circle[1]: bad r 'abc': must be a number with an optional unit"),
        ('<polygon points="0 0 1 1 2"/>', "polygon[1]: points must be x,y pairs, got an odd count"),
        (
            "",
            "nothing to cut; camtool reads path, rect, circle, ellipse, line, polyline and polygon",
        ),
        (
            "<text>only text</text>",
            "nothing to cut; camtool reads path, rect, circle, ellipse, line, polyline and "
            "polygon elements that are drawn (skipped 1 <text> element (convert text to paths "
            "in the drawing program to cut it))",
        ),
        ('<rect width="5em" height="1"/>', "bad width '5em': font-relative units (em, ex)"),
        ('<circle r="-5"/>', "circle[1]: bad r '-5': must not be negative"),
        ('<rect x="1e400" width="1" height="1"/>', "rect[1]: bad x '1e400': must be a number"),
        ('<g id="g"><use id="u" href="#g"/></g>', "use#u: <use> places itself; remove the loop"),
        ('<use id="a" href="#b"/><use id="b" href="#a"/>', "use#a: <use> places itself"),
        (
            '<g transform="scale(1e10)"><path d="M 0 0 L 1e300 0"/></g>',
            "path[1]: a point at (inf, 100) mm, not a finite number within ±1e9 mm",
        ),
    ],
)
def test_bad_input_names_file_and_element(tmp_path: Path, body: str, message: str) -> None:
    path = svg(tmp_path, body)
    with pytest.raises(InputError) as err:
        read_svg(path)
    assert str(err.value).startswith(f"{path}: ")
    assert message in str(err.value)


@pytest.mark.parametrize(
    ("root", "message"),
    [
        (
            'width="10ft" height="10mm"',
            "<svg> width '10ft': unit 'ft' unknown; use mm, cm, in, pt, px, pc",
        ),
        ('width="wide" height="10mm"', "<svg> width 'wide' is not a length"),
        ('width="-5mm" height="10mm"', "<svg> width '-5mm' must be positive"),
        ('viewBox="0 0 10"', "viewBox '0 0 10' must be four numbers"),
        ('viewBox="0 0 0 10"', "viewBox '0 0 0 10' must have a positive width and height"),
        # numbers Python's float() reads and SVG's grammar does not (a browser ignores the
        # viewBox or the size): read, the page would be 10 times another size than drawn
        ('viewBox="0 0 1_0 10"', "viewBox '0 0 1_0 10' must be four numbers"),
        ('viewBox="0 0 inf 10"', "viewBox '0 0 inf 10' must be four numbers"),
        ('viewBox="0 0 \u0661\u0660 10"', "viewBox '0 0 \u0661\u0660 10' must be four numbers"),
        ('width="\u0661\u0660mm" height="10mm"', "<svg> width '\u0661\u0660mm' is not a length"),
        (
            'width="1mm" height="1mm" viewBox="0 0 1 1" preserveAspectRatio="middle"',
            "preserveAspectRatio",
        ),
    ],
)
def test_bad_page_attributes(tmp_path: Path, root: str, message: str) -> None:
    path = svg(tmp_path, HALF, root)
    with pytest.raises(InputError) as err:
        read_svg(path)
    assert str(err.value).startswith(f"{path}: ")
    assert message in str(err.value)


def test_bad_tolerance_is_a_usage_error(tmp_path: Path) -> None:
    with pytest.raises(UsageError, match=r"tolerance must be a positive number of mm, got 0\.0"):
        read_svg(svg(tmp_path, HALF), ImportOptions(tolerance=0.0))


def test_malformed_xml_names_line_and_column(tmp_path: Path) -> None:
    path = tmp_path / "broken.svg"
    path.write_text('<svg xmlns="http://www.w3.org/2000/svg">\n<path d="M 0 0 L 1 1">\n</svg>\n')
    with pytest.raises(InputError, match=r"broken.svg: malformed XML at line 3, column 3"):
        read_svg(path)


def test_an_empty_file_is_called_empty(tmp_path: Path) -> None:
    """Not "malformed XML at line 1, column 1 (no element found)": the file has nothing."""
    path = tmp_path / "empty.svg"
    path.write_bytes(b"")
    with pytest.raises(InputError, match=r"empty.svg: empty file; export the drawing again"):
        read_svg(path)


def test_not_svg_and_missing_file(tmp_path: Path) -> None:
    path = tmp_path / "x.svg"
    path.write_text("<html><body/></html>")
    with pytest.raises(InputError, match=r"not an SVG document \(the root element is <html>\)"):
        read_svg(path)
    with pytest.raises(InputError, match=r"nope\.svg: no such file"):
        read_svg(tmp_path / "nope.svg")


def test_a_hidden_root_svg_is_nothing_to_cut(tmp_path: Path) -> None:
    """resvg's painting/display/none-on-svg.svg: svgelements gives no document at all."""
    path = tmp_path / "t.svg"
    path.write_text(
        '<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 200 200" display="none">'
        '<rect x="20" y="20" width="160" height="160"/></svg>'
    )
    with pytest.raises(InputError, match=r"t\.svg: nothing to cut: the <svg> element itself is"):
        read_svg(path)


def test_percentages_are_of_the_viewport_width_height_or_diagonal(tmp_path: Path) -> None:
    """SVG 1.1 §7.10 in a 200 × 100 mm page (viewBox 0 0 200 100, so 1 unit = 1 mm, Y up).

    x-like lengths are of 200, y-like of 100, ``r`` of sqrt((200² + 100²) / 2) = 158.114;
    inside a nested ``<svg>`` with a viewBox, of that viewBox. svgelements had the rect
    from x 10 to 60 (expected 20 to 120).
    """
    body = (
        '<rect id="r" x="10%" y="10%" width="50%" height="50%" rx="5%" ry="10%"/>'
        '<circle id="c" cx="50%" cy="50%" r="10%"/>'
        '<ellipse id="e" cx="25%" cy="75%" rx="10%" ry="10%"/>'
        '<line id="l" x1="0%" y1="0%" x2="100%" y2="100%" stroke="black"/>'
        '<svg x="0" y="0" width="200" height="100" viewBox="0 0 50 50" preserveAspectRatio="none">'
        '<rect id="n" width="10%" height="10%"/></svg>'
        '<defs><rect id="u" width="10" height="10"/></defs><use href="#u" x="10%" y="50%"/>'
    )
    drawing = read_svg(svg(tmp_path, body, 'width="200mm" height="100mm" viewBox="0 0 200 100"'))
    r = 0.1 * math.sqrt((200**2 + 100**2) / 2)
    boxes = {c.source: c.bbox() for c in drawing.contours}
    assert boxes["rect#r"] == pytest.approx((20, 40, 120, 90))
    assert boxes["circle#c"] == pytest.approx((100 - r, 50 - r, 100 + r, 50 + r))
    assert boxes["ellipse#e"] == pytest.approx((30, 15, 70, 35))
    assert boxes["line#l"] == pytest.approx((0, 0, 200, 100))
    # 10% of the nested 50 × 50 viewBox: 5 × 5 units, stretched 4 × 2 to 20 × 10 mm
    assert boxes["rect#n"] == pytest.approx((0, 90, 20, 100))
    # a <use> placed at 10 % and 50 % of the page: (20, 50), so from y 40 to 50 once flipped
    assert boxes["use[1] > rect#u"] == pytest.approx((20, 40, 30, 50))


def test_a_shape_without_its_size_is_not_drawn_and_an_ellipse_radius_is_auto(
    tmp_path: Path,
) -> None:
    """SVG 2 §10: a rect's missing width or height, a circle's missing r, an ellipse's two
    missing radii draw nothing (svgelements drew a size of 1: a 60 × 1 rect); one missing
    radius of an ellipse is ``auto``, the other's (resvg's missing-rx-attribute.svg)."""
    body = (
        '<rect id="no-height" x="20" y="20" width="60"/>'
        '<circle id="no-r" cx="50" cy="50"/>'
        '<ellipse id="no-radii" cx="50" cy="50"/>'
        '<ellipse id="ry-only" cx="50" cy="50" ry="30"/>'
        '<rect id="css-height" x="1" y="1" width="5" style="height:5"/>'
    )
    drawing = read_svg(svg(tmp_path, body))
    boxes = {c.source: c.bbox() for c in drawing.contours}
    assert set(boxes) == {"ellipse#ry-only", "rect#css-height"}  # SVG 2: a CSS size counts
    assert boxes["ellipse#ry-only"] == pytest.approx((20, 20, 80, 80))


def test_a_paint_reference_to_nothing_paints_its_fallback_or_nothing(tmp_path: Path) -> None:
    """SVG 2 §13.2: ``url(#id)`` to no element, or to one that is not a paint server, uses
    its fallback colour, else paints nothing (resvg's painting/fill/funcIRI-* tests).
    svgelements painted every url() black, so invisible shapes were cut."""
    body = (
        '<defs><linearGradient id="g"><stop offset="0" stop-color="red"/></linearGradient>'
        '<rect id="not-paint" width="1" height="1"/></defs>'
        '<rect id="missing" width="9" height="9" fill="url(#nope)"/>'
        '<rect id="missing-none" width="9" height="9" fill="url(#nope) none"/>'
        '<rect id="missing-red" width="9" height="9" fill="url(#nope) red"/>'
        '<rect id="gradient" width="9" height="9" style="fill:url(#g)"/>'
        '<rect id="not-a-server" width="9" height="9" style="fill:url(\'#not-paint\')"/>'
        '<rect id="stroke" width="9" height="9" fill="none" stroke="url(#nope)"/>'
    )
    drawing = read_svg(svg(tmp_path, body))
    assert [c.source for c in drawing.contours] == ["rect#missing-red", "rect#gradient"]
    assert f"{tmp_path / 't.svg'}: skipped 4 elements with neither fill nor stroke" in (
        drawing.warnings
    )


@pytest.mark.parametrize(
    "origin",
    ['transform-origin="50% 50%"', 'transform-origin="center"', 'transform-origin="50px 50"',
     'style="transform-origin: 50 center"', 'transform-origin="left 50%"'],
)  # fmt: skip
def test_transform_origin_turns_a_shape_about_it(tmp_path: Path, origin: str) -> None:
    """CSS Transforms 1 §6, SVG 2: rotate(45) about (50, 50) of the 100 × 100 viewBox.

    The 20 mm square centred there keeps its centre; its box is 50 ± 10·√2. svgelements
    ignored the origin and turned it about (0, 0), out of the page. With ``left 50%`` the
    origin is (0, 50), and the square's centre turns about it.
    """
    body = f'<rect id="r" x="40" y="40" width="20" height="20" transform="rotate(45)" {origin}/>'
    (contour,) = read_svg(svg(tmp_path, body)).contours
    x0, y0, x1, y1 = contour.bbox()
    half = 10 * math.sqrt(2)
    if "left" in origin:  # about (0, 50): (50, 50) goes to (50 cos 45°, 50 + 50 sin 45°)
        cx, cy = 50 * math.cos(math.pi / 4), 50 + 50 * math.sin(math.pi / 4)
    else:
        cx, cy = 50.0, 50.0
    assert (x0, y0, x1, y1) == pytest.approx(
        (cx - half, 100 - cy - half, cx + half, 100 - cy + half)
    )


def test_a_transform_origin_camtool_cannot_read_is_refused(tmp_path: Path) -> None:
    body = '<rect id="r" width="2" height="2" transform="rotate(9)" transform-origin="calc(1px)"/>'
    with pytest.raises(InputError, match=r"rect#r: transform-origin 'calc\(1px\)' is not one"):
        read_svg(svg(tmp_path, body))


def test_a_gradient_without_stops_paints_nothing(tmp_path: Path) -> None:
    """SVG 1.1 §13.2.4: no stops, painted as none; stops taken through href chains count
    (Inkscape's gradients with coordinates point to one with the stops). A pattern without
    children is no paint server, so with no fallback nothing is painted (Chromium)."""
    body = (
        '<defs><linearGradient id="stops"><stop offset="0" stop-color="red"/></linearGradient>'
        '<linearGradient id="chain" xlink:href="#stops" x2="1"/>'
        '<radialGradient id="chain2" href="#chain"/><linearGradient id="empty"/>'
        '<linearGradient id="loop1" href="#loop2"/><linearGradient id="loop2" href="#loop1"/>'
        '<pattern id="p" width="1" height="1"/></defs>'
        '<rect id="a" width="9" height="9" fill="url(#stops)"/>'
        '<rect id="b" width="9" height="9" fill="url(#chain)"/>'
        '<rect id="c" width="9" height="9" fill="url(#chain2)"/>'
        '<rect id="d" width="9" height="9" fill="url(#empty)"/>'
        '<rect id="e" width="9" height="9" fill="url(#loop1)"/>'
        '<rect id="f" width="9" height="9" fill="url(#p)"/>'
        '<rect id="g" width="9" height="9" fill="url(#empty) blue"/>'
    )
    drawing = read_svg(svg(tmp_path, body))
    assert [c.source for c in drawing.contours] == [
        "rect#a",
        "rect#b",
        "rect#c",
        "rect#g",
    ]


def test_a_url_paint_with_spaces_inside_the_parentheses_is_a_reference(tmp_path: Path) -> None:
    """CSS url(): white space may surround the URL (resvg's structure/svg/funcIRI-parsing)."""
    body = (
        '<defs><linearGradient id="g"><stop offset="0" stop-color="red"/></linearGradient></defs>'
        '<rect id="spaced" width="9" height="9" fill="  url(  #g   )  "/>'
        '<rect id="in-style" width="9" height="9" style="fill: url( \'#g\' )"/>'
    )
    drawing = read_svg(svg(tmp_path, body))
    assert [c.source for c in drawing.contours] == ["rect#spaced", "rect#in-style"]


@pytest.mark.parametrize(
    ("paint", "colour"),
    [
        ("rgb(0.8, 127.5, 14.2)", "#01800e"),  # SVG 2 fractions: CSS rounds half up
        ("rgb(1e2, 0, 0)", "#640000"),
        ("rgb(0 127 14)", "#007f0e"),  # CSS Color 4 spaces
        ("rgb(0 127 14 / 50%)", "#007f0e"),
        ("rgb(10%, 50.5%, 0%)", "#1a8100"),  # 25.5 → 26, 128.775 → 129
        ("rgb(300, -5, 0)", "#ff0000"),  # clamped
        ("hsl(120deg 100% 25%)", "#008000"),  # CSS Color 4 §7: CSS green
        ("hsl(0.5turn, 100%, 50%)", "#00ffff"),  # hue 180°: cyan
        ("hsla(240, 100%, 50%, 0.5)", "#0000ff"),
    ],
)
def test_rgb_and_hsl_colours_svgelements_does_not_read(
    tmp_path: Path, paint: str, colour: str
) -> None:
    """svgelements dropped a shape filled ``rgb(0.8, 127.5, 14.2)`` without a word (resvg's
    painting/fill/rgb-color-with-floats) and read CSS Color 4's forms as black."""
    body = (
        f'<rect id="attr" width="9" height="9" fill="{paint}"/>'
        f'<rect id="css" width="9" height="9" style="fill:none; stroke: {paint}"/>'
    )
    drawing = read_svg(svg(tmp_path, body))
    assert [(c.source, c.colour) for c in drawing.contours] == [
        ("rect#attr", colour),
        ("rect#css", colour),
    ]


def test_opacities_are_clamped_and_one_that_is_no_number_is_ignored(tmp_path: Path) -> None:
    """CSS Color 4 §4.2: an opacity is clamped to [0, 1]; an invalid declaration is ignored
    (initial value 1). svgelements raised OverflowError on ``fill-opacity="1e400"``, which
    camtool reported as an internal error."""
    body = (
        '<rect id="huge" width="9" height="9" fill-opacity="1e400"/>'
        '<rect id="huge-css" width="9" height="9" style="fill-opacity:1e400; opacity: 5"/>'
        '<rect id="word" width="9" height="9" fill-opacity="inf"/>'
        '<rect id="half" width="9" height="9" style="fill-opacity:50%"/>'
        '<rect id="stroke" width="9" height="9" fill="none" stroke="red" stroke-opacity="1e999"/>'
        '<g fill-opacity="0"><rect id="inherits" width="9" height="9" fill-opacity="inherit"/></g>'
        '<rect id="negative" width="9" height="9" fill-opacity="-0.5"/>'
        '<rect id="negative-css" width="9" height="9" style="opacity:-2%"/>'
    )
    drawing = read_svg(svg(tmp_path, body))
    assert [c.source for c in drawing.contours] == [
        "rect#huge",
        "rect#huge-css",
        "rect#word",
        "rect#half",
        "rect#stroke",
    ]
    assert any("skipped 1 element with opacity 0" in w for w in drawing.warnings)
    assert any("skipped 2 elements with neither fill nor stroke" in w for w in drawing.warnings)


def test_contours_wholly_outside_the_page_are_cut_with_a_warning(tmp_path: Path) -> None:
    """SVG 1.1 §14.3.3: the root viewport clips, so a viewer shows nothing of a shape left
    beside the page or moved away by a stray transform (Fritzing's SMD_crystal_HC49.svg has
    a rect translated 1 034 px down). camtool cuts what it reads, and says so. A shape that
    crosses the page's edge is not named there: a second warning counts those."""
    body = (
        '<rect id="on" x="10" y="10" width="20" height="20"/>'
        '<rect id="across" x="90" y="90" width="20" height="20"/>'
        '<rect id="away" x="10" y="10" width="5" height="5" transform="translate(0,1034.6)"/>'
        '<circle id="left" cx="-20" cy="50" r="5"/>'
        # starting off the page, onto which a line or an arc's bulge comes back
        '<path id="enter" d="M -20 50 L 50 50 L 50 60 Z"/>'
        '<circle id="bulge" cx="104" cy="50" r="5"/>'
    )
    drawing = read_svg(svg(tmp_path, body))
    assert [c.source for c in drawing.contours] == [
        "rect#on",
        "rect#across",
        "rect#away",
        "circle#left",
        "path#enter",
        "circle#bulge",
    ]
    assert drawing.contours[5].start[0] > 100.0  # its start is off the page
    assert drawing.warnings == (
        f"{tmp_path / 't.svg'}: 2 contours lie wholly outside the 100 × 100 mm page, where a "
        "viewer shows nothing (first rect#away at (10.0000, -949.6000) mm); camtool cuts them: "
        "delete them or move them onto the page",
        f"{tmp_path / 't.svg'}: 3 contours reach beyond the 100 × 100 mm page, where a viewer "
        "shows only the part on the page (farthest: path#enter at (-20.0000, 40.0000) mm, 20 mm "
        "beyond); camtool cuts them whole: trim them to the page in the drawing program if the "
        "rest is not to be cut",
    )
    no_size = read_svg(svg(tmp_path, body, root="", name="n.svg"))  # no page to judge by
    assert not any("outside the" in w or "beyond the" in w for w in no_size.warnings)
