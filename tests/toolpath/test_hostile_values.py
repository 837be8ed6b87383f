"""Hostile values in the planner: clear errors and limits instead of crashes and hangs.

One regression test per class of internal error found by fuzzing (issue 14): huge
coordinates in the chaining hash, chord counts from zero/NaN/tiny tolerances,
an empty polyline, acos of a ratio below float resolution, and pocket ring counts.
"""

from __future__ import annotations

import itertools
import math
import re
from pathlib import Path

import pytest

from camtool.cli.main import main
from camtool.geometry.arcfit import fit_polyline
from camtool.geometry.chain import chain
from camtool.model.errors import InputError, ToolpathError, UsageError
from camtool.model.shapes import MAX_CHORDS, Contour, Line, chord_count
from camtool.toolpath import offset, pocket_uncut
from camtool.toolpath.chain import close_gaps
from camtool.toolpath.options import PlanOptions
from camtool.toolpath.pocket import MAX_POCKET_PATHS, MAX_POCKET_WORK


def _open(*points: tuple[float, float]) -> Contour:
    segs = tuple(Line(a, b) for a, b in itertools.pairwise(points))
    return Contour(segs, False)


def test_chain_joins_lines_at_huge_coordinates() -> None:
    # 1e305 / 0.001 overflows a float: the hash cell must not come from that quotient
    far = 1e305
    got = chain([_open((far, 0.0), (far, 5.0)), _open((far, 5.0), (far + 1e292, 5.0))], 1e-3)
    assert len(got) == 1
    assert got[0].start == (far, 0.0)
    assert got[0].end == (far + 1e292, 5.0)


def test_chain_refuses_a_non_finite_end() -> None:
    with pytest.raises(ToolpathError, match="not finite"):
        chain([_open((0.0, 0.0), (math.inf, 1.0)), _open((0.0, 0.0), (1.0, 0.0))], 1e-3)


def test_chain_tolerance_zero_joins_only_coinciding_ends() -> None:
    got = chain([_open((0, 0), (1, 0)), _open((1, 0), (1, 1)), _open((1, 1e-9), (2, 2))], 0.0)
    assert [len(c.segments) for c in got] == [2, 1]


@pytest.mark.parametrize("tolerance", [0.0, -1.0, math.nan, math.inf])
def test_chord_count_refuses_a_bad_tolerance(tolerance: float) -> None:
    with pytest.raises(UsageError, match="--tolerance"):
        chord_count(1.0, math.pi, tolerance)


@pytest.mark.parametrize(("radius", "sweep"), [(math.nan, 1.0), (1.0, math.nan), (math.inf, 1.0)])
def test_chord_count_refuses_non_finite_arcs(radius: float, sweep: float) -> None:
    with pytest.raises(ToolpathError, match="must be finite"):
        chord_count(radius, sweep, 0.01)


def test_chord_count_of_a_tiny_tolerance_uses_the_exact_small_angle_form() -> None:
    # t/r = 1e-10: 1 - t/r keeps 6 digits of t/r; the widest chord spans 4·asin(√(t/2r))
    # = 4·asin(√5e-6·1e-3) = 2.8284271e-5 rad, so a quarter turn needs ⌈(π/2)/that⌉ chords
    widest = 4 * math.asin(math.sqrt(0.5e-10))
    assert widest == pytest.approx(2.8284271e-5, rel=1e-7)
    assert chord_count(1.0, math.pi / 2, 1e-10) == math.ceil(math.pi / 2 / widest)
    assert chord_count(1.0, math.pi / 2, 1e-10) == 55537  # 55536.6 rounded up


def test_chord_count_refuses_more_chords_than_the_limit() -> None:
    # r = 1 mm within 1e-300 mm: 1 - t/r rounds to 1 (acos 0 divided by before)
    with pytest.raises(UsageError, match=f"limit of {MAX_CHORDS}; give a larger --tolerance"):
        chord_count(1.0, 2 * math.pi, 1e-300)
    with pytest.raises(UsageError, match="chords"):  # t/r underflows to 0
        chord_count(1e300, 2 * math.pi, 1e-300)


def test_fit_polyline_of_no_points_says_so() -> None:
    with pytest.raises(InputError, match="a polyline needs 2 distinct points, got none"):
        fit_polyline([], 0.01)


def test_quad_segs_of_a_ratio_below_float_resolution_are_the_most_allowed() -> None:
    # 1e-12 / 4 / 1e6 = 2.5e-19: 1 - that == 1.0 and acos gives 0 (not a division by zero)
    assert pocket_uncut.quad_segs(1e6, 1e-12) == pocket_uncut._MAX_QUAD_SEGS
    assert offset.quad_segs(1e6, 1e-19) == offset._MAX_QUAD_SEGS


SQUARE_DXF = (
    "0\nSECTION\n2\nHEADER\n9\n$INSUNITS\n70\n4\n0\nENDSEC\n0\nSECTION\n2\nENTITIES\n"
    + "".join(
        f"0\nLINE\n8\n0\n10\n{a[0]}\n20\n{a[1]}\n11\n{b[0]}\n21\n{b[1]}\n"
        for a, b in itertools.pairwise([(0, 0), (100, 0), (100, 100), (0, 100), (0, 0)])
    )
    + "0\nENDSEC\n0\nEOF\n"
)


@pytest.mark.parametrize(
    ("args", "count"),
    [
        # (100 / 2 - 1.5) mm / (1e-6 × 3 mm) = 1.62e7 rings
        (["--stepover", "1e-6"], "1.62e+07 rings"),
        # a 1 µm tool at 1e-3 step-over: (50 - 5e-4) / 1e-6 = 5.0e7 rings
        (["--tool-diameter", "1e-3", "--stepover", "1e-3"], "5e+07 rings"),
        # zigzag: diagonal 141.42 mm / 3e-6 mm = 4.71e7 lines
        (["--stepover", "1e-6", "--pocket", "zigzag"], "4.71e+07 zigzag lines"),
    ],
)
def test_pocket_refuses_more_rings_than_the_limit(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], args: list[str], count: str
) -> None:
    drawing = tmp_path / "square.dxf"
    drawing.write_text(SQUARE_DXF)
    out = tmp_path / "out.nc"
    argv = ["post", str(drawing), "-t", "grbl", "--offset", "pocket", "--tool-diameter", "3"]
    # a tolerance as fine as these step-overs: a coarser one is refused first (below)
    code = main([*argv, "--tolerance", "1e-6", *args, "-o", str(out)])
    err = capsys.readouterr().err
    assert code == 2
    assert count in err
    assert f"limit of {MAX_POCKET_PATHS} per pocket" in err
    assert "--stepover" in err and "internal error" not in err
    assert not out.exists()


@pytest.mark.parametrize("style", ["concentric", "zigzag"])
def test_pocket_refuses_a_step_over_finer_than_the_tolerance(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], style: str
) -> None:
    # 0.0001 × 3 mm = 0.3 µm between rings fitted within 1 µm (the default --tolerance):
    # refused before any ring is made
    drawing = tmp_path / "square.dxf"
    drawing.write_text(SQUARE_DXF)
    out = tmp_path / "out.nc"
    argv = ["post", str(drawing), "-t", "grbl", "--offset", "pocket", "--pocket", style]
    code = main([*argv, "--tool-diameter", "3", "--stepover", "0.0001", "-o", str(out)])
    err = capsys.readouterr().err
    assert code == 2
    assert "step-over of 0.0003 mm (--stepover 0.0001 × --tool-diameter 3 mm)" in err
    assert "finer than --tolerance 0.001 mm" in err and "at least 0.000333" in err
    assert not out.exists()
    # a step-over of 4 × 0.124 mm under --tolerance 0.5 is refused; 4 × 0.125 mm is planned
    coarse = [*argv, "--tool-diameter", "4", "--tolerance", "0.5", "-o", str(out)]
    assert main([*coarse, "--stepover", "0.124"]) == 2
    assert "step-over of 0.496 mm" in capsys.readouterr().err and not out.exists()
    assert main([*coarse, "--stepover", "0.125"]) == 0, capsys.readouterr().err
    assert out.exists()


def test_closed_gap_message_never_prints_minus_zero() -> None:
    # gap from (-1e-5, 0.01) back to (0, 0): midpoint (-5e-6, 0.005) rounds to 0.0000
    drawn = _open((0.0, 0.0), (10.0, 0.0), (10.0, 10.0), (-1e-5, 0.01))
    _, findings = close_gaps([drawn], 0.02, 0.001)
    assert "at (0.0000, 0.0050) mm" in findings[0].message
    assert "-0.0000" not in findings[0].message


def test_a_bad_start_position_is_not_called_the_origin_option() -> None:
    # PlanOptions.origin is the API's start position; --origin sets PlanOptions.placement
    with pytest.raises(UsageError) as caught:
        PlanOptions(origin=(math.nan, 0.0))
    message = str(caught.value)
    assert "--origin" not in message
    assert "PlanOptions.origin" in message


def _star_dxf(n: int, outer: float, inner: float) -> str:
    """A closed R12 POLYLINE of ``n`` vertices, on circles of ``outer`` and ``inner`` mm in
    turn (a jagged outline no arc fits: one pocket of ``n`` vertices)."""
    radii = [outer if k % 2 == 0 else inner for k in range(n)]
    vertices = "".join(
        f"0\nVERTEX\n8\n0\n10\n{r * math.cos(math.tau * k / n)}\n"
        f"20\n{r * math.sin(math.tau * k / n)}\n"
        for k, r in enumerate(radii)
    )
    return (
        "0\nSECTION\n2\nHEADER\n9\n$INSUNITS\n70\n4\n0\nENDSEC\n0\nSECTION\n2\nENTITIES\n"
        f"0\nPOLYLINE\n8\n0\n66\n1\n70\n1\n{vertices}0\nSEQEND\n0\nENDSEC\n0\nEOF\n"
    )


def test_pocket_refuses_a_job_of_too_many_rings_times_vertices(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # 2 000 vertices on R = 50 and 49 in turn: inradius 49 (an inner vertex), found
    # within 50 / 1000 mm. A 0.01 mm tool at step-over 0.4 (4 µm) needs
    # (49 - 0.005) / 0.004 ≈ 12 249 rings, under the ring limit, but 12 249 × 2 001
    # coordinates ≈ 2.45e7 passes over vertices: refused before any work.
    drawing = tmp_path / "star.dxf"
    drawing.write_text(_star_dxf(2000, 50.0, 49.0))
    out = tmp_path / "out.nc"
    argv = ["post", str(drawing), "-t", "grbl", "--offset", "pocket", "--tool-diameter", "0.01"]
    code = main([*argv, "-o", str(out)])
    err = capsys.readouterr().err
    assert code == 2
    found = re.search(r"about (\S+) rings .* need (\S+) rings × vertices", err)
    assert found is not None, err
    rings, work = float(found[1]), float(found[2])
    assert (49 - 0.05 - 0.005) / 0.004 <= rings <= (49 + 0.05 - 0.005) / 0.004 * 1.005
    assert work == pytest.approx(rings * 2001, rel=0.005)
    assert f"limit of {MAX_POCKET_WORK:.3g} for one job" in err
    assert "2001 outline vertices" in err and "--stepover" in err
    assert not out.exists()


def test_the_ring_bound_follows_the_largest_circle_inside_not_the_box() -> None:
    # An annulus R = 20, r = 14 (bbox 40 × 40): rings fit in its 3 mm half-width only,
    # (3 - 0.5) / 0.4 = 6.25 with a 1 mm tool; the box alone would allow (20 - 0.5) / 0.4.
    from shapely import Point as ShapelyPoint

    from camtool.toolpath.options import PlanOptions
    from camtool.toolpath.pocket import _path_count

    ring = (
        ShapelyPoint(0, 0)
        .buffer(20, quad_segs=256)
        .difference(ShapelyPoint(0, 0).buffer(14, quad_segs=256))
    )
    options = PlanOptions(offset="pocket", tool_diameter=1.0, feed_mm_min=100.0)
    count = _path_count(ring, 0.4, options)
    assert 6.25 <= count <= 6.25 * 1.05  # an upper bound within the circle's search slack
