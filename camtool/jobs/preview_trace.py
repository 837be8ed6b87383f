"""Picture of a verification (kept for its callers): see :func:`camtool.preview.render_preview`."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from camtool.preview import FORMATS, render_preview

if TYPE_CHECKING:
    from camtool.model.shapes import Drawing
    from camtool.verify.verifier import Verification

__all__ = ["FORMATS", "write_trace_preview"]


def write_trace_preview(
    v: Verification,
    path: str | Path,
    *,
    drawing: Drawing | None = None,
    edge_radius_mm: float = 0.0,
) -> bytes:
    """Draw ``v`` and return the image bytes (the caller writes them atomically).

    The nominal path, rapids, the simulated trace coloured by its deviation in
    µm with a colour scale, the worst point with its code line, and a zoom inset
    on it (:func:`camtool.preview.render_preview`).

    Args:
        v: a verification.
        path: the intended file name; its ending picks PNG or SVG.
        drawing: the drawing in program coordinates, drawn under the path.
        edge_radius_mm: tool radius of an offset cut, mm (draws the tool width).

    Raises:
        UsageError: the ending is neither ``.png`` nor ``.svg``.
    """
    return render_preview(path, verification=v, drawing=drawing, edge_radius_mm=edge_radius_mm)
