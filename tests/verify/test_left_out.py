"""Open contours an offset cut leaves out are not compared with what it cut.

A disc of radius 10 mm with its two diameter lines and an open two-line construction
line beside it: ``--offset outside`` cuts only the disc (the lines are ``open-left-out``
findings). Before, the comparison measured the lines too: the disc's centre lies
``R + r`` from the trace, so "against the drawing" said about R = 10 000 µm. Expected
now, from analysis: the G2 circle is exact, so only the dialect's rounding and the
machine's steps are left, a few µm (GRBL's profile steps 4 µm).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import ezdxf
import pytest

from camtool.geometry.chain import chain_members
from camtool.model.shapes import Contour, Line

R = 10.0
FEW_STEPS_UM = 20.0


@pytest.fixture
def disc(tmp_path: Path) -> Path:
    doc = ezdxf.new(units=4)  # mm
    msp = doc.modelspace()
    msp.add_circle((0, 0), R)
    msp.add_line((-R, 0), (R, 0))  # the diameters: they cross, their ends meet nothing
    msp.add_line((0, -R), (0, R))
    msp.add_line((15, -5), (15, 5))  # a construction line of two pieces, end to end
    msp.add_line((15, 5), (20, 5))
    path = tmp_path / "disc.dxf"
    doc.saveas(path)
    return path


OPTIONS = ["--offset", "outside", "--tool-diameter", "3", "--depth", "1"]


def test_post_verify_compares_only_what_the_plan_cuts(run: Any, disc: Path, tmp_path: Path) -> None:
    out, report = tmp_path / "disc.ngc", tmp_path / "report.json"
    code, err = run(
        "post", str(disc), "-t", "grbl", *OPTIONS, "-o", str(out), "--verify",
        "--report", str(report),
    )  # fmt: skip
    assert code == 0, err
    assert err.count("not cut: open contour") == 3  # the two diameters, the joined pair
    against = json.loads(report.read_text())["against"]
    assert against["max_um"] < FEW_STEPS_UM
    assert against["overcut_um"] < FEW_STEPS_UM


def test_a_limit_is_not_failed_by_the_lines_left_out(run: Any, disc: Path, tmp_path: Path) -> None:
    out = tmp_path / "disc.ngc"
    code, err = run(
        "post", str(disc), "-t", "grbl", *OPTIONS, "-o", str(out), "--verify",
        "--max-error-um", "50",
    )  # fmt: skip
    assert code == 0, err


def test_verify_against_leaves_them_out_as_the_header_says(
    run: Any, disc: Path, tmp_path: Path
) -> None:
    out, report = tmp_path / "disc.ngc", tmp_path / "report.json"
    code, err = run("post", str(disc), "-t", "grbl", *OPTIONS, "-o", str(out))
    assert code == 0, err
    code, err = run(
        "verify", str(out), "-t", "grbl", "--against", str(disc), "--report", str(report)
    )
    assert code == 0, err
    assert "4 open contour(s) of the drawing not compared" in err
    assert json.loads(report.read_text())["against"]["max_um"] < FEW_STEPS_UM


def test_a_cut_on_the_line_compares_every_contour(run: Any, disc: Path, tmp_path: Path) -> None:
    out, report = tmp_path / "disc.ngc", tmp_path / "report.json"
    code, err = run("post", str(disc), "-t", "grbl", "-o", str(out), "--offset", "on")
    assert code == 0, err
    code, err = run(
        "verify", str(out), "-t", "grbl", "--against", str(disc), "--report", str(report)
    )
    assert code == 0, err
    assert "not compared" not in err
    assert json.loads(report.read_text())["against"]["max_um"] < FEW_STEPS_UM


def test_chain_members_names_the_pieces_of_each_chain() -> None:
    square = [((0, 0), (1, 0)), ((1, 1), (0, 1)), ((1, 0), (1, 1)), ((5, 5), (6, 5))]
    square.insert(2, ((0, 1), (0, 0)))
    contours = [Contour((Line(a, b),), False) for a, b in square]
    joined, members = chain_members(contours, 1e-6)
    assert [c.closed for c in joined] == [True, False]
    assert sorted(members[0]) == [0, 1, 2, 3] and members[1] == (4,)


JOB = """
[job]
origin = "drawing"

[[tools]]
id = 1
type = "end-mill"
diameter = 3.0
feed = 400

[[operations]]
type = "engrave"
tool = 1
layers = ["MARK"]
depth = 0.3

[[operations]]
type = "profile"
tool = 1
layers = ["0"]
side = "outside"
depth = 1.0
"""


def test_each_operation_of_a_job_is_compared_with_what_it_cuts(disc: Path, tmp_path: Path) -> None:
    from camtool.importers import read_drawing
    from camtool.jobs.jobfile import load_job
    from camtool.jobs.pipeline import verify_job
    from camtool.jobs.run import run_job
    from camtool.post.registry import load_target

    doc = ezdxf.readfile(disc)
    doc.layers.add("MARK")
    doc.modelspace().add_line((-5, 15), (5, 15), dxfattribs={"layer": "MARK"})
    doc.saveas(disc)
    (tmp_path / "job.toml").write_text(JOB)
    job = run_job(read_drawing(disc), load_target("linuxcnc"), load_job(tmp_path / "job.toml"))
    profile = job.operations[1]
    assert len(profile.placed.contours) == 5 and len(profile.cut.contours) == 1
    parts = verify_job(job, budget=False).parts
    for part in parts:  # linuxcnc writes 1 µm and steps 5 µm
        assert part.verification.against.max_um < FEW_STEPS_UM, part.label
