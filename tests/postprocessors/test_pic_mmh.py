"""The pic-mmh dialect against UNAM-GMM §3 (S000-01…08, Tablas 21-22)."""

from __future__ import annotations

import itertools
import math
import re
from pathlib import Path
from typing import Any

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from camtool.jobs.pipeline import OutputOptions, post_file
from camtool.model.errors import DialectError, InputError, ParseError
from camtool.model.program import (
    ArcMove,
    Command,
    Dwell,
    Home,
    Linear,
    Move,
    Program,
    Rapid,
    Spindle,
    ToolChange,
)
from camtool.post.base import PostResult
from camtool.post.registry import load_target
from camtool.toolpath.options import PlanOptions
from camtool.verify.verifier import verify_code
from camtool_postprocessors.pic_mmh.dialect import FeedTable, PicMmhPost
from tests.shapes import golden_arc_dxf

SAMPLES = Path(__file__).parents[2] / "samples"
GOLDEN = Path(__file__).parents[1] / "golden" / "pic-mmh"

# UNAM-GMM §3.6, the inferred grammar, for the blocks a toolpath uses.
COORD = r"[+-]?\d{5}\.\d{2}"
GRAMMAR = re.compile(
    rf"^(G00X{COORD}Y{COORD}"
    rf"|G01X{COORD}Y{COORD}F\d\d"
    rf"|G0[23]X{COORD}Y{COORD}I{COORD}J{COORD}F\d\d"
    r"|G54|G90|M30);$"
)


def test_golden_block_seed000_l1731(tmp_path: Path) -> None:
    # UNAM-GMM L1731 / S000-04: CW arc centred (3.012, 3.040) mm ending (2.969, 3.400) mm, F08.
    job = post_file(golden_arc_dxf(tmp_path / "arc.dxf"), "pic-mmh", PlanOptions(feed_mm_min=0.8))
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


@pytest.mark.parametrize("feed", [0.04, 10.0, 25.0, math.nan, math.inf])
def test_feed_outside_f01_f99_is_an_error(feed: float) -> None:
    with pytest.raises(DialectError, match=r"contour 2, block 4: feed .* outside F01–F99"):
        _emit((Rapid(1, 1, contour=2), Linear(2, 1, feed, contour=2)))


def test_a_toolpath_longer_than_the_travel_is_an_error() -> None:
    # G54 part zero (S000-02): any position, but 1 … 11.5 mm is longer than the 10 mm of X.
    _emit((Rapid(-1, -1, contour=1), Linear(9, 6, 0.8, contour=1)))
    with pytest.raises(DialectError, match=r"10.5 × 0 mm, larger than the 10 × 7 mm travel"):
        _emit((Rapid(1, 1, contour=1), Linear(11.5, 1, 0.8, contour=1)))


def test_a_circle_taller_than_the_travel_is_an_error() -> None:
    # Starts and ends at (1.4, 3.6), but the full circle of r = 3.6 is 7.2 mm tall > 7 mm.
    with pytest.raises(DialectError, match=r"7.2 × 7.2 mm, larger than the 10 × 7 mm"):
        _emit((Rapid(1.4, 3.6), ArcMove(1.4, 3.6, 5, 3.6, True, 0.8)))


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


# -- the whole G/M set of Tablas 21-22 (S000-06): Program.commands ---------------------------


def _post(program: Program, **options: Any) -> PostResult:
    return PicMmhPost(**options).emit(program, load_target("pic-mmh").machine)


SQUARE = (Rapid(1, 1, contour=1), Linear(2, 1, 0.8, contour=1), Linear(2, 2, 0.8, contour=1))


def test_every_command_in_the_thesis_syntax() -> None:
    # UNAM-GMM Tabla 22 (L3418-L3471) `M03S____;` `M04S____;` `M05;` `M06T__;`, Tabla 21
    # (L3359-L3386) `G04P__;` and `G28X0Y0;     ó     G28Z0;`, each before the move it precedes.
    commands: tuple[tuple[int, Command], ...] = (
        (0, ToolChange(3)),
        (0, Spindle("cw", 1200)),
        (0, Dwell(5)),
        (2, Spindle("ccw", 9999)),
        (3, Spindle("off")),
        (3, Home("Z")),
        (3, Home("XY")),
    )
    result = _post(Program(SQUARE, commands=commands))
    assert str(result.code).splitlines() == [
        "G54;",
        "G90;",
        "M06T03;",
        "M03S1200;",
        "G04P05;",
        "G00X01000.00Y01000.00;",
        "G01X02000.00Y01000.00F08;",
        "M04S9999;",
        "G01X02000.00Y02000.00F08;",
        "M05;",
        "G28Z0;",
        "G28X0Y0;",
        "M30;",
    ]
    assert result.warnings == ()
    assert result.blocks == 13


def test_commands_read_back_at_their_index() -> None:
    commands: tuple[tuple[int, Command], ...] = (
        (0, Spindle("cw", 1500)),
        (1, Dwell(12)),
        (2, ToolChange(0)),
        (3, Home("XY")),
        (3, Spindle("off")),
    )
    program = Program(SQUARE, commands=commands)
    back = PicMmhPost().parse(str(_post(program).code))
    assert back.commands == commands
    assert back.moves == SQUARE
    assert back.lines == (4, 6, 8)  # G54; G90; M03…; then the moves, the dwell and M06


def test_home_xyz_is_z_first_then_xy() -> None:
    # UNAM-GMM §7 (L1698-L1705): "primero se desplaza el eje Z, enseguida el eje X, y por
    # último el eje Y"; the dialect homes X and Y together (Tabla 21, L3375-L3386).
    lines = str(_post(Program(SQUARE, commands=((0, Home("XYZ")),))).code).splitlines()
    assert lines[2:4] == ["G28Z0;", "G28X0Y0;"]


@pytest.mark.parametrize("axes", ["X", "Y", "XZ", ""])
def test_home_on_other_axes_is_an_error(axes: str) -> None:
    with pytest.raises(DialectError, match=r"contour 1, block 3: cannot return .*G28X0Y0"):
        _post(Program(SQUARE, commands=((0, Home(axes)),)))


def test_a_cut_right_after_g28_xy_is_refused_a_rapid_first_is_fine() -> None:
    # After G28X0Y0; the machine is at machine zero, which the program does not know
    # (Tabla 21 L3375-L3386 vs the G54 part zero L3392-L3399).
    with pytest.raises(DialectError, match=r"contour 1, block 5: a cut right after G28X0Y0"):
        _post(Program(SQUARE, commands=((1, Home("XY")),)))
    ok = _post(Program(SQUARE, commands=((0, Home("XY")),)))
    assert str(ok.code).splitlines()[2:4] == ["G28X0Y0;", "G00X01000.00Y01000.00;"]
    after_z = _post(Program(SQUARE, commands=((1, Home("Z")),)))  # Z home: XY still known
    assert "G28Z0;" in str(after_z.code)


@pytest.mark.parametrize(
    ("seconds", "blocks", "warnings"),
    [
        (0, ["G04P00;"], []),
        (99, ["G04P99;"], []),
        (2.5, ["G04P03;"], ["dwell 2.5 s rounded up to 3 s"]),
        (1e-12 + 4, ["G04P04;"], []),  # float noise is not rounded up
        (150, ["G04P99;", "G04P51;"], ["dwell 150 s written as 2 G04 blocks"]),
        (198, ["G04P99;", "G04P99;"], ["dwell 198 s written as 2 G04 blocks"]),
        (
            250.2,
            ["G04P99;", "G04P99;", "G04P53;"],
            ["dwell 250.2 s rounded up to 251 s", "dwell 251 s written as 3 G04 blocks"],
        ),
    ],
)
def test_dwell_is_whole_seconds_two_digits(
    seconds: float, blocks: list[str], warnings: list[str]
) -> None:
    # UNAM-GMM Tabla 21 (L3359-L3366): `G04P__;`, P "en segundos y de 2 dígitos".
    result = _post(Program(SQUARE, commands=((1, Dwell(seconds)),)))
    lines = str(result.code).splitlines()
    assert lines[3 : 3 + len(blocks)] == blocks
    assert lines[3 + len(blocks)].startswith("G01")
    assert len(result.warnings) == len(warnings)
    for message, expected in zip(result.warnings, warnings, strict=True):
        assert message.startswith("contour 1, block 4: ") and expected in message
    back = PicMmhPost().parse(str(result.code))
    total = sum(c.seconds for _, c in back.commands if isinstance(c, Dwell))
    assert total == math.ceil(seconds - 1e-9)


def test_dwell_warnings_are_counted_once_per_kind() -> None:
    commands = ((0, Dwell(0.5)), (1, Dwell(1.5)), (2, Dwell(2.5)))
    (warning,) = _post(Program(SQUARE, commands=commands)).warnings
    assert warning.startswith("contour 1, block 3: dwell 0.5 s rounded up to 1 s")
    assert warning.endswith("(3 times)")


@pytest.mark.parametrize(
    ("command", "match"),
    [
        (Dwell(-1), r"contour 1, block 3: dwell of -1 s"),
        (Dwell(math.inf), r"dwell of inf s"),
        (Spindle("cw", 10000), r"contour 1, block 3: spindle speed 10000 rev/min .*1–9999"),
        (Spindle("ccw", 0.4), r"spindle speed 0.4 rev/min does not fit"),
        (Spindle("cw", -5), r"spindle speed -5 rev/min does not fit"),
        (Spindle("cw", math.nan), r"spindle speed nan rev/min does not fit"),
        # more digits than decimal's 28 to round to whole rev/min (not: InvalidOperation)
        (Spindle("cw", 1e30), r"spindle speed 1e\+30 rev/min does not fit"),
        (ToolChange(100), r"contour 1, block 3: tool 100 does not fit M06T## \(0–99"),
        (ToolChange(-1), r"tool -1 does not fit"),
    ],
)
def test_commands_out_of_their_field_are_errors(command: Command, match: str) -> None:
    with pytest.raises(DialectError, match=match):
        _post(Program(SQUARE, commands=((0, command),)))


def test_spindle_speed_is_rounded_to_whole_rev_min_with_a_warning() -> None:
    result = _post(Program(SQUARE, commands=((0, Spindle("cw", 9999.4)),)))
    assert "M03S9999;" in str(result.code).splitlines()
    assert result.warnings == ("spindle speed 9999.4 rev/min rounded to S9999 (whole rev/min)",)


def test_spindle_without_a_speed_is_dropped_with_one_warning() -> None:
    # A bare M3 (Gcodetools) has no speed: M03S#### cannot be written, M05 can.
    commands = ((0, Spindle("cw")), (1, Spindle("ccw")), (3, Spindle("off")))
    result = _post(Program(SQUARE, commands=commands))
    lines = str(result.code).splitlines()
    assert not any(line.startswith(("M03", "M04")) for line in lines)
    assert lines[-2:] == ["M05;", "M30;"]
    (warning,) = result.warnings
    assert "spindle on without a speed" in warning and warning.endswith("(2 times)")


def test_target_spindle_rpm_wraps_the_logo() -> None:
    job = post_file(SAMPLES / "logo.dxf", "pic-mmh", output=OutputOptions(spindle_rpm=3000))
    lines = str(job.result.code).splitlines()
    assert lines[:3] == ["G54;", "G90;", "M03S3000;"]
    assert lines[-2:] == ["M05;", "M30;"]


_AUX_BLOCKS = {
    "M03S1200;": Spindle("cw", 1200.0),
    "M04S0050;": Spindle("ccw", 50.0),
    "M05;": Spindle("off"),
    "G04P07;": Dwell(7.0),
    "M06T12;": ToolChange(12),
    "G28X0Y0;": Home("XY"),
    "G28Z0;": Home("Z"),
}


@pytest.mark.parametrize(("block", "command"), _AUX_BLOCKS.items())
def test_parse_reads_each_command(block: str, command: Command) -> None:
    back = PicMmhPost().parse(f"G54;\nG90;\n{block}\nG00X01000.00Y01000.00;\n{block}\nM30;\n")
    assert back.commands == ((0, command), (1, command))


@pytest.mark.parametrize(
    "bad",
    [
        "M03S120;",  # 3 digits (Tabla 22: 4)
        "M03;",
        "M05S1000;",
        "G04P5;",  # 1 digit (Tabla 21: 2)
        "G04P100;",
        "M06T1;",
        "G28X0;",  # only G28X0Y0 or G28Z0 (Tabla 21)
        "G28X00000.00Y00000.00;",
        "M07;",
        "G91;",  # no G91 in the dialect (§3.3)
        "G01X01000.00Y01000.00F00;",  # F00: no feed (firmware divides by it, L3664)
    ],
)
def test_parse_rejects_blocks_outside_tablas_21_22(bad: str) -> None:
    with pytest.raises(ParseError, match=r"prog.pic:2"):
        PicMmhPost().parse(f"G54;\n{bad}\n", source="prog.pic")


# -- round trip: random programs with commands inside the 10 × 7 mm area -----------------------

_xy = st.tuples(st.integers(0, 1_000_000), st.integers(0, 700_000)).map(
    lambda p: (p[0] / 100_000, p[1] / 100_000)  # 0.01 µm grid (5.2 µm fields)
)
_command = st.one_of(
    st.builds(Spindle, st.sampled_from(["cw", "ccw"]), st.integers(1, 9999).map(float)),
    st.just(Spindle("off")),
    st.builds(Dwell, st.integers(0, 99).map(float)),
    st.builds(ToolChange, st.integers(0, 99)),
    st.just(Home("Z")),
)


@settings(max_examples=60, deadline=None)
@given(
    points=st.lists(st.tuples(_xy, st.booleans(), st.integers(1, 99)), min_size=1, max_size=8),
    commands=st.lists(st.tuples(st.integers(0, 8), _command), max_size=6),
)
def test_round_trip_random_programs_with_commands(
    points: list[tuple[tuple[float, float], bool, int]],
    commands: list[tuple[int, Command]],
) -> None:
    # Lines and rapids on the 0.01 µm grid, feeds F01-F99 (S000-05), commands of every kind:
    # post → parse gives the same moves (exactly, the grid is the field's) and commands.
    moves: list[Move] = []
    for (x, y), rapid, code in points:
        moves.append(Rapid(x, y) if rapid or not moves else Linear(x, y, code / 10))
    placed = sorted(((min(i, len(moves)), c) for i, c in commands), key=lambda pair: pair[0])
    program = Program(tuple(moves), commands=tuple(placed))
    back = PicMmhPost().parse(str(_post(program).code))
    assert back.commands == program.commands
    assert [type(m) for m in back.moves] == [type(m) for m in moves]
    for got, want in zip(back.moves, moves, strict=True):
        assert (got.x, got.y) == pytest.approx((want.x, want.y), abs=1e-9)
        if isinstance(want, Linear):
            assert isinstance(got, Linear) and got.feed_mm_min == pytest.approx(want.feed_mm_min)


# -- feed codes (S000-05) -------------------------------------------------------------------


def test_default_feed_table_is_the_firmware_formula() -> None:
    # UNAM-GMM §4.9: F in units of 0.1 mm/min, F01-F99; F08 = 0.8 mm/min (L1731).
    table = FeedTable.linear()
    assert table.lowest == (1, pytest.approx(0.1)) and table.highest == (99, pytest.approx(9.9))
    assert table.feed_of(8) == pytest.approx(0.8)
    assert table.feed_of(0) is None and table.feed_of(100) is None
    assert PicMmhPost().feeds == PicMmhPost(feed_unit_mm_min=0.1).feeds == table
    # Beyond either end by up to half a step (0.05 mm/min) still rounds to F01 / F99.
    assert table.nearest(0.05) == table.lowest and table.nearest(9.95) == table.highest
    assert table.nearest(0.049) is None and table.nearest(9.951) is None
    assert table.nearest(0.86) == (9, pytest.approx(0.9))


def _target_file(tmp_path: Path, options: str) -> Path:
    path = tmp_path / "mmh.toml"
    path.write_text(
        'name = "mmh"\ndialect = "pic-mmh"\nmachine = "mmh-gmm"\ndefault_feed_mm_min = 0.8\n'
        f"[dialect_options]\n{options}\n",
        encoding="utf-8",
    )
    return path


def test_feed_codes_table_from_a_target_file(tmp_path: Path) -> None:
    # A firmware with three speeds: F01 0.1, F08 0.8, F13 1.3 mm/min (F13 is the fastest
    # under the 166 Hz cap at 140 nm/step, §4.9).
    target = load_target(
        str(_target_file(tmp_path, 'feed_codes = { "01" = 0.1, "08" = 0.8, 13 = 1.3 }'))
    )
    program = Program(
        (Rapid(1, 1), Linear(2, 1, 0.8), Linear(3, 1, 0.9), Linear(4, 1, 1.1), Linear(5, 1, 0.1))
    )
    result = target.emit(program)
    assert [line[-4:-1] for line in str(result.code).splitlines()[3:7]] == [
        "F08",
        "F08",  # 0.9 is nearer 0.8 than 1.3
        "F13",  # 1.1 is nearer 1.3
        "F01",
    ]
    assert "feed 0.9 mm/min rounded to F08 (0.8 mm/min)" in result.warnings
    back = target.post.parse(str(result.code))
    assert [m.feed_mm_min for m in back.moves[1:]] == [0.8, 0.8, 1.3, 0.1]
    with pytest.raises(ParseError, match=r"<code>:2: F09 is not in the feed table \(its codes\)"):
        target.post.parse("G00X01000.00Y01000.00;\nG01X02000.00Y01000.00F09;\n")
    with pytest.raises(DialectError, match=r"block 4: feed 1.6 mm/min is outside F01–F13"):
        target.emit(Program((Rapid(1, 1), Linear(2, 1, 1.6))))  # beyond 1.3 + (1.3-0.8)/2


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ('feed_codes = { "100" = 10.0 }', "not a code of one or two digits"),
        ('feed_codes = { "00" = 0.1 }', "is not F01–F99"),
        ('feed_codes = { "x" = 0.1 }', "not a code of one or two digits"),
        ('feed_codes = { "01" = -0.1 }', "must be a number of mm/min > 0"),
        ('feed_codes = { "01" = "fast" }', "must be a number of mm/min > 0"),
        ('feed_codes = { "01" = 0.5, "02" = 0.4 }', "feeds strictly increasing"),
        ('feed_codes = { "1" = 0.1, "01" = 0.2 }', "names code 1 twice"),
        ("feed_codes = {}", "feed_codes is empty"),
        ("feed_codes = 5", "must be a table"),
        ('feed_unit_mm_min = 0.1\nfeed_codes = { "01" = 0.1 }', "not both"),
        ("feed_unit_mm_min = 0", "feed_unit_mm_min must be a number of mm/min > 0"),
        ("feed_unit_mm_min = true", "feed_unit_mm_min must be a number"),
        ('sign = "plus"', "unknown sign policy 'plus'"),
        ("always_sign = true", "always_sign"),
        ("max_line_chars = 0", "max_line_chars must be a whole number ≥ 1"),
        ("max_line_chars = 35.5", "max_line_chars must be a whole number ≥ 1"),
    ],
)
def test_dialect_options_are_validated(tmp_path: Path, options: str, message: str) -> None:
    path = _target_file(tmp_path, options)
    with pytest.raises(InputError, match=r"mmh\.toml: invalid dialect_options") as info:
        load_target(str(path))
    assert message in str(info.value)


# -- S000-05 step rate and S000-07 line length ------------------------------------------------


def test_step_rate_warning_names_blocks_contours_and_the_effective_feed() -> None:
    # S000-05: F14 = 1.4 mm/min at 7142.857 steps/mm needs 1.4·7142.857/60 = 166.7 steps/s
    # > 166 Hz (L3198); at the cap the feed is 166·60/7142.857 = 1.3944 mm/min. F13 is fine.
    moves = (
        Rapid(1, 1, contour=1),
        Linear(2, 1, 1.4, contour=1),
        Linear(2, 2, 1.3, contour=1),
        Rapid(3, 3, contour=2),
        Linear(4, 3, 1.4, contour=2),
    )
    (warning,) = _post(Program(moves)).warnings
    rate = 1.4 * (1e6 / 140) / 60
    capped = 166 * 60 / (1e6 / 140)
    assert warning.startswith(f"F14 = 1.4 mm/min needs {rate:.1f} steps/s")
    assert "166 Hz" in warning
    assert "blocks 4, 7 (contours 1, 2)" in warning
    assert warning.endswith(f"will run at about {capped:.3g} mm/min")


def test_line_length_warning_is_off_by_default_and_counts_the_semicolon() -> None:
    # S000-07 / UNAM-GMM §2.4: the receive vector holds 35 characters (L1740) but the
    # thesis's own G02 block (L1731) has 43, so the check is an opt-in warning.
    arc = (Rapid(3.012 - 0.36256, 3.040), ArcMove(2.969, 3.4, 3.012, 3.040, True, 0.8))
    assert _post(Program(arc)).warnings == ()
    warned = _post(Program(arc), max_line_chars=35)
    assert "G02X02969.00Y03400.00I03012.00J03040.00F08;" in str(warned.code)
    (warning,) = warned.warnings
    assert warning.startswith("1 block(s) longer than 35 characters")
    assert warning.endswith("block 4; the longest has 43")
    assert _post(Program(arc), max_line_chars=43).warnings == ()


# -- end to end: post, read back, simulate ------------------------------------------------


def test_logo_with_commands_verifies_and_dwell_counts_in_the_time() -> None:
    # The verifier reads the code back with this reader; the dwell read from `G04P05;`
    # adds its 5 s to the predicted time (verifier.Verification.dwell_s). The DSM/DDA
    # interpolators at 140 nm/step keep the path within a few steps of the ideal
    # (UNAM-GMM Tabla 7: ≤ 1 BLU = 0.14 µm per interpolator; backlash residuals aside).
    target = load_target("pic-mmh")
    job = post_file(SAMPLES / "logo.dxf", "pic-mmh")
    program = job.program
    with_dwell = Program(program.moves, program.origin, commands=((1, Dwell(5)),))
    plain_code = str(target.emit(program).code)
    dwell_code = str(target.emit(with_dwell).code)
    assert dwell_code.splitlines()[3] == "G04P05;"
    plain, dwelling = verify_code(plain_code, target), verify_code(dwell_code, target)
    assert dwelling.dwell_s == 5.0
    assert dwelling.time_s == pytest.approx(plain.time_s + 5.0)
    assert math.isfinite(plain.max_error_um)
    assert dwelling.max_error_um == plain.max_error_um


@pytest.mark.parametrize("tolerance", [0.001, 0.0001])
def test_large_radius_arc_becomes_chords_with_a_warning(tolerance: float) -> None:
    # From (1, 3) to (9, 3) mm clockwise round (5, −200) mm: r = √(4² + 203²) ≈ 203.04 mm,
    # sagitta 4²/(2r) ≈ 0.039 mm. J = −200 000.00 µm needs 6 integer digits: no G02 can
    # hold it, so the arc is written as n = ceil(sweep / (2·acos(1 − t/r))) G01 chords.
    target = load_target("pic-mmh")
    r = math.hypot(4.0, 203.0)
    sweep = 2 * math.asin(4.0 / r)
    n = math.ceil(sweep / (2 * math.acos(1 - tolerance / r)))
    program = Program((Rapid(1, 3), ArcMove(9, 3, 5, -200, True, 0.8)), tolerance_mm=tolerance)
    result = target.post.emit(program, target.machine)
    lines = str(result.code).splitlines()
    chords = [line for line in lines if line.startswith("G01")]
    assert len(chords) == n and lines[-2] == "G01X09000.00Y03000.00F08;"
    assert not any(line.startswith(("G02", "G03")) for line in lines)
    assert result.warnings == (
        f"1 arc(s) with a centre beyond the I/J field (±99.99999 mm, 5 integer digits of µm) "
        f"written as {n} G01 chords within {tolerance:g} mm",
    )
    back = target.post.parse(result.code).moves
    points = [(1.0, 3.0)] + [(m.x, m.y) for m in back[1:]]
    q = 0.5e-5 * math.sqrt(2)  # half the 0.01 µm written step on each axis, mm
    for a, b in itertools.pairwise(points):  # every chord within t of the circle
        mid = ((a[0] + b[0]) / 2, (a[1] + b[1]) / 2)
        assert r - math.dist(mid, (5, -200)) <= tolerance + q
        assert abs(math.dist(b, (5, -200)) - r) <= q


def test_arc_with_a_centre_in_the_field_stays_an_arc() -> None:
    # The thesis block (UNAM-GMM L1731): centre (3.012, 3.040) mm fits; no chords, no warning.
    r = math.dist((2.969, 3.400), (3.012, 3.040))
    program = Program((Rapid(3.012 - r, 3.04), ArcMove(2.969, 3.4, 3.012, 3.04, True, 0.8)))
    target = load_target("pic-mmh")
    result = target.post.emit(program, target.machine)
    assert "G02X02969.00Y03400.00I03012.00J03040.00F08;" in str(result.code).splitlines()
    assert result.warnings == ()


def test_a_coordinate_too_long_for_its_word_names_the_option_that_moves_the_drawing() -> None:
    """dxf-parser's arc1.dxf lies at X -650.8 mm: 5 integer digits of µm hold 99.99999 mm.

    The drawing, not the machine, is far off: the message names --origin lower-left (which
    posts it) rather than stopping at the number.
    """
    target = load_target("pic-mmh")
    program = Program((Rapid(-650.8, 1.0), Linear(-650.7, 1.0, 10.0)))
    with pytest.raises(
        DialectError, match=r"X = .* does not fit 5 integer digits .*--origin lower-"
    ):
        PicMmhPost().emit(program, target.machine)


def test_an_arc_whose_centre_is_on_its_start_step_is_written_as_its_chord() -> None:
    # 140 nm steps (UNAM-GMM S000-12): 1.0 mm is 7142.857 steps, 7143; the centre 0.05 µm
    # right of the start, 1.00005 mm = 7143.214 steps, is the same step: a direct search
    # (A.6) from a start on its centre has radius 0. The half circle ends at 1.0001 mm
    # (7143.571 steps, 7144) and lies within 2r = 0.1 µm of the chord to it. An arc of
    # 0.3 µm radius (centre 7145.0 steps) is two steps off its start and stays an arc.
    target = load_target("pic-mmh")
    program = Program(
        (
            Rapid(1.0, 1.0),
            ArcMove(1.0001, 1.0, 1.00005, 1.0, False, 0.8),
            ArcMove(1.0007, 1.0, 1.0004, 1.0, False, 0.8),
        )
    )
    result = target.post.emit(program, target.machine)
    lines = str(result.code).splitlines()
    assert lines[2:5] == [
        "G00X01000.00Y01000.00;",
        "G01X01000.10Y01000.00F08;",
        "G03X01000.70Y01000.00I01000.40J01000.00F08;",
    ]
    assert result.warnings == (
        "1 arc(s) whose centre falls on the step of their start or end (0.14 µm steps), which "
        "the controller's arc interpolation (UNAM-GMM A.6) cannot run, written as G01 lines "
        "to their ends (within 0.1 µm of the arc)",
    )
    # read back and run by the modelled controller (a radius-0 arc is refused there)
    assert math.isfinite(verify_code(str(result.code), target).max_error_um)

    with pytest.raises(DialectError, match=r"block 4: an arc of radius 0\.05 µm has its centre"):
        target.post.emit(Program(program.moves, tolerance_mm=0.00005), target.machine)
