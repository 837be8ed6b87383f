"""Previews a person can read: a program, a drawing, or a verification, as SVG or PNG.

Design notes: docs/internals.md, ``camtool/preview/__init__.py``.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from camtool.model.errors import UsageError
from camtool.model.program import Program
from camtool.model.progress import Progress, Step, no_progress
from camtool.model.shapes import BBox, Drawing
from camtool.preview.program_layers import AREA_COLOUR, CUT_COLOUR, RAPID_COLOUR

if TYPE_CHECKING:
    from camtool.model.machine import Machine
    from camtool.post.base import Target
    from camtool.verify.verifier import Verification

__all__ = [
    "AREA_COLOUR",
    "CUT_COLOUR",
    "FORMATS",
    "RAPID_COLOUR",
    "preview_format",
    "program_svg",
    "render_preview",
]

FORMATS = (".png", ".svg")
"""Preview file endings."""
WIDTH_PX = 900
"""Default picture width, pixels."""


def preview_format(path_or_suffix: str | Path) -> str:
    """``".png"`` or ``".svg"``: the preview format a file name (or a bare ending) asks for.

    Raises:
        UsageError: any other ending (the message lists the valid ones).
    """
    text = str(path_or_suffix)
    suffix = text.lower() if text.startswith(".") and "/" not in text else Path(text).suffix.lower()
    if suffix not in FORMATS:
        got = repr(suffix) if suffix else "no ending"
        raise UsageError(f"{text}: a preview is {' or '.join(FORMATS)}, not {got}")
    return suffix


def render_preview(
    path_or_suffix: str | Path,
    *,
    program: Program | None = None,
    drawing: Drawing | None = None,
    verification: Verification | None = None,
    target: Target | None = None,
    edge_radius_mm: float = 0.0,
    title: str | None = None,
    work_area: BBox | None = None,
    width_px: int = WIDTH_PX,
    sections: Sequence[tuple[str, int, int]] | None = None,
    progress: Progress = no_progress,
) -> bytes:
    """Draw a preview and return the file's bytes (the caller writes them, atomically).

    Args:
        path_or_suffix: the intended file name or just its ending: ``.svg`` or ``.png``.
        program: the moves to draw, mm (default: the verification's program).
        drawing: a drawing in the program's coordinates, drawn under it (mm).
        verification: adds the simulated trace, the worst point and the inset.
        target: gives the work area, the name and the timing model of the time
            estimate (a verification brings its own machine and name).
        edge_radius_mm: tool radius of an offset cut, mm; > 0 draws the swept tool.
        title: a first title line (e.g. the input's name); the facts follow.
        work_area: ``(xmin, ymin, xmax, ymax)`` mm, instead of the target's.
        width_px: picture width in pixels (the height keeps the page's aspect).
        sections: ``(label, first move, end move)`` parts of ``program`` cut in colours
            of their own (a job's operations); ``None``: one per tool where the
            program changes tools. Tool changes are marked either way.
        progress: told the ``drawing`` stage (``total``: the program's moves).

    Returns:
        SVG text encoded as UTF-8, or PNG bytes. Same input, same SVG bytes.

    Raises:
        UsageError: the ending is neither ``.png`` nor ``.svg``, or there is
            nothing to draw.
        CamtoolError: the target's machine cannot be simulated for the time estimate.
    """
    from camtool.preview.layout import Content, compose, estimated_time

    suffix = preview_format(path_or_suffix)
    if program is None and verification is not None:
        program = verification.program
    machine = verification.machine if verification is not None else None
    if machine is None and target is not None:
        machine = target.machine
    name = verification.target if verification is not None else target.name if target else ""
    if work_area is None and machine is not None:
        work_area = machine.work_area_mm
    if (program is None or not program.moves) and (drawing is None or not drawing.contours):
        raise UsageError("nothing to preview: the program has no moves and there is no drawing")
    progress(Step("drawing", 0, len(program.moves) if program is not None else 0))
    content = Content(
        program=program,
        drawing=drawing,
        verification=verification,
        work_area=work_area,
        target_name=name,
        time=estimated_time(program, machine, verification),
        edge_radius_mm=edge_radius_mm,
        title=title,
        width_px=width_px,
        sections=_sections(program, sections),
        resolution_mm=_resolution_mm(machine, target),
    )
    scene = compose(content)
    if suffix == ".svg":
        from camtool.preview.svg import scene_svg

        return scene_svg(scene).encode("utf-8")
    from camtool.preview.ahead import draw_ahead

    drawn = draw_ahead(scene)  # by the child a command started ahead, if there is one
    if drawn is not None:
        return drawn
    from camtool.preview.raster import scene_png

    return scene_png(scene)


def _resolution_mm(machine: Machine | None, target: Target | None) -> float | None:
    """The machine's XY resolution, mm: its motor step or its code's quantum, the coarser."""
    if machine is None:
        return None
    steps = [1.0 / s for s in machine.steps_per_mm[:2] if s > 0]
    quantum = target.post.resolution_mm() if target is not None else None
    candidates = [*steps, *([quantum] if quantum else [])]
    return max(candidates) if candidates else None


def _sections(
    program: Program | None, sections: Sequence[tuple[str, int, int]] | None
) -> tuple[tuple[str, int, int], ...]:
    """The sections drawn in colours: given, or the program's tools; none for one.

    A section of no moves (a job's operation left with nothing to cut) is not drawn.
    """
    from camtool.preview.program_layers import sections_of

    if program is None:
        return ()
    chosen = tuple(sections) if sections is not None else sections_of(program)
    chosen = tuple(s for s in chosen if s[2] > s[1])  # not an operation left with nothing
    return chosen if len(chosen) > 1 else ()


def program_svg(program: Program, *, work_area: BBox | None = None, title: str = "") -> str:
    """Draw ``program`` as an SVG document (see :func:`render_preview`); time at programmed feeds.

    Args:
        program: the program to draw.
        work_area: the machine's ``(xmin, ymin, xmax, ymax)`` in mm, drawn as a
            dashed frame; ``None`` draws none.
        title: a first title line.

    Raises:
        UsageError: the program has no moves.
    """
    data = render_preview(".svg", program=program, work_area=work_area, title=title or None)
    return data.decode("utf-8")
