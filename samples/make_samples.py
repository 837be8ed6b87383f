"""Regenerate the bundled sample drawings (run: ``python samples/make_samples.py``).

``logo.dxf`` is camtool's own logo, 5.0 × 4.5 mm, placed inside the 10 × 7 mm
work area of the pic-mmh machine (seed-000 §2.1), the size of the 5 mm logos
the thesis cut. It uses every entity kind the first importer reads:

- a shield outline: a closed LWPOLYLINE whose top edge is a bulged arc;
- a hole: a CIRCLE;
- a "C": an ARC with two LINE serifs that chain to one open contour;
- a cutter point: a triangle of three LINEs that chain to one closed contour;
- a base mark: a 2D POLYLINE with a bulge (a shallow "smile").
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


if __name__ == "__main__":
    make_logo(HERE / "logo.dxf")
    print(f"wrote {HERE / 'logo.dxf'}")
