"""Canonical test drawings, written as real DXF files with ezdxf."""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import ezdxf

# seed-000 L1731: G02X02969.00Y03400.00I03012.00J03040.00F08;
GOLDEN_CENTRE = (3.012, 3.040)
GOLDEN_END = (2.969, 3.400)


def write_dxf(path: Path, build: Callable[[Any], None], *, insunits: int = 4) -> Path:
    """Write a DXF whose model space ``build(msp)`` fills; ``insunits`` as $INSUNITS."""
    doc = ezdxf.new("R2010", setup=False)
    doc.header["$INSUNITS"] = insunits
    build(doc.modelspace())
    doc.saveas(path)
    return path


def golden_arc_dxf(path: Path) -> Path:
    """An LWPOLYLINE with one clockwise (negative-bulge) arc ending at the golden point.

    The arc starts on the same circle at 180° (left of the centre) and runs
    clockwise over the top to the end point at about 96.8°.
    """
    cx, cy = GOLDEN_CENTRE
    ex, ey = GOLDEN_END
    r = math.hypot(ex - cx, ey - cy)
    start = (cx - r, cy)
    end_angle = math.atan2(ey - cy, ex - cx)
    sweep = end_angle - math.pi  # negative: clockwise
    bulge = math.tan(sweep / 4)

    def build(msp: Any) -> None:
        msp.add_lwpolyline([(*start, bulge), (ex, ey, 0.0)], format="xyb")

    return write_dxf(path, build)


def rectangle_dxf(path: Path, w: float = 10.0, h: float = 5.0, *, insunits: int = 4) -> Path:
    """A closed LWPOLYLINE rectangle ``w`` × ``h`` with its lower-left corner at (1, 1)."""

    def build(msp: Any) -> None:
        msp.add_lwpolyline([(1, 1), (1 + w, 1), (1 + w, 1 + h), (1, 1 + h)], close=True)

    return write_dxf(path, build, insunits=insunits)
