"""DXF ELLIPSE and SPLINE: biarc fits hold the tolerance against ezdxf's own curve.

Every fit test samples the TRUE curve densely with ezdxf's evaluation of the entity as
read back from the file (BSpline.point, the ellipse's parametric form) and checks both
ways: every curve sample within the tolerance of the fitted contour, and every point of
the contour within the tolerance of the curve (tests/shapes.two_sided_error).

The property test runs a few examples; set CAMTOOL_FIT_EXAMPLES=300 for a deeper search (a
few hundred passed when this was written).
"""

from __future__ import annotations

import math
import os
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

import ezdxf
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from camtool.importers.dxf import read_dxf
from camtool.importers.options import ImportOptions
from camtool.model.errors import InputError
from camtool.model.shapes import Arc, Contour
from tests.shapes import two_sided_error, write_dxf

TOL = 0.001  # mm, the default --tolerance


Curve = tuple[Callable[[float], tuple[float, float]], float, float]


def _spline_curve(path: Path, index: int = 0) -> Curve:
    """A SPLINE's true curve as ezdxf evaluates it, over its valid domain [u_p, u_n]."""
    splines = [e for e in ezdxf.readfile(path).modelspace() if e.dxftype() == "SPLINE"]
    bs = splines[index].construction_tool()
    k = bs.knots()

    def point_at(t: float) -> tuple[float, float]:
        p = bs.point(t)
        return (p[0], p[1])

    return point_at, float(k[bs.degree]), float(k[bs.count])


def _ellipse_curve(entity: Any) -> Curve:
    """An ELLIPSE from its DXF definition: c + M cos t + m sin t, t0 to t1 (ezdxf axes)."""
    ce = entity.construction_tool()
    t0, t1 = ce.start_param, ce.end_param
    if t1 <= t0:
        t1 += math.tau
    (cx, cy), (mx, my), (nx, ny) = ((v[0], v[1]) for v in (ce.center, ce.major_axis, ce.minor_axis))

    def point_at(t: float) -> tuple[float, float]:
        return (cx + mx * math.cos(t) + nx * math.sin(t), cy + my * math.cos(t) + ny * math.sin(t))

    return point_at, t0, t1


def _assert_fits(curve: Curve, contour: Contour, tol: float = TOL, n: int = 2000) -> None:
    point_at, t0, t1 = curve
    forward, backward = two_sided_error(point_at, t0, t1, contour.segments, tol, n)
    assert forward <= tol, f"curve is {forward} mm from the fit"
    assert backward <= tol, f"fit is {backward} mm from the curve"
    assert contour.start == pytest.approx(point_at(t0), abs=1e-9)


@pytest.mark.parametrize("degree", [2, 3, 5])
def test_open_spline_fit_holds_tolerance(tmp_path: Path, degree: int) -> None:
    cps = [(0, 0), (10, 25), (30, -10), (45, 30), (60, 5), (75, 20), (90, 0)]

    def build(msp: Any) -> None:
        msp.add_open_spline([(*p, 0) for p in cps], degree=degree)

    path = write_dxf(tmp_path / "s.dxf", build)
    (contour,) = read_dxf(path).contours
    assert contour.source.startswith("SPLINE #") and not contour.closed
    assert any(isinstance(s, Arc) for s in contour.segments)
    _assert_fits(_spline_curve(path), contour)
    # a clamped spline ends on its last control point
    assert contour.end == pytest.approx((90.0, 0.0), abs=1e-9)


def test_tolerance_option_is_in_mm_even_for_inch_drawings(tmp_path: Path) -> None:
    # The same curve in inches: the fit must hold 0.01 mm, i.e. 0.01/25.4 in.
    def build(msp: Any) -> None:
        msp.add_open_spline([(0, 0, 0), (1, 2, 0), (3, -1, 0), (4, 1, 0)], degree=3)

    path = write_dxf(tmp_path / "in.dxf", build, insunits=1)
    coarse = read_dxf(path, ImportOptions(tolerance=0.01)).contours[0]
    fine = read_dxf(path, ImportOptions(tolerance=0.001)).contours[0]
    point_at, t0, t1 = _spline_curve(path)

    def in_mm(t: float) -> tuple[float, float]:
        x, y = point_at(t)
        return (x * 25.4, y * 25.4)

    _assert_fits((in_mm, t0, t1), coarse, 0.01)
    _assert_fits((in_mm, t0, t1), fine, 0.001)
    assert len(fine.segments) > len(coarse.segments)


def test_fit_point_spline(tmp_path: Path) -> None:
    fit = [(0, 0), (10, 8), (20, -3), (35, 6), (50, 0)]

    def build(msp: Any) -> None:
        msp.add_spline([(*p, 0) for p in fit])  # fit points only, as AutoCAD's SPLINE

    path = write_dxf(tmp_path / "f.dxf", build)
    (contour,) = read_dxf(path).contours
    (spline,) = ezdxf.readfile(path).modelspace().query("SPLINE")
    assert spline.control_point_count() == 0  # really a fit-point-only spline
    _assert_fits(_spline_curve(path), contour)
    # the curve passes through every fit point (the definition of a fit point)
    from camtool.geometry.arcfit import distances

    assert float(np.max(distances(np.array(fit, float), contour.segments))) <= TOL


def test_closed_periodic_spline_is_a_closed_contour(tmp_path: Path) -> None:
    def build(msp: Any) -> None:
        spline = msp.add_spline()
        spline.set_closed([(0, 0, 0), (20, 0, 0), (20, 10, 0), (0, 10, 0)], degree=3)

    path = write_dxf(tmp_path / "c.dxf", build)
    (contour,) = read_dxf(path).contours
    assert contour.closed and contour.end == contour.start
    _assert_fits(_spline_curve(path), contour)


def test_periodic_spline_with_n_plus_1_knots_equals_the_unwrapped_one(tmp_path: Path) -> None:
    # ObjectARX stores a periodic spline with count + 1 knots and no repeated control
    # points; it is the same curve as the uniform closed spline ezdxf writes.
    cps = [(0, 0, 0), (20, 0, 0), (25, 12, 0), (5, 15, 0), (-4, 6, 0)]

    def build(msp: Any) -> None:
        a = msp.add_spline()
        a.set_closed(cps, degree=3)
        b = msp.add_spline(dxfattribs={"flags": 3, "degree": 3})
        b.control_points = cps
        b.knots = [float(k) for k in range(len(cps) + 1)]

    path = write_dxf(tmp_path / "p.dxf", build)
    wrapped, arx = read_dxf(path).contours
    assert arx.closed
    _assert_fits(_spline_curve(path, 0), arx)
    assert wrapped.length == pytest.approx(arx.length, abs=2 * TOL)


def test_rational_spline_circle_fits_as_its_circle(tmp_path: Path) -> None:
    # A NURBS quarter circle (weights 1, √2/2, 1) is exactly a circle: the fit's
    # points must stay on radius 10 within the tolerance.
    def build(msp: Any) -> None:
        w = math.sqrt(0.5)
        msp.add_rational_spline([(10, 0, 0), (10, 10, 0), (0, 10, 0)], [1, w, 1], degree=2)

    (contour,) = read_dxf(write_dxf(tmp_path / "r.dxf", build)).contours
    assert contour.start == pytest.approx((10, 0)) and contour.end == pytest.approx((0, 10))
    for seg in contour.segments:
        for k in range(17):
            assert math.hypot(*seg.point_at(k / 16)) == pytest.approx(10.0, abs=TOL)


def _circle_as_degree(msp: Any, declared: int, knots: list[float] | None = None) -> None:
    """A NURBS full circle of radius 10 at (5, 5) (9 control points, the quadratic's
    12 knots, weights 1 and √2/2), its degree written as ``declared``."""
    w = math.sqrt(0.5)
    corners = [(15, 5), (15, 15), (5, 15), (-5, 15), (-5, 5), (-5, -5), (5, -5), (15, -5), (15, 5)]
    spline = msp.add_rational_spline(
        [(x, y, 0) for x, y in corners], [1, w, 1, w, 1, w, 1, w, 1], degree=2
    )
    spline.knots = knots or [0, 0, 0, 1, 1, 2, 2, 3, 3, 4, 4, 4]
    spline.dxf.degree = declared


def test_a_quadratic_written_as_degree_3_is_read_as_its_circle(tmp_path: Path) -> None:
    """dxf-parser's ``arcs-as-splines.dxf`` writes its circles so; ezdxf refuses them (12
    knots where degree 3 needs 13) and camtool skipped them with a warning."""
    d = read_dxf(write_dxf(tmp_path / "c.dxf", lambda m: _circle_as_degree(m, 3)))
    (contour,) = d.contours
    assert contour.closed and all(isinstance(seg, Arc) for seg in contour.segments)
    for seg in contour.segments:
        for k in range(17):
            x, y = seg.point_at(k / 16)
            assert math.hypot(x - 5, y - 5) == pytest.approx(10.0, abs=TOL)
    assert contour.length == pytest.approx(20 * math.pi, abs=2 * TOL)
    (warning,) = [w for w in d.warnings if "SPLINE" in w]
    assert "declared 3, its data that of degree 2" in warning


def test_counts_that_imply_no_clamped_degree_stay_invalid(tmp_path: Path) -> None:
    """12 knots of 9 control points imply degree 2, but these do not start with three equal
    knots: no one curve is described, and the SPLINE is skipped as before."""
    knots = [0, 0, 0.5, 1, 1, 2, 2, 3, 3, 4, 4, 4]

    def build(msp: Any) -> None:
        msp.add_line((0, 0), (1, 0))
        _circle_as_degree(msp, 3, knots)

    d = read_dxf(write_dxf(tmp_path / "c.dxf", build))
    assert len(d.contours) == 1
    assert any("skipped 1 SPLINE entity (invalid spline data)" in w for w in d.warnings)


@pytest.mark.parametrize(
    ("inner", "why"),
    [
        ([0.7, 0.5], "its knots decrease"),  # no B-spline has them
        ([0.5, 0.5 + 1e-12], "ezdxf cannot evaluate it"),  # ezdxf's basis divides by ~0
    ],
)
def test_a_spline_whose_knots_cannot_be_evaluated_is_skipped_by_name(
    tmp_path: Path, inner: list[float], why: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """Knots that decrease, or that ezdxf's evaluator cannot take, skip the SPLINE with a
    warning, and ``inspect`` says why (not an internal error, not a curve made up)."""
    from camtool.cli.main import main

    def build(msp: Any) -> None:
        msp.add_line((0, 0), (1, 0))
        spline = msp.add_open_spline([(0, 0, 0), (1, 2, 0), (3, -1, 0), (4, 1, 0), (6, 0, 0)])
        spline.knots = [0, 0, 0, 0, *inner, 1, 1, 1]

    path = write_dxf(tmp_path / "k.dxf", build)
    d = read_dxf(path)
    assert len(d.contours) == 1
    assert any("skipped 1 SPLINE entity (invalid spline data)" in w for w in d.warnings)
    assert main(["inspect", str(path)]) == 0
    assert f"invalid spline data: {why}" in capsys.readouterr().out


def test_spline_with_a_corner_knot_keeps_the_corner(tmp_path: Path) -> None:
    # degree 2 with a double inner knot: the curve passes the middle control point
    # with a corner there (C0); the fit must hold around it.
    def build(msp: Any) -> None:
        cps = [(0, 0, 0), (5, 10, 0), (10, 0, 0), (15, 10, 0), (20, 0, 0)]
        msp.add_open_spline(cps, degree=2, knots=[0, 0, 0, 1, 1, 2, 2, 2])

    path = write_dxf(tmp_path / "k.dxf", build)
    (contour,) = read_dxf(path).contours
    _assert_fits(_spline_curve(path), contour)
    assert any(s.end == pytest.approx((10.0, 0.0), abs=1e-12) for s in contour.segments)


@pytest.mark.parametrize(
    ("major", "ratio", "t0", "t1", "closed"),
    [
        ((30, 0, 0), 0.4, 0.0, math.tau, True),  # full
        ((30, 0, 0), 0.4, 0.5, 2.5, False),  # partial
        ((20, 20, 0), 0.25, 4.0, 1.0, False),  # rotated 45°, wrapping through 0
    ],
)
def test_ellipse_fit_holds_tolerance(
    tmp_path: Path, major: tuple[float, ...], ratio: float, t0: float, t1: float, closed: bool
) -> None:
    def build(msp: Any) -> None:
        msp.add_ellipse((5, 7), major, ratio, t0, t1)

    path = write_dxf(tmp_path / "e.dxf", build)
    (contour,) = read_dxf(path).contours
    assert contour.closed is closed
    (entity,) = ezdxf.readfile(path).modelspace().query("ELLIPSE")
    _assert_fits(_ellipse_curve(entity), contour)


def test_mirrored_ellipse_runs_clockwise(tmp_path: Path) -> None:
    # extrusion (0,0,-1): minor axis = extrusion x major points -Y; t runs clockwise.
    def build(msp: Any) -> None:
        msp.add_ellipse(
            (0, 0), (10, 0, 0), 0.5, 0, math.pi / 2, dxfattribs={"extrusion": (0, 0, -1)}
        )

    path = write_dxf(tmp_path / "m.dxf", build)
    (contour,) = read_dxf(path).contours
    assert contour.start == pytest.approx((10, 0)) and contour.end == pytest.approx((0, -5))
    (entity,) = ezdxf.readfile(path).modelspace().query("ELLIPSE")
    _assert_fits(_ellipse_curve(entity), contour)


def test_circular_ellipse_is_an_exact_arc(tmp_path: Path) -> None:
    def build(msp: Any) -> None:
        msp.add_ellipse((1, 2), (0, 5, 0), 1.0)  # full circle of radius 5
        msp.add_ellipse((1, 2), (5, 0, 0), 1.0, 0.0, math.pi / 3)

    full, part = read_dxf(write_dxf(tmp_path / "c.dxf", build)).contours
    (arc,) = full.segments
    assert isinstance(arc, Arc) and arc.is_full_circle and full.closed
    assert arc.centre == (1.0, 2.0) and arc.radius == pytest.approx(5.0, abs=1e-12)
    (arc,) = part.segments
    assert isinstance(arc, Arc) and not arc.clockwise
    assert arc.sweep == pytest.approx(math.pi / 3, abs=1e-12)


def test_ellipse_end_param_rounded_by_the_cad_program_still_closes(tmp_path: Path) -> None:
    # FreeCAD 0.20 writes end_param 6.28318 (6 digits): the ends are 1.6e-5 mm apart.
    def build(msp: Any) -> None:
        msp.add_ellipse((28, 10), (6, 0, 0), 0.5, 0.0, 6.28318)

    (contour,) = read_dxf(write_dxf(tmp_path / "fc.dxf", build)).contours
    assert contour.closed and contour.end == contour.start


_coord = st.floats(-50, 50, allow_nan=False).map(lambda v: round(v, 4))


@settings(max_examples=int(os.environ.get("CAMTOOL_FIT_EXAMPLES", "10")), deadline=None)
@given(
    degree=st.integers(2, 5),
    points=st.lists(st.tuples(_coord, _coord), min_size=6, max_size=9),
    tol=st.sampled_from([0.01, 0.001]),
)
def test_property_random_spline_fit_holds_tolerance(
    degree: int, points: list[tuple[float, float]], tol: float
) -> None:
    with tempfile.TemporaryDirectory() as tmp:

        def build(msp: Any) -> None:
            msp.add_open_spline([(*p, 0) for p in points], degree=degree)

        path = write_dxf(Path(tmp) / "h.dxf", build)
        curve = _spline_curve(path)
        if np.ptp(np.array(points), axis=0).max() == 0.0:  # all on one spot: no curve
            with pytest.raises(InputError, match="no usable entity"):
                read_dxf(path, ImportOptions(tolerance=tol))
            return
        (contour,) = read_dxf(path, ImportOptions(tolerance=tol)).contours
    _assert_fits(curve, contour, tol)


def _counting_evaluators(monkeypatch: pytest.MonkeyPatch) -> tuple[list[int], list[int]]:
    """Count the ezdxf evaluators built and the lengths of their ``points`` batches."""
    from ezdxf.math import BSpline

    built: list[int] = []
    batches: list[int] = []
    evaluator = BSpline.evaluator

    class Counting:
        def __init__(self, inner: Any) -> None:
            self.inner = inner

        def point(self, t: float) -> Any:
            return self.inner.point(t)

        def derivative(self, t: float, n: int) -> Any:
            return self.inner.derivative(t, n)

        def points(self, ts: Any) -> Any:
            batches.append(len(ts))
            return self.inner.points(ts)

    def counting(spline: BSpline) -> Counting:
        built.append(1)
        return Counting(evaluator.fget(spline))  # type: ignore[attr-defined]

    monkeypatch.setattr(BSpline, "evaluator", property(counting))
    return built, batches


def test_a_rational_spline_is_evaluated_by_one_evaluator_in_arrays(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """ezdxf's ``BSpline.point(t)`` builds an evaluator from every control point at each call:
    one is built per spline, and the fit's samples are asked for in arrays."""
    cps = [(10.0 * i, 20.0 * math.sin(i / 2.0)) for i in range(40)]
    weights = [1.0 + 0.5 * (i % 3) for i in range(40)]
    path = write_dxf(
        tmp_path / "s.dxf",
        lambda msp: msp.add_rational_spline([(*p, 0) for p in cps], weights, degree=3),
    )
    built, batches = _counting_evaluators(monkeypatch)
    (contour,) = read_dxf(path).contours
    assert len(built) == 1
    assert batches and min(batches) > 1
    monkeypatch.undo()
    _assert_fits(_spline_curve(path), contour)


def test_a_clamped_cubic_spline_is_fitted_as_its_bezier_spans(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Between two knots a clamped non-rational cubic B-spline is one cubic Bézier: each of
    its 37 spans (40 control points, uniform knots) is fitted as an SVG curve is, none
    through the evaluator's samples; the fit holds the tolerance against ezdxf's curve."""
    from camtool.importers import dxf_entities

    cps = [(10.0 * i, 20.0 * math.sin(i / 2.0)) for i in range(40)]
    path = write_dxf(
        tmp_path / "s.dxf", lambda msp: msp.add_open_spline([(*p, 0) for p in cps], degree=3)
    )
    built, batches = _counting_evaluators(monkeypatch)
    keys: list[Any] = []
    fit_key = dxf_entities.fit_key

    def counted(key: Any, tolerance: float) -> Any:
        keys.append(key)
        return fit_key(key, tolerance)

    monkeypatch.setattr(dxf_entities, "fit_key", counted)
    (contour,) = read_dxf(path).contours
    assert len(built) <= 1 and batches == []
    assert len(keys) == 40 - 3 and {kind for kind, _ in keys} == {"cubic"}
    assert keys[0][1][0] == cps[0] and keys[-1][1][-1] == cps[-1]  # a clamped spline's ends
    monkeypatch.undo()
    _assert_fits(_spline_curve(path), contour)
