"""The flashcut target (a TOML word-address dialect) against Yanez-07 §3, R1–R8, R11, R14."""

from __future__ import annotations

import math
import re
from pathlib import Path

import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from camtool.jobs.pipeline import post_file, verify_job
from camtool.model.errors import DialectError, ParseError
from camtool.model.program import ArcMove, Linear, Move, Program, Rapid, Spindle
from camtool.model.shapes import Arc
from camtool.post.registry import load_target
from camtool.verify.verifier import verify_code

ROOT = Path(__file__).parents[2]
GOLDEN = ROOT / "tests" / "golden" / "flashcut"
TARGET = load_target("flashcut")
POST = TARGET.post

# Yanez-07 §3.7 inferred grammar, for the blocks camtool writes (R1, R7): every number with a
# point and at least one decimal, words separated by one space.
NUM = r"-?\d{1,4}\.\d{1,3}"
GRAMMAR = re.compile(
    rf"^(G00 X{NUM} Y{NUM}|G00 Z{NUM}|G01 X{NUM} Y{NUM}( F{NUM})?|G01 Z{NUM}( F{NUM})?"
    rf"|G0[23] X{NUM} Y{NUM} I{NUM} J{NUM}( F{NUM})?|M0[345]|M30)$"
)


def emit(moves: tuple[Move, ...], **program: object) -> list[str]:
    return str(TARGET.emit(Program(moves, **program)).code).splitlines()  # type: ignore[arg-type]


def test_r1_r2_thesis_examples_are_written_verbatim() -> None:
    # Yanez-07 §3.3, L1004-1005 and L1020-1021: the four literal lines (tests/data holds them).
    moves = (
        Linear(1, 1, 3.0),
        ArcMove(3, 3, 2, 2, True, 3.0),  # starts (1,1), centre (2,2), ends (3,3)
        Linear(2, 1, 8.0),
        ArcMove(0, 3, 1, 2, False, 8.0),  # starts (2,1), centre (1,2), ends (0,3)
    )
    thesis = (ROOT / "tests" / "data" / "flashcut-seed001.nc").read_text().splitlines()
    assert emit(moves) == [*thesis, "M30"]  # F3.0 not repeated: F is modal (R3)


def test_r2_thesis_examples_read_to_their_glossed_arcs() -> None:
    program = POST.parse((ROOT / "tests" / "data" / "flashcut-seed001.nc").read_text())
    a, b, c, d = program.moves
    assert a == Linear(1, 1, 3.0, contour=1) and c == Linear(2, 1, 8.0, contour=1)
    assert b == ArcMove(3, 3, 2, 2, True, 3.0, contour=1)  # "con centro en (2,2)", same F (R3)
    assert d == ArcMove(0, 3, 1, 2, False, 8.0, contour=1)  # "con centro en (1,2)"
    # Both are semicircles of radius √2 (Yanez-07 §3.3): the G02 (225° → 45° clockwise)
    # passes (2 − √2, 2) and (2, 2 + √2) a quarter and three quarters of the way; the G03
    # (−45° → 135°) passes (1 + √2, 2) and, half way, (2, 3).
    first = Arc((1, 1), (b.x, b.y), (b.cx, b.cy), b.clockwise)
    second = Arc((2, 1), (d.x, d.y), (d.cx, d.cy), d.clockwise)
    assert first.sweep == pytest.approx(-math.pi) and second.sweep == pytest.approx(math.pi)
    assert first.point_at(0.25) == pytest.approx((2 - math.sqrt(2), 2))
    assert first.point_at(0.75) == pytest.approx((2, 2 + math.sqrt(2)))
    assert second.point_at(0.25) == pytest.approx((1 + math.sqrt(2), 2))
    assert second.point_at(0.5) == pytest.approx((2, 3))


def test_r3_f_is_modal_and_g00_takes_none() -> None:
    moves = POST.parse("G01 X1.0 Y1.0 F3.0\nG01 X2.0 Y1.0\nG00 X0.0 Y0.0\n").moves
    assert [getattr(m, "feed_mm_min", None) for m in moves] == [3.0, 3.0, None]
    with pytest.raises(ParseError, match=r"p.nc:1: F in a rapid block"):
        POST.parse("G00 X1.0 Y1.0 F3.0\n", source="p.nc")


@pytest.mark.parametrize("block", ["G00 X1.0", "G01 Y1.0 F3.0", "G02 X1.0 I1.0 J0.0"])
def test_r4_both_x_and_y_are_required(block: str) -> None:
    # L985: "si una de las dos coordenadas (X o Y) no cambia de valor, aún así es necesario
    # ponerla".
    with pytest.raises(ParseError, match=r"p.nc:1: missing [XY] word"):
        POST.parse(block + "\n", source="p.nc")


def test_r4_writer_repeats_unchanged_x_and_y() -> None:
    assert emit((Rapid(1, 1), Linear(1, 2, 3.0)))[:2] == ["G00 X1.0 Y1.0", "G01 X1.0 Y2.0 F3.0"]


def test_r7_z_in_blocks_of_its_own_with_a_decimal_everywhere() -> None:
    # L982, L991: "G00 Zvalor_z" and "G01 Zvalor_z" are blocks of their own.
    moves = (
        Rapid(0, 0, z=1.0),
        Rapid(2.5, 3.25, z=1.0),
        Linear(2.5, 3.25, 3.0, z=-0.05),
        Linear(4, 3.25, 3.0),
        Rapid(4, 3.25, z=1.0),
    )
    lines = emit(moves, commands=((0, Spindle("cw", 100.0)), (5, Spindle("off"))))
    assert lines == [
        "M03",  # no S word in the app's M03 (L1068-1076)
        "G00 Z1.0",
        "G00 X2.5 Y3.25",
        "G01 Z-0.05 F3.0",
        "G01 X4.0 Y3.25",
        "G00 Z1.0",
        "M05",
        "M30",
    ]
    assert all(GRAMMAR.match(line) for line in lines)


def test_a_counter_clockwise_spindle_is_written_and_its_speed_warned_by_both_codes() -> None:
    # L1068-1076: the app writes M03 and M04 without an S word.
    program = Program((Rapid(0, 0), Linear(1, 0, 3.0)), commands=((0, Spindle("ccw", 900.0)),))
    result = TARGET.emit(program)
    assert str(result.code).splitlines()[0] == "M04"
    assert result.warnings[0].startswith("flashcut's M03/M04 take no S word: 1 spindle speed")


def test_full_circle_is_written_as_two_halves() -> None:
    # start == end is not described for the VB6 app (§4.4): two halves work either way.
    lines = emit((Rapid(6, 5), ArcMove(6, 5, 5, 5, True, 3.0)))
    assert lines[1:3] == ["G02 X4.0 Y5.0 I-1.0 J0.0 F3.0", "G02 X6.0 Y5.0 I1.0 J0.0"]


def test_r8_work_area_20_by_35_mm() -> None:
    # L620: 20 mm of travel in X, 35 mm in Y, from the "Cero de programa" the operator sets
    # (§7.6): work coordinates, so a toolpath of 20 × 35 mm fits wherever it lies, and one
    # 20.5 mm long does not.
    assert TARGET.machine.work_area_mm == (0.0, 0.0, 20.0, 35.0)
    assert TARGET.machine.coordinates == "work"
    emit((Rapid(-10, -5), Linear(10, 30, 3.0)))
    with pytest.raises(DialectError, match=r"20.5 × 1 mm, larger than the 20 × 35 mm travel"):
        emit((Rapid(0, 0), Linear(20.5, 1, 3.0)))


def test_r8_r11_a_10_by_5_mm_line_is_5263_steps_and_2763_at_20_ms() -> None:
    # R8: 10 mm → 5263 steps at the app's 1.9 µm (L1208); R11 / Table 3.8: at the recommended
    # 20 ms half period the non-dominant Y makes 2763 steps for the theoretical 2632;
    # time 5263 × 2·(20 + 1) ms = 221.046 s (R15).
    v = verify_code("\n".join(emit((Rapid(0, 0), Linear(10, 5, 3.0)))), TARGET)
    assert v.trace.block_steps[-1].tolist() == [5263, 2763, 0]
    assert v.time_s == pytest.approx(5263 * 0.042)


def test_logo_golden_and_grammar(update_golden: bool) -> None:
    code = str(post_file(ROOT / "samples" / "logo.dxf", "flashcut").result.code)
    golden = GOLDEN / "logo.nc"
    if update_golden:
        golden.parent.mkdir(parents=True, exist_ok=True)
        golden.write_text(code)
    assert code == golden.read_text()
    assert all(GRAMMAR.match(line) for line in code.splitlines())


def _expected(program: Program) -> list[Move]:
    """The moves as written: full circles in two halves (analytic: through 2·centre − start)."""
    out: list[Move] = []
    for start, move in program.steps():
        if isinstance(move, ArcMove) and math.dist(start, (move.x, move.y)) < 1e-9:
            half = (2 * move.cx - start[0], 2 * move.cy - start[1])
            out.append(ArcMove(*half, move.cx, move.cy, move.clockwise, move.feed_mm_min))
        out.append(move)
    return out


def _assert_round_trip(program: Program) -> None:
    # X/Y within half a written step (0.0005 mm); the centre is written start + rounded I/J,
    # so within one step; feeds at 0.1 mm/min.
    back = POST.parse(TARGET.emit(program).code).moves
    want = _expected(program)
    assert [type(m) for m in back] == [type(m) for m in want]
    for got, exp in zip(back, want, strict=True):
        assert abs(got.x - exp.x) <= 0.0005 + 1e-12 and abs(got.y - exp.y) <= 0.0005 + 1e-12
        if isinstance(exp, ArcMove):
            assert isinstance(got, ArcMove) and got.clockwise == exp.clockwise
            assert math.dist((got.cx, got.cy), (exp.cx, exp.cy)) <= 0.001 * math.sqrt(2) + 1e-12
        if isinstance(exp, Linear | ArcMove):
            assert abs(got.feed_mm_min - exp.feed_mm_min) <= 0.05 + 1e-12  # type: ignore[union-attr]


def test_round_trip_logo() -> None:
    _assert_round_trip(post_file(ROOT / "samples" / "logo.dxf", "flashcut").program)


@st.composite
def programs(draw: st.DrawFn) -> Program:
    """Random rapids, lines and arcs inside the 20 × 35 mm work area."""
    coord = st.floats(0.0, 1.0)
    moves: list[Move] = [Rapid(draw(st.floats(5, 15)), draw(st.floats(5, 30)))]
    for _ in range(draw(st.integers(1, 6))):
        here = (moves[-1].x, moves[-1].y)
        feed = draw(st.floats(0.1, 99.0))
        if draw(st.booleans()):
            moves.append(Linear(5 + 10 * draw(coord), 5 + 25 * draw(coord), feed))
            continue
        r = draw(st.floats(0.01, 4.0))
        a0, a1 = draw(st.floats(0, 2 * math.pi)), draw(st.floats(0, 2 * math.pi))
        cx, cy = here[0] - r * math.cos(a0), here[1] - r * math.sin(a0)
        end = (cx + r * math.cos(a1), cy + r * math.sin(a1))
        if draw(st.booleans()):
            end = here  # a full circle
        assume(math.dist(end, here) > 0.002 or end == here)  # near-full: test_wordaddress
        assume(cx - r > 4 and cx + r < 16 and cy - r > 4 and cy + r < 31)
        moves.append(ArcMove(*end, cx, cy, draw(st.booleans()), feed))
    return Program(tuple(moves))


@settings(max_examples=40, deadline=None)
@given(programs())
def test_round_trip_random_programs(program: Program) -> None:
    _assert_round_trip(program)


def test_logo_verified_end_to_end() -> None:
    # The shield (contour 5) is 5 mm wide: the app counts 1.9 µm steps that really move
    # 1.88 µm (R14), so it comes out 5 × (1.88/1.9 − 1) = −52.6 µm narrow, ± a step (1.9 µm)
    # and the compensation excess 661.2 − 654 = 7.2 µm (mmh-lmm.toml).
    job = post_file(ROOT / "samples" / "logo.dxf", "flashcut")
    v = verify_job(job)
    shield = v.contours[-1]
    assert shield.size_error_um[0] == pytest.approx(5000 * (1.88 / 1.9 - 1), abs=1.9 + 7.2)
    # The largest deviation: 1.06 % scale error at up to 7.5 mm (79 µm) plus the timer's
    # non-dominant overshoot (R11); finite and below 0.15 mm.
    assert 50.0 < v.deviation.max_um < 150.0
