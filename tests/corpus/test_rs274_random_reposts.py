"""Random programs re-posted to grbl and linuxcnc cut the path LinuxCNC's ``rs274`` reads.

Each program mixes what real programs write: G20/G21 changes (a block's own numbers in its
new unit), G90/G91, G90.1/G91.1 centres, I/J and R arcs (negative R: the long way), full
circles, helices, arcs of nearly 360° over a short chord, modal lines naming one axis, F
changes, N words, comments and lower case. The programs are drawn from a seeded generator
that tracks the position as the written (rounded) numbers give it, so each arc's end lies
on its circle to the written decimals, as a CAM writes it.

The judge is ``rs274`` (tests/corpus/test_rs274.py): it reads the program and camtool's
re-post of it, and the two paths must lie within 0.01 mm of each other everywhere (a
Hausdorff distance of their points every 0.004 mm along, arcs as rs274 states them), and
every cut must run at the feed rs274 reads in the program, to the 0.1 mm/min the targets
write. The bound is analysis, not camtool's output: the targets print 0.001 mm, and an arc
conformed to the controller's radius check or written as chords stays within 0.002 mm.
"""

from __future__ import annotations

import math
import random
import re
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial import cKDTree

from camtool.cli.main import main
from tests.corpus.test_rs274 import arc_points, needs_rs274, rs274

CANON = re.compile(r"(STRAIGHT_TRAVERSE|STRAIGHT_FEED|ARC_FEED|USE_LENGTH_UNITS|SET_FEED_RATE)\(")
PATH_MM = 0.01
STEP_MM = 0.004
"""Points along each path this far apart: the nearest point is within 0.002 mm of the path."""
FEED_MM_MIN = 0.051  # the targets write F to 0.1 mm/min


def _number(value: float, inch: bool, rng: random.Random) -> str:
    text = f"{value:.{4 if inch else 3}f}"
    if rng.random() < 0.15:
        text = text.rstrip("0").rstrip(".") or "0"
    if text.startswith("0.") and rng.random() < 0.3:
        text = text[1:]
    return text


def program(seed: int) -> str:
    """A random program of 30 blocks that ``rs274`` accepts (see the module docstring)."""
    rng = random.Random(seed)
    inch = rng.random() < 0.5
    absolute, arc_absolute = True, False
    x = y = 0.0
    z = 5.0
    blocks = [f"{'G20' if inch else 'G21'} G90 G17", "G0 X0 Y0 Z" + ("0.2" if inch else "5")]
    z = 0.2 * 25.4 if inch else 5.0
    feed_given = False

    def word(letter: str, mm: float, here: float | None = None) -> tuple[str, float]:
        """The word for a target ``mm`` (incremental from ``here`` in G91); the mm it gives."""
        scale = 25.4 if inch else 1.0
        value = mm / scale if here is None else (mm - here) / scale
        text = _number(value, inch, rng)
        got = float(text) * scale
        return letter + text, got if here is None else here + got

    for _ in range(30):
        words: list[str] = []
        roll = rng.random()
        if roll < 0.1:
            inch = not inch
            words.append("G20" if inch else "G21")
        elif roll < 0.2:
            absolute = not absolute
            words.append("G90" if absolute else "G91")
        elif roll < 0.26:
            arc_absolute = not arc_absolute
            words.append("G90.1" if arc_absolute else "G91.1")
        scale = 25.4 if inch else 1.0
        if not feed_given or rng.random() < 0.15:
            words.append(f"F{rng.uniform(60, 900) / scale:.{3 if inch else 1}f}")
            feed_given = True
        kind = rng.choice(["G0", "G1", "G1", "G2", "G3", "G2", "G3", "near"])
        if kind in ("G0", "G1"):
            words.append(kind)
            if rng.random() < 0.6:
                text, x = word("X", x + rng.uniform(-20, 20), (None if absolute else x))
                words.append(text)
            if rng.random() < 0.6 or words[-1] == kind:  # X, Y or both
                text, y = word("Y", y + rng.uniform(-20, 20), (None if absolute else y))
                words.append(text)
            if rng.random() < 0.3:
                text, z = word("Z", rng.uniform(-3, 5), (None if absolute else z))
                words.append(text)
        else:
            clockwise = kind == "G2" or (kind == "near" and rng.random() < 0.5)
            words.append("G2" if clockwise else "G3")
            radius = rng.uniform(1, 15)
            a0 = rng.uniform(0, 2 * math.pi)
            cx, cy = x - radius * math.cos(a0), y - radius * math.sin(a0)
            full = kind != "near" and rng.random() < 0.1
            if kind == "near":  # 359.4° to 359.9°: a short chord, the long way round
                sweep = math.radians(rng.uniform(359.4, 359.9))
                a1 = a0 - sweep if clockwise else a0 + sweep
            else:
                a1 = rng.uniform(0, 2 * math.pi)
            use_r = kind != "near" and not full and rng.random() < 0.25
            if not full:
                text, ex = word("X", cx + radius * math.cos(a1), (None if absolute else x))
                words.append(text)
                text, ey = word("Y", cy + radius * math.sin(a1), (None if absolute else y))
                words.append(text)
            else:
                ex, ey = x, y
            if use_r:
                chord = math.dist((x, y), (ex, ey))
                if chord < 0.5:
                    continue
                r = chord / 2 * rng.uniform(1.05, 3.0)
                long_way = rng.random() < 0.3
                words.append("R" + _number((-r if long_way else r) / scale, inch, rng))
            else:
                if arc_absolute:
                    text_i, _ = word("I", cx)
                    text_j, _ = word("J", cy)
                else:
                    text_i, _ = word("I", cx - x)
                    text_j, _ = word("J", cy - y)
                words += [text_i, text_j]
            if rng.random() < 0.2:
                text, z = word("Z", z + rng.uniform(-1, 1), (None if absolute else z))
                words.append(text)
            x, y = ex, ey
        if rng.random() < 0.2:
            rng.shuffle(words)
        if rng.random() < 0.1:
            words.insert(0, f"N{rng.randint(1, 9999)}")
        line = (" " if rng.random() < 0.7 else "").join(words)
        if rng.random() < 0.1:
            line = line.lower()
        blocks.append(line + (" (c)" if rng.random() < 0.1 else ""))
    return "\n".join([*blocks, "M2"]) + "\n"


def _path(stdout: str) -> tuple[np.ndarray, list[float]]:
    """rs274's motion as points every :data:`STEP_MM` (mm, XY) and the feed of each cut (mm/min)."""
    points, feeds = [(0.0, 0.0)], []
    scale, feed_raw, pending, feed = 1.0, 0.0, False, 0.0
    for line in stdout.splitlines():
        found = CANON.search(line)
        if found is None:
            continue
        name, args = found.group(1), line[found.end() : line.rindex(")")]
        if name == "USE_LENGTH_UNITS":
            scale = 25.4 if "INCHES" in args else 1.0
            continue
        if name == "SET_FEED_RATE":
            feed_raw, pending = float(args), True
            continue
        if pending:  # an F word is in the unit of its block, G20/G21 of the block included
            feed, pending = feed_raw * scale, False
        v = [float(a) * scale for a in args.split(",")]
        start = points[-1]
        if name == "ARC_FEED":
            # a full circle's start may be printed in the unit before a G20/G21 change and
            # its end in the new one: ends within 0.003 mm are one point
            points += arc_points(start, (v[0], v[1]), (v[2], v[3]), v[4], STEP_MM, full_mm=0.003)
        else:
            n = max(1, int(math.dist(start, v[:2]) / STEP_MM))
            for t in np.linspace(0.0, 1.0, n + 1)[1:]:
                points.append((start[0] + (v[0] - start[0]) * t, start[1] + (v[1] - start[1]) * t))
        if name != "STRAIGHT_TRAVERSE":
            feeds.append(feed)
    return np.array(points), feeds


@needs_rs274
@pytest.mark.parametrize("target", ["grbl", "linuxcnc"])
@pytest.mark.parametrize("seed", range(12))
def test_a_random_program_reposted_cuts_the_path_rs274_reads(
    seed: int, target: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    source = tmp_path / "random.ngc"
    source.write_text(program(seed))
    original = rs274(source)
    assert original.returncode == 0, (
        f"the generator wrote a program rs274 refuses: {original.stderr}"
    )
    out = tmp_path / f"random.{target}.ngc"
    assert main(["post", str(source), "-t", target, "-o", str(out)]) == 0, capsys.readouterr().err
    reposted = rs274(out)
    assert reposted.returncode == 0, reposted.stderr
    theirs, their_feeds = _path(original.stdout)
    ours, our_feeds = _path(reposted.stdout)
    apart = max(
        float(np.max(cKDTree(theirs).query(ours)[0])), float(np.max(cKDTree(ours).query(theirs)[0]))
    )
    assert apart <= PATH_MM, f"the re-posted path lies {apart:.4f} mm from the program's"
    if len(our_feeds) == len(their_feeds):  # a full circle may be split: then unpaired
        for ours_f, theirs_f in zip(our_feeds, their_feeds, strict=True):
            assert ours_f == pytest.approx(theirs_f, abs=FEED_MM_MIN)
    else:
        assert set(np.round(our_feeds, 1)) <= set(np.round(their_feeds, 1))
