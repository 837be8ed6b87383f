"""--tolerance holds at the size planning gives the drawing (--scale, --fit), not as drawn.

Curves are fitted within ``--tolerance`` mm. Before this was fixed they were fitted at the
drawing's own size and the drawing was scaled afterwards, so a Bézier scaled up 19 times
by ``--fit`` came out 18 µm from its curve at the default 1 µm (a scaled-down drawing was
fitted 17 times finer than asked: Inkscape's filters.svg made 768 000 blocks and took
101 s). Expected curves come from svgpathtools (SVG) and ezdxf (DXF), both independent of
the importers, mapped by the placement's own definition (scale about the origin for
``--scale``; for ``--fit`` about the drawing's lower-left corner, here the exact corner of
a frame drawn with straight lines at 0..100).
"""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any

import ezdxf
import pytest

import camtool.importers.svg as svg_importer
from camtool.cli.main import main
from camtool.importers import read_drawing
from camtool.importers.options import ImportOptions
from camtool.jobs.pipeline import post_bytes, post_path
from camtool.model.errors import InputError
from camtool.model.program import ArcMove, Linear, Program
from camtool.model.shapes import Arc, Contour, Drawing, Line, Segment, make_arc
from camtool.post.registry import load_target
from camtool.toolpath.options import PlanOptions
from camtool.toolpath.plan import place
from tests.importers.svgutil import page, svg, true_curve
from tests.importers.svgutil import two_sided_error as svg_error
from tests.shapes import two_sided_error, write_dxf

TOL = 0.001  # mm, the default --tolerance
FRAME = '<path id="frame" d="M 0 0 H 100 V 100 H 0 Z" fill="none" stroke="black"/>'
BEZ_D = "M 0 50 C 20 0, 80 100, 100 50"
BEZ = f'<path id="bez" d="{BEZ_D}" fill="none" stroke="black"/>'


def _placed(path: Path, options: ImportOptions) -> Drawing:
    """The drawing read with ``options`` and placed as planning places it."""
    drawing = read_drawing(path, options)
    return place(drawing, PlanOptions(scale=options.scale, fit=options.fit))


def _factor(options: ImportOptions) -> float:
    """The scale of the 100 × 100 mm frame's drawing: --scale, or --fit's W / 100."""
    return options.scale if options.fit is None else min(options.fit) / 100.0


def _named(drawing: Drawing, name: str) -> list[Contour]:
    return [c for c in drawing.contours if name in c.source]


def test_curve_tolerance_is_the_tolerance_divided_by_the_placement_scale() -> None:
    assert ImportOptions().curve_tolerance() == 0.001
    assert ImportOptions(scale=4.0).curve_tolerance() == 0.001 / 4.0
    assert ImportOptions(scale=0.5).curve_tolerance() == 0.001 / 0.5
    fit = ImportOptions(fit=(100.0, 50.0))
    assert fit.curve_tolerance((0.0, 0.0, 10.0, 10.0)) == 0.001 / 5.0  # min(100/10, 50/10)
    assert fit.curve_tolerance((2.0, 3.0, 202.0, 13.0)) == 0.001 / 0.5  # min(100/200, 50/10)
    assert fit.curve_tolerance(None) == 0.001  # no extent: as drawn
    assert fit.curve_tolerance((5.0, 5.0, 5.0, 5.0)) == 0.001  # a point: --fit leaves it
    exact = fit.at_tolerance(0.0002)
    assert (exact.tolerance, exact.scale, exact.fit) == (0.0002, 1.0, None)
    assert exact.curve_tolerance() == 0.0002


@pytest.mark.parametrize(
    "options",
    [
        ImportOptions(fit=(400.0, 400.0)),
        ImportOptions(scale=4.0),
        ImportOptions(fit=(10.0, 10.0)),
        ImportOptions(scale=0.1),
        ImportOptions(),
    ],
    ids=["fit-up", "scale-up", "fit-down", "scale-down", "as-drawn"],
)
def test_svg_bezier_holds_the_tolerance_once_placed(tmp_path: Path, options: ImportOptions) -> None:
    k = _factor(options)
    placed = _placed(svg(tmp_path, FRAME + BEZ), options)
    curve = true_curve(BEZ_D, lambda xy: k * page(xy), n=40001)
    there, back = svg_error(_named(placed, "bez"), curve)
    assert there <= TOL, f"the curve is {there * 1000:.3f} µm from its arcs"
    assert back <= TOL, f"the arcs are {back * 1000:.3f} µm from the curve"


def test_a_drawing_scaled_down_is_fitted_with_fewer_arcs(tmp_path: Path) -> None:
    path = svg(tmp_path, FRAME + BEZ)
    (as_drawn,) = _named(read_drawing(path), "bez")
    (down,) = _named(read_drawing(path, ImportOptions(fit=(10.0, 10.0))), "bez")
    assert len(down.segments) < len(as_drawn.segments)


def test_a_path_of_zero_length_does_not_widen_the_fit(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # A zero-length path far away is not drawn: its ends do not count in the box the fit
    # is made for, so the drawing is read once, fitted for its own factor (4).
    far = '<path id="dot" d="M 500 500 L 500 500" fill="none" stroke="black"/>'
    path = svg(tmp_path, FRAME + BEZ + far)
    used: list[float] = []
    made = svg_importer.svg_drawing

    def noting(*args: Any, **kwargs: Any) -> tuple[Drawing, float]:
        drawing, tolerance = made(*args, **kwargs)
        used.append(tolerance)
        return drawing, tolerance

    monkeypatch.setattr(svg_importer, "svg_drawing", noting)
    placed = _placed(path, ImportOptions(fit=(400.0, 400.0)))
    assert [c.source for c in placed.contours] == ["path#frame", "path#bez"]
    assert used == [TOL / 4.0]


def test_a_dxf_scaled_up_is_read_again_finer(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # A DXF is read for its size as drawn; its factor (4) known, it is read again, fitted
    # within TOL / 4 (a millionth finer, for the extent the finer fit moves).
    asked = _asked(monkeypatch)
    read_drawing(_spline_dxf(tmp_path / "s.dxf"), ImportOptions(fit=(400.0, 400.0)))
    assert asked == [TOL, pytest.approx(TOL / 4.0 * (1 - 1e-6), rel=1e-12)]


def test_a_dxf_of_lines_only_is_read_once_for_fit(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # A LINE does not depend on the tolerance: the drawing read as drawn is the drawing at
    # any size (a 200 000-LINE drawing was read twice, both copies alive at once).
    def build(msp: Any) -> None:
        msp.add_line((0, 0), (100, 0))
        msp.add_line((100, 0), (100, 100))

    asked = _asked(monkeypatch)
    drawing = read_drawing(write_dxf(tmp_path / "l.dxf", build), ImportOptions(fit=(400.0, 400.0)))
    assert asked == [TOL]
    assert [c.segments[0] for c in drawing.contours] == [
        Line((0.0, 0.0), (100.0, 0.0)),
        Line((100.0, 0.0), (100.0, 100.0)),
    ]


def _asked(monkeypatch: pytest.MonkeyPatch) -> list[float]:
    """The tolerance of each DXF read from now on (the importer's own entry, patched)."""
    import camtool.importers.dxf as dxf_importer

    asked: list[float] = []
    import_dxf = dxf_importer.import_dxf

    def noting(path: Path, options: ImportOptions, **given: Any) -> Any:
        asked.append(options.tolerance)
        return import_dxf(path, options, **given)

    monkeypatch.setattr(dxf_importer, "import_dxf", noting)
    return asked


def _spline_dxf(path: Path) -> Path:
    def build(msp: Any) -> None:
        msp.add_lwpolyline([(0, 0), (100, 0), (100, 100), (0, 100)], close=True)
        msp.add_open_spline([(5, 20, 0), (30, 90, 0), (60, 5, 0), (95, 70, 0)], degree=3)

    return write_dxf(path, build)


@pytest.mark.parametrize(
    "options",
    [ImportOptions(fit=(400.0, 400.0)), ImportOptions(scale=4.0)],
    ids=["fit-up", "scale-up"],
)
def test_dxf_spline_holds_the_tolerance_once_placed(tmp_path: Path, options: ImportOptions) -> None:
    path = _spline_dxf(tmp_path / "s.dxf")
    k = _factor(options)
    splines: list[Any] = [e for e in ezdxf.readfile(path).modelspace() if e.dxftype() == "SPLINE"]
    (spline,) = splines
    bs = spline.construction_tool()
    knots = bs.knots()

    def point_at(t: float) -> tuple[float, float]:
        p = bs.point(t)
        return (k * p[0], k * p[1])

    (contour,) = _named(_placed(path, options), "SPLINE")
    lo, hi = float(knots[bs.degree]), float(knots[bs.count])
    forward, backward = two_sided_error(point_at, lo, hi, contour.segments, TOL)
    assert forward <= TOL and backward <= TOL


def test_a_dxf_scaled_down_is_read_as_drawn(tmp_path: Path) -> None:
    # A DXF is fitted for its size as drawn and fitted again only when --fit scales it up
    # (its extent is known once read): scaled down, its curves are the ones read without.
    path = _spline_dxf(tmp_path / "s.dxf")
    down = read_drawing(path, ImportOptions(fit=(10.0, 10.0)))
    assert down == read_drawing(path)


def _cut_segments(program: Program) -> list[Contour]:
    """The cutting moves of the program's contours that hold an arc, as contours (mm)."""
    by_contour: dict[int, list[Segment]] = {}
    here = program.origin
    for move in program.moves:
        end = (move.x, move.y)
        if isinstance(move, ArcMove):
            seg: Segment = make_arc(here, end, (move.cx, move.cy), move.clockwise)
            by_contour.setdefault(move.contour, []).append(seg)
        elif isinstance(move, Linear) and end != here:
            by_contour.setdefault(move.contour, []).append(Line(here, end))
        here = end
    return [
        Contour(tuple(segs), False)
        for segs in by_contour.values()
        if any(isinstance(s, Arc) for s in segs)
    ]


def test_every_way_in_fits_curves_for_the_planned_size(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # post_path (the CLI, batch --jobs) and post_bytes (a Dask worker) take the planned
    # --fit to the importer; the CLI's file and stdin paths write post_path's code.
    path = svg(tmp_path, FRAME + BEZ)
    target = load_target("linuxcnc")
    plan = PlanOptions(fit=(190.0, 190.0))  # within the 300 × 200 mm travel
    curve = true_curve(BEZ_D, lambda xy: 1.9 * page(xy), n=40001)
    by_path = post_path(path, target, plan)
    by_bytes = post_bytes(path.read_bytes(), path.name, target, plan)
    for job in (by_path, by_bytes):
        (cut,) = _cut_segments(job.program)
        assert max(svg_error([cut], curve)) <= TOL
    assert by_bytes.result.code == by_path.result.code
    fit = ["-t", "linuxcnc", "--fit", "190", "190"]
    assert main(["post", str(path), *fit, "-o", str(tmp_path / "f.ngc")]) == 0
    assert (tmp_path / "f.ngc").read_text() == by_path.result.code
    # standard input is read as DXF: a spline scaled up 1.9 times, fitted again finer
    dxf = _spline_dxf(tmp_path / "s.dxf")
    monkeypatch.setattr("sys.stdin", io.TextIOWrapper(io.BytesIO(dxf.read_bytes())))
    assert main(["post", "-", *fit, "-o", str(tmp_path / "s.ngc")]) == 0
    as_file = str(post_path(dxf, target, plan).result.code)
    assert _blocks((tmp_path / "s.ngc").read_text()) == _blocks(as_file)


def _blocks(code: str) -> list[str]:
    """The program's blocks without its comments (which name the input)."""
    return [line for line in code.splitlines() if not line.startswith("(")]


def test_a_scale_too_large_for_the_tolerance_says_the_tolerance_was_divided(
    tmp_path: Path,
) -> None:
    # 100 mm × 10⁶: a fit within 1 µm would need a tolerance of 10⁻⁹ mm as drawn, the
    # curve 10¹¹ times it; the message says why the tolerance it names is not --tolerance
    path = svg(tmp_path, FRAME + BEZ)
    with pytest.raises(InputError, match=r"--scale and --fit divide it") as err:
        read_drawing(path, ImportOptions(scale=1e6))
    assert "path#bez" in str(err.value) and "1e-09" in str(err.value)


def test_fit_scales_and_fits_what_is_cut_not_a_dashed_guide(tmp_path: Path) -> None:
    """A dashed guide four times the frame's size is not cut, so ``--fit 400 400`` scales
    the frame and its curve by 4 (not by 1, the guide's), and the curve holds the
    tolerance at that size (the importer fits it for the factor planning uses)."""
    guide = (
        '<path id="guide" d="M -150 -150 H 250 V 250 H -150 Z" fill="none" stroke="black" '
        'stroke-dasharray="4 2"/>'
    )
    placed = _placed(svg(tmp_path, FRAME + BEZ + guide), ImportOptions(fit=(400.0, 400.0)))
    curve = true_curve(BEZ_D, lambda xy: 4.0 * page(xy), n=40001)
    there, back = svg_error(_named(placed, "bez"), curve)
    assert there <= TOL, f"the curve is {there * 1000:.3f} µm from its arcs"
    assert back <= TOL, f"the arcs are {back * 1000:.3f} µm from the curve"
