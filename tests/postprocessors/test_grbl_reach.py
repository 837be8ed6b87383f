"""How far from work zero a GRBL program may lie: what GRBL itself reads from camtool's numbers.

The judge is a transcription of GRBL 1.1's own C code, not camtool's: ``nuts_bolts.c``
``read_float`` (the first 8 digits as an integer, the rest dropped, converted to float32
and scaled by 0.01 and 0.1 in float32, as on the AVR; in doubles rounded to float32, as in
grbl-sim on a PC) and ``gcode.c``'s radius check of a centre-format arc (error 33), on the
program's text as written. The grbl target writes at most 4 integer digits (9999.999 mm):
beyond 16777.216 mm ``read_float`` no longer reads 1 µm, and small arcs 40 m out fail the
check; its I, J and K hold 5 (8 digits in all): an arc of a centre farther off is
written as chords.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from decimal import Decimal
from pathlib import Path
from typing import Any

import numpy as np
import pytest

ezdxf = pytest.importorskip("ezdxf")

ROOT = Path(__file__).resolve().parents[2]
F32 = np.float32


def avr(value: np.float32, factor: float) -> np.float32:
    """``fval *= factor`` on the AVR: ``double`` is float32 there."""
    return F32(value * F32(factor))


def host(value: np.float32, factor: float) -> np.float32:
    """``fval *= factor`` in grbl-sim: a double product stored in a float."""
    return F32(float(value) * factor)


def kept_digits(text: str) -> tuple[int, int]:
    """``read_float``'s integer and power of ten (``MAX_INT_DIGITS`` 8; leading zeros count)."""
    intval, exp, ndigit, decimal = 0, 0, 0, False
    for ch in text.lstrip("+-"):
        if ch.isdigit():
            ndigit += 1
            if ndigit <= 8:
                exp -= decimal
                intval = intval * 10 + int(ch)
            elif not decimal:
                exp += 1  # an integer digit dropped
        elif ch == "." and not decimal:
            decimal = True
        else:
            break
    return intval, exp


def read_float(text: str, times: Callable[[np.float32, float], np.float32]) -> np.float32:
    """GRBL 1.1 ``nuts_bolts.c`` ``read_float`` of a word's number."""
    intval, exp = kept_digits(text)
    value = F32(intval)
    if value != 0:
        while exp <= -2:
            value, exp = times(value, 0.01), exp + 2
        if exp < 0:
            value = times(value, 0.1)
        while exp > 0:
            value, exp = times(value, 10.0), exp - 1
    return -value if text.startswith("-") else value


def arc_errors(program: str, times: Callable[[np.float32, float], np.float32]) -> list[str]:
    """The G2/G3 blocks GRBL answers ``error:33``: ``gcode.c``'s check on the words as read."""
    position = [F32(0), F32(0)]
    motion, refused = 0, []
    for line in program.splitlines():
        block = re.sub(r"\(.*?\)", "", line).upper()
        words = dict(re.findall(r"([A-Z])([-+.0-9]+)", block))
        for code in re.findall(r"G([0-9.]+)", block):
            if float(code) in (0, 1, 2, 3):
                motion = int(float(code))
        target = [
            read_float(words[a], times) if a in words else position[k] for k, a in enumerate("XY")
        ]
        if motion in (2, 3) and ("X" in words or "Y" in words):
            i, j = (read_float(words.get(a, "0"), times) for a in "IJ")
            x, y = (target[0] - position[0]) - i, (target[1] - position[1]) - j
            target_r, r = np.sqrt(x * x + y * y), np.sqrt(i * i + j * j)
            delta = abs(target_r - r)
            if delta > 0.005 and (delta > 0.5 or delta > 0.001 * r):
                refused.append(line)
        position = target
    return refused


def test_the_judge_reads_as_grbl_does() -> None:
    """By hand: 93274180 is no float32 (they are 8 apart there): 93274176; × 0.01 → 932741.75
    (float32, 1/16 apart); × 0.1 → 93274.175, stored as 93274.171875 in grbl-sim, while the
    AVR's float32 0.1 (0.10000000149) gives 93274.1764 → 93274.1796875. A ninth digit is
    dropped; 9999.999 reads within half a float32 step (1/1024) either way."""
    assert read_float("93274.180", host) == F32(93274.171875)
    assert read_float("93274.180", avr) == F32(93274.1796875)
    assert read_float("238379.324", avr) == read_float("238379.32", avr)
    for times in (avr, host):
        assert abs(float(read_float("9999.999", times)) - 9999.999) <= 1 / 2048


def _small_arcs(path: Path) -> Path:
    """300 arcs and circles of 5 µm to 1.6 mm radius on a 60 × 45 mm grid, mm."""
    rng = np.random.default_rng(5)
    doc = ezdxf.new()
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    for k in range(300):
        x, y = 3.0 * (k % 20) + rng.random(), 3.0 * (k // 20) + rng.random()
        r = 10 ** rng.uniform(-2.3, 0.2)
        if k % 2:
            msp.add_circle((x, y), r)
        else:
            a = rng.uniform(0, 360)
            msp.add_arc((x, y), r, a, a + rng.uniform(10, 350))
    doc.saveas(path)
    return path


@pytest.mark.parametrize("times", [avr, host], ids=["avr", "grbl-sim"])
def test_arcs_at_the_reach_pass_grbl_s_check_as_grbl_reads_them(
    tmp_path: Path, run: Any, times: Callable[[np.float32, float], np.float32]
) -> None:
    drawing = _small_arcs(tmp_path / "arcs.dxf")
    out = tmp_path / "arcs.gcode"
    move = ["--origin", "lower-left", "--translate", "-9999", "9953"]  # to -9999.x, 999x.x
    code, err = run("post", str(drawing), "-t", "grbl", "--depth", "1", *move, "-o", str(out))
    assert code == 0, err
    program = out.read_text()
    assert re.search(r"X-999\d\.\d{3}", program) and re.search(r"Y999\d\.\d{3}", program)
    assert program.count("G2") + program.count("G3") >= 300
    assert arc_errors(program, times) == []


def test_the_same_arcs_further_out_are_refused_by_grbl_and_by_camtool(
    tmp_path: Path, run: Any
) -> None:
    """Written 40 m out by a grbl target without the limit, GRBL refuses some of the arcs;
    the grbl target refuses the toolpath, names the word and says how to place it."""
    drawing = _small_arcs(tmp_path / "arcs.dxf")
    unlimited = tmp_path / "grbl-unlimited.toml"
    text = (ROOT / "postprocessors" / "grbl" / "grbl.toml").read_text()
    unlimited.write_text(
        re.sub(r"\nint_digits = 4[^\n]*", "", text).replace('name = "grbl"', 'name = "far"')
    )
    far = ["--origin", "lower-left", "--translate", "40000", "40000", "--depth", "1"]
    out = tmp_path / "far.gcode"
    code, err = run("post", str(drawing), "-t", str(unlimited), *far, "-o", str(out))
    assert code == 0, err
    assert arc_errors(out.read_text(), avr)  # what the limit is for

    out = tmp_path / "grbl.gcode"
    code, err = run("post", str(drawing), "-t", "grbl", *far, "-o", str(out))
    assert code == 1
    assert "X = 4000" in err and "4 integer digits" in err and "--origin lower-left" in err
    assert not out.exists()


@pytest.mark.parametrize(
    "text", ["X238379.324", "Y-100000.5", "I12345.6789", "X0.000000012", "X123456789", "Z1.5"]
)
def test_send_refuses_exactly_the_numbers_grbl_reads_000_5_or_more_off(text: str) -> None:
    """``misread`` against the digits the transcribed ``read_float`` keeps."""
    from camtool_postprocessors.grbl.link import misread

    intval, exp = kept_digits(text[1:])
    kept = Decimal(intval).scaleb(exp) * (-1 if text[1] == "-" else 1)
    found = misread(f"G1 {text}")
    assert (found is not None) == (abs(Decimal(text[1:]) - kept) >= Decimal("0.0005"))
    if found is not None:
        assert Decimal(found.split(" as ")[1][1:]) == kept


def test_an_arc_of_a_centre_beyond_eight_digits_is_written_as_chords(
    tmp_path: Path, run: Any
) -> None:
    """A 200 m radius ARC (its J would read -200029.99 for -200029.997): chords within
    0.002 mm of the circle, judged by ezdxf's own arc (its construction tool), and every
    number GRBL reads as written."""
    from camtool_postprocessors.grbl.link import misread

    doc = ezdxf.new()
    doc.header["$INSUNITS"] = 4
    centre, radius = (25.0, -200000.0123), 200030.0
    doc.modelspace().add_arc(centre, radius, 89.99, 90.01)
    doc.saveas(tmp_path / "flat.dxf")
    out = tmp_path / "flat.gcode"
    code, err = run("post", str(tmp_path / "flat.dxf"), "-t", "grbl", "-o", str(out))
    assert code == 0, err
    assert "1 arc(s) with a centre farther away than grbl's I and J write" in err
    blocks = [b for b in out.read_text().splitlines() if not b.startswith("(")]
    assert not any(re.match(r"G[23] ", b) for b in blocks)
    assert all(misread(b) is None for b in blocks)
    arc = ezdxf.math.ConstructionArc(centre, radius, 89.99, 90.01)
    points = re.findall(r"G[01] X(\S+) Y(\S+)", "\n".join(blocks))  # its start, its chords
    path = [(float(x), float(y)) for x, y in points]
    assert len(path) >= 3
    for x, y in path:
        assert abs(np.hypot(x - centre[0], y - centre[1]) - radius) <= 0.002 + 0.0005
    for end in (arc.start_point, arc.end_point):
        assert min(np.hypot(x - end.x, y - end.y) for x, y in path) <= 0.0005
