"""LinuxCNC's own interpreter, ``rs274``, judges camtool's linuxcnc programs.

``rs274`` is LinuxCNC's stand-alone RS-274/NGC interpreter (Debian ``linuxcnc-uspace``,
``usr/bin/rs274``); fetch_corpus.py extracts it with ``dpkg-deb -x`` together with the one
library a plain Debian system lacks (``libboost-python1.74.0``) and runs it with
``LD_LIBRARY_PATH`` set, no root and no install needed. ``rs274 -t TOOL.TBL -g FILE``
interprets FILE in batch mode and prints the canonical machining calls it would make
(``STRAIGHT_TRAVERSE(x, y, z, a, b, c)``, ``STRAIGHT_FEED(...)``, ``ARC_FEED(first_end,
second_end, first_axis, second_axis, rotation, axis_end_point, a, b, c)`` — in the XY plane
first/second are X/Y, the axes are the centre, rotation > 0 is counter-clockwise); on an
error it prints the message and the offending block on stderr and exits 1. Without ``-t``
it looks for a tool table of a sample configuration that is not installed, so one is given.

Two checks: every linuxcnc program of the corpus run (test_corpus.py, shared per session)
is accepted, and for a few of them rs274's end points, arc centres and directions equal
those of the program camtool planned (``camtool.jobs.pipeline.post_file``), within the 0.0005 mm
that the 3-decimal output rounds to.
"""

from __future__ import annotations

import math
import os
import re
import subprocess
import tempfile
from pathlib import Path

import numpy as np
import pytest

from camtool.cli.main import main
from camtool.jobs.pipeline import post_file
from camtool.model.program import ArcMove, Linear, Rapid
from camtool.toolpath.options import PlanOptions
from tests.corpus.conftest import (
    CORPUS,
    case_id,
    corpus_files,
    load_manifest,
    outcome_for,
    skip_reason,
)

MANIFEST = load_manifest()
FILES = corpus_files(MANIFEST)
KNOWN_GOOD = "G21 G90 G17\nG0 X1 Y2\nG1 X5 Y2 F100\nG2 X7 Y4 I0 J2\nM2\n"
CANON = re.compile(r"(STRAIGHT_TRAVERSE|STRAIGHT_FEED|ARC_FEED)\(([^)]*)\)")
ROUND_MM = 0.0005 + 1e-9  # the linuxcnc dialect writes 3 decimals


def rs274(program: Path, tool_table: Path | None = None) -> subprocess.CompletedProcess[str]:
    """Run rs274 in batch mode on PROGRAM (``tool_table``: the manifest's, with one tool).

    LinuxCNC 2.9 shares its tool table through ``$HOME/.tool.mmap``: two rs274 at once (the
    suite's workers) would read each other's tools. Each run gets a ``HOME`` of its own.
    """
    assert MANIFEST is not None
    entry = MANIFEST["rs274"]
    table = tool_table if tool_table is not None else CORPUS / entry["tool_table"]
    cmd = [str(CORPUS / entry["exe"]), "-t", str(table), "-g"]
    with tempfile.TemporaryDirectory(prefix="camtool-rs274-home-") as home:
        env = dict(
            os.environ,
            HOME=home,
            LD_LIBRARY_PATH=os.pathsep.join(str(CORPUS / d) for d in entry["ld_library_path"]),
        )
        return subprocess.run(
            [*cmd, str(program)], capture_output=True, text=True, env=env, timeout=120, check=False
        )


def rs274_problem() -> str | None:
    """Why rs274 cannot judge here (None when it can)."""
    if MANIFEST is None:
        return skip_reason()
    if "rs274" not in MANIFEST:
        return f"rs274 was not fetched: {'; '.join(MANIFEST.get('notes', []))}"
    with tempfile.TemporaryDirectory(prefix="camtool-rs274-") as tmp:  # the corpus is read-only
        probe = Path(tmp) / "rs274-probe.ngc"
        probe.write_text(KNOWN_GOOD)
        try:
            done = rs274(probe)
        except OSError as exc:
            return f"rs274 cannot run: {exc}"
    if done.returncode != 0 or "ARC_FEED(7.0000, 4.0000, 5.0000, 4.0000, -1" not in done.stdout:
        return f"rs274 fails on a known-good program: {done.stderr.strip()[-300:]}"
    return None


PROBLEM = rs274_problem()
needs_rs274 = pytest.mark.skipif(PROBLEM is not None, reason=PROBLEM or "")


def canon_moves(stdout: str) -> list[tuple[str, tuple[float, ...]]]:
    """(kind, numbers) of rs274's motion calls, in order: 'rapid', 'line' or 'arc'.

    rapid/line: (x, y, z); arc: (x, y, cx, cy, rotation, z).
    """
    moves = []
    for name, args in CANON.findall(stdout):
        v = tuple(float(a) for a in args.split(","))
        if name == "ARC_FEED":
            moves.append(("arc", (v[0], v[1], v[2], v[3], v[4], v[5])))
        else:
            moves.append(("rapid" if name == "STRAIGHT_TRAVERSE" else "line", v[:3]))
    return moves


def arc_points(
    start: tuple[float, float],
    end: tuple[float, float],
    centre: tuple[float, float],
    rotation: float,
    step_mm: float,
    full_mm: float = 1e-9,
) -> list[tuple[float, float]]:
    """Points at most ~``step_mm`` apart along an ``ARC_FEED``, its start left out, its end last.

    ``rotation`` > 0 is counter-clockwise (rs274's sign); ends closer than ``full_mm`` make a
    whole circle. The radius goes linearly from the start's to the end's, as LinuxCNC's
    ``pmCirclePoint`` takes an arc whose end is off its circle.
    """
    (x, y), (ex, ey), (cx, cy) = start, end, centre
    a0 = math.atan2(y - cy, x - cx)
    sweep = 0.0 if math.dist(start, end) < full_mm else math.atan2(ey - cy, ex - cx) - a0
    if rotation > 0:
        sweep = sweep % (2 * math.pi) or 2 * math.pi
    else:
        sweep = -((-sweep) % (2 * math.pi) or 2 * math.pi)
    r0, r1 = math.hypot(x - cx, y - cy), math.hypot(ex - cx, ey - cy)
    n = max(2, int(abs(sweep) * max(r0, r1) / step_mm))
    out = []
    for t in np.linspace(0.0, 1.0, n + 1)[1:]:
        r = r0 + (r1 - r0) * t
        out.append((cx + r * math.cos(a0 + sweep * t), cy + r * math.sin(a0 + sweep * t)))
    return out


def planned_moves(program_moves: tuple[object, ...]) -> list[tuple[str, tuple[float, ...]]]:
    """The same shape for camtool's planned moves (z None is taken as 0, the start height)."""
    moves: list[tuple[str, tuple[float, ...]]] = []
    z = 0.0
    for m in program_moves:
        if isinstance(m, Rapid | Linear | ArcMove):
            z = m.z if m.z is not None else z
        if isinstance(m, Rapid):
            moves.append(("rapid", (m.x, m.y, z)))
        elif isinstance(m, Linear):
            moves.append(("line", (m.x, m.y, z)))
        elif isinstance(m, ArcMove):
            moves.append(("arc", (m.x, m.y, m.cx, m.cy, -1.0 if m.clockwise else 1.0, z)))
    return moves


@needs_rs274
def test_rs274_rejects_a_wrong_arc_as_linuxcnc_would(tmp_path: Path) -> None:
    # the judge must be able to say no: an arc whose end is off its circle
    bad = tmp_path / "bad.ngc"
    bad.write_text(KNOWN_GOOD.replace("I0 J2", "I9 J2"))
    done = rs274(bad)
    assert done.returncode != 0
    assert "Radius to end of arc differs" in done.stderr


@needs_rs274
@pytest.mark.parametrize("rel", FILES or ["<none>"], ids=case_id)
def test_rs274_accepts_every_linuxcnc_program(rel: str) -> None:
    outcome = outcome_for(rel, "linuxcnc")
    if outcome.final.rc != 0:
        pytest.skip(f"no linuxcnc program to judge (see test_corpus): {outcome.final.error}")
    done = rs274(outcome.final.output)
    errors = [ln for ln in done.stderr.splitlines() if ln.strip() != "executing"]
    assert done.returncode == 0 and not errors, (
        f"rs274 -g {outcome.final.output} (from {outcome.final.command()}): "
        f"exit {done.returncode}: {' / '.join(errors)}"
    )
    assert canon_moves(done.stdout), "rs274 saw no motion in the program"


# First-try linuxcnc programs (lines, arcs, several contours) compared move by move.
COMPARED = [
    "pkg/tango-icon-theme/usr/share/icons/Tango/scalable/places/folder.svg",
    "pkg/tango-icon-theme/usr/share/icons/Tango/scalable/actions/media-seek-forward.svg",
    "pkg/librecad-data/usr/share/librecad/library/elektro/connector-iso/Junction-up2.dxf",
]


@needs_rs274
@pytest.mark.parametrize("rel", COMPARED, ids=case_id)
def test_rs274_moves_equal_the_planned_program(rel: str) -> None:
    if not (CORPUS / rel).exists():
        pytest.skip(f"{rel} is not in this corpus")
    outcome = outcome_for(rel, "linuxcnc")
    assert outcome.final.rc == 0, outcome.problems
    extra = outcome.final.args[6:]  # the remedy flags followed, if any
    assert extra == [] or extra[0] != "-o"
    job = post_file(CORPUS / rel, "linuxcnc", _options(extra))
    done = rs274(outcome.final.output)
    assert done.returncode == 0, done.stderr
    theirs = canon_moves(done.stdout)
    ours = planned_moves(job.program.moves)
    assert [k for k, _ in theirs] == [k for k, _ in ours]
    for i, ((kind, a), (_, b)) in enumerate(zip(theirs, ours, strict=True)):
        assert a == pytest.approx(b, abs=ROUND_MM), f"move {i} ({kind}): rs274 {a} planned {b}"


def _options(extra: list[str]) -> PlanOptions:
    """post_file planning options for the remedy flags a comparison file needed (only --fit)."""
    if not extra:
        return PlanOptions()
    if extra[0] == "--fit" and len(extra) == 3:
        return PlanOptions(fit=(float(extra[1]), float(extra[2])))
    pytest.skip(f"comparison with flags {extra} is not mapped to planning options")


OFFSET = re.compile(r"USE_TOOL_LENGTH_OFFSET\(([^)]*)\)")


def _offsets_and_moves(stdout: str) -> list[str]:
    """rs274's tool length offsets and motion calls, in order, a repeated one once."""
    calls = [
        line.split("N..... ", 1)[-1].strip()
        for line in stdout.splitlines()
        if OFFSET.search(line) or CANON.search(line)
    ]
    return [c for i, c in enumerate(calls) if i == 0 or c != calls[i - 1]]


@needs_rs274
def test_a_re_posted_tool_length_offset_is_the_one_rs274_applies(tmp_path: Path) -> None:
    """G43 H<n> right after T<n> M6 is what the linuxcnc dialect writes: the same offsets.

    A change with no G43 after it (the last, to T1) keeps the offset in force, in rs274 and
    in the program camtool writes (no G43 H1 there either).

    The judge is rs274 with a tool table whose tools have lengths (10, 20 and 30 in the
    table's units): every offset it applies and every move it makes, in order, are those of
    the program camtool reads; also for a G43 with no change and a G49 (written where the
    program had them: dropped, the tool stood a tool length off).
    """
    table = tmp_path / "lengths.tbl"
    table.write_text("".join(f"T{n} P{n} Z{10 * n}.0 D3.175 ;\n" for n in (1, 2, 3)))
    source = tmp_path / "in.ngc"
    source.write_text(
        "G21 G90 G17\nT2 M6\nG43 H2\nG0 X0 Y0 Z5\nG1 Z-1 F100\nG1 X10\nG0 Z5\n"
        "T3 M6\nG43\nG0 X5 Y5\nG1 Z-1\nG0 Z5\nT1 M6\nG0 X7 Y7\nG1 Z-2\nG0 Z5\nM2\n"
    )
    out = tmp_path / "out.ngc"
    assert main(["post", str(source), "-t", "linuxcnc", "-o", str(out)]) == 0
    want, got = rs274(source, table), rs274(out, table)
    assert want.returncode == 0 and got.returncode == 0, got.stderr
    expected = _offsets_and_moves(want.stdout)
    assert sum("USE_TOOL_LENGTH_OFFSET" in c for c in expected) == 2
    # the output's header says G49 first (no offset before the first change)
    zero = "0.0000 0.0000 0.0000"
    none = f"USE_TOOL_LENGTH_OFFSET({zero}, {zero}, {zero})"
    assert _offsets_and_moves(got.stdout) == [none, *expected]
    lone = tmp_path / "lone.ngc"  # LinuxCNC's cds.ngc: G43 H1 with no change, then G49
    lone.write_text("G21 G90 G17\nG0 X0 Y0 Z5\nG43 H1\nG1 Z-1 F100\nG1 X10\nG49\nG0 Z5\nM2\n")
    lone_out = tmp_path / "lone-out.ngc"
    assert main(["post", str(lone), "-t", "linuxcnc", "-o", str(lone_out)]) == 0
    expected = _offsets_and_moves(rs274(lone, table).stdout)
    assert "USE_TOOL_LENGTH_OFFSET(0.0000 0.0000 254.0000" in expected[1]
    assert _offsets_and_moves(rs274(lone_out, table).stdout) == [none, *expected]


@needs_rs274
def test_a_re_posted_work_offset_is_the_one_rs274_selects(tmp_path: Path) -> None:
    """G55 written as the program chose it: rs274 selects offset 2 for both (SET_G5X_OFFSET)."""
    source = tmp_path / "g55.ngc"
    source.write_text("G21 G90 G17 G55\nG0 X0 Y0 Z5\nG1 Z-1 F100\nG1 X10\nG0 Z5\nM2\n")
    out = tmp_path / "out.ngc"
    assert main(["post", str(source), "-t", "linuxcnc", "-o", str(out)]) == 0
    for program in (source, out):
        done = rs274(program)
        assert done.returncode == 0, done.stderr
        assert "SET_G5X_OFFSET(2," in done.stdout, program.name


_CONTROL = re.compile(
    r"(USE_LENGTH_UNITS|SET_MOTION_CONTROL_MODE|SET_NAIVECAM_TOLERANCE|STRAIGHT_FEED)\(([^)]*)\)"
)


def _controls(stdout: str) -> list[tuple[str, str, float | None]]:
    """rs274's path control calls, each with its tolerance in mm, and a mark per feed move."""
    out: list[tuple[str, str, float | None]] = []
    scale = 1.0
    for call, args in _CONTROL.findall(stdout):
        if call == "USE_LENGTH_UNITS":
            scale = 25.4 if "INCHES" in args else 1.0
        elif call == "STRAIGHT_FEED":
            out.append(("feed", "", None))
        else:
            mode, _, tolerance = args.rpartition(", ") if "," in args else ("", "", args)
            value = float(tolerance) * scale if re.fullmatch(r"[\d.]+", tolerance) else None
            out.append((call, mode or (tolerance if value is None else ""), value))
    return out


@needs_rs274
@pytest.mark.parametrize(
    ("modes", "units"),
    [
        (("G64 P0.01 Q0.005", "G61", "G61.1", "G64"), "G21"),
        (("G64 P0.001",), "G20"),  # 0.0254 mm: written 0.025, rounded down, never looser
        (("G64 P0.0004",), "G21"),  # below the 0.001 mm printed: 0.001, never P0 (no limit)
    ],
)
def test_a_re_posted_path_control_mode_is_the_one_rs274_sets(
    tmp_path: Path, modes: tuple[str, ...], units: str
) -> None:
    """F-Engrave writes G64 P0.001 for its engraving; LinuxCNC run without it blends
    corners by its own default. The judge is rs274: its path control calls, in order with
    the moves, for the program camtool writes are the input's (G61 exact path, G61.1 exact
    stop, G64 with its P and Q in mm): tolerances as written, rounded down to the 3
    decimals printed but a positive one never to 0, which rs274 shows is no limit at all
    (``G64 P0`` and ``G64`` both set CANON_CONTINUOUS, 0)."""
    source = tmp_path / "in.ngc"
    cuts = "".join(f"{m}\nG1 X{k + 1} F10\n" for k, m in enumerate(modes))
    source.write_text(f"{units} G90 G17\nG0 X0 Y0 Z1\nG1 Z0 F10\n{cuts}M2\n")
    out = tmp_path / "out.ngc"
    assert main(["post", str(source), "-t", "linuxcnc", "-o", str(out)]) == 0
    want, got = rs274(source), rs274(out)
    assert want.returncode == 0 and got.returncode == 0, got.stderr
    expected, written = _controls(want.stdout), _controls(got.stdout)
    assert [(c, m) for c, m, _ in written] == [(c, m) for c, m, _ in expected]
    for (_, _, asked), (_, _, put) in zip(expected, written, strict=True):
        if asked is None:
            assert put is None
        elif asked == 0:
            assert put == 0  # G64 alone: no limit, as asked
        else:
            assert 0 < put <= max(asked, 0.001) + 1e-9 and put > asked - 0.001
    assert any(c == "SET_MOTION_CONTROL_MODE" for c, _, _ in written)


def test_path_controls_are_the_rs274_codes_for_a_dialect_read_back_by_rs274() -> None:
    from camtool.model.errors import InputError
    from camtool.post.wordaddress_spec import load_spec

    ok = {"words": {"XYZ": {}}, "rs274": True, "path_controls": ["G61", "G64"]}
    assert load_spec(ok, "m.toml").path_controls == ("G61", "G64")
    with pytest.raises(InputError, match=r"a path control code is G61, G61\.1 or G64, got G65"):
        load_spec({**ok, "path_controls": ["G65"]}, "m.toml")
    with pytest.raises(InputError, match="path control modes need rs274 = true"):
        load_spec({**ok, "rs274": False}, "m.toml")


def test_a_negative_blending_tolerance_is_refused_at_its_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """LinuxCNC refuses ``G64 P-1``; camtool too, naming the line, writing nothing."""
    source = tmp_path / "in.ngc"
    source.write_text("G21 G90\nG0 X0 Y0\nG64 P-1\nG1 X1 F10\nM2\n")
    out = tmp_path / "out.ngc"
    assert main(["post", str(source), "-t", "linuxcnc", "-o", str(out)]) == 3
    assert "in.ngc:3: G64 P-1: a blending tolerance is ≥ 0" in capsys.readouterr().err
    assert not out.exists()


def test_a_target_without_path_controls_reads_them_as_before(tmp_path: Path) -> None:
    """GRBL has no G64: the mode is ignored with the warning it always had, nothing written."""
    source = tmp_path / "in.ngc"
    source.write_text("G21 G90\nG64 P0.01\nG0 X0 Y0\nG1 X1 F10\nM2\n")
    out = tmp_path / "out.gcode"
    assert main(["post", str(source), "-t", "grbl", "-o", str(out)]) == 0
    assert "G64" not in out.read_text()


@needs_rs274
def test_the_arcs_camtool_reads_are_the_ones_rs274_runs(tmp_path: Path) -> None:
    """The judge of tests/importers/test_gcode.py's arcs at LinuxCNC's tolerances."""
    from tests.importers.test_gcode import ARC_ENDS, arc_program

    for units, arc, runs in ARC_ENDS:
        path = tmp_path / "a.ngc"
        path.write_text(arc_program(units, arc) + "M2\n")
        done = rs274(path)
        assert ("PROGRAM_END" in done.stdout) == runs, (units, arc, done.stderr[-300:])


@needs_rs274
def test_rs274_runs_dxf2gcodes_spiral_arcs_and_camtools_re_post_of_them(tmp_path: Path) -> None:
    """tests/data/dxf2gcode-spiral-arcs.ngc: arcs up to 0.0265 mm off their circles."""
    source = Path(__file__).resolve().parents[1] / "data" / "dxf2gcode-spiral-arcs.ngc"
    assert "PROGRAM_END" in rs274(source).stdout
    out = tmp_path / "re.ngc"
    assert main(["post", str(source), "-t", "linuxcnc", "-o", str(out)]) == 0
    done = rs274(out)
    assert done.returncode == 0 and "PROGRAM_END" in done.stdout, done.stderr[-300:]


@needs_rs274
def test_rs274_refuses_the_comments_inside_words_that_camtool_refuses(tmp_path: Path) -> None:
    """The judge of tests/importers/test_gcode_comment_in_word.py's lines."""
    from tests.importers.test_gcode_comment_in_word import READ, REFUSED, program

    for words in [*REFUSED, *READ]:
        path = tmp_path / "w.ngc"
        path.write_text(program(words))
        done = rs274(path)
        assert ("PROGRAM_END" in done.stdout) == (words in READ), words


@needs_rs274
def test_the_cancels_of_refused_modes_post_as_no_ops(tmp_path: Path) -> None:
    """G15, G69 and G50.1 in a Fanuc-style header and footer: no move changes.

    Fusion 360's Fanuc post heads a program ``G90 G94 G17 G49 G40 G80`` / ``G69``; Fanuc
    cancels polar coordinates (G15) and mirror image (G50.1) the same way. The judge is
    rs274 on the same program without them (LinuxCNC knows none of the three): the moves of
    camtool's linuxcnc program are its moves, and rs274 accepts that program.
    """
    body = "G0 X0 Y0 Z5\nG1 Z-1 F100\nG1 X10\nG3 X20 Y0 I5 J0\nG0 Z5\n"
    source = tmp_path / "fanuc.nc"
    source.write_text(
        f"%\nO1001\nG90 G94 G17 G49 G40 G80\nG21\nG69 G15\nG50.1\n{body}G15\nM30\n%\n"
    )
    plain = tmp_path / "plain.ngc"
    plain.write_text(f"%\nG90 G94 G17 G49 G40 G80\nG21\n{body}M30\n%\n")
    out = tmp_path / "out.ngc"
    assert main(["post", str(source), "-t", "linuxcnc", "-o", str(out)]) == 0
    want, got = rs274(plain), rs274(out)
    assert want.returncode == 0 and got.returncode == 0, got.stderr
    expected = canon_moves(want.stdout)
    assert [k for k, _ in expected] == ["rapid", "line", "line", "arc", "rapid"]
    # a move to where the tool already is changes nothing (camtool's header rapids to the
    # safe height first, then in X and Y: here both at X0 Y0 Z5)
    written = canon_moves(got.stdout)
    moves = [m for i, m in enumerate(written) if i == 0 or m != written[i - 1]]
    assert len(moves) == len(expected)
    for (kind, a), (other, b) in zip(moves, expected, strict=True):
        assert kind == other and a == pytest.approx(b, abs=ROUND_MM)


@needs_rs274
def test_numbered_parameters_are_read_as_rs274_reads_them(tmp_path: Path) -> None:
    """tests/importers/test_gcode_params.py's programs, a gEDA PCB export in inches, one
    that sets parameters on a line that reads them and a pen plotter's of named ones: rs274
    cuts the original and camtool's linuxcnc re-post along the same moves, within the
    3-decimal rounding."""
    from tests.importers.test_gcode_params import GEDA, PARALLEL, PLOTTER

    for name, text in (("geda", GEDA), ("wizard", PARALLEL), ("plotter", PLOTTER)):
        source = tmp_path / f"{name}.ngc"
        source.write_text(text)
        out = tmp_path / f"{name}-out.ngc"
        assert main(["post", str(source), "-t", "linuxcnc", "-o", str(out)]) == 0
        want, got = rs274(source), rs274(out)
        assert want.returncode == 0 and got.returncode == 0, got.stderr[-300:]
        scale = 25.4 if "CANON_UNITS_INCHES" in want.stdout else 1.0
        cuts = [tuple(scale * v for v in xyz) for k, xyz in canon_moves(want.stdout) if k == "line"]
        again = [xyz for kind, xyz in canon_moves(got.stdout) if kind == "line"]
        printed = 0.00005 * scale  # rs274 prints 4 decimals of the program's unit
        assert len(cuts) == len(again) >= 2
        for a, b in zip(cuts, again, strict=True):
            assert a == pytest.approx(b, abs=ROUND_MM + printed), name


@needs_rs274
@pytest.mark.parametrize(
    ("line", "outcome"),
    [
        ("G1 X#1.5 Y0", "refused"),  # the parameter #1.5: no such number
        ("G1 X#1 .5 Y0", "refused"),  # spaces do not count: #1.5 again
        ("G1 X1#1 Y0", "refused"),  # a '#' after a number starts a setting
        ("G1 X#1#1 Y0", "refused"),
        ("#2=5.5.5 G1 X#2 Y0", "refused"),
        ("G1 X#1.0 Y0", "moved"),  # #1
        ("G1 X#01 Y0", "moved"),  # #1
        ("G1 X - #1 Y0", "moved"),  # -5
        ("G1 X#1 2 Y0", "unset"),  # #12, which nothing set: LinuxCNC reads 0, camtool refuses
        ("G1 X#<a>5 Y0", "refused"),  # "Bad character '5'"
        ("G1 X#<a> .5 Y0", "refused"),
        ("G1 X#<b> Y0", "refused"),  # "Named parameter #<b> not defined"
        ("G1 X - #< A > Y0", "moved"),  # -5: spaces and case do not count
        ("G1 X#<a>Y#1", "moved"),
        ("#<a>=7 G1 X#<a> Y0", "moved"),  # 5: read before the line sets 7
        ("G1 X#<_x> Y0", "unset"),  # the position: LinuxCNC's own, camtool refuses
        ("#<_x>=1 G1 X1 Y0", "refused"),  # "Cannot assign to read-only parameter"
    ],
)
def test_a_parameter_read_never_gives_a_move_rs274_does_not_make(
    tmp_path: Path, line: str, outcome: str
) -> None:
    """Where LinuxCNC refuses a line, camtool refuses it; where LinuxCNC moves, camtool writes
    the same move, or refuses a parameter read before any line sets it; never another move."""
    source = tmp_path / "p.ngc"
    source.write_text(f"G21 G90\n#1=5\n#<a>=5\nG0 X0 Y0 Z1\nG1 Z0 F100\n{line} F100\nM2\n")
    out = tmp_path / "out.ngc"
    want = rs274(source)
    assert (want.returncode != 0) == (outcome == "refused"), want.stderr[-200:]
    code = main(["post", str(source), "-t", "linuxcnc", "-o", str(out)])
    if outcome != "moved":
        assert code != 0 and not out.exists()
        return
    assert code == 0
    got = rs274(out)
    lines = [xyz for kind, xyz in canon_moves(want.stdout) if kind == "line"]
    again = [xyz for kind, xyz in canon_moves(got.stdout) if kind == "line"]
    assert again[-1] == pytest.approx(lines[-1], abs=ROUND_MM)
