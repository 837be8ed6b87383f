"""What a drawing holds that is not the part: centre lines, hidden lines, construction layers.

A machinist draws a part's edges continuous; centre lines (linetype CENTER), hidden edges
(HIDDEN, DASHED), phantom and dotted lines are drawing conventions (ISO 128-20, ASME
Y14.2), and layers named for construction or dimensions hold geometry that helps the
drawing, not the part. camtool never cuts them unless an operation selects them by name
(:mod:`camtool.jobs.selection`); they are left out with one line each on stderr and listed
by ``camtool inspect``.
"""

from __future__ import annotations

import re

from camtool.model.shapes import BBox, Contour, Drawing

DASHED_FAMILIES = ("CENTER", "DASH", "HIDDEN", "PHANTOM", "DOT", "DIVIDE", "BORDER", "ACAD_ISO")
"""Linetype name stems that are not continuous (AutoCAD's ``acad.lin`` and ``acadiso.lin``
families, with their ``2`` and ``X2`` variants; LibreCAD's ``DashLine``, ``CenterLine``...)."""

_CONSTRUCTION_LAYER = re.compile(
    r"(?:^|[^a-z])(?:constr[a-z]*|hilf[a-z]*|helpers?|aux[a-z]*|ref|references?|"
    r"dims?|dimensions?|bema(?:ss|ß)ung[a-z]*|cotas?|anno(?:t[a-z]*)?|notes?|title(?:blocks?)?|"
    r"hidden|defpoints)(?:[^a-z]|$)",
    re.IGNORECASE,
)
"""Layer names with a word that says construction, dimensions or annotation (AutoCAD's
``Defpoints`` too), in English and a few shop languages: a word of the name, so ``OUTLINE``
or ``POCKET`` never match, and ``A-ANNO-NOTE`` or ``Dimension (ISO)`` do."""

_CONSTRUCTION_ALONE = re.compile(
    r"^[^a-z]*(?:cent(?:er|re)|axis|axes|guides?|borders?|threads?|hatch(?:ing)?|origins?|"
    r"datums?|"
    r"(?:sheet|drawing|page)[ _-]?(?:borders?|frames?)|"
    r"bends?(?:[ _-]?(?:up|down))?|(?:section|break)[ _-]?lines?)(?:[ _-]?(?:lines?|marks?))?"
    r"(?:[ _]+-[ _]+[a-z]+)?(?:[^a-z(]*\([^)]*\))*[^a-z]*$",
    re.IGNORECASE,
)
"""Layer names that are centre lines, axes or guides, an origin or datum mark, a drawing
sheet's border, frame, hatching, thread, section or break lines, or a flat pattern's bend
lines, and nothing else (``CENTER``, ``Centerline (ISO)``, ``Center Mark (ISO)``,
``2-AXES``, ``Guides``; a laser panel's ``ORIGIN`` crosshair, ``Datum``; Autodesk
Inventor's ``Border (ANSI)`` and ``Border - Kova (ANSI)``, a style's name after the dash,
``Section Line (ANSI)``, ``Break Line (ISO)``, ``Thread Lines``, ``Hatch (ISO)``; ``Sheet
Border``, ``DRAWING_FRAME``; ``BEND``, ``Bend Lines``, ``BEND_DOWN``). These words also
name parts, so with another word they do not match: ``Center_Drawer``, OpenSCAD's
``fan_side_center``, ``X_Axis_Plate``, ``Guide_Rail``, ``Border_Panel``, ``Hatch_Cover``,
``Bend_Bracket`` are cut."""


_INVENTOR_FLAT = re.compile(
    r"^IV_(?:BEND(?:_UP|_DOWN)?|TANGENT|ROLL(?:_TANGENT)?|ARC_CENTERS?|TOOL_CENTER(?:_DOWN)?|"
    r"FEATURE_PROFILES(?:_DOWN)?|ALTREP_(?:FRONT|BACK))$",
    re.IGNORECASE,
)
"""Autodesk Inventor's flat-pattern DXF layers that are not the cut (its "Layer Mapping for
Export Flat Pattern Reference"): bend centre and extent lines, roll lines, arc centre and
punch tool centre marks, the edges of formed features and punches' alternative drawings.
``IV_OUTER_PROFILE`` and ``IV_INTERIOR_PROFILES`` are the cut."""


LAYER_FLAGS = {
    "CONSTRUCTION": "a LibreCAD construction layer",
    "NO-PLOT": "a layer that does not plot",
    "GUIDE": "a Shaper Origin guide",
}
"""What an importer writes in place of a contour's linetype when the drawing itself marks
the contour as not the part, whatever its line looks like, and how a message says it: a
LibreCAD construction layer (its DXF LAYER's extended data ``LibreCad`` 1070 = 1, its SVG's
``lc:is_construction``; LibreCAD draws such layers' lines endless and never prints them),
a DXF layer whose plot flag is off (group 290 = 0: AutoCAD's and LibreCAD's "do not
print", where drawings keep construction and viewport frames), a Shaper Origin guide."""


def line_kind(linetype: str) -> str:
    """How a message names a contour's ``linetype`` that is not continuous.

    ``"linetype DASHED"``, or a :data:`LAYER_FLAGS` phrase; ``""`` (continuous) is named by
    its layer's name instead: ``"a construction layer"``.
    """
    if not linetype:
        return "a construction layer"
    return LAYER_FLAGS.get(linetype, f"linetype {linetype}")


def dashed_name(linetype: str) -> bool:
    """Whether the linetype ``linetype`` (any case) is by its name not continuous."""
    name = linetype.upper()
    return any(stem in name for stem in DASHED_FAMILIES)


def construction_layer(layer: str) -> bool:
    """Whether the layer name ``layer`` says it holds construction, not the part."""
    return bool(
        _CONSTRUCTION_LAYER.search(layer)
        or _CONSTRUCTION_ALONE.match(layer)
        or _INVENTOR_FLAT.match(layer)
    )


def is_construction(contour: Contour) -> bool:
    """Whether a selection of everything leaves ``contour`` uncut.

    So it does for a linetype that is not continuous (``contour.linetype`` is set only for
    those) and on a construction layer (:func:`construction_layer`).
    """
    return bool(contour.linetype) or construction_layer(contour.layer)


def fit_extent(drawing: Drawing, *, marks: bool = True) -> BBox:
    """The extent ``--fit W H`` scales into W × H mm: the drawing's, construction left out.

    Centre lines run past the part and a sheet's border frames it; neither is cut, so
    neither counts: what is cut is what fits (and holds the fit's tolerance). The marks
    (points to drill) count, but for those on a construction layer: a job passes the
    drawing with the marks its drills drill (a mark nothing drills is not cut either).
    ``marks=False``: the contours' alone while there are any (the importer's guess before
    the job is known, never smaller a factor than the job's). A drawing of construction
    only has its whole extent.
    """
    cut = tuple(c for c in drawing.contours if not is_construction(c))
    points = tuple(m for m in drawing.marks if not construction_layer(m.layer))
    if cut and not marks:
        points = ()
    if not cut and not points:
        return drawing.bbox()
    return Drawing(cut, drawing.source, (), points).bbox()
