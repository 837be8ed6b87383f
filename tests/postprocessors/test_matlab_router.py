"""The matlab-router dialect against Angel-11 §3 (the GUI), §2.7 (the wire), §2.8 (jobs), R1–R7.

Golden numbers: reference/Angel-11.md §3, the star worked example (thesis L3183–L3235).
Other expectations are analytic (chord sagitta, the GUI's rounding rule, int16 limits).
"""

from __future__ import annotations

import dataclasses
import itertools
import math
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from camtool.importers.points import read_points
from camtool.jobs.pipeline import OutputOptions, post_file
from camtool.model.errors import DialectError, InputError, ParseError, UsageError
from camtool.model.program import ArcMove, Dwell, Linear, Move, Program, Rapid, Spindle
from camtool.post.registry import load_target
from camtool.verify.verifier import verify_code
from camtool_postprocessors.matlab_router.arrays import matlab_round, router_arrays
from camtool_postprocessors.matlab_router.dialect import MatlabRouterPost
from tests.shapes import STAR_LXY, STAR_VELXY, STAR_XY_01MM

SAMPLES = Path(__file__).parents[2] / "samples"
GOLDEN = Path(__file__).parents[1] / "golden" / "matlab-router"
TARGET = load_target("matlab-router")
GUI = str(Path(__file__).parents[1] / "data" / "matlab-router-gui.toml")
"""The target on the GUI's own 0.1 mm grid: the thesis's arrays, as the GUI wrote them."""
GUI_TARGET = load_target(GUI)
MACHINE = TARGET.machine
FEED = 225.0  # R7: 480 counts / 5 ms at 25 600 counts/mm = 3.75 mm/s on the major axis

# Angel-11 §3, thesis text lines as printed: the velxy block and the first rows of xy, lxy.
THESIS_LINES = [
    "[   151   400   630   575   815   501   400   294     6   220   153; ",  # L3198
    "[   249   230    55   240   314   101   106   288   214    67; ",  # L3214
    "velxy = ",  # L3224
    "[   480   480   -77   480  -480  -136  -144  -480   433   -94; ",  # L3226
    "    345  -374   480   416     5   480  -480    33  -480  -480 ] ",  # L3228
]


def _emit(
    moves: tuple[Move, ...], fmt: str | None = None, **options: object
) -> tuple[str, tuple[str, ...]]:
    options = {"grid_mm": 0.1} | options  # the GUI's grid unless a test says otherwise
    result = MatlabRouterPost(**options).emit(Program(moves), MACHINE, fmt=fmt)  # type: ignore[arg-type]
    assert isinstance(result.code, str)
    return result.code, result.warnings


def _star_moves(contour: int = 0) -> tuple[Move, ...]:
    (x0, *xs), (y0, *ys) = STAR_XY_01MM
    return (
        Rapid(x0 / 10, y0 / 10, contour=contour),
        *(Linear(x / 10, y / 10, FEED, contour=contour) for x, y in zip(xs, ys, strict=True)),
    )


# ------------------------------------------------------------------ the star (golden)


def test_star_csv_is_the_thesis_star_in_mm() -> None:
    # Angel-11 §3, L3196–L3200: xy of the star in 0.1 mm; samples/star.csv holds it in mm.
    drawing = read_points(SAMPLES / "star.csv")
    (contour,) = drawing.contours
    points = contour.points(1e-3)
    assert [p[0] * 10 for p in points] == pytest.approx(STAR_XY_01MM[0], abs=1e-9)
    assert [p[1] * 10 for p in points] == pytest.approx(STAR_XY_01MM[1], abs=1e-9)
    assert not contour.closed  # it ends at (153, 86), not (151, 86): as drawn


def test_posted_star_has_the_thesis_arrays_exactly() -> None:
    # R2 golden test: lxy, velxy of L3212–L3228; n = 10, first point x = 151, y = 86 (L3233).
    job = post_file(SAMPLES / "star.csv", GUI)
    assert isinstance(job.target.post, MatlabRouterPost)
    (router_job,), warnings = job.target.post.jobs(job.program, MACHINE)
    arrays = router_job.arrays
    assert arrays.xy.tolist() == [list(row) for row in STAR_XY_01MM]
    assert arrays.lxy.tolist() == STAR_LXY
    assert arrays.velxy.tolist() == STAR_VELXY
    assert (arrays.n, arrays.first_point) == (10, (151, 86))
    assert warnings == []


def test_star_script_shows_the_thesis_text() -> None:
    # R3: the thesis display format; these lines are verbatim thesis text (L3198–L3228).
    code = str(post_file(SAMPLES / "star.csv", GUI).result.code)
    lines = code.splitlines()
    for line in THESIS_LINES:
        assert line in lines
    assert "% job 1 of 1: stroke 1, contour 1, n = 10, first point x = 151, y = 86" in lines


def test_star_wire_is_the_byte_stream_the_gui_sent() -> None:
    # §2.7 / R4: n, x1, y1, lx(1..n), ly(1..n), velx(1..n), vely(1..n), each '%d' then CR.
    code = post_file(SAMPLES / "star.csv", GUI, output=OutputOptions(fmt="wire")).result.code
    values = [10, 151, 86, *STAR_LXY[0], *STAR_LXY[1], *STAR_VELXY[0], *STAR_VELXY[1]]
    assert code == "".join(f"{v}\r" for v in values)
    assert len(values) == 3 + 4 * 10


@pytest.mark.parametrize(("fmt", "name"), [("script", "star.m"), ("wire", "star.txt")])
def test_star_golden_files(fmt: str, name: str, update_golden: bool) -> None:
    code = str(post_file(SAMPLES / "star.csv", GUI, output=OutputOptions(fmt=fmt)).result.code)
    golden = GOLDEN / name
    if update_golden:
        golden.parent.mkdir(parents=True, exist_ok=True)
        golden.write_bytes(code.encode("ascii"))
    assert code.encode("ascii") == golden.read_bytes()


def test_star_verifies_end_to_end_with_the_chunk_closure() -> None:
    # R14: on the servo model the star ends (+0.4, −0.2) mm from its first point (the
    # floor(d/2) 0.2 mm chunks); the GUI commanded (+0.2, 0). The code is read as the CLI
    # reads it (bytes, CR kept), for both formats.
    for fmt in ("script", "wire"):
        code = str(post_file(SAMPLES / "star.csv", GUI, output=OutputOptions(fmt=fmt)).result.code)
        v = verify_code(code.encode("ascii"), TARGET)
        end = v.trace.carriage_mm[-1] - np.array([15.1, 8.6])
        assert end == pytest.approx((0.4, -0.2), abs=1e-6)
        assert math.isfinite(v.deviation.max_um) and v.deviation.max_um < 400.0
        assert [type(m) for m in v.program.moves] == [Rapid] + [Linear] * 10


def test_the_built_in_target_gives_the_listed_slave_whole_chunks_only() -> None:
    """The listed slave moves an axis floor(d/2) chunks of 0.2 mm (Angel-11 §4.2).

    On the GUI's 0.1 mm grid the star's odd distances lose 0.1 mm each and it ends
    (+0.4, -0.2) mm from its first point (above). The built-in target rounds the vertices
    to 0.2 mm, half away from zero: the star from (151, 86) to (153, 86) in 0.1 mm is
    written from (152, 86) to (154, 86), every distance even, and the servo model ends it
    exactly there.
    """
    job = post_file(SAMPLES / "star.csv", "matlab-router")
    assert isinstance(job.target.post, MatlabRouterPost)
    (router_job,), warnings = job.target.post.jobs(job.program, MACHINE)
    xy = router_job.arrays.xy  # (2, N): x then y
    assert (xy % 2 == 0).all() and (router_job.arrays.lxy % 2 == 0).all()
    assert (xy[:, 0].tolist(), xy[:, -1].tolist()) == ([152, 86], [154, 86])
    assert not any("0.1 mm (first" in w for w in warnings)
    v = verify_code(str(job.result.code).encode("ascii"), TARGET)
    assert v.trace.carriage_mm[-1] == pytest.approx((15.4, 8.6), abs=1e-6)


def test_a_circle_on_the_built_in_target_has_no_segment_the_slave_runs_away_on() -> None:
    """Chords of a circle on the 0.1 mm grid include 0.1 mm moves (the slave's d = 1
    underflow, Angel-11 §4.2: that axis runs away); on the 0.2 mm grid none is left."""
    circle = (Rapid(65, 50), ArcMove(65, 50, 50, 50, "ccw", FEED))  # r = 15 mm
    _, gui_warnings = _emit(circle)
    assert any("move an axis by 0.1 mm" in w for w in gui_warnings)
    result = MatlabRouterPost().emit(Program(circle), MACHINE)
    assert not any("move an axis by 0.1 mm" in w for w in result.warnings)
    program = MatlabRouterPost().parse(str(result.code))
    ends = [(m.x, m.y) for m in program.moves]
    steps = np.abs(np.diff(np.round(np.array(ends) * 10).astype(int), axis=0))
    assert (steps % 2 == 0).all() and len(ends) > 20
    # every vertex within half the grid's diagonal plus the chords' sagitta of the circle
    assert all(abs(math.dist(p, (50, 50)) - 15) <= 0.05 + 0.1 * math.sqrt(2) + 1e-9 for p in ends)


def test_a_vertex_the_grid_moves_out_of_the_work_area_is_refused() -> None:
    """199.9 mm rounds to 200 mm on the 0.2 mm grid: beyond a work area that ends at 199.9
    mm (a --machine bound off the grid); 0.1 mm further in it rounds to 199.8 mm."""
    edge = dataclasses.replace(MACHINE, work_area_mm=(0.0, 0.0, 199.9, 199.9))
    moves = (Rapid(1, 1), Linear(199.9, 1, FEED), Linear(199.9, 50, FEED))
    with pytest.raises(DialectError, match=r"\(200, 50\) mm on the 0.2 mm grid, outside the work "):
        MatlabRouterPost().emit(Program(moves), edge)
    inside = (Rapid(1, 1), Linear(199.8, 1, FEED), Linear(199.8, 50, FEED))
    code = MatlabRouterPost().emit(Program(inside), edge).code
    assert max(m.x for m in MatlabRouterPost().parse(code).moves) == pytest.approx(199.8)


def test_posted_script_is_read_by_the_points_importer(tmp_path: Path) -> None:
    # The script is a Matlab file of xy/lxy/velxy: camtool's own .m importer reads the strokes.
    path = tmp_path / "star.m"
    path.write_text(str(post_file(SAMPLES / "star.csv", GUI).result.code))
    (contour,) = read_points(path).contours
    assert [round(p[0] * 10) for p in contour.points(1e-3)] == list(STAR_XY_01MM[0])


def test_first_pointy_as_char_reproduces_the_gui_bug() -> None:
    # L4306: fprintf(s,'%c',first_pointy) sends y1 = 86 as the one character 'V' (chr 86).
    post = MatlabRouterPost(first_pointy_as_char=True, grid_mm=0.1)
    code = str(post.emit(Program(_star_moves()), MACHINE, fmt="wire").code)
    assert code.startswith("10\r151\rV\r249\r")
    assert post.parse(code) == MatlabRouterPost().parse(code.replace("\rV\r", "\r86\r", 1))
    with pytest.raises(DialectError, match="y1 = 200 cannot be sent as one character"):
        post.emit(Program((Rapid(1, 20), Linear(2, 21, FEED))), MACHINE, fmt="wire")


# ------------------------------------------------------------------ capacity, jobs


def _zigzag(points: int) -> tuple[Move, ...]:
    """``points`` vertices 1 mm apart in X and Y (every segment at 480/480)."""
    return (
        Rapid(10.0, 10.0, contour=1),
        *(Linear(10.0 + i, 10.0 + i % 2, FEED, contour=1) for i in range(1, points)),
    )


def test_129_points_fit_one_job_130_are_split() -> None:
    # §2.7: the master's arrays hold 128 lines (X_ROUTE[128], L4625): 129 points = 128 lines.
    post = MatlabRouterPost()
    jobs, warnings = post.jobs(Program(_zigzag(129)), MACHINE)
    assert [j.arrays.n for j in jobs] == [128] and warnings == []
    jobs, warnings = post.jobs(Program(_zigzag(130)), MACHINE)
    assert [j.arrays.n for j in jobs] == [128, 1]
    assert jobs[1].arrays.first_point == tuple(jobs[0].arrays.xy[:, -1].tolist())
    assert (jobs[1].part, jobs[1].parts, jobs[1].first_segment) == (2, 2, 129)
    assert any("split into jobs that continue from the same vertex" in w for w in warnings)
    back = post.parse(post.emit(Program(_zigzag(130)), MACHINE).code).moves
    assert isinstance(back[129], Rapid) and (back[129].x, back[129].y) == (back[128].x, back[128].y)


def test_max_segments_option_and_the_reader_refuses_more() -> None:
    code, _ = _emit(_star_moves(), max_segments=4)
    assert code.count("\nxy = ") == 3  # 10 segments: 4 + 4 + 2
    with pytest.raises(ParseError, match="n = 10 segments; a job holds 1 to 4"):
        MatlabRouterPost(max_segments=4).parse(_emit(_star_moves())[0])
    wire = "129\r" + "0\r" * (3 + 4 * 129)
    with pytest.raises(ParseError, match=r"<code>:1: job 1: n = 129; a job holds 1 to 128"):
        MatlabRouterPost().parse(wire)


def test_every_stroke_is_a_job_and_the_script_names_them() -> None:
    moves = (*_star_moves(1)[:3], Rapid(100, 100, contour=2), Linear(110, 100, FEED, contour=2))
    code, warnings = _emit(moves)
    assert "% job 2 of 2: stroke 2, contour 2, n = 1, first point x = 1000, y = 1000" in code
    assert any(w.startswith("2 jobs: the router has no travel inside a job") for w in warnings)


# ------------------------------------------------------------------ arcs → chords


def test_full_circle_becomes_chords_within_the_tolerance() -> None:
    # Analytic: r = 10 mm, tol 0.05 mm: θ ≤ 2·acos(1 − 0.05/10), so ⌈2π/θ⌉ = 32 chords of
    # sagitta r(1 − cos(π/32)) = 0.0482 mm; vertices then move by ≤ √2·0.05 mm (rounding).
    r, tol = 10.0, 0.05
    count = math.ceil(math.tau / (2 * math.acos(1 - tol / r)))
    sagitta = r * (1 - math.cos(math.pi / count))
    moves = (Rapid(60.0, 50.0), ArcMove(60.0, 50.0, 50.0, 50.0, False, FEED))
    code, warnings = _emit(moves, chord_tolerance_mm=tol)
    assert count == 32
    assert (
        f"1 arc(s) written as {count} chords within 0.05 mm (largest sagitta {sagitta:.4f} mm)"
        in (" ".join(warnings))
    )
    back = MatlabRouterPost().parse(code).moves
    pts = np.array([(m.x, m.y) for m in back]) - 50.0
    assert len(back) == count + 1 and (back[-1].x, back[-1].y) == (60.0, 50.0)
    rounding = math.sqrt(2) * 0.05
    assert np.abs(np.hypot(*pts.T) - r).max() <= rounding + 1e-9
    mids = (pts[1:] + pts[:-1]) / 2
    assert (r - np.hypot(*mids.T)).max() <= tol + rounding


def test_machine_tolerance_is_the_default_and_the_option_overrides_it() -> None:
    # router-2011 [motion] chord_tolerance_mm = 0.05; a 0.01 mm option gives more chords.
    moves = (Rapid(60.0, 50.0), ArcMove(40.0, 50.0, 50.0, 50.0, True, FEED))  # half circle
    half = math.pi

    def chords(tol: float) -> int:
        return math.ceil(half / (2 * math.acos(1 - tol / 10.0)))

    _, default = _emit(moves)
    _, fine = _emit(moves, chord_tolerance_mm=0.01)
    assert f"as {chords(MACHINE.motion.chord_tolerance_mm)} chords" in " ".join(default)
    assert f"as {chords(0.01)} chords" in " ".join(fine)


# ------------------------------------------------------------------ round trips


@st.composite
def _grid_strokes(draw: st.DrawFn) -> list[list[tuple[int, int]]]:
    """Strokes of 2–20 whole-0.1 mm vertices inside 0–2000 whose speeds never round to 0."""
    coord = st.integers(0, 2000)
    strokes = []
    for _ in range(draw(st.integers(1, 3))):
        pts = draw(st.lists(st.tuples(coord, coord), min_size=2, max_size=20))
        pts = [p for i, p in enumerate(pts) if i == 0 or p != pts[i - 1]]
        if len(pts) >= 2:
            arrays = router_arrays(np.array(pts))
            if not ((arrays.lxy > 0) & (arrays.velxy == 0)).any():
                strokes.append(pts)
    return strokes


def _stroke_program(
    strokes: list[list[tuple[float, float]]], feed: float = FEED
) -> tuple[Move, ...]:
    moves: list[Move] = []
    for number, pts in enumerate(strokes, start=1):
        moves.append(Rapid(*pts[0], contour=number))
        moves.extend(Linear(x, y, feed, contour=number) for x, y in pts[1:])
    return tuple(moves)


@settings(max_examples=60, deadline=None)
@given(_grid_strokes(), st.sampled_from(["script", "wire"]))
def test_round_trip_on_the_grid_is_exact(strokes: list[list[tuple[int, int]]], fmt: str) -> None:
    # post → parse gives every move back exactly: vertices on the 0.1 mm grid, one Rapid
    # per job, feeds = the major-axis speed (225 mm/min).
    assume(strokes)
    program = _stroke_program([[(x / 10, y / 10) for x, y in s] for s in strokes])
    code, _ = _emit(program, fmt)
    back = MatlabRouterPost().parse(code.encode("ascii"))
    assert back.moves == program
    assert len(back.lines) == len(program)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.floats(0, 200), st.floats(0, 200)), min_size=2, max_size=15))
def test_the_built_in_grid_gives_whole_chunks_only(points: list[tuple[float, float]]) -> None:
    """On the 0.2 mm grid every distance is even in 0.1 mm (the slave's whole chunks, Angel-11
    §4.2), slow minor axes cut into pieces included; the stroke's ends are its points rounded
    half away from zero to 0.2 mm."""
    try:
        result = MatlabRouterPost().emit(Program(_stroke_program([points])), MACHINE)
    except DialectError as exc:  # a stroke that rounds to one point
        assert "nothing to cut" in str(exc)
        return
    back = [(round(m.x * 10), round(m.y * 10)) for m in MatlabRouterPost().parse(result.code).moves]
    assert all(x % 2 == 0 and y % 2 == 0 for x, y in back)
    grid = [tuple((2 * matlab_round(np.array(p) * 5.0)).tolist()) for p in points]
    kept = [p for i, p in enumerate(grid) if i == 0 or p != grid[i - 1]]
    assert back[0] == kept[0] and back[-1] == kept[-1]
    assert not any("move an axis by 0.1 mm" in w for w in result.warnings)


@settings(max_examples=60, deadline=None)
@given(st.lists(st.tuples(st.floats(0, 200), st.floats(0, 200)), min_size=2, max_size=15))
def test_round_trip_rounds_half_away_from_zero(points: list[tuple[float, float]]) -> None:
    # R1: each vertex comes back as matlab_round(x_mm·10)/10, repeats after rounding dropped.
    grid = [tuple(matlab_round(np.array(p) * 10.0).tolist()) for p in points]
    kept = [p for i, p in enumerate(grid) if i == 0 or p != grid[i - 1]]
    try:
        code, warnings = _emit(_stroke_program([points]))
    except DialectError as exc:  # a stroke that rounds to one point
        assert "nothing to cut" in str(exc)
        return
    back = [(round(m.x * 10), round(m.y * 10)) for m in MatlabRouterPost().parse(code).moves]
    _assert_pieces_of(back, kept)
    assert (len(back) > len(kept)) == any("cut into pieces" in w for w in warnings)
    assert (len(kept) < len(grid)) == any("rounded onto the previous one" in w for w in warnings)


def _assert_pieces_of(back: list[tuple[int, int]], kept: list[tuple[int, int]]) -> None:
    """``back`` is ``kept`` (0.1 mm), a segment at times cut into pieces ending on the grid.

    Every vertex of ``kept`` comes back in order; one between two of them lies on the
    segment they make, to half a count (0.05 mm, as every rounded vertex does), and each
    piece's minor axis moves at a speed that does not round to 0 (480 · minor/major ≥ 0.5).
    """
    at = 0
    for k, vertex in enumerate(kept):
        while back[at] != vertex:
            (ax, ay), (bx, by), (px, py) = kept[k - 1], vertex, back[at]
            off = abs((bx - ax) * (py - ay) - (by - ay) * (px - ax)) / math.hypot(bx - ax, by - ay)
            assert off <= 0.5 * math.sqrt(2) + 1e-9, (back[at], kept[k - 1], vertex)
            at += 1
        at += 1
    assert at == len(back)
    for (x0, y0), (x1, y1) in itertools.pairwise(back):
        major, minor = max(abs(x1 - x0), abs(y1 - y0)), min(abs(x1 - x0), abs(y1 - y0))
        assert minor == 0 or 480 * minor / major >= 0.5


# ------------------------------------------------------------------ writer errors, warnings


def test_z_moves_are_refused() -> None:
    with pytest.raises(DialectError, match=r"contour 1, block 2: matlab-router has no Z"):
        _emit((Rapid(1, 1, contour=1), Linear(2, 2, FEED, z=-1.0, contour=1)))


def test_point_outside_the_work_area_names_contour_and_block() -> None:
    # router-2011: the GUI's drawable 20 × 20 cm (axis([0 20 0 20]), L4406).
    where = r"contour 3, block 2: .*outside the work area X 0…200, Y 0…200 mm"
    with pytest.raises(DialectError, match=where + r".*--translate moved by -1 0 mm"):
        _emit((Rapid(150, 150, contour=3), Linear(201, 150, FEED, contour=3)))
    with pytest.raises(DialectError, match="outside"):  # an arc bulging past y = 200
        _emit((Rapid(150, 195), ArcMove(170, 195, 160, 195, True, FEED)))


def test_a_reposted_program_outside_the_area_names_its_line_and_is_moved_where_it_was_written(
    tmp_path: Path,
) -> None:
    """G-code from another program (its Z dropped: the router has none) reaching X -0.5:
    the refusal names the input line, and the remedy is to move it where it was written
    (``--origin`` and ``--translate`` are refused for G-code)."""
    source = tmp_path / "cambam.nc"
    source.write_text(
        "G21 G90\nG0 Z3\nG0 X2 Y2\nG1 Z-1 F300\nG1 X10 Y2 F2000\nG1 X-0.5 Y5\nG0 Z3\nM30\n"
    )
    with pytest.raises(DialectError) as refused:
        post_file(source, "matlab-router")
    text = str(refused.value)
    assert text.startswith(
        "contour 1, block 3 (input line 6): reaches X -0.5000…10.0000, Y 2.0000…"
    )
    assert text.endswith(
        "move the program by X0.5 Y0 mm in the program that wrote it (its work zero), then "
        "post it again: camtool re-posts a program where it is"
    )


def test_a_segment_whose_minor_axis_speed_rounds_to_zero_is_cut_into_pieces() -> None:
    """§3: vely = 480/(1940/2) = 0.49 rounds to 0: the slave never reaches its count (§4.2).

    An openclipart drawing (sailing_capsize2.svg) had such a segment, 0.1 mm in 106.1 mm,
    and could not be posted. At most 480 counts of the major axis a piece, the minor axis
    moves at speed 1 or more: ceil(1940 / 480) = 5 pieces, ends on the grid.
    """
    code, warnings = _emit((Rapid(1.0, 1.0), Linear(195.0, 1.2, FEED)))
    back = [(round(m.x * 10), round(m.y * 10)) for m in MatlabRouterPost().parse(code).moves]
    assert len(back) == 6
    _assert_pieces_of(back, [(10, 10), (1950, 12)])
    assert any(
        "1 segment(s) whose shorter axis would move at a speed that rounds to 0" in w
        and "block 2: 2 in 1940 counts, in 5 pieces" in w
        for w in warnings
    )
    # 1 in 960: 480/960 = 0.5 rounds half away from zero to 1 (R1): it runs, as it is
    code, warnings = _emit((Rapid(1.0, 1.0), Linear(97.0, 1.1, FEED)))
    assert len(MatlabRouterPost().parse(code).moves) == 2
    assert not any("cut into pieces" in w for w in warnings)


def test_conversions_are_warned_once_per_kind() -> None:
    moves = (
        Rapid(10, 10),
        Linear(20, 10, 100.0),
        Linear(20, 10.01, 100.0),  # rounds onto (20, 10): dropped
        Linear(30, 10.1, 300.0),  # ly = 1: the firmware's d = 1 underflow (§4.2)
        Rapid(0, 0),
    )
    program = Program(
        moves, commands=((0, Spindle("cw", 10000)), (3, Dwell(1.0)), (5, Spindle("off")))
    )
    result = MatlabRouterPost(grid_mm=0.1).emit(program, MACHINE)
    text = "\n".join(result.warnings)
    assert "2 Spindle command(s) not written" in text and "1 Dwell command(s)" in text
    assert "feeds ignored (100, 300 mm/min)" in text and "225 mm/min" in text
    assert "1 vertex(es) rounded onto the previous one" in text and "block 3" in text
    assert "the final rapid to (0, 0) mm is not written" in text
    assert "1 segment(s) move an axis by 0.1 mm (first: block 4 (stroke 1, segment 2) Y)" in text
    assert len(result.warnings) == 6


def test_a_stroke_that_rounds_to_one_point_is_dropped_with_a_warning() -> None:
    _, warnings = _emit(
        (Rapid(5, 5), Linear(5.02, 5.01, FEED), Rapid(10, 10), Linear(11, 11, FEED))
    )
    assert any("rounds to the single point (5, 5) mm" in w for w in warnings)
    with pytest.raises(DialectError, match="nothing to cut"):
        _emit((Rapid(5, 5), Linear(5.02, 5.01, FEED)))


def test_speed_option_scales_the_arrays_and_the_reader_checks_it() -> None:
    # R7: major axis = speed, minor = round(speed·minor/major): 300·179/249 = 215.66 → 216.
    post = MatlabRouterPost(speed=300, grid_mm=0.1)
    code = str(post.emit(Program(_star_moves()), MACHINE).code)
    assert "[   300   300   -48   300  -300" in code  # 300·55/345 = 47.8 → 48
    assert "    216  -233   300" in code  # 300·179/249 = 215.66, 300·179/230 = 233.48
    segment = post.parse(code).moves[1]
    assert isinstance(segment, Linear)
    assert segment.feed_mm_min == pytest.approx(300 / 25600 / 0.005 * 60)  # R7
    with pytest.raises(
        ParseError, match=r"job 1, velxy column 1 .*: 300 where the GUI's rule gives 480"
    ):
        MatlabRouterPost().parse(code)


@pytest.mark.parametrize(
    "options",
    [{"speed": 0}, {"speed": 480.5}, {"speed": True}, {"max_segments": 256}, {"max_segments": 0},
     {"chord_tolerance_mm": 0}, {"first_pointy_as_char": "yes"}, {"grid_mm": 0.3},
     {"grid_mm": True}, {"grid_mm": "0.2"}],
)  # fmt: skip
def test_bad_options_are_usage_errors(options: dict[str, object], tmp_path: Path) -> None:
    with pytest.raises(UsageError):
        MatlabRouterPost(**options)  # type: ignore[arg-type]
    key, value = next(iter(options.items()))
    toml = tmp_path / "bad.toml"
    shown = str(value).lower() if isinstance(value, bool) else repr(value).replace("'", '"')
    toml.write_text(
        f'dialect = "matlab-router"\nmachine = "router-2011"\n[dialect_options]\n{key} = {shown}\n'
    )
    with pytest.raises(InputError, match=r"bad\.toml: invalid dialect_options"):
        load_target(str(toml))


# ------------------------------------------------------------------ reader strictness


def _star_script() -> str:
    return _emit(_star_moves())[0]


@pytest.mark.parametrize(
    ("old", "new", "message"),
    [
        ("  -480   433", "  -480   432", r"velxy column 9 .*row 1 \(x\): 432 where .* gives 433"),
        ("   179   179   345", "   179   178   345", r"job 1, lxy column 2 .*row 2 \(y\): 178"),
        ("lxy = ", "lx = ", r":\d+: expected 'xy = ', 'lxy = ' or 'velxy = '"),
        ("   -77 ", "  -7.7 ", r"velxy: '-7.7' is not a whole number"),
        ("   -77 ", "   -077 ", r"velxy: '-077' is not a whole number"),
        ("   433   -94; ", "   433; ", r"velxy: 9 and 10 numbers in 2 row"),
        ("velxy = ", "xy = ", r"job 1: found xy, lxy, xy; each job is xy, lxy, velxy"),
    ],
)
def test_script_reader_is_strict(old: str, new: str, message: str) -> None:
    code = _star_script()
    assert old in code
    with pytest.raises(ParseError, match=message):
        MatlabRouterPost().parse(code.replace(old, new, 1), source="star.m")


@pytest.mark.parametrize("newline", ["\n", "\r\n"])
def test_reader_reads_the_arrays_as_the_thesis_prints_them(newline: str) -> None:
    # tests/data/star.m is L3196–L3228 verbatim (its second rows sit one column left of
    # camtool's): the reader takes any spacing, and Windows line ends.
    text = (Path(__file__).parents[1] / "data" / "star.m").read_text().replace("\n", newline)
    program = MatlabRouterPost().parse(text.encode("ascii"), source="star.m")
    assert program.moves == _star_moves(1)


def test_script_errors_name_the_source_and_line() -> None:
    code = _star_script().replace("-144  -480   433", "-144  -480   432")
    line = next(i for i, t in enumerate(code.splitlines(), 1) if "432" in t)
    with pytest.raises(ParseError, match=rf"^star.m:{line}: job 1, velxy column 9"):
        MatlabRouterPost().parse(code, source="star.m")


def _star_wire() -> str:
    return _emit(_star_moves(), "wire")[0]


def _replace(old: str, new: str) -> Callable[[str], str]:
    return lambda code: code.replace(old, new, 1)


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (lambda c: c.replace("\r", "\n"), r":1: '10\\n151\\n86.*' does not end with CR"),
        (lambda c: c[:-1], r":43: '-480' does not end with CR"),
        (lambda c: c.rsplit("\r", 3)[0] + "\r", r":41: job 1: the stream ends after 41 of its"),
        (lambda c: "0\r" + c, r":1: job 1: n = 0"),
        (_replace("\r249\r", "\r-249\r"), r":4: job 1: lx\(1\) = -249; distances are absolute"),
        (_replace("\r-77\r", "\r-0\r"), r":26: job 1: velx\(3\): '-0' is not a decimal integer"),
        (_replace("\r-374\r480\r", "\r-374\r481\r"), r":36: job 1, velxy column 3 .*: 481"),
        (_replace("\r151\r", "\r1234567\r"), r":2: job 1: x1: '1234567' is not .* at most 6"),
        (_replace("\r151\r", "\r40000\r"), r":2: job 1: x1: 40000 does not fit"),
        (lambda c: "1\r10\r10\r2\r2000\r0\r480\r", r":6: job 1, segment 1: X moves 2 .* speed 0"),
    ],
)
def test_wire_reader_is_strict(edit: Callable[[str], str], message: str) -> None:
    # §2.7: ASCII decimals of at most 6 characters, each ended by CR; 3 + 4n values per job.
    with pytest.raises(ParseError, match="^star.txt" + message):
        MatlabRouterPost().parse(edit(_star_wire()).encode("ascii"), source="star.txt")


def test_reader_lines_point_at_the_vertex() -> None:
    # Script: the line of the x row of xy; wire: the record of x1 (the rapid) and of lx(i).
    script = _star_script()
    xy_line = script.splitlines().index(THESIS_LINES[0]) + 1
    assert MatlabRouterPost().parse(script).lines == (xy_line,) * 11
    assert MatlabRouterPost().parse(_star_wire()).lines == (2, *range(4, 14))


def test_empty_and_non_text_code_is_refused() -> None:
    with pytest.raises(ParseError, match="empty"):
        MatlabRouterPost().parse(b"  \n")
    with pytest.raises(ParseError, match="byte 1 is not text"):
        MatlabRouterPost().parse(b"1\xff\r")


def test_cli_post_wire_then_verify(tmp_path: Path) -> None:
    # The CLI reads matlab-router code as bytes (binary = True), so the CRs survive.
    from click.testing import CliRunner

    from camtool.cli.main import cli

    out = tmp_path / "star.txt"
    runner = CliRunner()
    posted = runner.invoke(
        cli,
        [
            "post",
            str(SAMPLES / "star.csv"),
            "-t",
            GUI,
            "--format",
            "wire",
            "-o",
            str(out),
        ],
    )
    assert posted.exit_code == 0, posted.output
    assert out.read_bytes().startswith(b"10\r151\r86\r249\r")
    verified = runner.invoke(cli, ["verify", str(out), "-t", "matlab-router"])
    assert verified.exit_code == 0, verified.output
