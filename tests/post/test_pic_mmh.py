"""The pic-mmh dialect against seed-000 §3 (S000-01…08)."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest

from camtool.errors import DialectError, ParseError
from camtool.pipeline import post_file
from camtool.post.pic_mmh import PicMmhPost
from camtool.post.registry import load_target
from camtool.program import ArcMove, Linear, Move, Program, Rapid
from tests.shapes import golden_arc_dxf

SAMPLES = Path(__file__).parents[2] / "samples"
GOLDEN = Path(__file__).parents[1] / "golden"

# seed-000 §3.6, the inferred grammar, for the blocks a toolpath uses.
COORD = r"[+-]?\d{5}\.\d{2}"
GRAMMAR = re.compile(
    rf"^(G00X{COORD}Y{COORD}"
    rf"|G01X{COORD}Y{COORD}F\d\d"
    rf"|G0[23]X{COORD}Y{COORD}I{COORD}J{COORD}F\d\d"
    r"|G54|G90|M30);$"
)


def test_golden_block_seed000_l1731(tmp_path: Path) -> None:
    # seed-000 L1731 / S000-04: CW arc centred (3.012, 3.040) mm ending (2.969, 3.400) mm, F08.
    job = post_file(golden_arc_dxf(tmp_path / "arc.dxf"), "pic-mmh", feed_mm_min=0.8)
    lines = str(job.result.code).splitlines()
    assert "G02X02969.00Y03400.00I03012.00J03040.00F08;" in lines


def test_logo_every_line_matches_the_grammar() -> None:
    job = post_file(SAMPLES / "logo.dxf", "pic-mmh")
    lines = str(job.result.code).splitlines()
    assert lines[:2] == ["G54;", "G90;"]  # S000-06
    assert lines[-1] == "M30;"
    bad = [line for line in lines if not GRAMMAR.match(line)]
    assert bad == []
    assert job.result.blocks == len(lines)


def test_logo_golden_file(update_golden: bool) -> None:
    code = str(post_file(SAMPLES / "logo.dxf", "pic-mmh").result.code)
    golden = GOLDEN / "logo.pic"
    if update_golden:
        golden.write_text(code)
    assert code == golden.read_text()


def _emit(moves: tuple, **options: str) -> list[str]:  # type: ignore[type-arg]
    target = load_target("pic-mmh")
    return str(PicMmhPost(**options).emit(Program(moves), target.machine).code).splitlines()


def test_a_g00_starts_each_contour_and_feeds_are_two_digits() -> None:
    lines = _emit(
        (Rapid(1, 1, contour=1), Linear(2, 1, 0.8, contour=1), Linear(2, 2, 9.9, contour=1))
    )
    assert lines == [
        "G54;",
        "G90;",
        "G00X01000.00Y01000.00;",
        "G01X02000.00Y01000.00F08;",
        "G01X02000.00Y02000.00F99;",
        "M30;",
    ]


def test_full_circle_becomes_two_half_arcs() -> None:
    lines = _emit((Rapid(4, 3), ArcMove(4, 3, 5, 3, True, 0.8)))
    assert lines[3:5] == [
        "G02X06000.00Y03000.00I05000.00J03000.00F08;",
        "G02X04000.00Y03000.00I05000.00J03000.00F08;",
    ]


def test_sign_always_option() -> None:
    lines = _emit((Rapid(1, 2),), sign="always")
    assert lines[2] == "G00X+01000.00Y+02000.00;"


@pytest.mark.parametrize("feed", [0.04, 10.0, 25.0])
def test_feed_outside_f01_f99_is_an_error(feed: float) -> None:
    with pytest.raises(DialectError, match=r"contour 2, block 4: feed .* outside F01–F99"):
        _emit((Rapid(1, 1, contour=2), Linear(2, 1, feed, contour=2)))


def test_point_outside_the_work_area_names_contour_and_block() -> None:
    with pytest.raises(DialectError, match=r"contour 1, block 4: .*outside the 10 × 7 mm"):
        _emit((Rapid(1, 1, contour=1), Linear(11, 1, 0.8, contour=1)))


def test_arc_bulging_outside_the_area_is_an_error() -> None:
    # Ends inside the area, but the arc passes y = 7.5 (centre (5, 5), r = 2.5).
    with pytest.raises(DialectError, match="outside"):
        _emit((Rapid(2.5, 5), ArcMove(7.5, 5, 5, 5, True, 0.8)))


def test_z_moves_are_refused() -> None:
    with pytest.raises(DialectError, match="no Z word"):
        _emit((Rapid(1, 1, z=0.5),))


def test_step_rate_warning_above_166_hz() -> None:
    # S000-05: at 140 nm/step, F14 = 1.4 mm/min needs 166.7 steps/s > 166 Hz; F13 does not.
    target = load_target("pic-mmh")
    post = PicMmhPost()
    slow = post.emit(Program((Rapid(1, 1), Linear(2, 1, 1.3))), target.machine)
    fast = post.emit(Program((Rapid(1, 1), Linear(2, 1, 1.4))), target.machine)
    assert slow.warnings == ()
    assert any("166 Hz" in w for w in fast.warnings)


def test_round_trip_logo() -> None:
    # post → parse gives every move back within the 5.2 µm field's resolution (0.01 µm);
    # a full circle comes back as two halves, the first ending at the diametrically
    # opposite point (analytic: 2·centre − start).
    job = post_file(SAMPLES / "logo.dxf", "pic-mmh")
    expected: list[Move] = []
    for start, move in job.program.steps():
        if isinstance(move, ArcMove) and math.dist(start, (move.x, move.y)) < 1e-9:
            ox, oy = 2 * move.cx - start[0], 2 * move.cy - start[1]
            expected.append(ArcMove(ox, oy, move.cx, move.cy, move.clockwise, move.feed_mm_min))
        expected.append(move)
    back = PicMmhPost().parse(str(job.result.code)).moves
    assert [type(m) for m in back] == [type(m) for m in expected]
    resolution = 0.5e-5  # half of 0.01 µm, in mm
    for got, want in zip(back, expected, strict=True):
        assert abs(got.x - want.x) <= resolution and abs(got.y - want.y) <= resolution
        if isinstance(want, ArcMove):
            assert isinstance(got, ArcMove) and got.clockwise == want.clockwise
            assert abs(got.cx - want.cx) <= resolution and abs(got.cy - want.cy) <= resolution
        if not isinstance(want, Rapid):
            assert not isinstance(got, Rapid)
            assert got.feed_mm_min == pytest.approx(want.feed_mm_min)


@pytest.mark.parametrize(
    "bad",
    [
        "G01X01000.00Y01000.00;",
        "G02X01000.00Y01000.00F08;",
        "G01 X01000.00Y01000.00F08;",
        "G01X1000.00Y01000.00F08;",
        "G01X01000.00Y01000.00F08",
        "N10G00X01000.00Y01000.00;",
    ],
)
def test_parse_rejects_what_the_firmware_rejects(bad: str) -> None:
    with pytest.raises(ParseError, match=r"prog.pic:2"):
        PicMmhPost().parse(f"G54;\n{bad}\n", source="prog.pic")
