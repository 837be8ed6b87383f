"""Features the planner reported it cannot cut as drawn are measured apart from the rest.

The drawing (then moved by (5, 5) mm): a 40 × 30 mm plate cut on its outside
with a 3 mm tool, a notch 10 × 3 mm at the top (two 90° inside corners) and a
2 mm wide slot inside. The expected numbers come from the geometry, not from
camtool:

- a 90° inside corner keeps the tool radius r = 1.5 mm: the drawn vertex is
  r·(√2 − 1) = 621.32 µm from the fillet;
- the 2 mm slot is narrower than the tool, so nothing cuts it: its drawn edge
  is as far from the cut edge as the nearest other cut allows. The outside
  path is the plate grown by r; the slot's top edge y = 12 at x >= 12 is
  12 + r = 13.5 mm from the path's bottom line y = −r and farther from every
  other side (x + r, 31.5 − 12, 41.5 − x), the farthest any slot point is,
  so 13.5 − r = 12 mm from the machined edge.
"""

from __future__ import annotations

import itertools
import math
from typing import Any

import pytest

from camtool.jobs.pipeline import post_drawing, verify_job
from camtool.model.shapes import Contour, Drawing, Line, Point
from camtool.post.registry import load_target
from camtool.toolpath.options import PlanOptions
from camtool.verify.not_cut import NotCut
from camtool.verify.report import not_cut_text, summary_lines

R = 1.5
CORNER_UM = R * (math.sqrt(2.0) - 1.0) * 1000.0  # 621.32 µm
SLOT_UM = (13.5 - R) * 1000.0


def _polygon(points: list[Point], source: str) -> Contour:
    pairs = zip(points, [*points[1:], points[0]], strict=True)
    return Contour(tuple(Line(a, b) for a, b in pairs), True, source=source)


def plate() -> Drawing:
    """The plate, notch and slot above, moved by (5, 5) mm into the work area."""
    outline = [(0, 0), (40, 0), (40, 30), (30, 30), (30, 27), (20, 27), (20, 30), (0, 30)]
    slot = [(5, 10), (15, 10), (15, 12), (5, 12)]
    return Drawing(
        (
            _polygon([(x + 5.0, y + 5.0) for x, y in outline], "outline"),
            _polygon([(x + 5.0, y + 5.0) for x, y in slot], "slot"),
        )
    )


@pytest.fixture(scope="module")
def verified():  # type: ignore[no-untyped-def]
    job = post_drawing(
        plate(), load_target("grbl"), PlanOptions(offset="outside", tool_diameter=2 * R)
    )
    kinds = sorted(f.kind for f in job.plan.findings) if job.plan else []
    assert kinds == ["offset-vanished", "tight-corner"]
    return verify_job(job)


def test_main_figure_is_what_was_cut(verified) -> None:  # type: ignore[no-untyped-def]
    a = verified.against
    # grbl steps are 4 µm (250 steps/mm); the cut part is within a few steps of the drawing.
    assert a.max_um < 12.0
    assert verified.max_error_um < 12.0


CORNERS = (("tight-corner", 25, 32), ("tight-corner", 35, 32))
SLOT = ("offset-vanished", 15, 16)


def plate_features(not_cut: tuple[NotCut, ...]) -> dict[tuple[str, int, int], NotCut]:
    """The plate's three features by kind and rounded place, their errors checked."""
    found = {(f.kind, round(f.at[0]), round(f.at[1])): f for f in not_cut}
    assert len(not_cut) == 3  # one feature each
    assert set(found) == {*CORNERS, SLOT}
    for key in CORNERS:
        assert found[key].error_um == pytest.approx(CORNER_UM, abs=10.0)
        assert found[key].at == pytest.approx((key[1], key[2]), abs=0.01)  # the drawn vertex
    assert found[SLOT].error_um == pytest.approx(SLOT_UM, abs=10.0)
    return found


def test_features_apart_with_their_geometry(verified) -> None:  # type: ignore[no-untyped-def]
    slot = plate_features(verified.against.not_cut)[SLOT]
    assert slot.value == pytest.approx(2.0, abs=0.01)
    assert slot.label == "2 mm wide region"
    # the whole slot outline (24 mm at 5 µm) is in it
    assert slot.samples >= 24 / 0.005
    assert verified.strict_error_um == pytest.approx(SLOT_UM, abs=10.0)


def test_summary_names_the_features(verified) -> None:  # type: ignore[no-untyped-def]
    text = "\n".join(summary_lines(verified))
    assert "3 features not cut as drawn" in text
    assert "tight corner at (25, 32) mm" in text
    assert "2 mm wide region at (15, 16) mm" in text
    assert "max 12.0 mm" in text


def test_without_findings_everything_is_the_main_figure() -> None:
    job = post_drawing(
        plate(), load_target("grbl"), PlanOptions(offset="outside", tool_diameter=2 * R)
    )
    from camtool.verify.verifier import verify_code

    v = verify_code(job.result.code, job.target, against=job.placed, tool_diameter=2 * R)
    assert v.against is not None and v.against.not_cut == ()
    assert v.against.max_um == pytest.approx(SLOT_UM, abs=10.0)


def test_not_cut_text_counts_and_units() -> None:
    from camtool.verify.drawing_compare import Against

    a = Against(
        1.0,
        1.0,
        (0.0, 0.0),
        0.0,
        10,
        (NotCut("tight-corner", (-0.00001, 27.0), 621.3, 5, 2.0),),
    )
    assert not_cut_text(a).startswith("1 feature not cut as drawn with this tool: ")
    assert "tight corner at (0, 27) mm" in not_cut_text(a)  # never "-0"
    assert "max 621.30 µm" in not_cut_text(a)


def test_a_stretch_across_a_closed_contours_seam_is_one_feature() -> None:
    import numpy as np

    from camtool.verify.not_cut import _stretches

    # a closed square sampled from its corner (0, 0): the flagged corner region wraps around
    ring = np.array([(0, 0), (1, 0), (2, 0), (2, 2), (0, 2), (0, 1), (0, 0)], dtype=np.float64)
    line = np.array([(5, 5), (6, 5), (7, 5)], dtype=np.float64)
    samples = np.vstack([ring, line])
    contour_of = np.array([0] * 7 + [1] * 3)
    flagged = np.array([1, 1, 0, 0, 0, 1, 1, 1, 0, 1], dtype=bool)
    got = [sorted(s.tolist()) for s in _stretches(samples, contour_of, flagged)]
    assert got == [[0, 1, 5, 6], [7], [9]]  # the open line's ends stay apart


def loose_plate(order: list[int], reverse: set[int]) -> Drawing:
    """:func:`plate` as loose LINEs, one open contour each (as most DXF files draw a
    part), in ``order``, the lines of ``reverse`` drawn end to start."""
    lines = [seg for contour in plate().contours for seg in contour.segments]
    out = []
    for k in order:
        seg = lines[k]
        assert isinstance(seg, Line)
        a, b = (seg.end, seg.start) if k in reverse else (seg.start, seg.end)
        out.append(Contour((Line(a, b),), False, source=f"LINE #{k}"))
    return Drawing(tuple(out))


@pytest.mark.parametrize(
    ("order", "reverse"),
    [
        (list(range(12)), set()),  # in drawing order, end to start as the outline goes
        ([5, 0, 9, 3, 11, 7, 1, 10, 4, 2, 8, 6], {0, 3, 4, 10}),  # shuffled, some reversed
    ],
)
def test_loose_lines_are_measured_as_the_contours_they_make(
    order: list[int], reverse: set[int]
) -> None:
    # The plan chains the 12 lines into the outline and the slot, and its findings name
    # those contours: the same features apart as for the closed polygons, with the same
    # geometry (the drawn vertex r(√2 − 1) from the fillet); the rest within a few steps.
    job = post_drawing(
        loose_plate(order, reverse),
        load_target("grbl"),
        PlanOptions(offset="outside", tool_diameter=2 * R),
    )
    v = verify_job(job)
    assert v.against is not None
    assert v.against.max_um < 12.0
    slot = plate_features(v.against.not_cut)[SLOT]  # one feature each, not one per line
    assert slot.samples >= 24 / 0.005  # the whole slot outline, its four lines


def test_lines_joined_at_a_larger_chain_tolerance_are_grouped_as_the_plan_joined_them() -> None:
    # Each line of the plate drawn as two LINEs with a 0.1 mm gap at its middle: only
    # --chain-tolerance 0.2 (which camtool's own warning suggests) makes the outline and
    # the slot. The comparison groups the drawing's lines at the plan's joint distance,
    # not the default 0.01 mm: before, each corner's far side and seven of the slot's
    # eight pieces were counted in the main figure (12 mm: the slot).
    out = []
    for k, seg in enumerate(s for c in plate().contours for s in c.segments):
        assert isinstance(seg, Line)
        (x0, y0), (x1, y1) = seg.start, seg.end
        length = math.dist(seg.start, seg.end)
        u = ((x1 - x0) / length, (y1 - y0) / length)
        mid = ((x0 + x1) / 2, (y0 + y1) / 2)
        before = (mid[0] - 0.05 * u[0], mid[1] - 0.05 * u[1])
        after = (mid[0] + 0.05 * u[0], mid[1] + 0.05 * u[1])
        out.append(Contour((Line(seg.start, before),), False, source=f"LINE #{k}a"))
        out.append(Contour((Line(after, seg.end),), False, source=f"LINE #{k}b"))
    options = PlanOptions(offset="outside", tool_diameter=2 * R, chain_tolerance=0.2)
    job = post_drawing(Drawing(tuple(out)), load_target("grbl"), options)
    assert job.plan is not None and job.plan.joint_mm == 0.2
    v = verify_job(job)
    assert v.against is not None
    assert v.against.max_um < 12.0
    slot = plate_features(v.against.not_cut)[SLOT]
    assert slot.samples >= (24 - 4 * 0.1) / 0.005  # the whole slot outline, its eight lines


def test_a_region_the_plan_closed_or_drew_without_area_is_set_apart() -> None:
    # Inside a 40 × 30 mm rectangle cut outside with the 3 mm tool: the 2 mm slot drawn
    # as four loose LINEs with a 0.015 mm gap at one corner (more than the 0.01 mm joint:
    # the plan closes it, a closed-gap finding), and a line drawn there and back (two
    # LINEs whose ends meet: a closed contour of no area, its finding at its start). Both
    # are offset-vanished; before, the comparison named the rectangle around them for
    # both findings, and kept them in the main figure (15 mm).
    # Expected from the geometry: the machined edge is the rectangle (5..45, 5..35);
    # the line's end (25, 20) is 15 mm from it, the slot's top edge 12 mm.
    outline = _polygon([(5, 5), (45, 5), (45, 35), (5, 35)], "outline")
    corners = [(10, 15), (20, 15), (20, 17), (10, 17)]
    slot = [
        Contour((Line(a, b),), False, source=f"LINE #{k}")
        for k, (a, b) in enumerate(zip(corners, [*corners[1:], (10, 15.015)], strict=True))
    ]
    there = Contour((Line((25, 20), (35, 20)),), False, source="LINE #there")
    back = Contour((Line((35, 20), (25, 20)),), False, source="LINE #back")
    job = post_drawing(
        Drawing((outline, *slot, there, back)),
        load_target("grbl"),
        PlanOptions(offset="outside", tool_diameter=2 * R),
    )
    assert job.plan is not None
    kinds = sorted(f.kind for f in job.plan.findings)
    assert kinds == ["closed-gap", "offset-vanished", "offset-vanished"]
    v = verify_job(job, budget=False)
    assert v.against is not None
    assert v.against.max_um < 12.0
    apart = sorted(v.against.not_cut, key=lambda f: f.error_um)
    assert [f.kind for f in apart] == ["offset-vanished", "offset-vanished"]
    assert apart[0].error_um == pytest.approx(SLOT_UM, abs=10.0)
    assert apart[1].error_um == pytest.approx(15_000.0, abs=10.0)


def test_a_region_without_area_names_the_contour_that_starts_there() -> None:
    # Two closed polylines of no area end to end (LibreCAD's pe6.dxf draws a terminal so):
    # A from (25, 20) to (35, 20) and back, B from (35, 20) to (40, 20) and back. B's
    # finding is at its start (35, 20), which A passes through too: before, both
    # findings named A and B stayed in the main figure. Expected from the geometry (the
    # machined edge is the rectangle 5..45 × 5..35): A's far end 15 mm from it, B's 10 mm.
    outline = _polygon([(5, 5), (45, 5), (45, 35), (5, 35)], "outline")
    a = Contour((Line((25, 20), (35, 20)), Line((35, 20), (25, 20))), True, source="A")
    b = Contour((Line((35, 20), (40, 20)), Line((40, 20), (35, 20))), True, source="B")
    job = post_drawing(
        Drawing((outline, a, b)),
        load_target("grbl"),
        PlanOptions(offset="outside", tool_diameter=2 * R),
    )
    v = verify_job(job, budget=False)
    assert v.against is not None
    assert v.against.max_um < 12.0
    errors = sorted(f.error_um for f in v.against.not_cut)
    assert errors == [pytest.approx(10_000.0, abs=10.0), pytest.approx(15_000.0, abs=10.0)]


def test_a_pocket_outline_without_area_is_said_and_set_apart() -> None:
    # A pocket of the rectangle 5..45 × 5..35 and, beside it, a closed polyline of no
    # area from (60, 20) to (70, 20) and back: no region to clear. Before, the plan said
    # nothing and its 25 mm counted against the drawing; now an offset-vanished finding
    # (width 0, at its start) and the feature apart. Expected from the geometry: the
    # pocket's wall is the rectangle, 25 mm from the line's far end (70, 20).
    outline = _polygon([(5, 5), (45, 5), (45, 35), (5, 35)], "outline")
    flat = Contour((Line((60, 20), (70, 20)), Line((70, 20), (60, 20))), True, source="flat")
    job = post_drawing(
        Drawing((outline, flat)),
        load_target("grbl"),
        PlanOptions(offset="pocket", tool_diameter=2 * R),
    )
    assert job.plan is not None
    said = [f for f in job.plan.findings if f.kind == "offset-vanished"]
    assert len(said) == 1 and said[0].at == (60, 20) and "encloses no area" in said[0].message
    v = verify_job(job, budget=False)
    assert v.against is not None
    assert v.against.max_um < 12.0
    flat_apart = [f for f in v.against.not_cut if f.kind == "offset-vanished"]
    assert len(flat_apart) == 1
    assert flat_apart[0].error_um == pytest.approx(25_000.0, abs=10.0)


def _curl_posted(offset: str) -> tuple[Any, Any]:
    """The curl below, (0,0) (30,0) (30,30) (10,30) (10,10) (20,10) (20,20) (0,20) moved by
    (5, 5), posted for grbl with ``offset`` and the 3 mm tool; its one self-crossing finding."""
    points = [(0, 0), (30, 0), (30, 30), (10, 30), (10, 10), (20, 10), (20, 20), (0, 20)]
    job = post_drawing(
        Drawing((_polygon([(x + 5.0, y + 5.0) for x, y in points], "curl"),)),
        load_target("grbl"),
        PlanOptions(offset=offset, tool_diameter=2 * R),
    )
    assert job.plan is not None
    (said,) = [f for f in job.plan.findings if f.kind == "self-crossing"]
    return job, said


def test_a_hole_that_crosses_itself_is_said_to_be_offset_inside() -> None:
    # The curl as a hole of a 40 mm square: an outside profile cuts the hole on its inside
    # (the even-odd nesting), so the finding names the inside offset, as the tool runs
    points = [(0, 0), (30, 0), (30, 30), (10, 30), (10, 10), (20, 10), (20, 20), (0, 20)]
    square = _polygon([(0.0, 0.0), (40.0, 0.0), (40.0, 40.0), (0.0, 40.0)], "square")
    curl = _polygon([(x + 5.0, y + 5.0) for x, y in points], "curl")
    job = post_drawing(
        Drawing((square, curl)), load_target("grbl"), PlanOptions(offset="outside", tool_diameter=1)
    )
    assert job.plan is not None
    (said,) = [f for f in job.plan.findings if f.kind == "self-crossing"]
    assert "the inside offset follows the boundary of the area it encloses" in said.message
    _, alone = _curl_posted("outside")  # the curl alone is a part: cut on its outside
    assert "the outside offset follows the boundary" in alone.message


def test_a_contour_that_crosses_itself_is_said_and_its_loops_set_apart() -> None:
    # A closed outline that curls into itself: (0,0) (30,0) (30,30) (10,30) (10,10)
    # (20,10) (20,20) (0,20), moved by (5, 5); its last edge crosses the one down from
    # (10,30) at (10,20). The outside offset (shapely's buffer, OpenCASCADE refuses it)
    # follows the boundary of the area it encloses, (0,0) (30,0) (30,30) (10,30) (10,20)
    # (0,20): the curl's edges inside are not cut, and before nothing said so. Expected
    # from the geometry: the curl's corner (20,10) is 10 mm from that boundary (the
    # bottom and the right side), the farthest of its points.
    job, said = _curl_posted("outside")
    assert said.at == pytest.approx((15.0, 25.0))
    assert "crosses itself" in said.message and "--offset on" in said.message
    v = verify_job(job, budget=False)
    assert v.against is not None
    assert v.against.max_um < 12.0
    (loops,) = v.against.not_cut
    assert loops.kind == "self-crossing" and loops.label == "loops of a self-crossing contour"
    assert loops.error_um == pytest.approx(10_000.0, abs=10.0)


def test_a_pocket_outline_that_crosses_itself_is_said() -> None:
    # The curl of the test above pocketed: its region is the area it encloses, so the
    # pocket clears through the curl's inner edges (before, nothing said so). Expected:
    # the tool's centre passes over them, so their drawn points are cut r deep (1.5 mm),
    # apart from the main figure; the rest within a few steps.
    job, said = _curl_posted("pocket")
    assert "clears the whole area it encloses" in said.message
    v = verify_job(job, budget=False)
    assert v.against is not None and v.against.max_um < 12.0
    (loops,) = [f for f in v.against.not_cut if f.kind == "self-crossing"]
    assert loops.error_um == pytest.approx(R * 1000.0, abs=10.0)


def test_two_crossing_regions_narrower_than_the_tool_each_name_their_own_contour() -> None:
    # Inside the rectangle 5..45 × 5..35, two 0.8 mm bars that cross at (25, 20), one
    # along X (20..30), one along Y (15..25): both narrower than the 3 mm tool, their
    # findings at one place, (25, 20). Before, both named the first bar and the second
    # stayed in the main figure (Inkscape's gradient.svg: 3 256 µm). Expected from the
    # geometry: each bar's point farthest from the rectangle is 15 mm from it ((20, 20)
    # and (24.6, 20) or (25.4, 20)).
    outline = _polygon([(5, 5), (45, 5), (45, 35), (5, 35)], "outline")
    across = _polygon([(20, 19.6), (30, 19.6), (30, 20.4), (20, 20.4)], "across")
    up = _polygon([(24.6, 15), (25.4, 15), (25.4, 25), (24.6, 25)], "up")
    job = post_drawing(
        Drawing((outline, across, up)),
        load_target("grbl"),
        PlanOptions(offset="outside", tool_diameter=2 * R),
    )
    assert job.plan is not None
    places = [f.at for f in job.plan.findings if f.kind == "offset-vanished"]
    assert places == [pytest.approx((25.0, 20.0))] * 2
    v = verify_job(job, budget=False)
    assert v.against is not None and v.against.max_um < 12.0
    errors = [f.error_um for f in v.against.not_cut if f.kind == "offset-vanished"]
    assert errors == [pytest.approx(15_000.0, abs=10.0)] * 2


def _scan_named(
    samples: Any, contour_of: Any, runs: Any, at: Any, inside: bool, joint: float, named: set[int]
) -> int:
    """The contour a finding names, by a scan of every sample and every contour (the rule of
    :class:`camtool.verify.not_cut._Contours`, written out plainly as the reference)."""
    import numpy as np

    from camtool.verify.not_cut import _ends_meet

    gap = np.hypot(*(samples - at).T)
    nearest = int(np.argmin(gap))
    if inside and gap[nearest] > 1e-9:
        best, best_area = -1, math.inf
        for c in sorted(set(contour_of.tolist())):
            idx = np.flatnonzero(contour_of == c)
            pts = samples[idx]
            lo, hi = pts.min(axis=0), pts.max(axis=0)
            if len(idx) < 4 or c in named or not (lo <= at).all() or not (at <= hi).all():
                continue
            area = float((hi[0] - lo[0]) * (hi[1] - lo[1]))
            if area >= best_area:
                continue
            piece = runs[idx]
            same = piece[1:] == piece[:-1]
            starts = np.flatnonzero(np.concatenate([[True], ~same]))
            stops = np.concatenate([starts[1:], [len(idx)]]) - 1
            if not _ends_meet(np.concatenate([pts[starts], pts[stops]]), joint):
                continue
            a, b = pts[:-1][same], pts[1:][same]
            crossed = 0
            for (ax, ay), (bx, by) in zip(a, b, strict=True):
                if (ay > at[1]) != (by > at[1]):
                    crossed += ax + (at[1] - ay) * (bx - ax) / (by - ay) > at[0]
            if crossed % 2 == 1:
                best, best_area = int(c), area
        if best >= 0:
            return best
    elif inside:
        on = [int(k) for k in np.flatnonzero(gap <= 1e-9)]
        first = [k for k in on if k == 0 or runs[k] != runs[k - 1]]
        nearest = first[0] if first else nearest
    return int(contour_of[nearest])


@pytest.mark.parametrize("seed", range(30))
def test_the_indexed_contour_lookup_names_what_a_scan_of_every_sample_names(seed: int) -> None:
    """Squares on a coarse grid (shared corners and edges: ties of distance), nested
    ones, chains of two open pieces, findings on samples, on edges and in between: the
    k-d tree and bounding boxes give the contour that the scan of every sample gives."""
    import numpy as np

    from camtool.verify.not_cut import _Contours

    rng = np.random.default_rng(seed)
    points, contour_of, runs = [], [], []
    piece = 0
    for c in range(int(rng.integers(2, 9))):
        x0, y0 = rng.integers(0, 4, size=2).astype(float)
        side = float(rng.integers(1, 4))
        square = [(x0, y0), (x0 + side, y0), (x0 + side, y0 + side), (x0, y0 + side)]
        ring = [*square, square[0]]
        split = bool(rng.integers(0, 2))  # a chain of two pieces, meeting at their ends
        for k, (a, b) in enumerate(itertools.pairwise(ring)):
            if split and k == 2:
                piece += 1
            for t in np.linspace(0.0, 1.0, 3)[: -1 if k < 3 else None]:
                points.append((a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])))
                contour_of.append(c)
                runs.append(piece)
        piece += 1
    samples = np.asarray(points, dtype=np.float64)
    contour_of_a = np.asarray(contour_of, dtype=np.int64)
    runs_a = np.asarray(runs, dtype=np.int64)
    index = _Contours(samples, contour_of_a, runs_a)
    named: set[int] = set()
    for _ in range(40):
        at = rng.integers(0, 14, size=2) / 2.0 + (rng.random(2) * 0.5 if rng.random() < 0.3 else 0)
        inside = bool(rng.integers(0, 2))
        want = _scan_named(samples, contour_of_a, runs_a, at, inside, 0.01, named)
        assert index.named(at, inside=inside, joint_mm=0.01, named=named) == want
        if inside and rng.random() < 0.3:
            named.add(want)
