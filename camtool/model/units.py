"""Units: mm is the one internal unit; conversions on the way in and out.

Every length inside camtool is a float in millimetres, Y up. Importers convert
on the way in, dialects on the way out. Names carry their unit when it is not mm
(``feed_mm_min``, ``backlash_um``, ``step_um``).
"""

from __future__ import annotations

from typing import Final

MM: Final = 1.0
UM: Final = 0.001
"""One micrometre in mm."""
TENTH_MM: Final = 0.1
"""0.1 mm in mm (the unit of Angel-11 point lists and of the pic-mmh feed word)."""
INCH: Final = 25.4
PX: Final = 25.4 / 96.0
"""One CSS pixel (1/96 in) in mm."""
PT: Final = 25.4 / 72.0
CM: Final = 10.0

LARGEST_VALUE: Final = 1e9
"""Largest magnitude (exclusive) of a number read from an input file: a length in mm
(1000 km), a feed, a speed. Anything larger is an absurd value (``1e308``, a corrupt
file), refused where it enters with the file and line named; below it a float64 still
holds a length to better than 1 nm."""

LENGTH_UNITS: Final[dict[str, float]] = {
    "mm": MM,
    "um": UM,
    "cm": CM,
    "m": 1000.0,
    "in": INCH,
    "ft": 12 * INCH,
    "pt": PT,
    "px": PX,
    "0.1mm": TENTH_MM,
}
"""Length units accepted by name, as mm per unit."""


def mm_to_um(value_mm: float) -> float:
    """Convert mm to µm."""
    return value_mm * 1000.0


def um_to_mm(value_um: float) -> float:
    """Convert µm to mm."""
    return value_um / 1000.0


def fmt_num(value: float, decimals: int = 4) -> str:
    """``value`` with ``decimals`` decimals for messages, never ``-0.0000``.

    A value that rounds to zero prints unsigned (``-0.00001`` → ``"0.0000"``).
    """
    text = f"{value:.{decimals}f}"
    return text[1:] if text.startswith("-") and not text.strip("-0.") else text


def fmt_point(point: tuple[float, float], decimals: int = 4) -> str:
    """``(x, y)`` for messages with :func:`fmt_num` (``"(1.5000, 0.0000)"``)."""
    return f"({fmt_num(point[0], decimals)}, {fmt_num(point[1], decimals)})"
