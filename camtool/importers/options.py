"""What the user asks of an importer and the limits every importer holds a drawing to.

:class:`ImportOptions` (the CLI's ``--layers``, ``--units``, ``--tolerance``,
``--hatch-boundaries``, ``--max-entities``) and the limits that keep a damaged or
hostile file from exhausting memory or time: :data:`MAX_ENTITIES`,
:data:`MAX_COORDINATE_MM`, :data:`MAX_CURVE_RATIO` (:func:`check_curve_size`) and the
error for too many entities (:func:`too_many_entities`). Every importer (DXF, SVG,
points) and every caller that builds options (jobs, cli) imports them from here.
"""

from __future__ import annotations

from dataclasses import dataclass

from camtool.model.errors import InputError, UsageError
from camtool.model.units import LARGEST_VALUE

MAX_ENTITIES = 5_000_000
"""Default :attr:`ImportOptions.max_entities`: 10 × the largest real job camtool was
measured on (10⁵–10⁶ LINEs); block "laughs" expand to 10³⁰ and are refused before expanding."""

MAX_COORDINATE_MM = LARGEST_VALUE
"""Largest coordinate magnitude, mm (1000 km), an importer accepts; beyond it (and for
NaN or infinity) the drawing is refused with an :class:`InputError` naming the entity.
No machine camtool drives has a travel near it; numbers past it come from damaged or
hostile files, and would make curve fitting and code formatting misbehave."""


MAX_CURVE_RATIO = 1e8
"""Largest ratio of a fitted curve's size to the fitting tolerance (100 m at 1 µm; a
1 m part at 1 µm is 10⁶). Fitting cost grows with it (an ellipse 10⁷ mm across at
0.001 mm takes 6 400 arcs and seconds); a curve beyond it is refused before fitting."""


def check_curve_size(extent: float, tolerance: float) -> None:
    """Refuse a curve too large to fit within ``tolerance`` at a bounded cost.

    Args:
        extent: the size of the curve (of its control polygon), same unit as ``tolerance``.
        tolerance: the fitting tolerance, > 0.

    Raises:
        ValueError: ``extent / tolerance`` is above :data:`MAX_CURVE_RATIO` (or not finite);
            the caller names the entity.
    """
    if not extent <= MAX_CURVE_RATIO * tolerance:
        raise ValueError(
            f"a curve {extent:g} across, more than {MAX_CURVE_RATIO:g} times the fitting "
            f"tolerance {tolerance:g}, would need too many arcs; scale the drawing or "
            "raise --tolerance"
        )


def too_many_entities(name: str, limit: int) -> InputError:
    """The error for a drawing that expands to more than ``limit`` entities."""
    return InputError(
        f"{name}: the drawing expands to more than {limit:,} entities (block references, "
        "MINSERT grids and <use> clones included), the --max-entities limit; if it really "
        "holds that many, raise the limit with --max-entities N"
    )


@dataclass(frozen=True, kw_only=True)
class ImportOptions:
    """What the user asked of an importer (the CLI's ``--layers``, ``--units`` ...).

    Attributes:
        layers: layer names to keep (DXF layers, Inkscape layers); ``None`` keeps all.
            A name that matches no layer is an error that lists the layers there are.
        tolerance: largest distance, mm, between a curve (spline, ellipse, Bézier)
            and the arcs and lines fitted to it.
        units: unit of unitless inputs (point lists): ``mm``, ``cm``, ``in``, ``um``
            or ``0.1mm``; ``None`` is each importer's documented default (mm).
        hatch_boundaries: take HATCH boundary paths as contours (DXF).
        max_entities: most entities a drawing may expand to (DXF block references and
            MINSERT grids, SVG ``<use>`` clones, counted before anything is expanded);
            a drawing over it is refused with an :class:`InputError` naming this limit.

    Raises:
        UsageError: ``max_entities`` is not a positive whole number.
    """

    layers: tuple[str, ...] | None = None
    tolerance: float = 0.001
    units: str | None = None
    hatch_boundaries: bool = False
    max_entities: int = MAX_ENTITIES

    def __post_init__(self) -> None:
        if isinstance(self.max_entities, bool) or not (
            isinstance(self.max_entities, int) and self.max_entities >= 1
        ):
            raise UsageError(
                f"--max-entities must be a whole number >= 1, got {self.max_entities!r}"
            )
