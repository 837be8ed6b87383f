"""Picture of a verification: nominal path, simulated trace coloured by its deviation.

PNG or SVG by the file name ending, drawn headless with matplotlib's Agg
backend. The worst point is marked and annotated, and an inset zooms on it:
on a 5 mm part a 20 µm error is invisible at full scale. Output is
deterministic (no dates; a fixed SVG hash salt) so CI can compare files.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

from camtool.errors import UsageError
from camtool.program import Rapid

if TYPE_CHECKING:
    from matplotlib.axes import Axes

    from camtool.verify.verifier import Verification

FORMATS = (".png", ".svg")
"""Preview file endings."""
_MAX_POINTS = 60_000
_NOMINAL = "#9a9a9a"
_RAPID = "#e0b000"  # yellow rapids, as the thesis GUI (S000-24)
_WORST = "#d62728"


def write_trace_preview(v: Verification, path: str | Path) -> bytes:
    """Draw ``v`` and return the image bytes (the caller writes them atomically).

    Args:
        v: a verification.
        path: the intended file name; its ending picks PNG or SVG.

    Raises:
        UsageError: the ending is neither ``.png`` nor ``.svg``.
    """
    suffix = Path(path).suffix.lower()
    if suffix not in FORMATS:
        raise UsageError(f"{path}: a preview is .png or .svg, not {suffix or 'no ending'!r}")
    import io

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    with matplotlib.rc_context({"svg.hashsalt": "camtool", "font.size": 8}):
        fig = plt.figure(figsize=(7.0, 5.6), dpi=120)
        try:
            ax = fig.add_axes((0.07, 0.09, 0.58, 0.8))
            cax = fig.add_axes((0.72, 0.12, 0.24, 0.025))
            inset = fig.add_axes((0.72, 0.3, 0.24, 0.5))
            _draw(v, ax, cax)
            if v.deviation.block >= 0:
                _inset(v, inset)
            else:
                inset.set_axis_off()
            buffer = io.BytesIO()
            metadata = {"Date": None} if suffix == ".svg" else {"Software": None}
            fig.savefig(buffer, format=suffix[1:], metadata=metadata)
        finally:
            plt.close(fig)
    return buffer.getvalue()


def _trace(v: Verification) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Drawable pieces ``(K, 2, 2)`` of the cutting trace (thinned) and their deviation, µm.

    Consecutive points are joined only inside one run of cutting moves, so a
    rapid never shows as a cut.
    """
    from camtool.verify.metrics import nominal_arrays, point_distances

    program, trace = v.program, v.trace
    rapid = np.asarray([isinstance(m, Rapid) for m in program.moves], dtype=bool)
    if len(trace.block_of_row) == 0:
        return np.zeros((0, 2, 2)), np.zeros(0)
    run = np.cumsum(rapid)[trace.block_of_row]
    keep = np.flatnonzero(~rapid[trace.block_of_row])
    keep = keep[:: max(1, math.ceil(len(keep) / _MAX_POINTS))]
    points, blocks = trace.carriage_mm[keep], trace.block_of_row[keep]
    dev_um = point_distances(points, blocks, nominal_arrays(program)) * 1000.0
    joined = np.flatnonzero(run[keep][1:] == run[keep][:-1])
    pieces = np.stack([points[joined], points[joined + 1]], axis=1)
    return pieces, dev_um[joined + 1]


def _draw(v: Verification, ax: Axes, cax: Axes) -> None:
    from matplotlib.collections import LineCollection

    program = v.program
    _nominal(program, ax, rapids=True)
    pieces, dev_um = _trace(v)
    top = max(float(dev_um.max()) if len(dev_um) else 0.0, 1e-3)
    if len(pieces):
        lines = LineCollection(list(pieces), cmap="plasma", lw=1.4, zorder=2)
        lines.set_array(dev_um)
        lines.set_clim(0.0, top)
        ax.add_collection(lines)
        bar = ax.figure.colorbar(lines, cax=cax, orientation="horizontal")
        bar.set_label("deviation from the path (µm)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.autoscale_view()
    ax.set_xlabel("X (mm)")
    ax.set_ylabel("Y (mm)")
    ax.grid(True, lw=0.3, color="#dddddd")
    box = program.bbox(cutting_only=True)
    ax.set_title(
        f"{v.target}: {box[2] - box[0]:.3f} × {box[3] - box[1]:.3f} mm, "
        f"max deviation {v.deviation.max_um:.2f} µm, rms {v.deviation.rms_um:.2f} µm, "
        f"≈ {v.time_s:.0f} s",
        fontsize=8,
        loc="left",
    )
    if v.deviation.block >= 0:
        wx, wy = v.deviation.at_mm
        line = program.line_of(v.deviation.block)
        where = f"line {line}" if line is not None else f"block {v.deviation.block + 1}"
        ax.plot([wx], [wy], marker="o", ms=8, mfc="none", mec=_WORST, mew=1.5, zorder=4)
        ax.annotate(
            f"max {v.deviation.max_um:.2f} µm, {where}",
            (wx, wy),
            xytext=(10, -14),
            textcoords="offset points",
            color=_WORST,
            fontsize=8,
            zorder=5,
        )


def _nominal(program: object, ax: Axes, *, rapids: bool, tolerance: float = 0.0005) -> None:
    for move, segment in program.segments():  # type: ignore[attr-defined]
        rapid = isinstance(move, Rapid)
        if rapid and not rapids:
            continue
        pts = np.asarray(segment.points(tolerance))
        ax.plot(
            pts[:, 0],
            pts[:, 1],
            color=_RAPID if rapid else _NOMINAL,
            lw=0.8,
            ls="--" if rapid else "-",
            zorder=1,
        )


def _inset(v: Verification, inset: Axes) -> None:
    """A window around the worst point, a few times the error wide."""
    from matplotlib.collections import LineCollection

    wx, wy = v.deviation.at_mm
    half = max(v.deviation.max_um * 4e-3, 0.005)  # mm
    _nominal(v.program, inset, rapids=False, tolerance=half / 400.0)
    pieces, dev_um = _trace(v)
    top = max(float(dev_um.max()) if len(dev_um) else 0.0, 1e-3)
    near = np.all(np.abs(pieces - (wx, wy)) < 2 * half, axis=(1, 2))
    if near.any():
        lines = LineCollection(list(pieces[near]), cmap="plasma", lw=2.0)
        lines.set_array(dev_um[near])
        lines.set_clim(0.0, top)
        inset.add_collection(lines)
    inset.plot([wx], [wy], marker="o", ms=8, mfc="none", mec=_WORST, mew=1.5)
    inset.set_xlim(wx - half, wx + half)
    inset.set_ylim(wy - half, wy + half)
    inset.set_aspect("equal")
    inset.tick_params(labelsize=6)
    inset.set_title(
        f"zoom on the worst point: {2000 * half:.0f} µm window\n"
        "grey: programmed path; colour: simulated tool centre",
        fontsize=7,
    )
