"""The error budget: each figure of a verification, and what it is with one source off.

Design notes: docs/internals.md, ``camtool/verify/budget.py``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from camtool.model.units import fmt_num
from camtool.verify.contour_measures import ContourMeasure
from camtool.verify.deviations import Deviation
from camtool.verify.drawing_compare import Against
from camtool.verify.path_shortfall import AlongPath
from camtool.verify.sources import SOURCES

MAX_CONTOURS = 20
"""Contours whose figures enter the budget (the first ones, in cutting order)."""
MAX_ROWS = 3_000_000
"""Largest trace (rows) the budget re-simulates; above it the budget is skipped with a note."""
NOTE = (
    "each figure: the total with every source on, and the figure re-simulated with only one "
    "source off (difference = total - without); sources do not add"
)

Figures = dict[str, float]
"""Figure name → value, µm (signed for size and diameter errors, else >= 0)."""


def figures(
    deviation: Deviation,
    along: AlongPath | None,
    contours: Sequence[ContourMeasure],
    against: Against | None,
) -> Figures:
    """The figures of one simulation, by name (see the module docstring)."""
    out: Figures = {"max deviation": deviation.max_um}
    if along is not None:
        out["shortfall along the path"] = along.shortfall_um
    for c in contours[:MAX_CONTOURS]:
        if c.closure_um is not None:
            out[f"contour {c.number} closure gap"] = math.hypot(*c.closure_um)
        out[f"contour {c.number} size error x"] = c.size_error_um[0]
        out[f"contour {c.number} size error y"] = c.size_error_um[1]
        if c.circle is not None:
            out[f"contour {c.number} diameter error"] = (c.circle[1] - c.circle[0]) * 1000.0
    return out | against_figures(against)


def against_figures(against: Against | None) -> Figures:
    """The figures of a drawing comparison: those :func:`figures` adds for it."""
    return {} if against is None else distance_figures(against.max_um)


def distance_figures(max_um: float) -> Figures:
    """:func:`against_figures` of a comparison whose largest distance is ``max_um``."""
    return {"distance to the drawing": max_um}


@dataclass(frozen=True)
class SourceStatus:
    """Whether a source is in the budget.

    Attributes:
        name: the source's switch name (a key of :data:`camtool.verify.sources.SOURCES`).
        status: ``"modelled"`` (re-simulated without it), ``"absent"`` (the machine
            or the program has none of it) or ``"unknown"`` (it exists but cannot be
            known from what is at hand).
        why: a few words for ``absent`` and ``unknown``.
    """

    name: str
    status: str
    why: str = ""

    @property
    def label(self) -> str:
        """The source in words (``"steps/mm scale"``)."""
        return SOURCES[self.name]


@dataclass(frozen=True)
class ErrorBudget:
    """Every figure with everything on and with each modelled source off.

    Attributes:
        total: figure → value with every source on, µm.
        without: source → figure → value with only that source off, µm (modelled
            sources only; a figure missing there could not be compared).
        sources: every source's status, in :data:`camtool.verify.sources.SOURCES` order.
        skipped: why the budget was not computed (then ``without`` is empty), else ``None``.
        notes: what else a reader should know (contours left out, ...).
    """

    total: Figures
    without: Mapping[str, Figures] = field(default_factory=dict)
    sources: tuple[SourceStatus, ...] = ()
    skipped: str | None = None
    notes: tuple[str, ...] = ()

    def difference(self, source: str, figure: str) -> float | None:
        """Total − the figure with only ``source`` off, µm (``None`` when not known)."""
        value = self.without.get(source, {}).get(figure)
        return None if value is None else self.total[figure] - value

    def dominant(self, figure: str) -> str | None:
        """The source with the largest |difference| on ``figure`` (``None``: none known)."""
        known = [
            (abs(d), name)
            for name in self.without
            if (d := self.difference(name, figure)) is not None
        ]
        return max(known)[1] if known and max(known)[0] > 0 else None

    @property
    def headline(self) -> str | None:
        """The figure the one-line verdict is about: the largest |total| with a dominant source."""
        ranked = sorted(self.total, key=lambda f: -abs(self.total[f]))
        return next((f for f in ranked if self.dominant(f) is not None), None)

    def dominant_text(self, figure: str | None = None) -> str | None:
        """``"contour 1 diameter error: dominant steps/mm scale (-105.8 µm of -82.9 µm total)"``."""
        figure = figure or self.headline
        if figure is None:
            return None
        source = self.dominant(figure)
        if source is None:
            return None
        diff = self.difference(source, figure)
        assert diff is not None
        return (
            f"{figure}: dominant {SOURCES[source]} ({_um(diff)} µm of "
            f"{_um(self.total[figure])} µm total)"
        )


def compute(
    total: Figures,
    statuses: Sequence[SourceStatus],
    without: Mapping[str, Figures],
    *,
    notes: Sequence[str] = (),
) -> ErrorBudget:
    """The budget: ``without[source]``, the figures re-measured with that source off.

    A figure that the re-simulation does not have (the program read differently)
    is left out of that source's column; the columns follow the modelled sources
    of ``statuses``, in order.
    """
    columns = {
        s.name: {k: v for k, v in without[s.name].items() if k in total}
        for s in statuses
        if s.status == "modelled"
    }
    return ErrorBudget(total, columns, tuple(statuses), None, tuple(notes))


def to_json(b: ErrorBudget, digits: Callable[[float], float]) -> dict[str, Any]:
    """The ``error_budget`` report key (``digits`` rounds a µm value)."""
    rows = []
    for name, value in b.total.items():
        rows.append(
            {
                "figure": name,
                "total_um": digits(value),
                "without_um": {
                    s: digits(f[name]) if name in f else None for s, f in b.without.items()
                },
                "difference_um": {
                    s: None if (d := b.difference(s, name)) is None else digits(d)
                    for s in b.without
                },
                "dominant": b.dominant(name),
            }
        )
    return {
        "note": NOTE,
        "skipped": b.skipped,
        "sources": [
            {"source": s.name, "label": s.label, "status": s.status, "why": s.why or None}
            for s in b.sources
        ],
        "figures": rows,
        "dominant": b.dominant_text(),
        "notes": list(b.notes),
    }


def text_lines(b: ErrorBudget, *, limit: int = 8) -> list[str]:
    """The budget for the one-screen summary (at most ``limit`` figures)."""
    if b.skipped is not None:
        return [f"error budget skipped: {b.skipped}"]
    modelled = list(b.without)
    lines = [
        "error budget, µm: total with everything on, its dominant source; then with only "
        "this one off (difference); sources do not add"
    ]
    shown = sorted(b.total, key=lambda f: -abs(b.total[f]))[:limit]
    for name in (f for f in b.total if f in shown):
        parts = []
        for s in modelled:
            d = b.difference(s, name)
            if d is not None:
                parts.append(f"{_short_label(s)} {_um(b.without[s][name])} ({_um(d)})")
        top = b.dominant(name)
        lead = f"  {name} {_um(b.total[name])}"
        if top is not None:
            lead += f", dominant {SOURCES[top]} ({_um(b.difference(top, name) or 0.0)})"
        lines.append(f"{lead}; without: " + ", ".join(parts))
    verdict = b.dominant_text()
    if verdict:
        lines.append(f"  largest figure: {verdict}")
    absent = [f"{s.label} ({s.why})" for s in b.sources if s.status != "modelled"]
    if absent:
        lines.append("  not in the budget: " + "; ".join(absent))
    lines.extend(f"  {note}" for note in b.notes)
    return lines


def _short_label(source: str) -> str:
    return {
        "interpolation": "interpolation",
        "chords": "chords",
        "scale": "scale",
        "backlash": "backlash",
        "dynamics": "dynamics",
        "rounding": "rounding",
    }[source]


def _um(value: float) -> str:
    """Signed µm with 1 decimal, ``-0`` never shown."""
    text = fmt_num(value, 1)
    return "0.0" if text == "-0.0" else text
