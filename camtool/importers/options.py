"""What the user asks of an importer and the limits every importer holds a drawing to.

:class:`ImportOptions` (the CLI's ``--layers``, ``--units``, ``--tolerance``,
``--hatch-boundaries``, ``--max-entities``) and the limits that keep a damaged or
hostile file from exhausting memory or time: :data:`MAX_ENTITIES`,
:data:`MAX_COORDINATE_MM`, :data:`MAX_CURVE_RATIO` (:func:`check_curve_size`) and the
error for too many entities (:func:`too_many_entities`). Every importer (DXF, SVG,
points) and every caller that builds options (jobs, cli) imports them from here.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace

from camtool.model.errors import InputError, UsageError
from camtool.model.keywords import checked_keywords
from camtool.model.shapes import BBox, fit_factor
from camtool.model.units import LARGEST_VALUE

MAX_ENTITIES = 5_000_000
"""Most entities a drawing may expand to without ``--max-entities``: 10 × the largest real
job camtool was measured on (10⁵–10⁶ LINEs); block "laughs" expand to 10³⁰ and are refused
before expanding."""

MAX_EXPANSION = 250_000
"""Most entities a drawing's block references (DXF INSERT, MINSERT) and ``<use>`` clones
(SVG) may add to those its file holds, without ``--max-entities``. Each entity read costs
memory (several kB in ezdxf or svgelements, docs/performance.md), and references cost
nothing in the file: a 40 kB SVG of 5 000 ``<use>`` of a row of 1 000 clones, under
:data:`MAX_ENTITIES`, would ask for tens of GB. Entities the file holds itself are not
limited by it (their memory grows with the file's size)."""

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
            f"tolerance {tolerance:g} (--tolerance at the drawing's own size: --scale and "
            "--fit divide it by their factor), would need too many arcs; scale the drawing "
            "less or raise --tolerance"
        )


def check_expansion(
    name: str, expanded: int, held: int, max_entities: int | None, references: str
) -> None:
    """Refuse a drawing that expands to too many entities.

    Args:
        name: the file, as messages name it.
        expanded: the entities the drawing expands to (at least ``held``; the counts may
            stop above the limit, :func:`entity_limit` + 1).
        held: the entities its file holds (model space and the blocks it places, their
            attributes included; every SVG element).
        max_entities: ``--max-entities``; ``None``: :data:`MAX_ENTITIES` in all, of which
            references may add at most :data:`MAX_EXPANSION`.
        references: what places the entities again, for the message (``"<use> clones"``).

    Raises:
        InputError: over either limit; the message names ``--max-entities``.
    """
    limit = entity_limit(max_entities)
    if expanded > limit:
        raise too_many_entities(name, limit)
    if max_entities is None and expanded - held > MAX_EXPANSION:
        raise InputError(
            f"{name}: its {references} expand the {held:,} entities the file holds to "
            f"{expanded:,}, more than the {MAX_EXPANSION:,} they may add without "
            "--max-entities (each costs memory to read: together, gigabytes); if the "
            f"drawing really holds that many, allow them with --max-entities {expanded}"
        )


def entity_limit(max_entities: int | None) -> int:
    """The most entities a drawing may expand to: ``max_entities`` or :data:`MAX_ENTITIES`."""
    return MAX_ENTITIES if max_entities is None else max_entities


def too_many_entities(name: str, limit: int) -> InputError:
    """The error for a drawing that expands to more than ``limit`` entities."""
    return InputError(
        f"{name}: the drawing expands to more than {limit:,} entities (block references, "
        "MINSERT grids and <use> clones included), the --max-entities limit; if it really "
        "holds that many, raise the limit with --max-entities N"
    )


def layer_list(names: Sequence[str]) -> str:
    """The layers ``names`` for a message: each quoted, and how to name one with a comma.

    ``--layers`` splits at commas, so a layer named ``Outline, top`` cannot be given there:
    the message says where it can (a job file's ``layers`` list).
    """
    text = ", ".join(map(repr, names))
    if any("," in name for name in names):
        text += (
            " (--layers splits names at commas: name a layer whose name holds one in a job "
            "file's layers list)"
        )
    return text


@checked_keywords({"fit_mm": "fit"})
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
            ``None``: :data:`MAX_ENTITIES`, of which references may add at most
            :data:`MAX_EXPANSION` to the entities the file holds (:func:`check_expansion`).
        scale: the uniform scale planning will apply to the drawing (``--scale``; 1:
            none). ``tolerance`` holds once scaled: curves are fitted within
            ``tolerance / scale`` at the drawing's size (:meth:`curve_tolerance`).
        fit: the box planning will scale the drawing into (``--fit W H``;
            :func:`~camtool.model.shapes.fit_factor`), or ``None``. Likewise, curves are
            fitted within ``tolerance`` divided by that factor, and
            :func:`camtool.importers.read_drawing` checks the factor of the drawing it
            read (and fits again, finer, if it must).
        shown: layers read even where the drawing hides them (a DXF layer that is off
            or frozen): those a job's operations name. ``layers`` are read so too.

    Raises:
        UsageError: ``max_entities`` is not a positive whole number.
    """

    layers: tuple[str, ...] | None = None
    tolerance: float = 0.001
    units: str | None = None
    hatch_boundaries: bool = False
    max_entities: int | None = None
    scale: float = 1.0
    fit: tuple[float, float] | None = None
    shown: tuple[str, ...] = ()

    def curve_tolerance(self, box: BBox | None = None) -> float:
        """The fitting tolerance at the drawing's size (mm) that is ``tolerance`` once placed.

        A fit within ``t`` of a curve is within ``k·t`` of it once the drawing is scaled
        by ``k``, so the curves of a drawing planning scales by ``k`` are fitted within
        ``tolerance / k``: a drawing scaled up (``--fit`` of a small icon) is fitted
        finer, one scaled down coarser, and the G-code holds ``--tolerance`` either way.
        ``k`` is ``scale``, or with ``fit`` the factor for ``box`` (the drawing's
        extent, or a box within it: a smaller box gives a larger factor, so a finer fit);
        1 without a box, or for a box with neither width nor height (not scaled).
        """
        if self.fit is None:
            return self.tolerance / self.scale
        k = 1.0 if box is None else fit_factor(box, self.fit)
        return self.tolerance / (1.0 if math.isinf(k) else k)

    def at_tolerance(self, tolerance: float) -> ImportOptions:
        """These options with curves fitted within ``tolerance`` (mm at the drawing's size)."""
        return replace(self, tolerance=tolerance, scale=1.0, fit=None)

    def __post_init__(self) -> None:
        if self.max_entities is not None and (
            isinstance(self.max_entities, bool)
            or not (isinstance(self.max_entities, int) and self.max_entities >= 1)
        ):
            raise UsageError(
                f"--max-entities must be a whole number >= 1, got {self.max_entities!r}"
            )
