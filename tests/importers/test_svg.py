"""SVG importer geometry: every path command, the basic shapes, transforms, curve tolerance.

Expected geometry is analytic (centres, radii, directions after the Y flip) or, for curves,
the TRUE curve evaluated by svgpathtools, sampled densely and compared both ways with the
fitted contour (tests/importers/svgutil.py).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from camtool.importers.options import ImportOptions
from camtool.importers.svg import read_svg
from camtool.model.shapes import Arc, Line
from tests.importers.svgutil import (
    HALF,
    Map,
    arc_only,
    assert_arc,
    one,
    page,
    svg,
    true_curve,
    two_sided_error,
    vertices,
)

# ------------------------------------------------------------------ path commands


LINES_ABS = "M 10 10 L 30 10 H 40 V 30 Z"
LINES_REL = "m 10 10 l 20 0 h 10 v 20 z"


@pytest.mark.parametrize("d", [LINES_ABS, LINES_REL])
def test_m_l_h_v_z_absolute_and_relative(tmp_path: Path, d: str) -> None:
    contour = one(read_svg(svg(tmp_path, f'<path id="p" d="{d}"/>')))
    assert contour.closed
    assert all(isinstance(s, Line) for s in contour.segments)
    # y -> 100 - y; Z adds the closing line back to (10, 90)
    assert vertices(contour) == [(10, 90), (30, 90), (40, 90), (40, 70), (10, 90)]
    assert contour.source == "path#p"
    assert contour.layer == "0"


def test_implicit_lineto_after_moveto(tmp_path: Path) -> None:
    contour = one(read_svg(svg(tmp_path, '<path d="M 0 0 10 0 10 10 m 5 5"/>')))
    assert vertices(contour) == [(0, 100), (10, 100), (10, 90)]


@pytest.mark.parametrize(
    ("d", "clockwise"),
    [
        ("M 10 50 A 20 20 0 0 1 50 50", True),  # sweep-flag 1: clockwise as seen on the page
        ("m 10 50 a 20 20 0 0 1 40 0", True),
        ("M 10 50 A 20 20 0 0 0 50 50", False),
        ("m 10 50 a 20 20 0 0 0 40 0", False),
    ],
)
def test_arc_half_circle_is_one_exact_arc(tmp_path: Path, d: str, clockwise: bool) -> None:
    contour = one(read_svg(svg(tmp_path, f'<path d="{d}"/>')))
    (seg,) = contour.segments
    arc = assert_arc(seg, (30.0, 50.0), 20.0, clockwise)
    assert arc.start == (10.0, 50.0)
    assert arc.end == (50.0, 50.0)
    # clockwise from the left end passes over the top: the middle is at (30, 70)
    assert arc.point_at(0.5) == pytest.approx((30.0, 70.0 if clockwise else 30.0), abs=1e-9)


@pytest.mark.parametrize("d", ["M 10 50 A 20 20 0 1 0 30 30", "m 10 50 a 20 20 0 1 0 20 -20"])
def test_arc_large_flag_three_quarters(tmp_path: Path, d: str) -> None:
    # ends (10, 50) and (30, 70) in mm; centres (30, 50) or (10, 70); large + sweep 0
    # (counter-clockwise on the page) -> around (30, 50) from 180 deg to 90 deg, 270 deg ccw
    (seg,) = one(read_svg(svg(tmp_path, f'<path d="{d}"/>'))).segments
    arc = assert_arc(seg, (30.0, 50.0), 20.0, False)
    assert arc.sweep == pytest.approx(1.5 * math.pi, abs=1e-9)


def test_arc_radius_too_small_is_scaled_up(tmp_path: Path) -> None:
    # SVG F.6.6: radii too small for the chord are scaled until the arc is a half circle
    (seg,) = one(read_svg(svg(tmp_path, '<path d="M 10 50 A 1 1 0 0 1 50 50"/>'))).segments
    assert_arc(seg, (30.0, 50.0), 20.0, True)


def test_arc_with_zero_radius_is_a_line_and_zero_length_arc_is_omitted(tmp_path: Path) -> None:
    d = "M 10 10 A 0 5 0 0 1 20 10 A 5 5 0 0 1 20 10"
    contour = one(read_svg(svg(tmp_path, f'<path d="{d}"/>')))
    assert contour.segments == (Line((10.0, 90.0), (20.0, 90.0)),)


@pytest.mark.parametrize(
    ("d", "to_mm"),
    [
        ("M 10 20 A 30 10 30 0 1 50 40", page),
        ("M 10 20 a 30 10 -20 1 0 30 5", page),
        ("M 50 50 A 40 10 90 0 0 50 70", page),
    ],
)
def test_elliptical_arc_is_fitted_within_tolerance(tmp_path: Path, d: str, to_mm: Map) -> None:
    tol = 0.001
    contour = one(read_svg(svg(tmp_path, f'<path d="{d}"/>'), ImportOptions(tolerance=tol)))
    assert len(contour.segments) > 1
    there, back = two_sided_error([contour], true_curve(d, to_mm))
    assert there <= tol + 1e-6
    assert back <= tol + 1e-6


CUBIC = "M 10 80 C 20 60 40 60 50 80 S 80 100 90 80"
CUBIC_EXPLICIT = (
    "M 10 80 C 20 60 40 60 50 80 C 60 100 80 100 90 80"  # S reflects (40,60) to (60,100)
)
QUAD = "M 10 50 Q 30 20 50 50 T 90 50"
QUAD_EXPLICIT = "M 10 50 Q 30 20 50 50 Q 70 80 90 50"  # T reflects (30,20) to (70,80)


@pytest.mark.parametrize(
    ("d", "explicit"),
    [
        (CUBIC, CUBIC_EXPLICIT),
        ("m 10 80 c 10 -20 30 -20 40 0 s 30 20 40 0", CUBIC_EXPLICIT),
        (QUAD, QUAD_EXPLICIT),
        ("m 10 50 q 20 -30 40 0 t 40 0", QUAD_EXPLICIT),
    ],
)
def test_bezier_s_t_reflection_and_tolerance(tmp_path: Path, d: str, explicit: str) -> None:
    tol = 0.001
    contour = one(read_svg(svg(tmp_path, f'<path d="{d}"/>'), ImportOptions(tolerance=tol)))
    assert contour.start == (10.0, 100.0 - float(d.split()[2]))
    assert contour.end == pytest.approx((90.0, 100.0 - float(explicit.split()[-1])), abs=0)
    there, back = two_sided_error([contour], true_curve(explicit, page))
    assert there <= tol + 1e-6
    assert back <= tol + 1e-6
    # consecutive segments share their end points exactly
    for a, b in zip(contour.segments, contour.segments[1:], strict=False):
        assert a.end == b.start


@pytest.mark.parametrize(
    "d",
    [
        "M 10 10 Q 50 90 90 10 S 50 50 10 90",  # S after Q: first control point is (90,10)
        "M 10 10 C 20 80 50 90 90 10 T 10 90",  # T after C: control point is (90,10)
        "M 10 10 C 20 80 50 90 90 10 T 10 90 T 50 50 t 20 -30",  # and the T's chained to it
        "m 10 10 q 40 80 80 0 s -40 40 -80 80 t 30 -20",  # relative, S then T
    ],
)
def test_a_smooth_curve_after_the_other_kind_starts_at_the_current_point(
    tmp_path: Path, d: str
) -> None:
    """SVG 1.1 §8.3.6-7: S reflects only a cubic's control point, T only a quadratic's."""
    tol = 0.001
    drawing = read_svg(svg(tmp_path, f'<path d="{d}"/>'), ImportOptions(tolerance=tol))
    there, back = two_sided_error(list(drawing.contours), true_curve(d, page))
    assert there <= tol + 1e-6
    assert back <= tol + 1e-6


def test_straight_bezier_is_one_line(tmp_path: Path) -> None:
    contour = one(read_svg(svg(tmp_path, '<path d="M 0 0 C 10 0 20 0 30 0"/>')))
    assert contour.segments == (Line((0.0, 100.0), (30.0, 100.0)),)


@settings(max_examples=20, deadline=None)
@given(
    st.lists(
        st.tuples(st.integers(0, 100), st.integers(0, 100)), min_size=4, max_size=4, unique=True
    ),
    st.sampled_from([0.01, 0.002]),
)
def test_random_cubic_beziers_stay_within_tolerance(
    tmp_path_factory: pytest.TempPathFactory, ctrl: list[tuple[int, int]], tol: float
) -> None:
    d = "M {} {} C {} {} {} {} {} {}".format(*(v for p in ctrl for v in p))
    path = svg(tmp_path_factory.mktemp("bez"), f'<path d="{d}"/>')
    drawing = read_svg(path, ImportOptions(tolerance=tol))
    there, back = two_sided_error(list(drawing.contours), true_curve(d, page, 6001))
    assert there <= tol + 1e-5
    assert back <= tol + 1e-5


def test_subpaths_each_m_starts_a_contour_z_closes(tmp_path: Path) -> None:
    d = "M 0 0 L 10 0 L 10 10 Z M 20 0 L 30 0 m 5 5 l 5 0 l -5 0"
    contours = read_svg(svg(tmp_path, f'<path id="multi" d="{d}"/>')).contours
    assert [c.closed for c in contours] == [True, False, True]
    assert [c.source for c in contours] == [f"path#multi subpath {k}" for k in (1, 2, 3)]
    assert vertices(contours[1]) == [(20, 100), (30, 100)]


def test_lineto_after_closepath_starts_from_the_subpath_start(tmp_path: Path) -> None:
    contours = read_svg(svg(tmp_path, '<path d="M 10 10 L 20 10 L 20 20 Z L 0 10"/>')).contours
    assert contours[0].closed
    assert vertices(contours[1]) == [(10, 90), (0, 90)]


@pytest.mark.parametrize(
    ("gap", "sides"),
    [
        (0.0009, 4),  # within the 0.001 mm tolerance: CorelDRAW's rounding, no closing line
        (0.0011, 5),  # beyond it: the closing line Z draws
    ],
)
def test_z_within_the_tolerance_of_the_start_moves_the_last_segment_there(
    tmp_path: Path, gap: float, sides: int
) -> None:
    """Relative coordinates rounded to 2 decimals (CorelDRAW) end a closed path a hair
    from its start: Z's line of 0.0009 mm would be a spike that offsetting reads as the
    contour crossing itself. Within ``--tolerance`` the last segment ends at the start."""
    d = f"m 10 10 l 20 0 l 0 20 l -20 0 l 0 {-20 + gap:.4f} z"
    contour = one(read_svg(svg(tmp_path, f'<path d="{d}"/>')))
    assert contour.closed and len(contour.segments) == sides
    assert contour.segments[-1].end == contour.start == (10.0, 90.0)
    if sides == 4:  # the last side runs from (10, 70) to the start, no 0.0009 mm line
        assert contour.segments[-1].start == (10.0, 70.0)


# ------------------------------------------------------------------ basic shapes


def test_circle_is_one_full_circle_arc(tmp_path: Path) -> None:
    contour = one(read_svg(svg(tmp_path, '<circle cx="30" cy="40" r="5"/>')))
    (seg,) = contour.segments
    arc = assert_arc(seg, (30.0, 60.0), 5.0, True)
    assert arc.is_full_circle
    assert contour.closed
    assert contour.source == "circle[1]"


def test_rounded_rect_is_lines_and_exact_arcs(tmp_path: Path) -> None:
    contour = one(read_svg(svg(tmp_path, '<rect x="10" y="10" width="40" height="20" rx="5"/>')))
    assert contour.closed
    kinds = [type(s).__name__ for s in contour.segments]
    assert kinds == ["Line", "Arc"] * 4
    arcs = [s for s in contour.segments if isinstance(s, Arc)]
    assert sorted(a.centre for a in arcs) == [(15, 75), (15, 85), (45, 75), (45, 85)]
    assert all(a.radius == pytest.approx(5.0) and a.clockwise for a in arcs)
    assert contour.bbox() == pytest.approx((10, 70, 50, 90))


def test_rect_with_rx_and_ry_has_elliptical_corners(tmp_path: Path) -> None:
    contour = one(
        read_svg(svg(tmp_path, '<rect x="10" y="10" width="40" height="20" rx="6" ry="3"/>'))
    )
    assert contour.bbox() == pytest.approx((10, 70, 50, 90))
    assert sum(isinstance(s, Line) for s in contour.segments) >= 4


PX_PER_MM = 96 / 25.4
"""User units (px) in a mm of a length written in mm (CSS: 96 px to the inch)."""


@pytest.mark.parametrize(
    ("attrs", "w", "h", "rx", "ry"),
    [
        # rx 2mm is 7.56 units, over half the width: rx 5, ry (auto) 7.56
        ('width="10" height="20" rx="2mm"', 10, 20, 5, 2 * PX_PER_MM),
        # the width is 37.8 units: rx 30 is cut to 18.9, ry (auto) stays 30
        ('width="10mm" height="20mm" rx="30"', 10 * PX_PER_MM, 20 * PX_PER_MM, 5 * PX_PER_MM, 30),
        # ry 1cm is 37.8 units: ry cut to half the height, rx (auto) to half of 0.4in
        ('width="0.4in" height="30" ry="1cm"', 38.4, 30, 19.2, 15),
        # rx auto is ry (3mm, 11.3 units), each then cut to half its side
        ('width="10" height="20" style="rx:auto;ry:3mm"', 10, 20, 5, 10),
        # sizes and radius as SVG 2 style properties
        ('style="width:10mm;height:20mm;rx:30"', 10 * PX_PER_MM, 20 * PX_PER_MM, 5 * PX_PER_MM, 30),
    ],
)
def test_a_rect_radius_in_other_units_is_at_most_half_its_side(
    tmp_path: Path, attrs: str, w: float, h: float, rx: float, ry: float
) -> None:
    """SVG 1.1 §9.2: the radii, in user units, are each cut to half the rect's side."""
    tol = 0.001
    body = f'<rect x="5" y="5" {attrs}/>'
    drawing = read_svg(svg(tmp_path, body), ImportOptions(tolerance=tol))
    x, y = 5.0, 5.0
    d = (
        f"M {x + rx} {y} H {x + w - rx} A {rx} {ry} 0 0 1 {x + w} {y + ry} V {y + h - ry} "
        f"A {rx} {ry} 0 0 1 {x + w - rx} {y + h} H {x + rx} A {rx} {ry} 0 0 1 {x} {y + h - ry} "
        f"V {y + ry} A {rx} {ry} 0 0 1 {x + rx} {y} Z"
    )
    there, back = two_sided_error(list(drawing.contours), true_curve(d, page))
    assert there <= tol + 1e-6
    assert back <= tol + 1e-6


def test_line_polyline_polygon_ellipse(tmp_path: Path) -> None:
    body = (
        '<line x1="0" y1="0" x2="10" y2="5" stroke="#000"/>'
        '<polyline points="0,10 10,10 10,20"/>'
        '<polygon points="20 20 30 20 30 30"/>'
        '<ellipse cx="50" cy="50" rx="10" ry="5"/>'
    )
    tol = 0.001
    drawing = read_svg(svg(tmp_path, body), ImportOptions(tolerance=tol))
    line, poly, gon, ellipse = drawing.contours
    assert vertices(line) == [(0, 100), (10, 95)] and not line.closed
    assert vertices(poly) == [(0, 90), (10, 90), (10, 80)] and not poly.closed
    assert vertices(gon) == [(20, 80), (30, 80), (30, 70), (20, 80)] and gon.closed
    assert [c.source for c in drawing.contours] == [
        "line[1]",
        "polyline[1]",
        "polygon[1]",
        "ellipse[1]",
    ]
    assert ellipse.closed
    t = np.linspace(0, 2 * math.pi, 4001)
    curve = np.column_stack([50 + 10 * np.cos(t), 50 + 5 * np.sin(t)])
    there, back = two_sided_error([ellipse], curve)
    assert max(there, back) <= tol + 1e-6


def test_filled_and_stroked_shapes_both_count_but_invisible_ones_do_not(tmp_path: Path) -> None:
    body = (
        '<rect width="10" height="10" style="fill:#000"/>'
        '<rect width="10" height="10" fill="none" stroke="red"/>'
        '<rect width="10" height="10" style="fill:none;stroke:none"/>'
    )
    drawing = read_svg(svg(tmp_path, body))
    assert [c.source for c in drawing.contours] == ["rect[1]", "rect[2]"]
    assert drawing.warnings == (
        f"{tmp_path / 't.svg'}: skipped 1 element with neither fill nor stroke",
    )


def test_a_line_without_a_stroke_is_not_shown_so_not_cut(tmp_path: Path) -> None:
    """SVG 2 §10.5: a ``<line>`` has no inside, so only its stroke paints it; the default
    fill (black) shows nothing. Stroked, by itself or by its group, it is cut."""
    body = (
        '<line id="bare" x1="0" y1="0" x2="50" y2="50"/>'
        '<line id="filled" x1="0" y1="0" x2="50" y2="50" fill="red"/>'
        '<g stroke="red"><line id="by-group" x1="0" y1="10" x2="50" y2="60"/></g>'
        '<line id="own" x1="0" y1="20" x2="50" y2="70" style="stroke:#00f"/>'
    )
    drawing = read_svg(svg(tmp_path, body))
    assert [c.source for c in drawing.contours] == ["line#by-group", "line#own"]
    assert drawing.warnings == (
        f"{tmp_path / 't.svg'}: skipped 2 <line> elements without a stroke (a line has no "
        "inside to fill, so a viewer shows nothing); give it a stroke to cut it",
    )


def test_a_stroke_of_width_0_paints_nothing_so_an_unfilled_shape_is_not_cut(
    tmp_path: Path,
) -> None:
    """SVG 1.1 §11.4: "A zero value causes no stroke to be painted". react-icons' Material
    icons put ``stroke="currentColor" stroke-width="0"`` on the root, so the icon's
    unfilled 24 × 24 frame, ``M0 0h24v24H0z``, shows nothing: cut, it would be a square
    around the part. A fill still shows (and gives the colour, not the stroke), a width
    above 0 or a negative one (an error viewers draw) is drawn, and a dash array on a
    stroke that is not drawn does not make a filled shape construction."""
    body = (
        '<g stroke="currentColor" fill="currentColor" stroke-width="0">'
        '<path id="frame" fill="none" d="M0 0h24v24H0z"/>'
        '<circle id="icon" cx="12" cy="12" r="10"/></g>'
        "<style>.zero { stroke-width: 0 }</style>"
        '<rect id="a" x="30" width="5" height="5" fill="none" stroke="red" class="zero"/>'
        '<rect id="b" x="40" width="5" height="5" fill="none" stroke="red" '
        'style="stroke-width:0.0px"/>'
        '<line id="c" x1="0" y1="30" x2="50" y2="30" stroke="red" stroke-width="0%"/>'
        '<rect id="d" x="50" width="5" height="5" fill="#00f" stroke="red" stroke-width="0" '
        'stroke-dasharray="4 2"/>'
        '<rect id="e" x="60" width="5" height="5" fill="none" stroke="red" '
        'stroke-width="0.001"/>'
        '<rect id="f" x="70" width="5" height="5" fill="none" stroke="red" stroke-width="-1"/>'
        '<g stroke-width="0"><rect id="g" x="80" width="5" height="5" fill="none" '
        'stroke="red" stroke-width="1"/></g>'
    )
    drawing = read_svg(svg(tmp_path, body))
    sources = [c.source for c in drawing.contours]
    assert sources == ["circle#icon", "rect#d", "rect#e", "rect#f", "rect#g"]
    filled = drawing.contours[1]
    assert (filled.colour, filled.linetype) == ("#0000ff", "")
    assert drawing.warnings == (
        f"{tmp_path / 't.svg'}: skipped 4 elements whose only paint is a stroke of "
        "stroke-width 0, which a viewer does not draw; give it a stroke width to cut it",
    )


def test_shapes_at_opacity_0_are_invisible_and_not_cut(tmp_path: Path) -> None:
    """What a browser shows is what is cut: opacity 0, or paint whose own opacity is 0."""
    body = (
        '<rect id="a" width="10" height="10" opacity="0"/>'
        '<g style="opacity:0%"><rect id="b" width="10" height="10"/></g>'
        '<style>.clear { opacity: 0.0 }</style><rect id="c" class="clear" width="1" height="1"/>'
        '<rect id="d" width="10" height="10" fill="none" stroke="red" stroke-opacity="0"/>'
        '<rect id="e" width="10" height="10" fill-opacity="0"/>'
        '<rect id="f" width="10" height="10" fill-opacity="0" stroke="red"/>'
        '<rect id="g" width="10" height="10" opacity="0.01"/>'
        '<rect id="h" width="10" height="10" opacity="bogus"/>'
        '<rect id="k" width="1" height="1" fill="transparent"/>'
        '<rect id="l" width="1" height="1" fill="rgba(0, 0, 0, 0)" stroke="#ff000000"/>'
        '<linearGradient id="gradient"><stop offset="0" stop-color="red"/></linearGradient>'
        '<rect id="m" width="1" height="1" fill="url(#gradient)"/>'
        '<g opacity="0"><g style="opacity:1"><rect id="i" style="opacity:0.5" width="1" '
        'height="1"/><rect id="j" opacity="1" width="1" height="1"/></g></g>'
    )
    drawing = read_svg(svg(tmp_path, body))
    assert [c.source for c in drawing.contours] == ["rect#f", "rect#g", "rect#h", "rect#m"]
    assert drawing.warnings == (
        f"{tmp_path / 't.svg'}: skipped 5 elements with opacity 0",
        f"{tmp_path / 't.svg'}: skipped 4 elements with neither fill nor stroke",
    )


# ------------------------------------------------------------------ transforms


def test_shapes_under_a_transform_that_is_not_invertible_are_not_cut(tmp_path: Path) -> None:
    """CSS Transforms 1 §6: an element whose matrix is non-invertible is not displayed.

    ``scale(0, 1)`` folds the rectangle onto the line x = 0 and ``matrix(1 1 1 1 0 0)``
    the circle onto y = x: their points exist, but no viewer draws them. ``rotate(10)
    matrix(1 2 2 4 0 0) rotate(20)`` is singular but for rounding (its determinant comes out
    4.4e-16, not 0); ``scale(1, 0.001)`` is invertible.
    """
    body = (
        '<rect id="a" width="10" height="10" fill="none" stroke="red" transform="scale(0, 1)"/>'
        '<g transform="matrix(1 1 1 1 0 0)"><circle id="b" cx="5" cy="5" r="2"/></g>'
        '<g transform="rotate(10) matrix(1 2 2 4 0 0) rotate(20)"><rect id="c" width="4" '
        'height="4"/></g>'
        '<rect id="d" width="10" height="10" transform="scale(1, 0.001)"/>'
        '<rect id="e" x="20" width="10" height="10"/>'
    )
    drawing = read_svg(svg(tmp_path, body))
    assert [c.source for c in drawing.contours] == ["rect#d", "rect#e"]
    assert drawing.warnings == (
        f"{tmp_path / 't.svg'}: skipped 3 elements whose transform is not invertible (a scale "
        "of 0 on an axis, or a matrix that folds the plane onto a line), which a viewer does "
        "not draw",
    )


def test_nested_translate(tmp_path: Path) -> None:
    body = f'<g transform="translate(5, -10)"><g transform="translate(1 2)">{HALF}</g></g>'
    arc = arc_only(read_svg(svg(tmp_path, body)))
    assert_arc(arc, (36.0, 58.0), 20.0, True)  # (30 + 6, 100 - (50 - 8))


def test_mirror_flips_arc_direction(tmp_path: Path) -> None:
    body = f'<g transform="translate(100 0) scale(-1, 1)">{HALF}</g>'
    arc = arc_only(read_svg(svg(tmp_path, body)))
    assert_arc(arc, (70.0, 50.0), 20.0, False)
    assert arc.start == pytest.approx((90.0, 50.0))


@pytest.mark.parametrize(
    "transform",
    [
        "rotate(90 30 50)",
        "matrix(0 1 -1 0 80 20)",
        "translate(30 50) rotate(90) translate(-30 -50)",
    ],
)
def test_rotation_keeps_an_exact_arc(tmp_path: Path, transform: str) -> None:
    # a quarter turn about the centre (30, 50): the start (10, 50) goes to (30, 30) -> mm (30, 70)
    arc = arc_only(read_svg(svg(tmp_path, f'<g transform="{transform}">{HALF}</g>')))
    assert_arc(arc, (30.0, 50.0), 20.0, True)
    assert arc.start == pytest.approx((30.0, 70.0), abs=1e-9)


def test_uniform_scale_keeps_a_circle(tmp_path: Path) -> None:
    body = '<g transform="scale(2)"><circle cx="10" cy="10" r="5"/></g>'
    arc = arc_only(read_svg(svg(tmp_path, body)))
    assert_arc(arc, (20.0, 80.0), 10.0, True)


@pytest.mark.parametrize(
    ("transform", "matrix"),
    [
        ("scale(2, 1)", (2.0, 0.0, 0.0, 1.0, 0.0, 0.0)),
        ("skewX(30)", (1.0, 0.0, math.tan(math.pi / 6), 1.0, 0.0, 0.0)),
        ("matrix(1 0.5 0 1 0 0)", (1.0, 0.5, 0.0, 1.0, 0.0, 0.0)),
    ],
)
def test_non_uniform_scale_or_skew_makes_an_ellipse_that_is_fitted(
    tmp_path: Path, transform: str, matrix: tuple[float, ...]
) -> None:
    tol = 0.001
    body = f'<g transform="{transform}"><circle cx="20" cy="20" r="10"/></g>'
    contour = one(read_svg(svg(tmp_path, body), ImportOptions(tolerance=tol)))
    assert len(contour.segments) > 4  # not the one full-circle arc
    a, b, c, d, e, f = matrix
    t = np.linspace(0, 2 * math.pi, 4001)
    x, y = 20 + 10 * np.cos(t), 20 + 10 * np.sin(t)
    curve = page(np.column_stack([a * x + c * y + e, b * x + d * y + f]))
    there, back = two_sided_error([contour], curve)
    assert max(there, back) <= tol + 1e-6


def test_transform_on_the_shape_and_its_groups_compose(tmp_path: Path) -> None:
    line = '<line x1="0" y1="0" x2="10" y2="0" stroke="red" transform="translate(5 5)"/>'
    body = f'<g transform="scale(2)">{line}</g>'
    assert vertices(one(read_svg(svg(tmp_path, body)))) == [(10, 90), (30, 90)]
