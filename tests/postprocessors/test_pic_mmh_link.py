"""Mode strings of the pic-mmh host link against UNAM-GMM §3.1-§3.2 (Tabla 23, S000-10)."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from camtool.model.errors import DialectError, ParseError
from camtool.post.registry import load_target
from camtool_postprocessors.pic_mmh.link import (
    AXES,
    Backlash,
    Faster,
    Frequency,
    GoHome,
    Jog,
    JogAxes,
    ModeString,
    Slower,
    Steps,
    Stop,
    StorePartZero,
    backlash_command,
    backlash_commands,
    parse_mode,
)

# Every string example of the reference, verbatim, with what it means.
THESIS_STRINGS: list[tuple[str, ModeString, str]] = [
    ("JX+;", Jog("X", "+"), "L1730, L1762 (§3.1, §3.5)"),
    ("&X+Y-Z+;", JogAxes((("X", "+"), ("Y", "-"), ("Z", "+"))), "S000-10 (Tabla 23 `&X±Y±Z±;`)"),
    ("PX+1000;", Steps("X", "+", 1000), "Tabla 23, L3474-L3505"),
    ("FX+250;", Frequency("X", "+", 250), "Tabla 23, L3474-L3505"),
    ("BX200;", Backlash("X", 200), "L3492"),
    ("H;", GoHome(), "Tabla 23"),
    ("A;", Stop(), "Tabla 23"),
    ("W;", Faster(), "Tabla 23"),
    ("V;", Slower(), "Tabla 23"),
    ("Q;", StorePartZero(), "Tabla 23"),
    ("PX+0014;", Steps("X", "+", 14), "§3.2 notes: zero padding presumed [derived]"),
]


@pytest.mark.parametrize(("text", "mode", "where"), THESIS_STRINGS)
def test_thesis_strings_parse_and_build_verbatim(text: str, mode: ModeString, where: str) -> None:
    assert parse_mode(text) == mode, where
    assert mode.to_string() == text, where


@pytest.mark.parametrize(
    ("text", "mode"),
    [
        ("JX-;", Jog("X", "-")),
        ("JY*;", Jog("Y", "+")),  # only '-' is negative, anything else clockwise (L1765-L1768)
        ("JZ0;", Jog("Z", "+")),
        ("PY-0001;", Steps("Y", "-", 1)),
        ("FZ 999;", Frequency("Z", "+", 999)),
        ("&Z-X;;", JogAxes((("Z", "-"), ("X", "+")))),  # the sign slot takes any character
        ("BZ000;", Backlash("Z", 0)),
    ],
)
def test_parser_reads_as_the_firmware(text: str, mode: ModeString) -> None:
    # UNAM-GMM §3.1 (Fig. 37, L1747-L1770): first character selects the mode, "obtén
    # sentido de giro" tests only for '-', then "esperar fin de línea".
    assert parse_mode(text) == mode


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("JX+", "expected ';' to end the string, found the end at character 4"),
        ("JX+;;", "expected ';' to end the string, found ';;'"),
        ("JX+;\n", "expected ';'"),
        ("Jx+;", "expected an axis X, Y or Z, found 'x'"),
        ("JA+;", "expected an axis X, Y or Z, found 'A'"),
        ("J", "expected an axis X, Y or Z, found the end"),
        ("JX", "expected a direction '+' or '-', found the end"),
        ("PX+100;", "expected 4 digits, found '100;'"),
        ("PX+10000;", "expected ';' to end the string, found '0;'"),
        ("FX+25;", "expected 3 digits, found '25;'"),
        ("BX-200;", "expected 3 digits, found '-20'"),
        ("BX2000;", "expected ';' to end the string"),
        ("H+;", "expected ';' to end the string, found '+;'"),
        ("&X+;", "'&' with one axis"),
        ("&X+X-;", "axis X twice"),
        ("&;", "expected an axis"),
        ("&X+Y+Z+X+;", "more than three axes"),
    ],
)
def test_parser_refuses_what_the_firmware_cannot_decode(text: str, message: str) -> None:
    with pytest.raises(ParseError, match=r"jog\.txt: ") as info:
        parse_mode(text, source="jog.txt")
    assert message in str(info.value)


@pytest.mark.parametrize("text", ["G01X01000.00Y01000.00F08;", "M30;", "K;", "", ";", "jx+;"])
def test_other_first_characters_are_not_mode_strings(text: str) -> None:
    with pytest.raises(ParseError, match="is not a mode string") as info:
        parse_mode(text)
    assert ("PicMmhPost.parse" in str(info.value)) == (text[:1] in ("G", "M"))


@pytest.mark.parametrize(
    ("build", "message"),
    [
        (lambda: Steps("X", "+", 10000), "step count 10000 does not fit 4 digits"),
        (lambda: Steps("X", "+", -1), "step count -1 does not fit"),
        (lambda: Steps("X", "+", 1.5), "step count 1.5 does not fit"),
        (lambda: Steps("X", "+", True), "step count True does not fit"),
        (lambda: Frequency("Y", "-", 1000), "frequency 1000 does not fit 3 digits (0–999 Hz"),
        (lambda: Backlash("X", 1000), "backlash 1000 does not fit 3 digits (0–999 µm"),
        (lambda: Backlash("X", -3), "backlash -3 does not fit"),
        (lambda: Jog("A", "+"), "axis 'A' is not one of X, Y, Z"),
        (lambda: Jog("X", "*"), "direction '*' is not '+' or '-'"),
        (lambda: JogAxes((("X", "+"),)), "2 or 3 different axes"),
        (lambda: JogAxes((("X", "+"), ("X", "-"))), "2 or 3 different axes"),
        (lambda: JogAxes((("X", "+"), ("Y", "+"), ("Z", "+"), ("X", "-"))), "2 or 3"),
    ],
)
def test_builder_refuses_out_of_range_values(build: object, message: str) -> None:
    with pytest.raises(DialectError) as info:
        build()  # type: ignore[operator]
    assert message in str(info.value)


def test_backlash_command_from_the_thesis_compensations() -> None:
    # UNAM-GMM §5.2: final compensation X 204 µm, Y 178 µm (L2486-L2490); the first pass
    # used 192.5 / 168.5 µm, which a 3-digit field can only carry rounded (half up).
    assert backlash_command("X", 200) == "BX200;"  # L3492
    assert backlash_command("x", 204.0) == "BX204;"
    assert backlash_command("Y", 168.5) == "BY169;"
    assert backlash_command("X", 192.5) == "BX193;"
    assert backlash_commands(load_target("pic-mmh").machine) == ("BX204;", "BY178;")
    for bad in (999.5, -0.6, float("nan"), True, 1e30, -1e30):  # 1e30: not an InvalidOperation
        with pytest.raises(DialectError):
            backlash_command("X", bad)
    with pytest.raises(DialectError, match="axis 'Q'"):
        backlash_command("Q", 10)


_axis = st.sampled_from(AXES)
_sign = st.sampled_from(["+", "-"])
_modes = st.one_of(
    st.builds(Jog, _axis, _sign),
    st.builds(
        lambda axes, signs: JogAxes(tuple(zip(axes, signs, strict=False))),
        st.permutations(AXES).flatmap(lambda p: st.integers(2, 3).map(lambda n: p[:n])),
        st.lists(_sign, min_size=3, max_size=3),
    ),
    st.builds(Steps, _axis, _sign, st.integers(0, 9999)),
    st.builds(Frequency, _axis, _sign, st.integers(0, 999)),
    st.builds(Backlash, _axis, st.integers(0, 999)),
    st.sampled_from([GoHome(), Stop(), Faster(), Slower(), StorePartZero()]),
)


@given(_modes)
def test_every_built_string_parses_back_to_itself(mode: ModeString) -> None:
    text = mode.to_string()
    assert text.endswith(";") and " " not in text
    assert parse_mode(text) == mode
