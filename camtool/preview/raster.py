"""Write a preview scene as PNG with matplotlib's Agg backend (headless, no display).

Design notes: docs/internals.md, ``camtool/preview/raster.py``.
"""

from __future__ import annotations

import io
from typing import TYPE_CHECKING, Any

from camtool.model.shapes import Point, Segment
from camtool.preview.scene import (
    Circle,
    Panel,
    Path,
    Polylines,
    Rect,
    Scene,
    Segments,
    Shape,
    Style,
    Text,
)

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

DPI = 100
ARC_TOLERANCE_PX = 0.1
"""Largest distance, pixels, of an arc's chords from the arc: arcs look round at any size."""
_ANCHOR = {"start": "left", "middle": "center", "end": "right"}


def preload() -> None:
    """Import what :func:`scene_png` needs (~0.3 s), in :mod:`camtool.preview.ahead`'s child."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: F401
    from matplotlib.figure import Figure  # noqa: F401


def scene_png(scene: Scene) -> bytes:
    """The PNG bytes of ``scene``."""
    buffer = io.BytesIO()
    scene_figure(scene).savefig(buffer, format="png", dpi=DPI, metadata={"Software": None})
    return buffer.getvalue()


def scene_figure(scene: Scene) -> Figure:
    """``scene`` as a matplotlib figure on an Agg canvas (what :func:`scene_png` saves)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(scene.width_px / DPI, scene.height_px / DPI), dpi=DPI)
    FigureCanvasAgg(fig)
    x0, y0, x1, y1 = scene.page
    points_per_mm = scene.width_px / (x1 - x0) * 72.0 / DPI
    for panel in scene.panels:
        f = panel.frame
        rect = ((f[0] - x0) / (x1 - x0), (f[1] - y0) / (y1 - y0))
        size = ((f[2] - f[0]) / (x1 - x0), (f[3] - f[1]) / (y1 - y0))
        ax = fig.add_axes((*rect, *size))
        ax.set_xlim(panel.window[0], panel.window[2])
        ax.set_ylim(panel.window[1], panel.window[3])
        ax.set_axis_off()
        if panel.background is not None:
            ax.add_artist(_rect(panel.window, Style(fill=panel.background), 0.0, 0))
        _draw(ax, panel, points_per_mm * panel.scale)
        if panel.border is not None:
            border = Style(panel.border.stroke, panel.border.width / panel.scale)
            ax.add_artist(_rect(panel.window, border, points_per_mm * panel.scale, 1000))
    return fig


def _draw(ax: Axes, panel: Panel, pt: float) -> None:
    """Draw every shape of ``panel`` in order; ``pt`` is points per window unit."""
    z = 1
    for layer in panel.layers:
        for shape in layer.shapes:
            _shape(ax, shape, pt, z, clip=panel.clip)
            z += 1


def _shape(ax: Axes, shape: Shape, pt: float, z: int, *, clip: bool) -> None:
    import numpy as np
    from matplotlib import patches
    from matplotlib.collections import LineCollection
    from matplotlib.path import Path as MplPath

    if isinstance(shape, Text):
        from matplotlib import patheffects

        halo = [patheffects.withStroke(linewidth=shape.size * pt * 0.2, foreground="#ffffff")]
        ax.text(
            *shape.at,
            shape.text,
            fontsize=shape.size * pt,
            color=shape.colour,
            ha=_ANCHOR[shape.anchor],
            va="baseline",
            fontweight="bold" if shape.bold else "normal",
            zorder=z,
            clip_on=clip,
            path_effects=halo if shape.halo else None,
        )
    elif isinstance(shape, Circle):
        ax.add_artist(patches.Circle(shape.centre, shape.radius, **_patch(shape.style, pt, z)))
    elif isinstance(shape, Rect):
        ax.add_artist(_rect(shape.box, shape.style, pt, z))
    elif isinstance(shape, Polylines) and shape.closed:
        verts, codes = [], []
        for ring in shape.lines:
            verts.extend([*ring.tolist(), ring[0].tolist()])
            codes.extend(
                [MplPath.MOVETO] + [MplPath.LINETO] * (len(ring) - 1) + [MplPath.CLOSEPOLY]
            )
        path = MplPath(np.asarray(verts), codes)
        ax.add_artist(patches.PathPatch(path, **_patch(shape.style, pt, z)))
    elif isinstance(shape, Segments):
        strokes: Any = shape.xy  # (M, 2, 2): what LineCollection takes, one array
        collection = LineCollection(strokes, **_line(shape.style, pt), zorder=z)
        ax.add_collection(collection, autolim=False)
    else:
        if isinstance(shape, Path):
            # arcs as chords within a tenth of a pixel (pt points per unit, DPI/72 px per point)
            tolerance = ARC_TOLERANCE_PX * 72.0 / (pt * DPI)
            lines = [line for chain in shape.chains for line in _chain_lines(chain, tolerance)]
        else:
            lines = [np.asarray(line) for line in shape.lines]
        collection = LineCollection(lines, **_line(shape.style, pt), zorder=z)
        ax.add_collection(collection, autolim=False)


def _chain_lines(chain: tuple[Segment, ...], tolerance: float) -> list[Any]:
    """A chain as polylines ``(N, 2)``, one per continuous stretch; arcs as chords."""
    import numpy as np

    out: list[list[Point]] = []
    for seg in chain:
        pts = seg.points(tolerance)
        if out and out[-1][-1] == seg.start:
            out[-1].extend(pts[1:])
        else:
            out.append(list(pts))
    return [np.asarray(p, dtype=np.float64) for p in out]


def _line(style: Style, pt: float) -> dict[str, Any]:
    lw = style.width * pt
    out: dict[str, Any] = {
        "colors": style.stroke or "none",
        "linewidths": lw,
        "alpha": style.opacity,
        "capstyle": "butt" if style.dash else "round",
        "joinstyle": "round",
    }
    if style.dash and lw > 0:
        out["linestyles"] = [(0.0, tuple(d * pt / lw for d in style.dash))]
    return out


def _patch(style: Style, pt: float, z: int) -> dict[str, Any]:
    out: dict[str, Any] = {
        "facecolor": style.fill or "none",
        "edgecolor": style.stroke or "none",
        "linewidth": style.width * pt if style.stroke else 0.0,
        "alpha": style.opacity,
        "zorder": z,
    }
    if style.dash and style.width > 0:
        out["linestyle"] = (0.0, tuple(d / style.width for d in style.dash))
    return out


def _rect(box: tuple[float, float, float, float], style: Style, pt: float, z: int) -> Any:
    from matplotlib import patches

    return patches.Rectangle(
        (box[0], box[1]), box[2] - box[0], box[3] - box[1], **_patch(style, pt, z)
    )
