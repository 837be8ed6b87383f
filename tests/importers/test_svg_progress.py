"""The SVG importer tells its stages to a progress callback, and the drawing stays the same.

A drawing built to be large enough for the fit pool (its threshold forced low) must report
``reading`` (the file, then its shapes one by one), ``fitting`` (the distinct curve shapes,
as the fits come in) and ``contours`` (the shapes again), in that order; the callback must not
change a float of the drawing.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from camtool.geometry import fitpool
from camtool.importers import read_drawing
from camtool.importers import svg as svg_module
from camtool.importers.svg import read_svg
from camtool.model.progress import Step
from tests.importers.test_svg_pool import _svg

# what this file checks is done by the accelerated versions only (docs/architecture.md)
pytestmark = pytest.mark.usefixtures("accel_on")

PATHS = 60
SHAPES = PATHS * 2 + 3 + 1
"""Distinct curve shapes of ``_svg(tmp_path, 60)``, the fits made: each path has five curves
(c, q, a with radii 3 and 1.5, an ellipse so fitted, s, t). The random cubics (c) and the
elliptical arcs (a) are each their own; q, s and t have the same control points relative to
their start in every path (``q 2 3 4 -1``; ``s`` and ``t`` follow a curve of another kind,
so their first control point is their start), one shape each; every ninth path adds the same
zero-length cubic at (10, 10), one more."""


def _stages(steps: list[Step]) -> list[str]:
    """The stages in the order met, each once per run of steps."""
    out: list[str] = []
    for s in steps:
        if not out or out[-1] != s.stage:
            out.append(s.stage)
    return out


def test_stages_of_a_large_drawing_in_order(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = _svg(tmp_path, PATHS)
    plain = read_svg(path)
    monkeypatch.setattr(svg_module, "MIN_CURVES", 1)
    monkeypatch.setattr(fitpool, "MIN_CURVES", 1)
    monkeypatch.setattr(
        fitpool.FIT_KERNELS, "_loaded", (None,)
    )  # the pool's chunks, not compiled fits
    monkeypatch.setattr(fitpool, "_CHUNK", 7)
    steps: list[Step] = []
    drawing = read_svg(path, progress=steps.append)
    assert repr(drawing) == repr(plain)
    assert _stages(steps) == ["reading", "fitting", "contours"]
    assert steps[0] == Step("reading", 0, 0, "many.svg")
    reading = [s for s in steps if s.stage == "reading"][1:]
    assert [(s.done, s.total, s.name) for s in reading] == [
        (i, PATHS, "many.svg") for i in range(PATHS + 1)
    ]  # 0 once counted, then each shape as it is read
    fitting = [s for s in steps if s.stage == "fitting"]
    assert {s.total for s in fitting} == {SHAPES}
    # the start, then one step per chunk of 7 fits as the workers answer, in order
    expected = [*range(0, SHAPES, 7)[1:], SHAPES]
    assert [s.done for s in fitting] == [0, *expected]
    contours = [s for s in steps if s.stage == "contours"]
    assert [(s.done, s.total) for s in contours] == [(i, PATHS) for i in range(PATHS + 1)]


def test_fits_here_count_one_by_one(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """With the curves fitted ahead but no pool (one job), every fit is counted."""
    path = _svg(tmp_path, 9)
    monkeypatch.setattr(svg_module, "MIN_CURVES", 1)
    monkeypatch.setattr(fitpool, "default_jobs", lambda: 1)
    steps: list[Step] = []
    read_svg(path, progress=steps.append)
    fitting = [s.done for s in steps if s.stage == "fitting"]
    assert fitting == list(range(9 * 2 + 3 + 1 + 1))  # 9 c, 9 a, the q, s, t and zero shapes


def test_a_small_drawing_has_no_fitting_stage(tmp_path: Path) -> None:
    """Below the pool's threshold the curves are fitted as met: reading, then contours."""
    steps: list[Step] = []
    read_drawing(_svg(tmp_path, 3), progress=steps.append)
    assert _stages(steps) == ["reading", "contours"]
