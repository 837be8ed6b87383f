"""The i8751 dialect against Intf8751 §3.7 (protocol) and R1–R7, R10 (reference/Intf8751.md)."""

from __future__ import annotations

import dataclasses
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from camtool.cli.main import main
from camtool.jobs.pipeline import post_file, verify_job
from camtool.model.errors import DialectError, InputError, ParseError, UsageError
from camtool.model.machine import Machine
from camtool.model.program import (
    ArcMove,
    Dwell,
    Home,
    Linear,
    Move,
    Program,
    Rapid,
    Spindle,
)
from camtool.post.registry import load_target
from camtool.toolpath.options import PlanOptions
from camtool.verify.interpolators import corte_recto_max_deviation
from camtool.verify.verifier import verify_code
from camtool_postprocessors.i8751.dialect import I8751Post, split_count, split_xy
from camtool_postprocessors.i8751.packets import Record, encode_block, encode_stream

SAMPLES = Path(__file__).parents[2] / "samples"
GOLDEN = Path(__file__).parents[1] / "golden" / "i8751"
SPM = 100.0  # postprocessors/i8751/i8751.toml: the documented placeholder, 0.01 mm per step


def _target(**machine: object) -> tuple[I8751Post, Machine]:
    target = load_target("i8751")
    m = dataclasses.replace(target.machine, **machine)  # type: ignore[arg-type]
    post = target.post.for_machine(m)
    assert isinstance(post, I8751Post)
    return post, m


WIDE = {"work_area_mm": (-1000.0, -1000.0, 1000.0, 1000.0)}


# -- bytes of the protocol ------------------------------------------------------------


def test_block_encoding_r2() -> None:
    # Intf8751 R2 (lines 4108–4134): +1000 → 01 03 03 E8; Y 0 → 02 05; − is 04H.
    assert encode_block(1, 1000) == bytes.fromhex("01 03 03 E8")
    assert encode_block(2, 0) == bytes.fromhex("02 05")
    assert encode_block(3, -100) == bytes.fromhex("03 04 00 64")
    assert encode_block(1, 65535) == bytes.fromhex("01 03 FF FF")  # FFFFH, lines 4222–4224
    with pytest.raises(ValueError):
        encode_block(1, 65536)


def test_thesis_worked_example_byte_for_byte() -> None:
    # Intf8751 §3.7 "Worked example": X +1000, Y −250, wait 2 s, Z −100, wait 0; then Y +300:
    # 13 | 01 03 03 E8 02 04 00 FA 00 02 03 04 00 64 00 00 | 01 05 02 03 01 2C 00 00 03 05
    # 00 00 | 45 | 54. At 100 steps/mm: X 10 mm, Y −2.5 mm, Z −1 mm, then Y +3 mm.
    post, machine = _target(**WIDE)
    program = Program(
        (Linear(10, -2.5, 60), Linear(10, -2.5, 60, z=-1), Linear(10, 0.5, 60)),
        commands=((1, Dwell(2)),),
    )
    expected = bytes.fromhex(
        "13"  # access key
        "01 03 03 E8 02 04 00 FA 00 02 03 04 00 64 00 00"  # move 1
        "01 05 02 03 01 2C 00 00 03 05 00 00"  # move 2
        "45 54"  # end of packet, end of data
    )
    result = post.emit(program, machine)
    assert result.code == expected
    assert result.blocks == 2
    back = post.parse(expected)
    assert [(m.x, m.y, m.z) for m in back.moves] == [
        (10, -2.5, None),
        (10, -2.5, -1),
        (10, 0.5, None),
    ]
    assert back.commands == ((1, Dwell(2.0)),)  # T1: after X/Y, before Z
    assert back.lines == (1, 1, 2)


# The golden program: a 10 mm square from (5, 5) and a diagonal of (10, 5) mm = (1000, 500)
# steps, the corte-recto case (100, 50) of Intf8751 R10 scaled by 10; a 2 s dwell before the
# diagonal. Bytes worked out by hand from §3.7 (block format 4106–4134, order M1 M2 T1 M3 T2
# 4129–4165, 45H after ≤ 5 moves, 54H at the end) with lift_mm = 1 (100 steps):
GOLDEN_MOVES = (
    Rapid(5, 5, contour=1),
    Linear(15, 5, 60, contour=1),
    Linear(15, 15, 60, contour=1),
    Linear(5, 15, 60, contour=1),
    Linear(5, 5, 60, contour=1),
    Linear(15, 10, 60, contour=1),
)
GOLDEN_BYTES = bytes.fromhex(
    "13"  # access key 13H (4399–4415)
    "01 05 02 05 00 00 03 03 00 64 00 00"  # 1: Z +100 (lift before the rapid)
    "01 03 01 F4 02 03 01 F4 00 00 03 04 00 64 00 00"  # 2: X +500 Y +500, then Z −100
    "01 03 03 E8 02 05 00 00 03 05 00 00"  # 3: X +1000
    "01 05 02 03 03 E8 00 00 03 05 00 00"  # 4: Y +1000
    "01 04 03 E8 02 05 00 00 03 05 00 00"  # 5: X −1000
    "45"  # end of packet 1 (5 moves)
    "01 05 02 04 03 E8 00 00 03 05 00 02"  # 6: Y −1000, wait T2 = 2 s
    "01 03 03 E8 02 03 01 F4 00 00 03 05 00 00"  # 7: X +1000 Y +500 (the diagonal)
    "45 54"  # end of packet 2, end of data
)


def _golden_program() -> Program:
    return Program(GOLDEN_MOVES, commands=((5, Dwell(2)),))


def test_golden_bin(update_golden: bool) -> None:
    post, machine = _target()
    code = post.emit(_golden_program(), machine).code
    assert code == GOLDEN_BYTES
    path = GOLDEN / "square-diagonal.bin"
    if update_golden:
        path.parent.mkdir(exist_ok=True)
        path.write_bytes(GOLDEN_BYTES)
    assert path.read_bytes() == code


def test_golden_dump(update_golden: bool) -> None:
    post, machine = _target()
    text = post.emit(_golden_program(), machine, fmt="dump").code
    assert isinstance(text, str)
    path = GOLDEN / "square-diagonal.txt"
    if update_golden:
        path.write_text(text)
    assert text == path.read_text()
    lines = [line for line in text.splitlines() if not line.startswith(";")]
    assert lines[0].startswith("0000  13 ") and lines[0].endswith("; access key")
    assert lines[2].startswith("000D  01 03 01 F4  02 03 01 F4  00 00  03 04 00 64  00 00  ;")
    assert "move 2: X +500 Y +500 | wait 0 | Z -100 | wait 0 -> X 5.0000 Y 5.0000" in lines[2]
    assert lines[-1] == "005D  " + "54".ljust(51) + "  ; end of data"
    # The dump reads back to the same program as the bytes.
    assert post.parse(text) == post.parse(GOLDEN_BYTES)
    assert post.parse(text.encode("ascii")) == post.parse(GOLDEN_BYTES)


def test_golden_reads_back() -> None:
    post, _ = _target()
    back = post.parse(GOLDEN_BYTES)
    # Record 1 (Z up) and 2 (X/Y at Z = 1 mm) end above Z = 0: rapids; the plunge is a cut.
    assert [type(m).__name__ for m in back.moves] == [
        "Rapid",
        "Rapid",
        "Linear",
        "Linear",
        "Linear",
        "Linear",
        "Linear",
        "Linear",
    ]
    assert [(m.x, m.y) for m in back.moves][1:] == [
        (5, 5),
        (5, 5),
        (15, 5),
        (15, 15),
        (5, 15),
        (5, 5),
        (15, 10),
    ]
    assert back.lines == (1, 2, 2, 3, 4, 5, 6, 7)
    assert back.commands == ((7, Dwell(2.0)),)


def test_packets_hold_five_moves() -> None:
    # Intf8751 §3.7: 15 blocks / 60 data per packet = 5 moves; 45H closes each packet.
    # 11 one-axis moves of 12 bytes each: 45H at 1 + 60, 1 + 60 + 1 + 60, then 1 more move.
    post, machine = _target()
    moves = tuple(Linear(0.01 * (k + 1), 0, 60) for k in range(11))
    code = post.emit(Program(moves), machine).code
    assert isinstance(code, bytes)
    assert len(code) == 1 + 11 * 12 + 3 + 1
    assert [i for i, b in enumerate(code) if b == 0x45] == [61, 122, 135]
    assert code[-1] == 0x54


# -- steps ----------------------------------------------------------------------------


def test_absolute_rounding_does_not_accumulate() -> None:
    # R1: ten moves of +0.004 mm at 100 steps/mm (0.4 step each). Rounding each increment
    # would write 0 steps ten times; rounding the absolute targets writes 0,1,1,2,... = 4
    # steps in all (round(4.0)), each the nearest step to its target.
    post, machine = _target()
    moves = tuple(Linear(0.004 * (k + 1), 0, 60) for k in range(10))
    result = post.emit(Program(moves), machine)
    back = post.parse(result.code)
    assert back.moves[-1].x == pytest.approx(0.04)
    assert [round(m.x * SPM) for m in back.moves] == [1, 2, 3, 4]
    assert any("shorter than half a step" in w for w in result.warnings)  # 6 wrote nothing


def test_split_over_65535_steps_r3() -> None:
    # Intf8751 R3: 70 000 steps become two moves, 65 535 + 4 465.
    assert split_xy(70000, 0) == [(65535, 0), (4465, 0)]
    assert split_count(-70000) == [-65535, -4465]
    # A diagonal keeps to its segment: Y at the nearest step of 65 535 · 35 000/70 000.
    assert split_xy(70000, -35000) == [(65535, -32768), (4465, -2232)]
    post, machine = _target(work_area_mm=(0.0, 0.0, 800.0, 800.0))
    result = post.emit(Program((Linear(700, 0, 60),)), machine)
    assert isinstance(result.code, bytes)
    assert result.code[1:13] == bytes.fromhex("01 03 FF FF 02 05 00 00 03 05 00 00")
    assert result.code[13:25] == bytes.fromhex("01 03 11 71 02 05 00 00 03 05 00 00")
    assert any("over 65535 steps" in w for w in result.warnings)
    assert [m.x for m in post.parse(result.code).moves] == [655.35, 700.0]


def test_z_over_65535_steps_splits_into_z_records() -> None:
    post, machine = _target()
    result = post.emit(Program((Linear(0, 0, 60, z=-700),)), machine)
    back = post.parse(result.code)
    assert [m.z for m in back.moves] == [-655.35, -700.0]


# -- conversions and warnings ---------------------------------------------------------


def test_arcs_become_chords_within_the_tolerance() -> None:
    # A half circle of radius 10 mm: chords within chord_tolerance_mm = 0.01 (profile). The
    # sagitta r(1 − cos(θ/2)) ≤ 0.01 gives θ ≤ 2·acos(0.999) = 0.0894 rad → 36 chords for π.
    post, machine = _target()
    program = Program((Rapid(10, 20), ArcMove(30, 20, 20, 20, True, 60)))
    result = post.emit(program, machine)
    n = math.ceil(math.pi / (2 * math.acos(1 - 0.01 / 10)))
    assert n == 36
    warning = next(w for w in result.warnings if "chords" in w)
    assert f"1 arc(s) written as {n} chords" in warning
    sagitta = 10 * (1 - math.cos(math.pi / n / 2))
    assert f"largest chord error {sagitta:.4f} mm" in warning
    back = post.parse(result.code).moves
    cuts = [m for m in back if isinstance(m, Linear) and m.z is None]
    assert len(cuts) == n
    for m in cuts:  # on the circle within the chord error and half a step per axis
        assert abs(math.hypot(m.x - 20, m.y - 20) - 10) <= 0.01 + 0.005 * math.sqrt(2)


def test_feeds_are_not_expressible() -> None:
    post, machine = _target()
    result = post.emit(Program((Linear(1, 0, 30), Linear(2, 0, 90))), machine)
    warning = next(w for w in result.warnings if "feeds" in w)
    # Cruise X = 11H ≈ 104 steps/s (max_step_rate_hz) at 100 steps/mm = 62.4 mm/min.
    assert "feed(s) 30, 90 mm/min ignored" in warning and "62.4 mm/min" in warning
    assert result.code == post.emit(Program((Linear(1, 0, 1), Linear(2, 0, 1))), machine).code
    back = post.parse(result.code).moves
    assert all(isinstance(m, Linear) and m.feed_mm_min == pytest.approx(62.4) for m in back)


def test_rapids_without_lift_cut_and_say_so() -> None:
    _, machine = _target()
    post = I8751Post(lift_mm=0).for_machine(machine)
    result = post.emit(Program((Rapid(1, 1), Linear(2, 1, 60))), machine)
    assert any("the tool stays down" in w for w in result.warnings)
    assert [type(m) for m in post.parse(result.code).moves] == [Linear, Linear]


def test_z_with_xy_runs_xy_first_going_down() -> None:
    # R4/R11: X/Y, wait T1, Z, wait T2 — Z never moves with X/Y.
    post, machine = _target()
    result = post.emit(Program((Linear(1, 2, 60, z=-0.5),)), machine)
    assert result.code == bytes.fromhex("13 01 03 00 64 02 03 00 C8 00 00 03 04 00 32 00 00 45 54")
    assert any("X/Y first, then Z" in w for w in result.warnings)
    back = post.parse(result.code).moves
    assert [(m.x, m.y, m.z) for m in back] == [(1, 2, None), (1, 2, -0.5)]


def test_a_cut_that_rises_goes_up_first() -> None:
    # a cut from Z -5 rising to Z -1 over 10 mm (a V-carve's or a 3-D finish's climb):
    # X/Y first would run the whole 10 mm at Z -5, 4 mm under the path's end; Z first
    # keeps the tool on or above the programmed line (as a rising rapid already did)
    post, machine = _target()
    program = Program((Linear(0, 0, 60, z=-5), Linear(10, 0, 60, z=-1)))
    result = post.emit(program, machine)
    back = post.parse(result.code).moves
    z, path = 0.0, []
    for m in back:
        z = z if m.z is None else m.z
        path.append((m.x, m.y, z))
    assert path == [(0, 0, -5), (0, 0, -1), (10, 0, -1)]
    assert any("rising as Z then X/Y" in w for w in result.warnings)


def test_a_helix_climbs_or_descends_over_its_chords() -> None:
    # a helix down from Z 0 to Z -2 over the upper half circle of radius 5 about (5, 0), then
    # back up to Z 0 over the lower half: the height in equal parts over the chords (not a
    # half circle at Z 0, then a 2 mm plunge), each chord run at the higher of its two
    # heights (down: X/Y then Z; up: Z then X/Y), so no point is below the helix and none
    # more than one chord's part of the height above it
    post, machine = _target()
    down = ArcMove(10, 0, 5, 0, True, 60, z=-2)
    up = ArcMove(0, 0, 5, 0, True, 60, z=0)
    result = post.emit(Program((Linear(0, 0, 60, z=0), down, up)), machine)
    z, path = 0.0, []
    for m in post.parse(result.code).moves:
        z = z if m.z is None else m.z
        path.append((m.x, m.y, z))
    half = path.index((10, 0, -2))
    corners = {p[:2] for p in path}
    assert len(corners) >= 16  # chords within the profile's 0.01 mm of a 5 mm radius
    step = 2 / ((len(corners) - 1) // 2)  # the height of one chord's part, about
    for k, (x, y, z) in enumerate(path):
        angle = math.atan2(y, x - 5)  # π → 0 going down, 0 → -π coming up
        if k <= half:
            helix = -2 * (1 - angle / math.pi) if k else 0.0
        else:
            helix = -2 * (1 + angle / math.pi) if (x, y) != (0, 0) else 0.0
        assert helix - 0.01 <= z <= helix + 1.5 * step + 0.01, (k, x, y, z, helix)
    assert path[-1] == (0, 0, 0)


def test_dwells_become_waits_and_commands_are_dropped_with_warnings() -> None:
    post, machine = _target()
    program = Program(
        (Linear(1, 0, 60), Linear(2, 0, 60)),
        commands=(
            (0, Spindle("cw", 1000)),
            (0, Dwell(300)),  # before the first move: 255 + 45 s in two motionless records
            (1, Dwell(1.6)),  # rounded to 2 s, in T2 of move 1
            (1, Dwell(0.2)),  # rounded to 0 s: dropped
            (2, Home("XY")),
            (2, Spindle("off")),
        ),
    )
    result = post.emit(program, machine)
    assert result.code == bytes.fromhex(
        "13"  # access key
        "01 05 02 05 00 00 03 05 00 FF"  # no motion, T2 = 255 s
        "01 05 02 05 00 00 03 05 00 2D"  # no motion, T2 = 45 s
        "01 03 00 64 02 05 00 00 03 05 00 02"  # X +100, T2 = 2 s
        "01 03 00 64 02 05 00 00 03 05 00 00"  # X +100
        "45 54"  # end of packet, end of data
    )
    text = "\n".join(result.warnings)
    assert "2 spindle command(s)" in text
    assert "1 home command(s)" in text
    assert "2 dwell(s) rounded to whole seconds" in text and "1 dwell(s) of 0 s" in text
    back = post.parse(result.code)
    assert back.commands == ((0, Dwell(300.0)), (1, Dwell(2.0)))
    assert back.lines == (3, 4)


def test_placeholder_steps_per_mm_warn_and_yours_do_not(tmp_path: Path) -> None:
    program = Program((Linear(1, 0, 62.4),))
    target = load_target("i8751")
    assert any("placeholder" in w for w in target.emit(program).warnings)
    mine = tmp_path / "my.toml"
    mine.write_text("[machine]\nsteps_per_mm = [200.0, 200.0, 50.0]\n")
    target = load_target("i8751", machine_file=mine)
    result = target.emit(program)
    assert not any("placeholder" in w for w in result.warnings)
    assert result.code == bytes.fromhex("13 01 03 00 C8 02 05 00 00 03 05 00 00 45 54")
    assert target.post.parse(result.code).moves[0].x == 1.0  # read with 200 steps/mm too


def test_a_toolpath_larger_than_the_travel_names_both_sizes() -> None:
    # Relative packets from where the tool stands (work coordinates): 1 … 700 mm is 699 mm.
    post, machine = _target()
    program = Program((Rapid(1, 1, contour=1), Linear(2, 1, 60, contour=1), Linear(700, 1, 60)))
    with pytest.raises(DialectError, match=r"699 × 0 mm, larger than the 655.35 × 655.35 mm"):
        post.emit(program, machine)


def test_z_on_a_machine_without_z_is_an_error() -> None:
    post, machine = _target(has_z=False)
    with pytest.raises(DialectError, match=r"block 1: Z = -1 mm but .* has no Z"):
        post.emit(Program((Linear(1, 1, 60, z=-1),)), machine)


@pytest.mark.parametrize(
    "options",
    [{"lift_mm": -1}, {"lift_mm": "high"}, {"placeholder_steps_per_mm": [1, 2]}, {"nope": 1}],
)
def test_bad_dialect_options_are_input_errors(tmp_path: Path, options: dict[str, object]) -> None:
    lines = [f"{k} = {v!r}".replace("'", '"') for k, v in options.items()]
    path = tmp_path / "t.toml"
    path.write_text(
        'dialect = "i8751"\nmachine = "i8751"\n[dialect_options]\n' + "\n".join(lines) + "\n"
    )
    with pytest.raises(InputError, match="invalid dialect_options"):
        load_target(str(path))


def test_an_unbound_reader_is_a_usage_error() -> None:
    with pytest.raises(UsageError, match="needs the machine's steps/mm"):
        I8751Post().parse(GOLDEN_BYTES)


# -- strict reader --------------------------------------------------------------------

ONE_MOVE = "01 03 00 64 02 05 00 00 03 05 00 00"


@pytest.mark.parametrize(
    ("hex_bytes", "offset", "message"),
    [
        ("", 0, "truncated: .* access key"),
        ("14" + ONE_MOVE + "45 54", 0, "wrong access key 14H"),
        ("13 01 07 00 64", 2, "bad direction code 07H for motor 1"),
        ("13 02 05", 1, r"expected motor 1 \(01H\), got 02H"),
        ("13 01 05 02 05 01 00", 5, "expected the wait marker 00H of T1"),
        ("13" + ONE_MOVE * 6 + "45 54", 61, "more than 5 moves"),
        ("13" + ONE_MOVE + "54", 13, "45H missing"),
        ("13" + ONE_MOVE + "45", 14, "truncated: .* end of data 54H"),
        ("13 01 03 00", 4, "truncated: .* low byte"),
        ("13 45 54", 1, "packet 1 is empty"),
        ("13" + ONE_MOVE + "45 54 00", 15, r"1 byte\(s\) after the end of data"),
    ],
)
def test_strict_reader_names_the_byte(hex_bytes: str, offset: int, message: str) -> None:
    post, _ = _target()
    with pytest.raises(
        ParseError, match=rf"prog.bin: byte {offset} \({offset:04X}H\): .*{message}"
    ):
        post.parse(bytes.fromhex(hex_bytes), source="prog.bin")


def test_dump_errors_name_the_line() -> None:
    post, _ = _target()
    good = str(post.emit(_golden_program(), _target()[1], fmt="dump").code).splitlines()
    # Lines 1-3 are comments, line 4 the key, line 5 move 1 (offset 0001), line 6 move 2.
    bad_line = [*good[:5], "000D  01 03 00 64 move", *good[6:]]
    with pytest.raises(ParseError, match=r"prog.txt:6: not an i8751 dump line"):
        post.parse("\n".join(bad_line), source="prog.txt")
    missing = good[:4] + good[5:]  # move 1's line left out: the next offset does not follow
    with pytest.raises(ParseError, match=r"prog.txt:5: offset 000D but the next byte is 0001H"):
        post.parse("\n".join(missing), source="prog.txt")
    wrong = [*good[:4], good[4].replace("03 03 00 64", "03 07 00 64"), *good[5:]]
    with pytest.raises(
        ParseError, match=r"prog.txt:5: byte 8 \(0008H\): bad direction code 07H for motor 3"
    ):
        post.parse("\n".join(wrong), source="prog.txt")


# -- round trips ----------------------------------------------------------------------

_step = st.integers(min_value=1, max_value=65000)  # inside the 655.35 mm work area
_sub = st.floats(min_value=-0.45, max_value=0.45)


@st.composite
def _programs(draw: st.DrawFn) -> tuple[Program, list[tuple[int, int, int]]]:
    """Random moves in the work area, each at least one step from the last on the axes it
    moves; and the step positions the reader must give back (X/Y, then Z, per move; Z, then
    X/Y for a move that rises)."""
    moves: list[Move] = []
    expected: list[tuple[int, int, int]] = []
    here = [0, 0, 0]
    for _ in range(draw(st.integers(min_value=1, max_value=12))):
        x, y = draw(_step), draw(_step)
        z = draw(st.one_of(st.none(), st.integers(min_value=-500, max_value=500)))
        if (x, y) == tuple(here[:2]) and (z is None or z == here[2]):
            continue
        if z == here[2]:
            z = None
        xmm, ymm = (x + draw(_sub)) / SPM, (y + draw(_sub)) / SPM
        # a height above the stock that rounds to its top (Z0) is refused, not written
        zmm = None if z is None else (z + (draw(_sub) if z else 0.0)) / SPM
        kind = draw(st.sampled_from(["rapid", "line"]))
        moves.append(Rapid(xmm, ymm, zmm) if kind == "rapid" else Linear(xmm, ymm, 60.0, zmm))
        if z is not None and z > here[2] and (x, y) != tuple(here[:2]):
            # a rising move goes up first, then across (never across at the old depth)
            expected += [(here[0], here[1], z), (x, y, z)]
            here = [x, y, z]
            continue
        if (x, y) != tuple(here[:2]):
            expected.append((x, y, here[2]))
        if z is not None:
            expected.append((x, y, z))
        here = [x, y, here[2] if z is None else z]
    return Program(tuple(moves)), expected


@settings(max_examples=60, deadline=None)
@given(_programs(), st.sampled_from(["bin", "dump"]))
def test_round_trip_random_programs(
    case: tuple[Program, list[tuple[int, int, int]]], fmt: str
) -> None:
    program, expected = case
    _, machine = _target()
    post = I8751Post().for_machine(machine)
    back = post.parse(post.emit(program, machine, fmt=fmt).code)
    z = 0.0
    got = []
    for m in back.moves:
        z = z if m.z is None else m.z
        got.append((m.x, m.y, z))
        assert isinstance(m, Rapid) == (z > 0)  # above the part surface: a rapid
    assert len(got) == len(expected)
    for (gx, gy, gz), (ex, ey, ez) in zip(got, expected, strict=True):
        assert (gx, gy, gz) == pytest.approx((ex / SPM, ey / SPM, ez / SPM), abs=1e-9)
    # Within one step of what was asked (exactly: half a step, by absolute rounding).
    for start, move in program.steps():
        del start
        near = min(abs(gx - move.x) + abs(gy - move.y) for gx, gy, _ in got)
        assert near <= 1.0 / SPM


def _distance_to_path(points: np.ndarray, program: Program) -> np.ndarray:
    """Distance of each point (N, 2) to the nearest point of the program's XY path, mm."""
    best = np.full(len(points), np.inf)
    for _, segment in program.segments():
        poly = np.asarray(segment.points(1e-4))
        a, b = poly[:-1], poly[1:]
        ab = b - a
        length2 = np.maximum((ab**2).sum(axis=1), 1e-30)
        for i, p in enumerate(points):
            t = np.clip(((p - a) * ab).sum(axis=1) / length2, 0.0, 1.0)
            d = np.hypot(*(a + t[:, None] * ab - p).T).min()
            best[i] = min(best[i], d)
    return best


def test_round_trip_logo_sample() -> None:
    # Every point read back lies on the planned path within the chord tolerance (0.01 mm)
    # plus half a step per axis; every planned end point comes back to the nearest step.
    job = post_file(SAMPLES / "logo.dxf", "i8751", PlanOptions(scale=10))
    post = job.target.post
    back = post.parse(job.result.code)
    xy = np.asarray([(m.x, m.y) for m in back.moves])
    assert _distance_to_path(xy, job.program).max() <= 0.01 + 0.005 * math.sqrt(2) + 1e-9
    read = {(round(m.x * SPM), round(m.y * SPM)) for m in back.moves}
    for m in job.program.moves:
        assert (math.floor(m.x * SPM + 0.5), math.floor(m.y * SPM + 0.5)) in read
    # The i8751 has Z, so the plan lifts the tool itself (no lift_mm): it starts by rising to
    # the 5 mm clearance, cuts at the top (Z = 0) and travels at safe Z (2 mm) or clearance;
    # every planned change of Z comes back, in order.
    planned_z = [m.z for m in job.program.moves if m.z is not None]
    changes = [z for k, z in enumerate(planned_z) if k == 0 or z != planned_z[k - 1]]
    assert [m.z for m in back.moves if m.z is not None] == changes
    assert changes[0] == 5.0 and changes[-1] == 5.0 and set(changes) == {5.0, 2.0, 0.0}
    assert any("heights the program gives" in w for w in job.result.warnings)


# -- end to end -----------------------------------------------------------------------


def test_verify_corte_recto_golden_r10() -> None:
    # Intf8751 R10: (100, 50) steps visits (50, 50) and deviates b(a − b)/√(a² + b²) =
    # 22.36 steps from the ideal segment; at 0.01 mm per step: 223.6 µm at (0.5, 0.5) mm.
    target = load_target("i8751")
    code = target.emit(Program((Linear(1.0, 0.5, 62.4),))).code
    assert code == bytes.fromhex("13 01 03 00 64 02 03 00 32 00 00 03 05 00 00 45 54")
    v = verify_code(code, target, source="r10.bin")
    assert v.deviation.max_um == pytest.approx(22.36 * 10, abs=0.05)
    assert v.deviation.at_mm == pytest.approx((0.5, 0.5))


def test_verify_logo_end_to_end() -> None:
    # The predicted error is the corte-recto error of the moves as written: at most the
    # largest b(a − b)/√(a² + b²) of any record (§4.2), times 10 µm per step.
    job = post_file(SAMPLES / "logo.dxf", "i8751", PlanOptions(scale=4))
    v = verify_job(job)
    back = v.program
    bound = 0.0
    for start, move in back.steps():
        dx = round((move.x - start[0]) * SPM)
        dy = round((move.y - start[1]) * SPM)
        if not isinstance(move, Rapid):
            bound = max(bound, corte_recto_max_deviation(dx, dy))
    assert 0 < v.deviation.max_um <= bound * 10 + 1e-6
    assert math.isfinite(v.time_s) and v.time_s > 0
    assert all(c.closure_um is None or max(map(abs, c.closure_um)) < 1e-6 for c in v.contours)


# -- the command line -----------------------------------------------------------------


def test_cli_post_bin_and_verify(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "logo.bin"
    code = main(["post", str(SAMPLES / "logo.dxf"), "-t", "i8751", "--scale", "2", "-o", str(out)])
    _, err = capsys.readouterr()
    assert code == 0 and "placeholder" in err
    data = out.read_bytes()
    assert data[0] == 0x13 and data[-2:] == b"\x45\x54"
    assert main(["verify", str(out), "--target", "i8751"]) == 0
    _, err = capsys.readouterr()
    assert "verified" in err and "deviation from the path" in err


def test_cli_dump_format_and_verify(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "logo.txt"
    argv = ["post", str(SAMPLES / "logo.dxf"), "-t", "i8751", "--scale", "2"]
    assert main([*argv, "--format", "dump", "-o", str(out)]) == 0
    assert out.read_text().startswith("; i8751 session")
    assert main(["verify", str(out), "--target", "i8751"]) == 0
    capsys.readouterr()
    bad = tmp_path / "bad.bin"
    bad.write_bytes(b"\x14\x54")
    assert main(["verify", str(bad), "--target", "i8751"]) == 3
    _, err = capsys.readouterr()
    assert "bad.bin: byte 0 (0000H): wrong access key 14H" in err


LOGO_ARGS = ("-t", "i8751", "--scale", "2", "-o", "-")


def test_cli_post_bytes_to_stdout_and_verify_from_stdin() -> None:
    post = subprocess.run(
        [sys.executable, "-m", "camtool", "post", str(SAMPLES / "logo.dxf"), *LOGO_ARGS],
        capture_output=True,
        check=False,
    )
    assert post.returncode == 0, post.stderr
    assert post.stdout[:1] == b"\x13" and post.stdout.endswith(b"\x45\x54")
    assert b"camtool" not in post.stdout
    assert post.stdout == encode_stream(_records(post.stdout))
    verify = subprocess.run(
        [sys.executable, "-m", "camtool", "verify", "-", "-t", "i8751"],
        input=post.stdout,
        capture_output=True,
        check=False,
    )
    assert verify.returncode == 0, verify.stderr


def _records(code: bytes) -> list[Record]:
    from camtool_postprocessors.i8751.packets import binary_locator, decode_stream

    return decode_stream(code, binary_locator("<stdout>"))


def test_a_rising_rapid_goes_up_before_it_travels() -> None:
    # Safety: re-posted G-code may rise and travel in one rapid (G0 X20 Y20 Z5 after a cut
    # at Z-1). The record order is X/Y then Z (R4), so written as one record the tool would
    # cross 20 mm at the cutting depth; it must go up first, then across.
    post, machine = _target()
    program = Program(
        (Linear(0.0, 0.0, 60.0, z=-1.0), Linear(10.0, 0.0, 60.0), Rapid(20.0, 20.0, z=5.0))
    )
    back = post.parse(post.emit(program, machine).code).moves
    z = 0.0
    at_depth = []
    for m in back:
        if m.z is None and z < 0:
            at_depth.append((m.x, m.y))
        z = z if m.z is None else m.z
    assert at_depth == [(10.0, 0.0)]  # only the cut travels below the surface
    assert (back[-2].x, back[-2].y, back[-2].z) == (10.0, 0.0, 5.0)  # up where the cut ended
    assert (back[-1].x, back[-1].y) == (20.0, 20.0)
