"""DXF files written by real programs (tests/data/README.md says which and how).

The expected numbers are FreeCAD's own measurements of the objects it exported, or
follow from the SVG that Inkscape exported; see tests/data/README.md.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from camtool.geometry.arcfit import distances
from camtool.geometry.chain import chain
from camtool.importers.dxf import import_dxf
from camtool.importers.lint import inspect_drawing
from camtool.model.shapes import Arc, Contour, Line

DATA = Path(__file__).parents[1] / "data"
TOL = 0.001


def _by_layer(contours: list[Contour], layer: str) -> Contour:
    (contour,) = [c for c in contours if c.layer == layer]
    return contour


def test_freecad_plate() -> None:
    read = import_dxf(DATA / "freecad-plate.dxf")
    assert read.units == "mm" and read.drawing.warnings == ()
    assert read.entity_counts == (
        ("ARC", "hook", 1),
        ("ARC", "outline", 1),
        ("CIRCLE", "hole", 1),
        ("ELLIPSE", "arch", 1),
        ("ELLIPSE", "slot", 1),
        ("LINE", "outline", 4),
        ("SPLINE", "wave", 1),
    )
    chained = chain(read.drawing.contours, TOL)
    assert [c.layer for c in chained if c.closed] == ["outline", "hole", "slot"]
    # FreeCAD's Shape.Length and optimalBoundingBox() of each object (README table)
    freecad = {
        "outline": (117.853982, (0, 0, 40, 20)),
        "hole": (18.849556, (7, 7, 13, 13)),
        "slot": (29.065345, (22, 7, 34, 13)),
        "arch": (17.156844, (12, -7, 28, -5)),
        "hook": (3.141593, (18, 10, 20, 12)),
        "wave": (43.076518, (2, 21.857116, 38, 30.344479)),
    }
    for layer, (length, box) in freecad.items():
        contour = _by_layer(chained, layer)
        # fitted curves differ from the true length by a few tolerances at most
        assert contour.length == pytest.approx(length, abs=5 * TOL), layer
        assert contour.bbox() == pytest.approx(box, abs=TOL), layer
    # exact entities stay exact: the outline's corner and the hole are true arcs
    outline = _by_layer(chained, "outline")
    assert sum(isinstance(s, Arc) for s in outline.segments) == 1
    assert outline.length == pytest.approx(110 + 2.5 * math.pi, abs=1e-9)
    (hole,) = _by_layer(chained, "hole").segments
    assert isinstance(hole, Arc) and hole.radius == 3.0 and hole.centre == (10.0, 10.0)
    # the rounded end_param 6.28318 still closes the ellipse
    slot = _by_layer(chained, "slot")
    assert slot.closed and slot.start == slot.end
    # the spline interpolates FreeCAD's points; 6 significant digits in the file
    wave = _by_layer(chained, "wave")
    through = np.array([(2, 25), (12, 30), (22, 24), (38, 29)], float)
    assert float(np.max(distances(through, wave.segments))) <= 2 * TOL


def test_inkscape_bracket() -> None:
    read = import_dxf(DATA / "inkscape-bracket.dxf")
    assert read.entity_counts == (
        ("LWPOLYLINE", "CUT", 2),
        ("LWPOLYLINE", "HOLES", 2),
        ("SPLINE", "CUT", 1),
        ("SPLINE", "HOLES", 6),
    )
    assert read.drawing.warnings == (
        f"{DATA / 'inkscape-bracket.dxf'}: skipped 1 LWPOLYLINE entity (zero length)",
    )
    (note,) = read.notes
    assert note.reason == "zero length" and note.location == (15.0, 19.0)
    outline, hole, slot = chain(read.drawing.contours, TOL)
    assert outline.layer == "CUT" and outline.closed
    assert outline.bbox() == pytest.approx((5, 5, 55, 36.25), abs=TOL)
    # 50 x 20 rectangle + 405 mm² under the cubic (Green's theorem on the SVG's Bézier)
    assert abs(outline.signed_area()) == pytest.approx(1405.0, abs=TOL * 120)
    assert hole.closed and all(isinstance(s, Arc) for s in hole.segments)
    radius_error = 4 * 2.8e-4 + TOL  # cubic Bézier circle error, then the fit
    for seg in hole.segments:
        for k in range(9):
            x, y = seg.point_at(k / 8)
            assert math.hypot(x - 15, y - 15) == pytest.approx(4.0, abs=radius_error)
    assert slot.closed and slot.bbox() == (35.0, 12.0, 47.0, 18.0)
    assert all(isinstance(s, Line) for s in slot.segments)


def test_inkscape_r12_flattened_lines() -> None:
    read = import_dxf(DATA / "inkscape-bracket-r12.dxf")
    assert read.units == "mm (assumed)"
    assert any("$INSUNITS = 0" in w for w in read.drawing.warnings)
    assert read.entity_counts == (("LINE", "CUT", 19),)
    (outline,) = chain(read.drawing.contours, TOL)
    assert outline.closed and len(outline.segments) == 19
    assert outline.bbox() == pytest.approx((5, 5, 55, 36.25), abs=1e-6)
    p = np.array([(55, 25), (45, 40), (15, 40), (5, 25)], float)
    vertices = {(round(s.start[0], 5), round(s.start[1], 5)) for s in outline.segments}
    for k in range(1, 16):
        t = k / 16
        b = (1 - t) ** 3 * p[0] + 3 * (1 - t) ** 2 * t * p[1] + 3 * (1 - t) * t**2 * p[2]
        b = b + t**3 * p[3]
        assert (round(b[0], 5), round(b[1], 5)) in vertices, (k, b)


def test_inspect_reports_the_inkscape_artefact_and_the_freecad_open_curves() -> None:
    ink = inspect_drawing(DATA / "inkscape-bracket.dxf")
    assert ink.counts() == {"zero-length": 1}
    (finding,) = ink.findings
    assert finding.location == (15.0, 19.0) and "LWPOLYLINE" in finding.message
    plate = inspect_drawing(DATA / "freecad-plate.dxf")
    opened = [f for f in plate.findings if f.kind == "open-contour"]
    # ends as FreeCAD gives them; the file's 3.14159 for π moves the arch's by 5e-6 mm
    starts = sorted(f.location for f in opened if f.location is not None)
    want = [(2.0, 25.0), (12.0, -5.0), (20.0, 12.0)]
    assert np.allclose(starts, want, atol=1e-5, rtol=0), starts
