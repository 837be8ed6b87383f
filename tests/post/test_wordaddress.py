"""The word-address dialect engine: strict spec loading, formatting, writer and reader rules.

The thesis targets built on it are tested in test_flashcut.py, test_valcnc.py and
test_grbl_linuxcnc.py; here a dialect is whatever a [dialect_options] table says.
"""

from __future__ import annotations

import itertools
import math
import re
from pathlib import Path
from typing import Any

import pytest

from camtool.model.errors import DialectError, InputError, ParseError
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
    ToolChange,
)
from camtool.post.registry import load_target
from camtool.post.wordaddress import WordAddressPost, word_address_dialect

BIG = Machine(name="test bench", steps_per_mm=(1000.0,) * 3, work_area_mm=(-900, -900, 900, 900))
"""A machine that never limits the dialect (work area ±900 mm, Z axis)."""

RS274: dict[str, Any] = {
    "preamble": ["G21 G90 G17"],
    "spindle_cw": "M3",
    "spindle_ccw": "M4",
    "spindle_off": "M5",
    "dwell": "G4",
    "tool_change": "M6",
    "end": ["M2", "M30"],
    "helix": True,
    "words": {
        "XYZIJ": {"decimals": 3},
        "F": {"decimals": 1, "min_decimals": 0},
        "S": {"decimals": 0},
        "P": {"decimals": 3, "min_decimals": 0},
        "T": {"decimals": 0},
    },
}
"""A plain RS-274 dialect: the defaults plus spindle, dwell, tool change and end codes."""


def post(options: dict[str, Any], where: str = "toy.toml") -> WordAddressPost:
    return word_address_dialect(options, where)


def emit(
    options: dict[str, Any], moves: tuple[Move, ...], **program: Any
) -> tuple[list[str], tuple[str, ...]]:
    result = post(options).emit(Program(moves, **program), BIG)
    return str(result.code).splitlines(), result.warnings


# -- strict loading: every error names the file and the full key path ---------------------


@pytest.mark.parametrize(
    ("options", "message"),
    [
        (
            {"words": {"XY": {"decimals": "3"}}},
            'toy.toml: dialect_options.words.XY.decimals: expected an integer, got "3"',
        ),
        (
            {"words": {"XY": {}}, "seperator": ""},
            r'dialect_options: unknown key\(s\) "seperator"; known: .*separator',
        ),
        (
            {"words": {"XY": {"decimal": 2}}},
            r'words.XY: unknown key\(s\) "decimal"; known: .*decimals',
        ),
        ({"words": {"XYQ": {}}}, "dialect_options.words.XYQ: unknown word; words are among"),
        (
            {"words": {"X": {}}},
            "dialect_options.words: the X and Y words are required, Y is missing",
        ),
        ({"words": {"XY": {}, "X": {}}}, "dialect_options.words.X: word X is defined twice"),
        ({"words": 3}, "dialect_options.words: expected a table, got 3"),
        (
            {"words": {"XY": {}}, "separator": ","},
            r'separator: expected one of \["", " "\], got ","',
        ),
        (
            {"words": {"XY": {}}, "z_moves": "own-block"},
            'z_moves: expected "none" .there is no Z word',
        ),
        ({"words": {"XYZ": {}}, "z_moves": "none"}, 'z_moves: expected "own-block" or "with-xy"'),
        ({"words": {"XYZIJ": {}}, "helix": True, "z_moves": "own-block"}, "helix: a helix needs"),
        ({"words": {"XY": {}}, "dwell": "G4"}, "dwell: a dwell code needs a P word"),
        (
            {"words": {"XY": {}}, "comment": ";", "operator_messages": True},
            r'operator_messages: \(MSG, ...\) messages need comment = "\(\)"',
        ),
        ({"words": {"XY": {}}, "tool_change": "M6"}, "tool_change: a tool change code needs a T"),
        ({"words": {"XY": {}}, "by_hand": "stop"}, "by_hand: changing tools with a stop needs"),
        (
            {"words": {"XY": {}}, "by_hand": "pause"},
            r'by_hand: expected one of \["programs", "stop"\]',
        ),
        ({"words": {"XYT": {"decimals": 3}}}, "words.T.decimals: a tool number is an integer"),
        ({"words": {"XYI": {}}}, "words: arcs need both I and J words; J is missing"),
        ({"words": {"XY": {}}, "modal": ["I"]}, 'modal: expected letters among .*, got "I"'),
        ({"words": {"XY": {}}, "modal": ["F"]}, 'modal: "F" is not a word of this dialect'),
        ({"words": {"XY": {}}, "preamble": ["G01"]}, r"preamble: G01 is a motion code"),
        ({"words": {"XY": {}}, "preamble": ["G1"]}, r"preamble: G1 has its own key"),
        ({"words": {"XY": {}}, "preamble": ["G91"]}, r"preamble: G91 .incremental coordinates"),
        (
            {"words": {"XY": {}}, "preamble": ["G21 X1"]},
            r'preamble\[0\]: expected codes .*"G21 X1"',
        ),
        (
            {"words": {"XY": {}}, "preamble": ["M30"], "end": ["M30"]},
            "preamble: M30 has its own key",
        ),
        (
            {"words": {"XYIJ": {}}, "preamble": ["G90.1"]},
            'preamble: G90.1 .absolute arc centre. needs arc_centre = "absolute"',
        ),
        (
            {"words": {"XY": {}}, "motion_codes": {"cw": "M3"}},
            "motion_codes.cw: the cw code is G2",
        ),
        (  # a spelling, not a meaning: every rapid at feed, every cut at rapid
            {"words": {"XY": {}}, "motion_codes": {"rapid": "G1", "linear": "G0"}},
            'motion_codes.rapid: the rapid code is G0 .spelled G0 or G00., got "G1"',
        ),
        (  # every arc the other way round
            {"words": {"XYIJ": {}}, "motion_codes": {"cw": "G03", "ccw": "G02"}},
            'motion_codes.cw: the cw code is G2 .spelled G2 or G02., got "G03"',
        ),
        ({"words": {"XYP": {}}, "dwell": "G92"}, 'dwell: the dwell code is G4, got "G92"'),
        ({"words": {"XY": {}}, "spindle_cw": "G5"}, "spindle_cw is an M code"),
        ({"words": {"XY": {}}, "end": ["G0"]}, "end: an end code is an M code"),
        (
            {"words": {"XY": {}}, "motion_codes": {"cw": 2}},
            "motion_codes.cw: expected a code such as",
        ),
        (
            {"words": {"XY": {}}, "motion_codes": {"arc": "G2"}},
            r'motion_codes: unknown key\(s\) "arc"',
        ),
        ({"words": {"XY": {}}, "spindle_off": "M30", "end": ["M30"]}, r"code\(s\) M30 given two"),
        ({"words": {"XY": {}}, "max_arc_deg": 400}, "max_arc_deg: expected a number from 1 to 360"),
        ({"words": {"XY": {}}, "max_block_bytes": 4.5}, "max_block_bytes: expected an integer"),
        ({"words": {"XY": {}}, "full_circle": "both"}, "full_circle: expected one of"),
        ({"words": {"XY": {}}, "helix": "yes"}, 'helix: expected true or false, got "yes"'),
        ({"words": {"XY": {}}, "block_end": "ab"}, "block_end: expected up to 4 punctuation"),
        ({"words": {"XY": {"decimals": 1, "grid_mm": 0.04}}}, "grid_mm: 0.04 mm is not a multiple"),
        ({"words": {"XY": {"decimals": 1, "min_decimals": 2}}}, "min_decimals: expected at most"),
        (
            {"words": {"XY": {"sign": "plus"}}},
            'words.XY.sign: expected one of \\["negative", "always"\\]',
        ),
        (
            {"words": {"XY": {"scale": -1}}},
            "words.XY.scale: expected a number from 1e-06 to 1e\\+06, got -1",
        ),
    ],
)
def test_spec_errors_name_file_and_key(options: dict[str, Any], message: str) -> None:
    with pytest.raises(InputError, match=message) as info:
        post(options)
    assert str(info.value).startswith("toy.toml: dialect_options")


def test_a_bad_target_file_names_itself_and_the_key(tmp_path: Path) -> None:
    bad = tmp_path / "mine.toml"
    bad.write_text(
        'name = "mine"\ndialect = "word-address"\nmachine = "grbl"\n'
        "[dialect_options.words.XY]\ndecimals = 3\nsign = 1\n",
        encoding="utf-8",
    )
    with pytest.raises(InputError, match=rf"{re.escape(str(bad))}: dialect_options.words.XY.sign"):
        load_target(str(bad))


# -- formatting (all through camtool.post.numfmt) -----------------------------------------


@pytest.mark.parametrize(
    ("word", "value", "text"),
    [
        ({"decimals": 3, "min_decimals": 1}, 1.0, "1.0"),  # FlashCut X1.0 (Yanez-07 L1004, R7)
        ({"decimals": 3, "min_decimals": 1}, -1.0, "-1.0"),  # I-1.0 (Yanez-07 L1021)
        ({"decimals": 3, "min_decimals": 1}, 2.969, "2.969"),
        ({"decimals": 3, "min_decimals": 1}, 1.25, "1.25"),
        ({"decimals": 3, "min_decimals": 1}, -0.0004, "0.0"),  # never -0
        ({"decimals": 3}, -0.0004, "0.000"),
        ({"decimals": 3}, 0.0005, "0.001"),  # half away from zero
        ({"decimals": 3, "sign": "always"}, 1.0, "+1.000"),
        ({"decimals": 2, "min_decimals": 0}, 12.0, "12"),
        ({"decimals": 2, "min_decimals": 0, "grid_mm": 0.04}, 0.05, "0.04"),  # 25 steps/mm
        ({"decimals": 2, "min_decimals": 0, "grid_mm": 0.04}, 0.07, "0.08"),
        ({"decimals": 0, "scale": 25.0}, 8.0, "200"),  # steps: 8 mm = 200 steps (S004-R08)
        ({"decimals": 2, "scale": 1000.0, "int_digits": 5, "zero_pad": True}, 2.969, "02969.00"),
        ({"decimals": 3, "int_digits": 4}, 1.5, "1.500"),  # a limit without padding
    ],
)
def test_word_format_table(word: dict[str, Any], value: float, text: str) -> None:
    lines, _ = emit({"words": {"XY": word}, "modal": []}, (Rapid(value, value),))
    assert lines == [f"G0 X{text} Y{text}"]


def test_the_pic_mmh_block_can_be_declared_in_toml() -> None:
    # UNAM-GMM L1731, verbatim: fixed-width µm, absolute centre, F in 0.1 mm/min, ';'.
    um = {"scale": 1000.0, "decimals": 2, "int_digits": 5, "zero_pad": True}
    options = {
        "separator": "",
        "block_end": ";",
        "arc_centre": "absolute",
        "modal": [],
        "motion_codes": {"rapid": "G00", "linear": "G01", "cw": "G02", "ccw": "G03"},
        "words": {
            "XYIJ": um,
            "F": {"scale": 10.0, "decimals": 0, "int_digits": 2, "zero_pad": True},
        },
    }
    r = math.dist((2.969, 3.400), (3.012, 3.040))
    start = (3.012 - r, 3.040)
    lines, _ = emit(options, (Rapid(*start), ArcMove(2.969, 3.4, 3.012, 3.04, True, 0.8)))
    assert lines[1] == "G02X02969.00Y03400.00I03012.00J03040.00F08;"
    back = post(options).parse("\n".join(lines))
    assert back.moves[1] == ArcMove(2.969, 3.4, 3.012, 3.04, True, 0.8, contour=1)


def test_number_over_its_field_names_the_block() -> None:
    with pytest.raises(DialectError, match=r"contour 2, block 2: X = 123.000 does not fit 2"):
        emit(
            {"words": {"XY": {"int_digits": 2}}}, (Rapid(1, 1, contour=1), Rapid(123, 1, contour=2))
        )


# -- the writer ----------------------------------------------------------------------------


def test_rs274_program_with_every_command() -> None:
    moves = (Rapid(0, 0, z=5.0), Rapid(10, 0), Linear(10, 0, 120.0, z=-1.0), Linear(20, 0, 120.0))
    commands = ((0, Spindle("cw", 12000)), (1, ToolChange(3)), (2, Dwell(0.5)), (4, Spindle("off")))
    lines, warnings = emit(RS274, moves, commands=commands)
    assert lines == [
        "G21 G90 G17",
        "M3 S12000",
        "G0 Z5.000",  # Z only: the program adds no X0 Y0
        "T3 M6",  # LinuxCNC's documentation writes T1 M6 ("M6 Tool Change")
        "G0 X10.000 Y0.000",
        "G4 P0.5",
        "G1 Z-1.000 F120",
        "G1 X20.000 Y0.000",  # F is modal (default modal = ["F"])
        "M5",
        "M2",
    ]
    assert warnings == ()


def test_what_the_dialect_lacks_is_dropped_with_one_warning_per_kind() -> None:
    moves = (Rapid(0, 0), Linear(1, 0, 100.0), Linear(1, 1, 100.0))
    commands = ((0, Spindle("cw", 1000)), (2, Dwell(1.0)), (2, Home("XY")), (3, Spindle("off")))
    lines, warnings = emit({"words": {"XY": {}}}, moves, commands=commands)
    assert lines == ["G0 X0.000 Y0.000", "G1 X1.000 Y0.000", "G1 X1.000 Y1.000"]
    assert len(warnings) == 4
    assert "toy has no F word: the feed of 2 cutting block(s)" in warnings[0]
    assert "toy has no spindle command: 2 spindle command(s) dropped" in warnings[1]
    assert "toy has no dwell: 1 pause(s) dropped" in warnings[2]
    assert "1 G28/G30/G53 return(s)" in warnings[3]


def test_spindle_without_s_word_keeps_the_code_and_warns() -> None:
    options = {"words": {"XY": {}}, "spindle_cw": "M03", "spindle_off": "M05"}
    lines, warnings = emit(options, (Rapid(0, 0),), commands=((0, Spindle("cw", 500)),))
    assert lines[0] == "M03"
    assert warnings == (
        "toy's M03 takes no S word: 1 spindle speed(s) not written; set the speed on the machine",
    )


def test_feed_rounding_is_warned_once() -> None:
    options = {"words": {"XY": {}, "F": {"decimals": 0}}}
    lines, warnings = emit(options, (Rapid(0, 0), Linear(1, 0, 99.6), Linear(2, 0, 99.6)))
    assert lines[1] == "G1 X1.000 Y0.000 F100"
    assert warnings == ("feed 99.6 mm/min written as F100 (100 mm/min)",)


def test_feed_from_inches_is_not_warned_of() -> None:
    # F19.68504 in/min (a pcb2gcode inch program's 500 mm/min) is 500.000016 mm/min.
    options = {"words": {"XY": {}, "F": {"decimals": 0}}}
    lines, warnings = emit(options, (Rapid(0, 0), Linear(1, 0, 19.68504 * 25.4)))
    assert lines[1] == "G1 X1.000 Y0.000 F500"
    assert warnings == ()


def test_feed_that_rounds_to_zero_is_an_error() -> None:
    with pytest.raises(DialectError, match=r"block 2: feed 0.4 mm/min rounds to F0"):
        emit({"words": {"XY": {}, "F": {"decimals": 0}}}, (Rapid(0, 0), Linear(1, 0, 0.4)))


def test_modal_axes_and_motion_omit_unchanged_words() -> None:
    options = {"words": {"XY": {}, "F": {"decimals": 0}}, "modal": ["G", "X", "Y", "F"]}
    moves = (Rapid(0, 0), Linear(5, 0, 100.0), Linear(5, 3, 100.0), Linear(5, 3, 100.0))
    lines, _ = emit(options, moves)
    assert lines == ["G0 X0.000 Y0.000", "G1 X5.000 F100", "Y3.000", "X5.000 Y3.000"]
    back = post(options).parse("\n".join(lines)).moves
    assert [(m.x, m.y) for m in back] == [(0, 0), (5, 0), (5, 3), (5, 3)]


def test_z_own_block_splits_rising_first_and_plunging_last() -> None:
    # Yanez-07 R7: Z moves in their own blocks.
    options = {"words": {"XYZ": {"decimals": 1}}, "z_moves": "own-block", "modal": []}
    moves = (Rapid(0, 0, z=5.0), Rapid(2, 0, z=1.0), Rapid(4, 0, z=6.0), Linear(4, 0, 9.0, z=3.0))
    lines, warnings = emit(options, moves)
    assert lines == [
        "G0 Z5.0",  # at the origin already: a Z-only move is one block
        "G0 X2.0 Y0.0",  # plunging (5 → 1): XY first, then Z
        "G0 Z1.0",
        "G0 Z6.0",  # rising (1 → 6): Z first, then XY
        "G0 X4.0 Y0.0",
        "G1 Z3.0",
    ]
    assert any(w.startswith("2 move(s) changing XY and Z together") for w in warnings)


def test_z_without_a_z_word_is_an_error() -> None:
    with pytest.raises(DialectError, match=r"block 1: toy has no Z axis \(z = -1 mm\)"):
        emit({"words": {"XY": {}}}, (Linear(1, 1, 100.0, z=-1.0),))


def test_a_helix_needs_helix() -> None:
    options: dict[str, Any] = {"words": {"XYZIJ": {}}}
    with pytest.raises(DialectError, match=r"an arc that moves Z .a helix. cannot be written"):
        emit(options, (Rapid(1, 0), ArcMove(-1, 0, 0, 0, False, 100.0, z=-1.0)))


def test_helix_split_interpolates_z() -> None:
    options = {**RS274, "max_arc_deg": 180.0, "full_circle": "split"}
    moves = (Rapid(1, 0, z=0.0), ArcMove(1, 0, 0, 0, False, 100.0, z=-2.0))
    lines, _ = emit(options, moves)
    assert lines[2:4] == [
        "G3 X-1.000 Y0.000 Z-1.000 I-1.000 J0.000 F100",
        "G3 X1.000 Y0.000 Z-2.000 I1.000 J0.000",
    ]


def test_block_over_max_block_bytes_names_block_and_limit() -> None:
    options = {"words": {"XY": {}}, "max_block_bytes": 17}
    with pytest.raises(
        DialectError, match=r"block 2: 'G0 X100.000 Y1.000' is 19 bytes .* at most 17"
    ):
        emit(options, (Rapid(1, 1), Rapid(100, 1)))


@pytest.mark.parametrize(
    ("limit", "full", "sweep_deg", "pieces"),
    [
        (360.0, "one-block", 360, 1),
        (360.0, "split", 360, 2),
        (180.0, "split", 360, 2),
        (90.0, "split", 360, 4),
        (180.0, "one-block", 270, 2),
        (100.0, "one-block", 270, 3),
        (180.0, "one-block", 180, 1),
    ],
)
def test_arcs_split_by_max_arc_deg_and_full_circle(
    limit: float, full: str, sweep_deg: int, pieces: int
) -> None:
    options = {"words": {"XYIJ": {}}, "max_arc_deg": limit, "full_circle": full}
    a = math.radians(sweep_deg)
    end = (round(10 * math.cos(a), 9), round(10 * math.sin(a), 9))
    lines, _ = emit(options, (Rapid(10, 0), ArcMove(*end, 0, 0, False, 100.0)))
    arcs = lines[1:]
    assert len(arcs) == pieces
    back = post(options).parse("\n".join(lines)).moves[1:]
    per_piece = sweep_deg / pieces  # equal pieces (analytic)
    start = (10.0, 0.0)
    for move in back:
        assert isinstance(move, ArcMove)
        swept = (
            math.degrees(
                (math.atan2(move.y - move.cy, move.x - move.cx) - math.atan2(start[1], start[0]))
                % (2 * math.pi)
            )
            or 360.0
        )
        assert swept == pytest.approx(per_piece, abs=0.01)
        start = (move.x, move.y)


def test_arc_too_small_for_the_resolution_becomes_a_line() -> None:
    # r = 0.0003 mm at 3 decimals: the centre rounds onto the start.
    options: dict[str, Any] = {"words": {"XYIJ": {}}}
    lines, warnings = emit(options, (Rapid(1, 1), ArcMove(1.0006, 1, 1.0003, 1, True, 100.0)))
    assert lines[1] == "G1 X1.001 Y1.000"
    assert "1 arc(s) too small for the 0.001 mm" in warnings[-1]


def test_an_arc_of_millimetres_at_a_dialect_of_whole_millimetres_is_chords_not_one_line() -> None:
    # A 240° arc of radius 7.3 mm no printed centre writes within GRBL's arc check at
    # 0 decimals is not "too small for the 1 mm the dialect writes": one line from its
    # start to its end would lie 11 mm from the arc's far side. It is chords, by analysis
    # each within 2 quanta of the arc (the chord tolerance) plus the half
    # quantum each printed end may move, so every point of the arc lies within 2.71 mm
    # of the written path.
    c, r = (20.4, 20.3), 7.3
    a0, a1 = math.radians(-40.0), math.radians(200.0)
    start = (c[0] + r * math.cos(a0), c[1] + r * math.sin(a0))
    end = (c[0] + r * math.cos(a1), c[1] + r * math.sin(a1))
    options = {"words": {"XYIJ": {"decimals": 0}}, "arc_check": "grbl"}
    lines, warnings = emit(options, (Rapid(*start), ArcMove(*end, *c, False, 100.0)))
    assert not [w for w in warnings if "too small" in w]
    path = [tuple(float(v) for v in re.findall(r"[XY](-?\d+)", line)) for line in lines]
    assert lines[0].startswith("G0") and all(line.startswith("G1") for line in lines[1:])

    def apart(p: tuple[float, float]) -> float:
        best = math.inf
        for (x0, y0), (x1, y1) in itertools.pairwise(path):
            dx, dy = x1 - x0, y1 - y0
            t = max(0.0, min(1.0, ((p[0] - x0) * dx + (p[1] - y0) * dy) / (dx * dx + dy * dy)))
            best = min(best, math.hypot(p[0] - x0 - t * dx, p[1] - y0 - t * dy))
        return best

    samples = [a0 + (a1 - a0) * k / 400 for k in range(401)]
    worst = max(apart((c[0] + r * math.cos(a), c[1] + r * math.sin(a))) for a in samples)
    assert worst <= 2.0 + math.sqrt(0.5), worst


def test_an_arc_whose_ends_print_the_same_is_a_tiny_arc_or_a_full_circle() -> None:
    options = {"words": {"XYIJ": {}}, "full_circle": "split"}
    # 359.99999° (the end 6e-8 mm from the start): a full circle as printed → two halves.
    near = (5.0, 5.0 - 6e-8)
    lines, _ = emit(options, (Rapid(5, 5), ArcMove(*near, 4.5, near[1], False, 100.0)))
    assert lines[1:] == ["G3 X4.000 Y5.000 I-0.500 J0.000", "G3 X5.000 Y5.000 I0.500 J0.000"]
    # 0.0001° of a 10 mm radius: nothing to print but a line to the same point.
    tiny = (10 * math.cos(1e-6), 10 * math.sin(1e-6))
    lines, warnings = emit(options, (Rapid(10, 0), ArcMove(*tiny, 0, 0, False, 100.0)))
    assert lines[1:] == ["G1 X10.000 Y0.000"] and "1 arc(s) too small" in warnings[-1]


def test_absolute_and_incremental_centres_read_to_the_same_arc() -> None:
    moves = (Rapid(1, 0), ArcMove(0, 1, 0, 0, False, 100.0))
    for centre in ("incremental", "absolute"):
        options = {"words": {"XYIJ": {}, "F": {"decimals": 0}}, "arc_centre": centre}
        lines, _ = emit(options, moves)
        assert lines[1] == (
            "G3 X0.000 Y1.000 I-1.000 J0.000 F100"
            if centre == "incremental"
            else "G3 X0.000 Y1.000 I0.000 J0.000 F100"
        )
        assert post(options).parse("\n".join(lines)).moves[1] == ArcMove(
            0, 1, 0, 0, False, 100.0, contour=1
        )


# -- the reader ----------------------------------------------------------------------------

FLASHLIKE: dict[str, Any] = {
    "motion_codes": {"rapid": "G00", "linear": "G01", "cw": "G02", "ccw": "G03"},
    "z_moves": "own-block",
    "spindle_cw": "M03",
    "spindle_off": "M05",
    "end": ["M30"],
    "words": {"XYZIJ": {"decimals": 3, "min_decimals": 1}, "F": {"decimals": 1, "min_decimals": 1}},
}


@pytest.mark.parametrize(
    ("line", "why"),
    [
        ("G01 X1 Y1.0", "X1 is not in the format of X"),  # at least one decimal (R7)
        ("G01 X1.00 Y1.0", "X1.00 is not in the format"),  # trailing zero beyond min_decimals
        ("G01 X-0.0 Y1.0", "X-0.0 is not in the format"),  # never -0
        ("G01 X+1.0 Y1.0", "X\\+1.0 is not in the format"),
        ("G01 X1e3 Y1.0", "'X1e3' is not a word"),
        ("G01  X1.0 Y1.0", "separated by one space"),
        ("G01X1.0 Y1.0", "separated by one space"),
        ("G01\tX1.0 Y1.0", "separated by one space"),  # a tab within one space-split word
        # a form feed or U+2028 is no line end (str.splitlines would make two blocks of it)
        ("G01 X1.0\x0cG01 Y1.0", "separated by one space"),
        ("G01 X1.0 Y1.0\u2028G01 X2.0 Y1.0", "separated by one space"),
        ("G01 X1.0 Y1.0 (a note)", "'\\(a' is not a word"),  # FLASHLIKE has no comments
        ("G01 X1.0", "missing Y word"),  # both X and Y (Yanez-07 R4)
        ("G1 X1.0 Y1.0", "unknown code 'G1'"),
        ("G17", "unknown code 'G17'"),
        ("G01 X1.0 Y1.0 Q1.0", "unknown word Q1.0"),
        ("G01 X1.0 Y1.0 X2.0", "X appears twice"),
        ("G02 X1.0 Y1.0 I1.0", "missing J word"),
        ("G00 X1.0 Y1.0 F3.0", "F in a rapid block"),
        ("G01 X1.0 Y1.0 M03", "G01, X, Y in a spindle block"),
        ("X1.0 Y1.0", "without a motion code"),
        ("G01 X1.0 Z1.0", "moves Z in blocks of its own"),
        ("G02 X2.0 Y0.0 I0.0 J0.0", "centre is its start point"),
        ("M05 S100.0", "unknown word S100.0"),
        ("g01 x1.0 y1.0", "unknown word g01"),
    ],
)
def test_reader_is_strict(line: str, why: str) -> None:
    with pytest.raises(ParseError, match=rf"prog.nc:2: .*{why}"):
        post(FLASHLIKE).parse(f"G01 X0.0 Y0.0 F3.0\n{line}\n", source="prog.nc")


def test_nothing_after_the_end_code() -> None:
    with pytest.raises(
        ParseError, match=r"prog.nc:3: 'G00 X1.0 Y1.0' after the program end on line 2"
    ):
        post(FLASHLIKE).parse("G00 X0.0 Y0.0\nM30\nG00 X1.0 Y1.0\n", source="prog.nc")


def test_reader_refuses_blocks_over_the_byte_limit() -> None:
    options = {"words": {"XY": {}}, "separator": "", "max_block_bytes": 20}
    with pytest.raises(
        ParseError, match="p:1: block is 21 bytes with its line end; toy takes at most 20"
    ):
        post(options).parse("G0X100.000Y100.00000\n", source="p")


def test_reader_block_end_and_no_spaces() -> None:
    options = {"words": {"XY": {}}, "separator": "", "block_end": ";"}
    assert post(options).parse("G0X1.000Y2.000;\n").moves == (Rapid(1, 2, contour=1),)
    for bad in ("G0X1.000Y2.000", "G0 X1.000Y2.000;"):
        with pytest.raises(ParseError, match="<code>:1"):
            post(options).parse(bad)


def test_reader_fills_lines_commands_and_contours() -> None:
    code = "\n".join(
        [
            "G21 G90 G17",
            "M3 S1000",
            "G0 Z5.000",  # Z only: the program adds no X0 Y0
            "G1 X1.000 Y0.000 Z-1.000 F100",
            "G4 P0.25",
            "G2 X-1.000 Y0.000 I-1.000 J0.000",
            "G0 X5.000 Y5.000",
            "M6 T2",
            "G1 X6.000 Y5.000",
            "M5",
            "M30",
        ]
    )
    program = post(RS274).parse(code, source="p.ngc")
    assert program.moves == (
        Rapid(0, 0, 5.0, contour=1),
        Linear(1, 0, 100.0, -1.0, contour=1),
        ArcMove(-1, 0, 0, 0, True, 100.0, contour=1),
        Rapid(5, 5, contour=2),
        Linear(6, 5, 100.0, contour=2),  # F is modal
    )
    assert program.lines == (3, 4, 6, 7, 9)
    assert program.commands == (
        (0, Spindle("cw", 1000.0)),
        (2, Dwell(0.25)),
        (4, ToolChange(2)),
        (5, Spindle("off")),
    )


def test_reader_modal_motion_and_axes_per_rs274() -> None:
    options = {"words": {"XYIJ": {}, "F": {"decimals": 0}}, "modal": ["G", "X", "Y", "F"]}
    code = (
        "G1 X1.000 Y1.000 F50\nX2.000\nG2 X3.000 Y2.000 I0.000 J1.000\nX4.000 Y1.000 I0.000 J-1.000"
    )
    moves = post(options).parse(code).moves
    assert moves == (
        Linear(1, 1, 50.0, contour=1),
        Linear(2, 1, 50.0, contour=1),
        ArcMove(3, 2, 2, 2, True, 50.0, contour=1),
        ArcMove(4, 1, 3, 1, True, 50.0, contour=1),  # G2 carries, I/J from the new start
    )


def test_reader_needs_f_where_f_is_not_modal() -> None:
    options = {"words": {"XY": {}, "F": {"decimals": 0}}, "modal": []}
    with pytest.raises(ParseError, match=":2: missing F word"):
        post(options).parse("G1 X1.000 Y1.000 F50\nG1 X2.000 Y1.000")
    with pytest.raises(ParseError, match=":1: a cutting move before any F word"):
        post({"words": {"XY": {}, "F": {}}}).parse("G1 X1.000 Y1.000")


def test_reader_without_f_word_reads_feed_zero() -> None:
    assert post({"words": {"XY": {}}}).parse("G1 X1.000 Y1.000").moves[0].feed_mm_min == 0.0  # type: ignore[union-attr]


def test_a_user_dialect_file_is_a_target(tmp_path: Path) -> None:
    # What docs/dialects.md shows: a Fanuc-like dialect with N-less blocks, ';' and inches.
    path = tmp_path / "my-router.toml"
    path.write_text(
        """
name = "my-router"
description = "my router: inch G-code with ';' block ends"
dialect = "word-address"
default_feed_mm_min = 254.0

[machine]  # no Z word: a 2D machine (a Z axis is refused at load)
profile = "my-router"
name = "my router"
steps_per_mm = [80.0, 80.0, 80.0]
work_area_mm = [0.0, 0.0, 600.0, 400.0]
has_z = false

[dialect_options]
suffix = ".tap"
block_end = ";"
preamble = ["G20 G90"]
motion_codes = { rapid = "G00", linear = "G01", cw = "G02", ccw = "G03" }
spindle_cw = "M03"
spindle_off = "M05"
end = ["M30"]

[dialect_options.words.XYIJ]
scale = 0.03937007874015748   # inches per mm
decimals = 4

[dialect_options.words.F]
scale = 0.03937007874015748   # inches/min per mm/min
decimals = 1
""",
        encoding="utf-8",
    )
    target = load_target(str(path))
    assert target.name == "my-router" and target.post.formats == {"code": ".tap"}
    program = Program(
        (Rapid(25.4, 0.0), Linear(50.8, 0.0, 254.0), ArcMove(76.2, 25.4, 50.8, 25.4, False, 254.0)),
        commands=((0, Spindle("cw", 9000)), (3, Spindle("off"))),
    )
    result = target.emit(program)
    assert str(result.code).splitlines() == [
        "G20 G90;",
        "M03;",
        "G00 X1.0000 Y0.0000;",
        "G01 X2.0000 Y0.0000 F10.0;",
        "G03 X3.0000 Y1.0000 I0.0000 J1.0000;",
        "M05;",
        "M30;",
    ]
    assert "my-router's M03 takes no S word" in result.warnings[0]
    back = target.post.parse(result.code)
    for got, want in zip(back.moves, program.moves, strict=True):
        assert math.dist((got.x, got.y), (want.x, want.y)) < 1e-9
    assert back.commands == ((0, Spindle("cw")), (3, Spindle("off")))


# -- comments, header and footer (job notes) ------------------------------------------------


def test_notes_become_comments_and_read_back() -> None:
    options = {**RS274, "comment": "()", "header": ["%"], "footer": ["%"], "max_block_bytes": 40}
    notes = ("camtool 0.1.0: a (b).dxf for toy", "an ä and a very long note " + "x" * 40)
    lines, _ = emit(options, (Rapid(0, 0, 5.0), Rapid(1, 2)), notes=notes)
    assert lines == [
        "%",
        "(camtool 0.1.0: a [b].dxf for toy)",  # RS-274 comments do not nest
        "(an ? and a very long note xxxxxxxx...)",  # 39 bytes + LF = 40: cut to fit
        "G21 G90 G17",
        "G0 Z5.000",
        "G0 X1.000 Y2.000",
        "M2",
        "%",
    ]
    assert all(len(line) + 1 <= 40 for line in lines)
    back = post(options).parse("\n".join(lines) + "\n")
    assert back.moves == (Rapid(0, 0, 5.0, contour=1), Rapid(1, 2, contour=1))
    assert back.lines == (5, 6)


def test_semicolon_comments_and_a_dialect_without_comments_drops_notes() -> None:
    semi, _ = emit({**RS274, "comment": ";"}, (Rapid(1, 1),), notes=("job",))
    assert semi[:2] == ["; job", "G21 G90 G17"]
    assert post({**RS274, "comment": ";"}).parse("; job\nG0 X1.000 Y1.000\n").moves == (
        Rapid(1, 1, contour=1),
    )
    none, warnings = emit(RS274, (Rapid(1, 1),), notes=("job",))
    assert none[0] == "G21 G90 G17" and warnings == ()
    with pytest.raises(ParseError, match="is not a word"):  # no comment syntax: not skipped
        post(RS274).parse("(job)\nG0 X1.000 Y1.000\n", source="p")


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"comment": "#"}, r'comment: expected one of \["\(\)", ";"\]'),
        ({"header": ["G0 X0"]}, r'header\[0\]: expected "%" \(the dialect has no comment'),
        ({"comment": "()", "footer": ["G0 X0"]}, r'footer\[0\]: expected "%" or a comment'),
        ({"comment": "()", "header": ["(a (b))"]}, r"header\[0\]: expected"),
        ({"comment": ";", "header": ["(x)"]}, r'header\[0\]: expected "%" or a comment'),
    ],
)
def test_header_and_footer_hold_only_comments_and_tape_marks(
    options: dict[str, Any], message: str
) -> None:
    with pytest.raises(InputError, match=rf"toy.toml: dialect_options.{message}"):
        post({"words": {"XY": {}}, **options})


def test_a_z_only_move_writes_no_x_or_y() -> None:
    # From the origin (where the machine stands) and mid-program: Z only, never X0 Y0.
    moves = (Rapid(0, 0, 5.0), Rapid(3, 4), Rapid(3, 4, 1.0), Linear(3, 4, 50.0, -1.0))
    lines, _ = emit({"words": {"XYZ": {}, "F": {}}}, moves)
    assert lines == ["G0 Z5.000", "G0 X3.000 Y4.000", "G0 Z1.000", "G1 Z-1.000 F50.000"]


def test_a_spindle_without_a_speed_writes_no_s0() -> None:
    # A re-posted "M3" (speed left to the machine) is not turned into "M3 S0" (spindle at 0).
    lines, _ = emit(RS274, (Rapid(1, 1),), commands=((0, Spindle("cw")),))
    assert lines[1] == "M3"
    back = post(RS274).parse("\n".join(lines) + "\n")
    assert back.commands[0] == (0, Spindle("cw"))  # no speed: None


def test_grbl_writes_an_arc_within_half_its_arc_tolerance_as_a_line() -> None:
    # GRBL's mc_arc divides by √($12·(2r − $12)): undefined for r ≤ $12/2 = 0.001 mm at the
    # default $12 = 0.002 mm. A 1-quantum radius (filters.svg, Inkscape's examples, had
    # 2 567) is written as a G1; 2 quanta stays an arc, and both programs verify.
    from camtool.verify.verifier import verify_code

    target = load_target("grbl")
    tiny = (Rapid(1.028, 0.728), ArcMove(1.027, 0.729, 1.027, 0.728, True, 300.0))
    result = target.emit(Program(tiny))
    lines = str(result.code).splitlines()
    assert [ln for ln in lines if ln.startswith(("G2 ", "G3 "))] == []
    assert any(ln.startswith("G1 X1.027 Y0.729") for ln in lines)
    assert any("1 arc(s) too small" in w for w in result.warnings)
    verify_code(str(result.code), target)
    half = (Rapid(1.028, 0.728), ArcMove(1.026, 0.728, 1.027, 0.728, True, 300.0))
    lines = str(target.emit(Program(half)).code).splitlines()
    assert any(ln.startswith("G1 X1.026 Y0.728") for ln in lines)
    small = (Rapid(1.030, 0.728), ArcMove(1.026, 0.728, 1.028, 0.728, True, 300.0))
    result = target.emit(Program(small))
    assert any(ln.startswith("G2 X1.026 Y0.728 I-0.002") for ln in str(result.code).splitlines())
    verify_code(str(result.code), target)
