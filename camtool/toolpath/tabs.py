"""Holding tabs on outside profiles (``--tabs N --tab-width MM --tab-height MM``).

A tab is material left standing between the part and the stock so the part does
not come loose on the last pass. Along the tool-centre path the tool must stay up
over the tab's width *plus its own diameter*: the tool's edge, not its centre,
defines the tab, so a stretch of path ``tab_width + tool_diameter`` long leaves a
tab ``tab_width`` wide at the part (for a straight edge).

Tabs are spaced evenly by arc length over the middle 90 % of the path: the first
and last 5 % hold the entry (plunge or ramp start) and are left free.
"""

from __future__ import annotations

from camtool.model.errors import ToolpathError

ENTRY_MARGIN = 0.05
"""Fraction of the path length kept free of tabs at each end (the entry)."""


def tab_spans(
    length: float, count: int, span: float, where: str = ""
) -> tuple[tuple[float, float], ...]:
    """Where the tool rises over the tabs, as arc-length intervals along a closed path.

    Args:
        length: the path's length, mm (> 0).
        count: number of tabs (≥ 1).
        span: length of path over each tab, mm: ``tab_width + tool_diameter``.
        where: the contour's name for the error message (see
            :func:`camtool.toolpath.cuts.where`).

    Returns:
        ``count`` intervals ``(start, end)`` in mm from the path's start, in
        order, each ``span`` long, centred at ``5 % + (k + ½)·90 %/count`` of the
        length, so none overlaps another or the first/last 5 %.

    Raises:
        ToolpathError: the tabs do not fit (``span`` is not shorter than the
            spacing ``0.9·length/count``).
    """
    spacing = (1.0 - 2.0 * ENTRY_MARGIN) * length / count
    if span >= spacing:
        raise ToolpathError(
            f"{count} tab(s) do not fit on {where or 'a contour'} ({length:.3f} mm long): "
            f"each needs {span:.3f} mm of path (tab width + tool diameter) and they are "
            f"{spacing:.3f} mm apart; use fewer --tabs or a smaller --tab-width"
        )
    margin = ENTRY_MARGIN * length
    centres = [margin + (k + 0.5) * spacing for k in range(count)]
    return tuple((c - span / 2.0, c + span / 2.0) for c in centres)
