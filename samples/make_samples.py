"""Regenerate the bundled sample drawings (run: ``python samples/make_samples.py``).

``logo.dxf`` is camtool's own logo, 5.0 × 4.5 mm, placed inside the 10 × 7 mm
work area of the pic-mmh machine (UNAM-GMM §2.1), the size of the 5 mm logos
the thesis cut. It uses every entity kind the first importer reads:

- a shield outline: a closed LWPOLYLINE whose top edge is a bulged arc;
- a hole: a CIRCLE;
- a "C": an ARC with two LINE serifs that chain to one open contour;
- a cutter point: a triangle of three LINEs that chain to one closed contour;
- a base mark: a 2D POLYLINE with a bulge (a shallow "smile").

``plate.dxf`` is a 40 × 30 mm bracket, drawn from the origin as parts are drawn, for profile cutting
(``--offset outside``): an outline with a 10 × 8 mm notch (two inside corners no round
tool can reach), four ø4 mm holes, a 12 × 4 mm slot with round ends and a 2 × 2 mm
square hole narrower than a 3 mm tool. ``pocket.dxf`` is a 30 × 20 mm pocket with 3 mm
corner radii around two islands, a ø6 mm boss and a 5 × 5 mm block, for
``--offset pocket``. ``part.dxf`` is the job sample (``part.toml``, docs/jobs.md): an
80 × 60 mm plate on layer OUTLINE, four ø3.2 mm holes on HOLES, a 30 × 20 mm pocket on
POCKET, a line to engrave on ENGRAVE and centre lines (linetype CENTER) on CENTER, two of
them across the whole part.
"""

from __future__ import annotations

import math
from pathlib import Path

import ezdxf

HERE = Path(__file__).parent


def make_logo(path: Path) -> None:
    """Write the camtool logo to ``path`` (units: mm)."""
    doc = ezdxf.new("R2010", setup=False)
    doc.header["$INSUNITS"] = 4  # mm
    msp = doc.modelspace()
    # Shield: 5 mm wide, straight sides, top edge a CCW arc with 1 mm sagitta
    # (bulge = 2 * sagitta / chord = 0.4); the outline runs counter-clockwise.
    msp.add_lwpolyline(
        [(2.5, 1.0, 0.0), (7.5, 1.0, 0.0), (7.5, 4.5, 0.4), (2.5, 4.5, 0.0)],
        format="xyb",
        close=True,
    )
    msp.add_circle((5.0, 3.6), 0.5)
    # "C" around the hole: an arc of r = 1.2 mm from 40° to 320°, serifs outwards.
    centre, r = (5.0, 3.6), 1.2
    msp.add_arc(centre, r, 40.0, 320.0)
    for deg in (40.0, 320.0):
        a = math.radians(deg)
        inner = (centre[0] + r * math.cos(a), centre[1] + r * math.sin(a))
        outer = (centre[0] + 1.5 * math.cos(a), centre[1] + 1.5 * math.sin(a))
        msp.add_line(inner, outer)
    # Cutter point: a triangle of three separate LINE entities.
    tri = [(4.4, 1.5), (5.6, 1.5), (5.0, 2.2)]
    for k in range(3):
        msp.add_line(tri[k], tri[(k + 1) % 3])
    # Base mark: one 2D POLYLINE whose middle segment is bulged downwards
    # (bulge 0.1 > 0: counter-clockwise while running left to right).
    base = msp.add_polyline2d(
        [(3.0, 1.4), (3.6, 1.4), (3.6, 1.25), (6.4, 1.25), (6.4, 1.4), (7.0, 1.4)]
    )
    base.vertices[2].dxf.bulge = 0.1
    doc.saveas(path)


def make_plate(path: Path) -> None:
    """Write the bracket plate to ``path`` (units: mm)."""
    doc = ezdxf.new("R2010", setup=False)
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    # Drawn from the origin: a tool cutting outside runs at X, Y < 0 (work coordinates; use
    # --origin lower-left to put the work zero at the toolpath's corner instead).
    outline = [(0, 0), (40, 0), (40, 30), (25, 30), (25, 22), (15, 22), (15, 30), (0, 30)]
    msp.add_lwpolyline(outline, close=True)
    for x, y in ((5, 5), (35, 5), (5, 25), (35, 25)):
        msp.add_circle((x, y), 2.0)
    # Slot 12 × 4: straight sides joined by semicircles (bulge 1 = 180°).
    msp.add_lwpolyline(
        [(16, 8, 0.0), (24, 8, 1.0), (24, 12, 0.0), (16, 12, 1.0)], format="xyb", close=True
    )
    msp.add_lwpolyline([(8, 14), (10, 14), (10, 16), (8, 16)], close=True)
    doc.saveas(path)


def make_pocket(path: Path) -> None:
    """Write the pocket with two islands to ``path`` (units: mm)."""
    doc = ezdxf.new("R2010", setup=False)
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    r, b = 3.0, math.tan(math.pi / 8)  # corner radius; bulge of a 90° CCW arc
    msp.add_lwpolyline(
        [
            (r, 0, 0.0), (30 - r, 0, b), (30, r, 0.0), (30, 20 - r, b),
            (30 - r, 20, 0.0), (r, 20, b), (0, 20 - r, 0.0), (0, r, b),
        ],
        format="xyb",
        close=True,
    )  # fmt: skip
    msp.add_circle((9.0, 10.0), 3.0)
    msp.add_lwpolyline([(18.5, 7.5), (23.5, 7.5), (23.5, 12.5), (18.5, 12.5)], close=True)
    doc.saveas(path)


def make_part(path: Path) -> None:
    """Write the job sample (a plate made by several operations) to ``path`` (units: mm)."""
    doc = ezdxf.new("R2010", setup=True)  # setup: the CENTER linetype
    doc.header["$INSUNITS"] = 4
    for name, colour, linetype in (
        ("OUTLINE", 7, "Continuous"),
        ("HOLES", 1, "Continuous"),
        ("POCKET", 3, "Continuous"),
        ("ENGRAVE", 5, "Continuous"),
        ("CENTER", 4, "CENTER"),
    ):
        doc.layers.add(name, color=colour, linetype=linetype)
    msp = doc.modelspace()
    r, b = 4.0, math.tan(math.pi / 8)  # corner radius; bulge of a 90° CCW arc
    msp.add_lwpolyline(
        [
            (r, 0, 0.0), (80 - r, 0, b), (80, r, 0.0), (80, 60 - r, b),
            (80 - r, 60, 0.0), (r, 60, b), (0, 60 - r, 0.0), (0, r, b),
        ],
        format="xyb",
        close=True,
        dxfattribs={"layer": "OUTLINE"},
    )  # fmt: skip
    holes = ((8, 8), (72, 8), (72, 52), (8, 52))
    for x, y in holes:
        msp.add_circle((x, y), 1.6, dxfattribs={"layer": "HOLES"})
    p = 3.0
    msp.add_lwpolyline(
        [
            (25 + p, 20, 0.0), (55 - p, 20, b), (55, 20 + p, 0.0), (55, 40 - p, b),
            (55 - p, 40, 0.0), (25 + p, 40, b), (25, 40 - p, 0.0), (25, 20 + p, b),
        ],
        format="xyb",
        close=True,
        dxfattribs={"layer": "POCKET"},
    )  # fmt: skip
    msp.add_lwpolyline([(30, 10), (50, 10)], dxfattribs={"layer": "ENGRAVE"})
    for x, y in holes:  # a cross of centre lines through each hole
        msp.add_line((x - 4, y), (x + 4, y), dxfattribs={"layer": "CENTER"})
        msp.add_line((x, y - 4), (x, y + 4), dxfattribs={"layer": "CENTER"})
    msp.add_line((-5, 30), (85, 30), dxfattribs={"layer": "CENTER"})  # across the part
    msp.add_line((40, -5), (40, 65), dxfattribs={"layer": "CENTER"})
    doc.saveas(path)


SAMPLES = {
    "logo.dxf": make_logo,
    "plate.dxf": make_plate,
    "pocket.dxf": make_pocket,
    "part.dxf": make_part,
}
"""Each bundled drawing and the function that writes it."""


if __name__ == "__main__":
    import sys

    for name in sys.argv[1:] or SAMPLES:
        SAMPLES[name](HERE / name)
        print(f"wrote {HERE / name}")
