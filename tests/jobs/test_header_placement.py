"""The header records how the drawing was placed; ``verify --against`` places it again.

Expected values from analysis: samples/plate.dxf is 40 × 30 mm from (0, 0), so
``--fit 50 50`` scales it by min(50/40, 50/30) = 1.25 about its lower-left corner, and
``--origin center`` then puts the toolpath's centre (the drawing's centre, grown by the
1.5 mm tool radius on every side) at X0 Y0: a shift of −(1.25 · 20, 1.25 · 15).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from camtool.jobs.header import read_placement, read_tool_diameter
from camtool.model.version import __version__

ROOT = Path(__file__).resolve().parents[2]
PLATE = str(ROOT / "samples" / "plate.dxf")
OPTIONS = ["--offset", "outside", "--tool-diameter", "3", "--depth", "1"]


def test_the_header_says_how_the_drawing_was_scaled_and_moved(run: Any, tmp_path: Path) -> None:
    out = tmp_path / "plate.ngc"
    placing = ["--fit", "50", "50", "--origin", "center"]
    code, err = run("post", PLATE, "-t", "grbl", *OPTIONS, *placing, "-o", str(out))
    assert code == 0, err
    text = out.read_text()
    assert "(--fit 50 x 50 mm: the drawing at 125 % of its size)" in text
    k, dx, dy = read_placement(text) or (0.0, 0.0, 0.0)
    assert k == pytest.approx(1.25)
    assert (dx, dy) == pytest.approx((-25.0, -18.75))
    assert read_tool_diameter(text) == 3.0


def test_verify_against_places_the_drawing_as_posted(run: Any, tmp_path: Path) -> None:
    out, report = tmp_path / "plate.ngc", tmp_path / "report.json"
    placing = ["--fit", "50", "50", "--origin", "center"]
    code, err = run("post", PLATE, "-t", "grbl", *OPTIONS, *placing, "-o", str(out))
    assert code == 0, err
    code, err = run("verify", str(out), "-t", "grbl", "--against", PLATE, "--report", str(report))
    assert code == 0, err
    assert "placed as the program's header says (scale 1.25" in err
    against = json.loads(report.read_text())["against"]
    # before: compared where it was drawn, 1500 µm of "overcut"; now the tool's own few µm
    assert against["overcut_um"] < 20.0


def test_a_comment_of_another_tool_is_not_read() -> None:
    foreign = "(placement: scale 2, shift X5 Y5 mm)\nG0 X1 Y1\n"
    assert read_placement(foreign) is None


PART, PART_JOB = str(ROOT / "samples" / "part.dxf"), str(ROOT / "samples" / "part.toml")


def test_verify_against_does_not_compare_a_jobs_program(run: Any, tmp_path: Path) -> None:
    # samples/part.toml drills with a 3.2 mm drill and cuts the pocket and outline with a
    # 3 mm end mill; its CENTER lines are cut by no operation. The program records none of
    # that, so its distance to the whole drawing would be read as machining error: the
    # drawing is not compared, the report says why, and a limit cannot pass unjudged.
    out, report = tmp_path / "part.ngc", tmp_path / "report.json"
    code, err = run("post", PART, "-t", "linuxcnc", "--job", PART_JOB, "-o", str(out))
    assert code == 0, err
    args = ["verify", str(out), "-t", "linuxcnc", "--against", PART, "--report", str(report)]
    code, err = run(*args)
    assert code == 0, err
    assert "the program is the job part.toml (4 operations)" in err
    assert "--job part.toml --verify" in err
    data = json.loads(report.read_text())
    assert data["against"] is None
    assert "the program is the job part.toml" in data["against_skipped"]
    code, err = run(*args, "--max-error-um", "1000")
    assert code == 4, err
    assert "--max-error-um 1000 cannot be judged" in err


def test_the_job_a_header_names_is_read_from_camtools_header_only(run: Any, tmp_path: Path) -> None:
    from camtool.jobs.header import read_job

    out = tmp_path / "part.ngc"
    code, err = run("post", PART, "-t", "linuxcnc", "--job", PART_JOB, "-o", str(out))
    assert code == 0, err
    assert read_job(out.read_text()) == ("part.toml", 4)
    plain = tmp_path / "plate.nc"
    code, err = run("post", PLATE, "-t", "grbl", *OPTIONS, "-o", str(plain))
    assert code == 0, err
    assert read_job(plain.read_text()) is None
    assert read_job("(job part.toml: 4 operations)\nG0 X1 Y1\n") is None  # another tool's


def test_verify_against_leaves_out_the_construction_post_did_not_cut(
    run: Any, tmp_path: Path
) -> None:
    # samples/part.dxf cut on its lines: post cuts every contour but the ten CENTER lines
    # (construction), which verify leaves out too: a hole's centre line lies 12.5 mm from
    # the nearest cut and would count as 12 500 µm of error. From analysis the cut follows
    # the drawing, so only the dialect's rounding and the machine's steps are left, a few µm.
    out, report = tmp_path / "part.ngc", tmp_path / "report.json"
    code, err = run("post", PART, "-t", "linuxcnc", "-o", str(out))
    assert code == 0, err
    code, err = run(
        "verify", str(out), "-t", "linuxcnc", "--against", PART, "--report", str(report)
    )
    assert code == 0, err
    assert "10 contour(s) of the drawing not compared" in err and "(construction)" in err
    assert json.loads(report.read_text())["against"]["max_um"] < 20.0


def test_verify_against_compares_the_layers_post_cut(run: Any, tmp_path: Path) -> None:
    # post --layers OUTLINE cuts the 80 × 60 mm outline alone; the header records it, and
    # verify --against compares that layer alone (the holes and the pocket, 25 mm away,
    # would count as 25 000 µm of error). Another drawing without that layer is refused.
    out, report = tmp_path / "outline.ngc", tmp_path / "report.json"
    code, err = run("post", PART, "-t", "linuxcnc", "--layers", "OUTLINE", *OPTIONS, "-o", str(out))
    assert code == 0, err
    from camtool.jobs.header import read_layers

    assert read_layers(out.read_text()) == ("OUTLINE",)
    code, err = run(
        "verify", str(out), "-t", "linuxcnc", "--against", PART, "--report", str(report)
    )
    assert code == 0, err
    assert "not on its layers OUTLINE" in err
    assert json.loads(report.read_text())["against"]["max_um"] < 20.0
    code, err = run("verify", str(out), "-t", "linuxcnc", "--against", PLATE)
    assert code == 2, err
    assert "the drawing has no layer 'OUTLINE'" in err
    assert read_layers("(layers: OUTLINE)\nG0 X1 Y1\n") is None  # another tool's comment


def test_layers_the_comments_could_not_hold_whole_are_still_found(run: Any, tmp_path: Path) -> None:
    # Six 10 mm squares, each on its layer; post --layers names five: one with non-ASCII
    # letters and parentheses (a comment holds them as '?' and brackets), four long ones
    # (GRBL's 80-byte line cuts the header's list short with '...'). verify --against
    # finds the five from what the header holds, and leaves out the sixth alone.
    import ezdxf

    names = ["Kontur-Äußen (1)", *(f"very-long-layer-name-number-{k:02d}" for k in range(4))]
    doc = ezdxf.new(units=4)
    for k, name in enumerate([*names, "other"]):
        doc.layers.add(name)
        x = 12.0 * k
        square = [(x, 0.0), (x + 10.0, 0.0), (x + 10.0, 10.0), (x, 10.0)]
        doc.modelspace().add_lwpolyline(square, close=True, dxfattribs={"layer": name})
    drawing, out = tmp_path / "layers.dxf", tmp_path / "layers.nc"
    doc.saveas(drawing)
    code, err = run("post", str(drawing), "-t", "grbl", "--layers", ",".join(names), "-o", str(out))
    assert code == 0, err
    assert "(layers: Kontur-?u?en [1], very-long-layer-name-number-00, " in out.read_text()
    assert "...)" in out.read_text()
    code, err = run("verify", str(out), "-t", "grbl", "--against", str(drawing))
    assert code == 0, err
    assert "1 contour(s) of the drawing not compared" in err
    assert "against the drawing: max 0.00 µm" in err


def test_a_reposted_program_keeps_what_its_header_says_of_the_cut(run: Any, tmp_path: Path) -> None:
    # post --layers OUTLINE --offset outside (the 80 × 60 mm outline alone, with a 3 mm
    # tool), re-posted for LinuxCNC, then that for GRBL: re-posting moves nothing, so the
    # header's tool, offset and layers still hold, and verify --against compares the
    # re-post as it compares the program it came from. Without them the whole drawing would
    # be compared at the tool centre: the holes 25 mm in, and the tool's radius, as error.
    first, again, third = tmp_path / "o.nc", tmp_path / "o.ngc", tmp_path / "o2.nc"
    report = tmp_path / "report.json"
    code, err = run("post", PART, "-t", "grbl", "--layers", "OUTLINE", *OPTIONS, "-o", str(first))
    assert code == 0, err
    code, err = run("post", str(first), "-t", "linuxcnc", "-o", str(again))
    assert code == 0, err
    code, err = run("post", str(again), "-t", "grbl", "-o", str(third))
    assert code == 0, err
    lines = third.read_text().splitlines()
    assert lines[:4] == [
        f"(camtool {__version__}: o.ngc for grbl)",
        "(re-posted program: moves as the input gives them)",
        f"(its header: camtool {__version__}: part.dxf for grbl)",
        "(tool diameter 3 mm, offset outside)",
    ]
    assert "(layers: OUTLINE)" in lines and lines.count("(depth 1 mm)") == 1
    for program, target in ((again, "linuxcnc"), (third, "grbl")):
        args = ["verify", str(program), "-t", target, "--against", PART]
        code, err = run(*args, "--report", str(report))
        assert code == 0, err
        assert "not on its layers OUTLINE" in err and "tool diameter 3 mm" in err
        assert json.loads(report.read_text())["against"]["max_um"] < 20.0


def test_only_camtools_own_header_is_carried() -> None:
    from camtool.jobs.header import carried_notes

    mine = "\ufeff%\n(camtool 0.1.0: a.dxf for grbl)\n\n(depth 1 mm)\nG0 X1 Y1\n(later)\n"
    assert carried_notes(mine) == ("its header: camtool 0.1.0: a.dxf for grbl", "depth 1 mm")
    semicolons = "; camtool 0.1.0: a.dxf for x\n; depth 1 mm\nG0 X1\n"
    assert carried_notes(semicolons) == ("its header: camtool 0.1.0: a.dxf for x", "depth 1 mm")
    # another tool's header, or camtool's name further down, is not camtool's header
    assert carried_notes("(Fusion 360 post)\n(camtool 0.1.0: a.dxf for grbl)\nG0 X1\n") == ()
    assert carried_notes("(tool diameter 3 mm, offset outside)\nG0 X1\n") == ()


def test_verify_against_closes_the_gaps_post_closed(run: Any, tmp_path: Path) -> None:
    # A 40 × 30 mm outline drawn open (its ends 0.3 mm apart) and a closed 20 × 20 mm
    # square. post --close-gap 0.5 closes the outline and cuts it outside; the header
    # records that, so verify --against compares the outline too instead of leaving it
    # out as an open contour no side cuts. Against the same drawing with the outline
    # 0.2 mm wider the program is then seen to cut 0.2 mm into the part: 200 µm of
    # overcut from analysis (left out, only the square would be measured, a few µm).
    import ezdxf

    def drawing(width: float) -> Path:
        doc = ezdxf.new(units=4)
        outline = [(0, 0), (width, 0), (width, 30), (0, 30), (0, 0.3)]
        doc.modelspace().add_lwpolyline(outline)
        doc.modelspace().add_lwpolyline([(60, 0), (80, 0), (80, 20), (60, 20)], close=True)
        path = tmp_path / f"gap-{width:g}.dxf"
        doc.saveas(path)
        return path

    out, report = tmp_path / "gap.nc", tmp_path / "r.json"
    posting = ["--offset", "outside", "--tool-diameter", "3", "--close-gap", "0.5"]
    code, err = run("post", str(drawing(40)), "-t", "grbl", *posting, "-o", str(out))
    assert code == 0, err
    from camtool.jobs.header import read_chaining

    assert read_chaining(out.read_text()) == (0.01, 0.5)
    # from analysis: the drawing it was posted from is overcut only by the dialect's
    # rounding (0.5 µm) and GRBL's steps and interpolation (4 µm steps), under 20 µm; the
    # drawing 0.2 mm wider by 200 µm and that same error
    for width, overcut in ((40, 0.0), (40.2, 200.0)):
        args = ["verify", str(out), "-t", "grbl", "--against", str(drawing(width))]
        code, err = run(*args, "--report", str(report))
        assert code == 0, err
        assert "not compared" not in err
        got = json.loads(report.read_text())["against"]["overcut_um"]
        assert overcut <= got + 20.0 and got < overcut + 20.0
    assert read_chaining("(chaining: ends within 0.1 mm joined, gaps up to 1 mm closed)") is None


@pytest.mark.parametrize(
    "line",
    [
        "(placement: scale 1e300, shift X0 Y0 mm)",
        "(placement: scale 1, shift X1e300 Y0 mm)",
        "(placement: scale nan, shift X0 Y0 mm)",
        "(placement: scale 1e-7, shift X0 Y0 mm)",
        "(tool diameter 1e300 mm, offset outside)",
        "(tool diameter 0.0000001 mm, offset outside)",
        "(chaining: ends within 0.01 mm joined, gaps up to 1e300 mm closed)",
        "(chaining: ends within inf mm joined, gaps up to 0.5 mm closed)",
    ],
)
def test_a_header_value_post_never_writes_is_not_read(line: str) -> None:
    # An edited or damaged header: a value beyond the range of post's own option (its
    # --scale, --tool-diameter, --close-gap checks) is read as no such line, so that
    # verify --against neither places the drawing 1e300 mm away nor refuses an option
    # the user never gave.
    from camtool.jobs.header import read_chaining, read_offset

    code = f"(camtool 0.1.0: a.dxf for grbl)\n{line}\nG0 X1 Y1\n"
    assert (read_placement(code), read_offset(code), read_chaining(code)) == (None, None, None)
    sane = code.replace("1e300", "2").replace("nan", "1").replace("inf", "0.1")
    sane = sane.replace("1e-7", "0.5").replace("0.0000001", "3")
    assert (read_placement(sane), read_offset(sane), read_chaining(sane)).count(None) == 2


def test_a_header_cut_short_at_the_line_limit_is_still_camtools(run: Any, tmp_path: Path) -> None:
    # A drawing named for a customer's order: GRBL's 80-byte line cuts camtool's first
    # line short ("...)", the target lost), and the header was then not read at all:
    # verify --against compared the plate where it was drawn and at the tool centre, the
    # 1.5 mm shift and the tool's 1.5 mm radius read as 9 060 µm. Read, the drawing is
    # placed and the tool's edge follows it within the dialect's rounding and the
    # machine's steps: a few µm of overcut, from analysis.
    name = "a-very-long-drawing-file-name-from-a-customer-order-number-12345-rev-C.dxf"
    drawing, out, report = tmp_path / name, tmp_path / "long.nc", tmp_path / "r.json"
    drawing.write_bytes(Path(PLATE).read_bytes())
    placing = ["--origin", "lower-left"]
    code, err = run("post", str(drawing), "-t", "grbl", *OPTIONS, *placing, "-o", str(out))
    assert code == 0, err
    first = out.read_text().splitlines()[0]
    assert first.endswith("...)") and " for grbl" not in first
    assert read_placement(out.read_text()) == (1.0, 1.5, 1.5)
    code, err = run(
        "verify", str(out), "-t", "grbl", "--against", str(drawing), "--report", str(report)
    )
    assert code == 0, err
    assert "placed as the program's header says" in err and "tool diameter 3 mm" in err
    assert json.loads(report.read_text())["against"]["overcut_um"] < 20.0


def test_a_program_read_from_a_pipe_is_read_once(tmp_path: Path) -> None:
    # A named pipe (mkfifo part.nc, a shell's process substitution) can be read once: the
    # header for the re-post's notes comes from a second look at a regular file only.
    # Looking again at the pipe would wait for a writer that never comes: the post would
    # hang, and the timeout (a bound on a hang, not on speed) fails the test.
    import os
    import subprocess
    import sys
    import threading

    program = tmp_path / "p.nc"
    code = "(camtool 0.1.0: a.dxf for grbl)\nG21 G90\nG0 X0 Y0 Z5\nG1 Z-1 F100\nG1 X10\nG0 Z5\nM2\n"
    pipe, out = tmp_path / "pipe.nc", tmp_path / "o.ngc"
    program.write_text(code)
    os.mkfifo(pipe)
    writer = threading.Thread(target=lambda: pipe.write_bytes(program.read_bytes()))
    writer.start()
    args = [sys.executable, "-m", "camtool", "post", str(pipe), "-t", "linuxcnc", "-o", str(out)]
    try:
        done = subprocess.run(args, capture_output=True, text=True, timeout=600, cwd=ROOT)
    finally:
        if writer.is_alive():  # the post never opened the pipe: let the writer finish
            with open(pipe, "rb") as drain:
                drain.read()
        writer.join()
    assert done.returncode == 0, done.stderr
    assert "G1 X10.000" in out.read_text()
