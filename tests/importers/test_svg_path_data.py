"""The SVG path-data check's one-match fast path against its lexer.

``check_path_data`` takes data its possessive pattern matches whole, with no bare decimal
point, as it is, without running the lexer (``_read_path_data``); everything else goes to
the lexer. The lexer is the reference: for any data, both give the same text or the same
error. The data is built from SVG 1.1 §8.3.9's grammar (commands, numbers in every form the
grammar has, separators, arc flags written without separators), with wrong counts, bare
points and unreadable exponents mixed in.
"""

from __future__ import annotations

import time

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from camtool.importers import svgcheck

ARITY = {"m": 2, "l": 2, "h": 1, "v": 1, "c": 6, "s": 4, "q": 4, "t": 2, "a": 7, "z": 0}

GOOD = ["1", "23", "0", "4.5", ".5", "12.25", "0.0", "09", "1e3", "2E-2", ".5e+1", "-3", "+7"]
BAD = ["7.", ".", "1e", "2e-", "-", "3.e2"]  # bare points (read), unreadable numbers (refused)
numbers = st.one_of(st.sampled_from(GOOD), st.sampled_from(GOOD), st.sampled_from(GOOD + BAD))
separators = st.sampled_from(["", " ", ",", " , ", "\n", "\t", ",,", "\r\n", "\f"])


@st.composite
def path_data(draw: st.DrawFn) -> str:
    out = [draw(separators)]
    for i in range(draw(st.integers(1, 6))):
        first = i == 0 and draw(st.integers(0, 9)) > 0
        command = draw(st.sampled_from("Mm" if first else "MmLlHhVvCcSsQqTtAaZzMLCSQAXxe"))
        out.append(command)
        arity = ARITY.get(command.lower(), 1)
        whole = arity and draw(st.integers(0, 19)) > 0
        count = arity * draw(st.integers(1, 3)) if whole else draw(st.integers(0, 8))
        for k in range(count):
            out.append(draw(separators))
            flag = command in "Aa" and k % 7 in (3, 4) and draw(st.integers(0, 9)) > 0
            out.append(draw(st.sampled_from("01")) if flag else draw(numbers))
        out.append(draw(separators))
    return "".join(out)


def _outcome(check: object, d: str) -> tuple[str, str]:
    try:
        return ("read", check(d))  # type: ignore[operator]
    except ValueError as exc:
        return ("refused", str(exc))


@settings(max_examples=1000, deadline=None)
@given(path_data())
def test_the_fast_path_answers_as_the_lexer(d: str) -> None:
    assert _outcome(svgcheck.check_path_data, d) == _outcome(svgcheck._read_path_data, d)


@pytest.mark.parametrize(
    "d",
    [
        "M 10,20 L 30 40 Z",
        "m1-2.5.5e3,4 c1,2,3,4,5,6 6,5,4,3,2,1 s1 2 3 4 q1 2 3 4 t5 6 h1 v-2 z",
        "M0 0a25,25 -30 0,1 50,-25 a1 1 0 1050 20",  # flags without separators (SVG 2)
        "\n  M1E2 0 H .5 V +3 Z M 4 4 l 1 1\t",
    ],
)
def test_well_formed_data_is_taken_whole(d: str) -> None:
    """Data as Inkscape, Illustrator and hand editors write it: no lexer needed."""
    assert svgcheck._WELL_FORMED.fullmatch(d) is not None
    assert svgcheck.check_path_data(d) == d == svgcheck._read_path_data(d)


@pytest.mark.parametrize(
    ("d", "said"),
    [
        ("M 300. 20 L 4.e1 5", "M 300.0 20 L 4.0e1 5"),  # bare points: written as the lexer does
        ("M 1 2 L 3", "takes a multiple of 2 numbers, got 1"),
        ("L 1 2", "must start with M or m"),
        ("M 0 0 A 1 1 0 2 0 5 5", "arc flag must be 0 or 1"),
        ("M 0 0 L 1e 2", "cannot read a number"),
        ("M 0 0 Z 3", "takes no numbers"),
        ("M 0 0 X 1", "unknown command"),
        *(
            (f"M0 0 {c} {' 1' * n}", "takes a multiple of")
            for c, n in [
                ("L", 3),
                ("H", 0),
                ("C", 4),
                ("S", 2),
                ("Q", 6),
                ("T", 1),
                ("A", 5),
                ("m", 1),
            ]
        ),
    ],
)
def test_data_the_pattern_does_not_take_goes_to_the_lexer(d: str, said: str) -> None:
    assert svgcheck._WELL_FORMED.fullmatch(d) is None or svgcheck._BARE_POINT.search(d)
    outcome = _outcome(svgcheck.check_path_data, d)
    assert outcome == _outcome(svgcheck._read_path_data, d)
    assert said in outcome[1]


@pytest.mark.parametrize(
    ("d", "said"),
    [
        ("M0 0" + "C1 2 3 4 5 6" * 50_000 + "C1", "takes a multiple of 6 numbers, got 1"),
        ("M0 0 L" + "7" * 21 + " x", "unknown command 'x'"),
    ],
    ids=["long", "digits"],
)
def test_data_that_fails_at_its_end_is_read_once_more_not_backtracked(d: str, said: str) -> None:
    """The pattern fails in one pass, then the lexer reads the data: no backtracking.

    5 × 10⁴ curves one number short, and a run of 21 digits before an unknown command: a
    pattern whose numbers were not atomic would try every split of the digits into numbers
    (2²⁰ ways: over a minute of CPU; the curves are linear either way). CPU time of this
    process, against the lexer's on the same data: no more than a few times its cost.
    """
    start = time.process_time()
    with pytest.raises(ValueError, match=said):
        svgcheck._read_path_data(d)
    lexer = time.process_time() - start
    start = time.process_time()
    with pytest.raises(ValueError, match=said):
        svgcheck.check_path_data(d)
    both = time.process_time() - start
    assert both < 10 * lexer + 1.0
