"""Programs per tool on a machine that cannot change tools: a tool that comes back, and the
spindle and height a program starts with.

Each program per tool runs alone, after the one before ended (``M2``: GRBL and LinuxCNC stop
the spindle and coolant there) and after the operator set Z zero for the new tool on the
stock's top. So each must start the spindle the input had running at its change, rise to
the height the input's tool was at before it moves sideways, and have a file of its own.
"""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path

from camtool.cli.main import main

ROOT = Path(__file__).resolve().parents[2]

JOB = """[job]
sequence = "file"
[[tools]]
id = 1
diameter = 3.0
[[tools]]
id = 2
type = "drill"
diameter = 3.2
[[operations]]
type = "pocket"
tool = 1
layers = ["POCKET"]
depth = 1
[[operations]]
type = "drill"
tool = 2
layers = ["HOLES"]
depth = 3
[[operations]]
type = "profile"
side = "outside"
tool = 1
layers = ["OUTLINE"]
depth = 3
"""
"""The sample plate cut in the file's order: T1's pocket, T2's holes, T1's outline."""

IDLE_THEN_CUTS = (
    "G21 G90\nT1 M6\nM3 S1000\nG0 Z5\nT2 M6\nG0 Z5\nG0 X0 Y0\nG1 Z-1 F100\nG1 X10 F300\n"
    "G0 Z5\nT3 M6\nG0 Z5\nG0 X20 Y0\nG1 Z-1 F100\nG1 X30 F300\nG0 Z5\nM5\nM2\n"
)
"""T1 loaded and the spindle started, then T2 at once (T1 cuts nothing), T2 cuts, T3 cuts:
the spindle runs from its M3 to the M5 at the end, through both changes."""


def _run(*args: str) -> tuple[int, str]:
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        code = main(list(args))
    return code, err.getvalue()


def _post_program(tmp_path: Path, name: str, text: str) -> Path:
    """Post the G-code ``text`` (as ``name``) to grbl, ``-o out/p.nc``; the folder ``out``."""
    source = tmp_path / name
    source.write_text(text)
    out = tmp_path / "out"
    out.mkdir()
    code, err = _run("post", str(source), "-t", "grbl", "-o", str(out / "p.nc"))
    assert code == 0, err
    return out


def _programs(folder: Path) -> dict[str, list[str]]:
    return {p.name: p.read_text().splitlines() for p in sorted(folder.iterdir())}


def _runs_pocket(lines: list[str]) -> bool:
    return any("1. pocket T1" in ln for ln in lines)


def test_a_tool_that_comes_back_gets_a_program_of_its_own_numbered_in_the_run(
    tmp_path: Path,
) -> None:
    job = tmp_path / "j.toml"
    job.write_text(JOB, encoding="utf-8")
    out = tmp_path / "post"
    out.mkdir()
    code, err = _run("post", str(ROOT / "samples/part.dxf"), "-t", "grbl", "--job", str(job),
                     "-o", str(out / "p.nc"))  # fmt: skip
    assert code == 0, err
    written = _programs(out)
    assert list(written) == ["p.1.T1.nc", "p.2.T2.nc", "p.3.T1.nc"]
    for k, (name, lines) in enumerate(written.items(), 1):
        assert any(ln.startswith(f"(program {k} of 3: load T{name[-4]}") for ln in lines)
    assert f"run {out / 'p.1.T1.nc'} (T1), then {out / 'p.2.T2.nc'} (T2), then" in err


def test_a_batch_writes_the_first_program_of_a_tool_that_comes_back_too(tmp_path: Path) -> None:
    """Both T1 programs would share ``part.T1.gcode``, the outline's in place of the
    pocket's: each is written, the pocket's first."""
    job = tmp_path / "j.toml"
    job.write_text(JOB, encoding="utf-8")
    code, err = _run("batch", str(ROOT / "samples/part.dxf"), "-t", "grbl", "--job", str(job),
                     "-o", str(tmp_path / "out"))  # fmt: skip
    assert code == 0, err
    written = _programs(tmp_path / "out")
    assert list(written) == ["part.1.T1.gcode", "part.2.T2.gcode", "part.3.T1.gcode"]
    assert _runs_pocket(written["part.1.T1.gcode"])
    assert any(ln.startswith("(program 1 of 3: load T1") for ln in written["part.1.T1.gcode"])
    assert any(ln.startswith("(program 3 of 3: load T1") for ln in written["part.3.T1.gcode"])


def test_each_program_starts_the_spindle_the_input_had_running_at_its_change(
    tmp_path: Path,
) -> None:
    """The M3 after the idle T1 belongs to no program of its own: T2's and T3's start it."""
    out = _post_program(tmp_path, "idle.ngc", IDLE_THEN_CUTS)
    written = _programs(out)
    assert list(written) == ["p.T2.nc", "p.T3.nc"]
    for lines in written.values():
        blocks = [ln for ln in lines if not ln.startswith("(")]
        first_cut = next(i for i, ln in enumerate(blocks) if ln.startswith("G1"))
        assert "M3 S1000" in blocks[:first_cut]
        # no move sideways before the rise to Z5, where the input's tool was
        rise = blocks.index("G0 Z5.000")
        assert not any(ln.startswith(("G0 X", "G1 X")) for ln in blocks[:rise])


def test_a_program_that_starts_its_own_spindle_gets_no_second_start(tmp_path: Path) -> None:
    out = _post_program(tmp_path, "own.ngc", IDLE_THEN_CUTS.replace("T3 M6\n", "T3 M6\nM3 S2000\n"))
    blocks = [ln for ln in (out / "p.T3.nc").read_text().splitlines() if not ln.startswith("(")]
    assert [ln for ln in blocks if ln.startswith("M3")] == ["M3 S2000"]


def test_one_tool_changed_to_twice_is_one_program_where_asked(tmp_path: Path) -> None:
    """``T1 M6`` written twice (the first changes to a tool that cuts nothing): one tool
    cuts, loaded before any cut, so its program is ``-o``'s, as for a single change."""
    out = _post_program(
        tmp_path,
        "twice.ngc",
        "G21 G90\nT1 M6\nG0 Z5\nT1 M6\nM3 S1000\nG0 X0 Y0\nG1 Z-1 F100\nG1 X10 F300\n"
        "G0 Z5\nM5\nM2\n",
    )
    assert [p.name for p in out.iterdir()] == ["p.nc"]
    blocks = (out / "p.nc").read_text().splitlines()
    assert "G1 X10.000 Y0.000 F300" in blocks and "M3 S1000" in blocks
    assert "load T1 before running: grbl cannot change tools" in " ".join(blocks)


FUSION_STYLE = """%
(T1  D=3.175 - flat end mill)
(T2  D=2. - drill)
G90 G94
G17
G21
T1 M6
S10000 M3
G55
G0 X10. Y10.
G0 Z15.
G1 Z-3. F300.
G1 X40. F1000.
G0 Z15.
M5
T2 M6
S5000 M3
G0 X25. Y20.
G0 Z5.
G1 Z-4. F200.
G0 Z15.
M5
M30
%
"""
"""Two tools in work offset G55, each change followed by its spindle start and then a move
sideways before any Z, as a CAM post for a tool changer writes them."""


def test_the_second_program_keeps_the_work_offset_and_rises_before_it_moves(
    tmp_path: Path,
) -> None:
    """``M2`` at the end of T1's program selects G54 again (GRBL, LinuxCNC): T2's program
    without G55 would drill 25, 20 from another zero. It selects G55 before any move,
    rises to Z15 (where the input's tool was at the change), then goes to the hole."""
    out = _post_program(tmp_path, "two.nc", FUSION_STYLE)
    blocks = [ln for ln in (out / "p.T2.nc").read_text().splitlines() if not ln.startswith("(")]
    moves = [i for i, ln in enumerate(blocks) if ln.startswith(("G0", "G1"))]
    assert blocks.index("G55") < moves[0]
    assert blocks[moves[0]] == "G0 Z15.000"
    assert blocks[moves[1]] == "G0 X25.000 Y20.000"
    assert "M3 S5000" in blocks[: moves[1]]


def test_a_second_batch_keeps_the_programs_per_tool_of_the_first_without_force(
    tmp_path: Path,
) -> None:
    """A re-posted program's programs per tool are known only once it is read: a second
    batch finds them all the same, and overwrites them only with ``--force``."""
    source = tmp_path / "in" / "two.nc"
    source.parent.mkdir()
    source.write_text(FUSION_STYLE)
    out = tmp_path / "out"
    code, err = _run("batch", str(source), "-t", "grbl", "-o", str(out))
    assert code == 0, err
    assert sorted(p.name for p in out.iterdir()) == ["two.T1.gcode", "two.T2.gcode"]
    (out / "two.T1.gcode").write_text("kept\n")
    code, err = _run("batch", str(source), "-t", "grbl", "-o", str(out))
    assert code == 2
    assert "2 output(s) exist already" in err and "two.T1.gcode" in err
    assert (out / "two.T1.gcode").read_text() == "kept\n"
    (out / "two.T7.gcode").write_text("another job's\n")  # a tool this program has not
    report = tmp_path / "batch.json"
    code, err = _run(
        "batch", str(source), "-t", "grbl", "-o", str(out), "--force", "--report", str(report)
    )
    assert code == 0, err
    assert (out / "two.T1.gcode").read_text() != "kept\n"
    # --force overwrites what the batch writes; the program of T7 it names, and keeps
    assert (out / "two.T7.gcode").read_text() == "another job's\n"
    (row,) = json.loads(report.read_text())["files"]
    assert f"{out / 'two.T7.gcode'}: a program per tool from an earlier run" in row["warnings"][-1]
