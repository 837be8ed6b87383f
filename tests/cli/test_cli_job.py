"""``camtool post --job``, ``batch --job`` and ``job init`` as a user runs them."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import ezdxf
import pytest

from camtool.cli.main import main
from tests.corpus.test_rs274 import MANIFEST, rs274, rs274_problem

ROOT = Path(__file__).resolve().parents[2]
PART = str(ROOT / "samples" / "part.dxf")
JOB = str(ROOT / "samples" / "part.toml")


@pytest.fixture
def run(capsys: pytest.CaptureFixture[str]) -> object:
    def call(*args: str) -> tuple[int, str, str]:
        code = main(list(args))
        out, err = capsys.readouterr()
        return code, out, err

    return call


def test_post_job_writes_one_program_for_the_whole_part(run: Any, tmp_path: Path) -> None:
    out = tmp_path / "part.ngc"
    code, _, err = run("post", PART, "-t", "linuxcnc", "--job", JOB, "-o", str(out))
    assert code == 0, err
    text = out.read_text()
    assert "(job part.toml: 4 operations)" in text
    assert "not cut: 10 contour(s) on layer 'CENTER'" in err


def test_a_shared_option_given_at_its_default_still_replaces_the_files(
    run: Any, tmp_path: Path
) -> None:
    # `--origin drawing` is the option's default, and given it replaces the file's
    # origin = "lower-left" as any other value would: the work zero is where the command
    # line puts it, not where the file did
    job = Path(JOB)
    assert 'origin = "lower-left"' in job.read_text()
    out = tmp_path / "part.ngc"
    code, _, err = run(
        "post", PART, "-t", "linuxcnc", "--job", str(job), "--origin", "drawing", "-o", str(out)
    )
    assert code == 0, err
    assert "(work zero X0 Y0: the drawing's origin)" in out.read_text()
    code, _, err = run("post", PART, "-t", "linuxcnc", "--job", str(job), "-o", str(out))
    assert code == 0, err
    assert "(work zero X0 Y0: the toolpath's lower-left corner)" in out.read_text()
    # the size is one choice: --scale 1 replaces a file's fit (not refused as both, and at
    # 1, its default, the part keeps its size)
    fitted = tmp_path / "fitted.toml"
    fitted.write_text(job.read_text().replace("[job]\n", "[job]\nfit = [40, 40]\n", 1))
    code, _, err = run(
        "post", PART, "-t", "linuxcnc", "--job", str(fitted), "--scale", "1", "-o", str(out)
    )
    assert code == 0, err
    assert out.read_text().splitlines()[1].startswith("(placement: scale 1, ")
    # a per-operation option given at its default is refused as any other value is
    got, _, err = run("post", PART, "-t", "grbl", "--job", str(job), "--offset", "on", "-o", "-")
    assert got == 2 and "--offset: with --job" in err


def test_a_point_nothing_drills_is_not_judged_against_the_travel(run: Any, tmp_path: Path) -> None:
    # a 10 mm square and a POINT 890 mm away: a plain post cuts the square alone, so the
    # point is no reason to refuse the drawing as larger than GRBL's 200 mm; a job that
    # drills the point and cuts the square is refused, its toolpath 890 mm across
    from tests.shapes import write_dxf

    def build(msp: Any) -> None:
        msp.add_lwpolyline([(10, 10), (20, 10), (20, 20), (10, 20)], close=True)
        msp.add_point((900, 900))

    dxf = write_dxf(tmp_path / "far.dxf", build)
    out = tmp_path / "far.gcode"
    code, _, err = run("post", str(dxf), "-t", "grbl", "-o", str(out))
    assert code == 0, err
    assert "G1 X20.000 Y10.000" in out.read_text()
    job = tmp_path / "job.toml"
    job.write_text(
        '[[tools]]\nid = 1\ntype = "drill"\ndiameter = 1\n'
        '[[operations]]\ntype = "drill"\ntool = 1\npoints = "only"\ndepth = 1\n'
        '[[operations]]\ntype = "engrave"\ntool = 1\nclosed = true\ndepth = 0.5\n'
    )
    out.unlink()
    code, _, err = run("post", str(dxf), "-t", "grbl", "--job", str(job), "-o", str(out))
    assert code == 1 and "larger than the 200 × 200 mm travel" in err and not out.exists()


@pytest.mark.parametrize(
    ("extra", "code", "message"),
    [
        (["--depth", "3"], 2, "--depth: with --job, each operation has its own"),
        (["--offset", "outside", "--tool-diameter", "3"], 2, "--offset, --tool-diameter"),
        (["--feed", "100"], 2, "--feed: with --job"),
        # refused for the job, not checked as one operation first ("--offset inside needs
        # --tool-diameter MM", "--tabs need --depth MM")
        (["--offset", "inside"], 2, "--offset: with --job, each operation has its own"),
        (["--tabs", "2"], 2, "--tabs: with --job, each operation has its own"),
    ],
)
def test_per_operation_options_with_a_job_are_refused(
    run: Any, tmp_path: Path, extra: list[str], code: int, message: str
) -> None:
    out = tmp_path / "part.gcode"
    got, _, err = run("post", PART, "-t", "grbl", "--job", JOB, "-o", str(out), *extra)
    assert got == code and message in err
    assert not out.exists()
    batch = tmp_path / "batch"
    got, _, err = run("batch", PART, "-t", "grbl", "--job", JOB, "-o", str(batch), *extra)
    assert got == code and message in err
    assert not batch.exists()


def test_a_bad_job_file_is_exit_3_and_writes_nothing(run: Any, tmp_path: Path) -> None:
    job = tmp_path / "job.toml"
    job.write_text(Path(JOB).read_text().replace("step_down = 2.0", "stepdown = 2.0", 1))
    out = tmp_path / "part.gcode"
    code, _, err = run("post", PART, "-t", "grbl", "--job", str(job), "-o", str(out))
    assert code == 3
    assert "unknown key 'stepdown'; did you mean 'step_down'?" in err
    assert not out.exists()


def test_a_job_for_a_program_is_refused(run: Any, tmp_path: Path) -> None:
    program = tmp_path / "p.ngc"
    program.write_text("G21 G90\nG0 X0 Y0\nG1 X1 F100\nM2\n")
    code, _, err = run("post", str(program), "-t", "grbl", "--job", JOB)
    assert code == 2 and "--job only applies to drawings" in err


def test_the_job_file_is_an_input_never_overwritten(run: Any, tmp_path: Path) -> None:
    job = tmp_path / "job.toml"
    job.write_text(Path(JOB).read_text())
    code, _, err = run("post", PART, "-t", "grbl", "--job", str(job), "-o", str(job))
    assert code == 2 and "would overwrite the --job file" in err
    assert job.read_text() == Path(JOB).read_text()


def test_job_init_then_post(run: Any, tmp_path: Path) -> None:
    job = tmp_path / "first.toml"
    code, _, err = run("job", "init", PART, "-o", str(job), "--thickness", "6")
    assert code == 0 and "wrote a job of 3 operation(s)" in err
    out = tmp_path / "part.gcode"
    code, _, err = run("post", PART, "-t", "grbl", "--job", str(job), "-o", str(out))
    assert code == 0, err


def test_job_init_says_what_its_guesses_rest_on(run: Any, tmp_path: Path) -> None:
    """The drawing's warnings (here: no units, mm assumed) come before the job: every
    guess in it (what is drilled, the end mill, the fit) is measured in those units."""
    drawing = tmp_path / "plate.dxf"
    doc = ezdxf.new("R2000")
    doc.header["$INSUNITS"] = 0
    doc.modelspace().add_lwpolyline([(0, 0), (2, 0), (2, 1.5), (0, 1.5)], close=True)
    doc.saveas(drawing)
    code, _, err = run("job", "init", str(drawing), "-o", str(tmp_path / "plate.toml"))
    assert code == 0 and "warning: " in err and "assuming mm" in err


def test_job_init_never_replaces_a_job_without_force(run: Any, tmp_path: Path) -> None:
    """A job is edited by hand after job init writes it: running job init again on its
    name would throw the edits away."""
    job = tmp_path / "first.toml"
    job.write_text("# my edits\n")
    code, _, err = run("job", "init", PART, "-o", str(job))
    assert code == 2 and "already exists" in err and "--force" in err
    assert job.read_text() == "# my edits\n"
    code, _, err = run("job", "init", PART, "-o", str(job), "--force")
    assert code == 0 and job.read_text().startswith("# camtool job for")


def test_batch_job_posts_each_drawing_with_the_job(run: Any, tmp_path: Path) -> None:
    report = tmp_path / "batch.json"
    code, _, err = run(
        "batch", PART, "-t", "grbl", "-o", str(tmp_path / "out"), "--job", JOB, "--jobs", "1",
        "--report", str(report),
    )  # fmt: skip
    assert code == 0, err
    for tool in (2, 1):  # two tools: GRBL gets one program per tool
        text = (tmp_path / "out" / f"part.T{tool}.gcode").read_text()
        assert "(job part.toml: 4 operations)" in text
    # the report names the job file among the options that shaped the programs, as the
    # programs' headers name it
    assert json.loads(report.read_text())["options"]["job"] == "part.toml"


TOOL_TABLE = "T1 P1 D3.0 Z0 ;end mill\nT2 P2 D3.2 Z0 ;drill\n"


@pytest.mark.skipif(MANIFEST is None or rs274_problem() is not None, reason="no rs274")
def test_linuxcnc_accepts_the_job_program(run: Any, tmp_path: Path) -> None:
    out = tmp_path / "part.ngc"
    code, _, err = run("post", PART, "-t", "linuxcnc", "--job", JOB, "-o", str(out))
    assert code == 0, err
    table = tmp_path / "tool.tbl"
    table.write_text(TOOL_TABLE)
    done = rs274(out, table)
    assert done.returncode == 0, done.stderr
    # LinuxCNC changes to T2 first, then T1, and feeds each drill hole down to Z-6.5
    changes = re.findall(r"CHANGE_TOOL\((\d+)\)", done.stdout)
    assert changes == ["2", "1"]
    bottoms = re.findall(r"STRAIGHT_FEED\(([-\d.]+), ([-\d.]+), -6\.5000", done.stdout)
    assert len(bottoms) >= 4


def test_a_job_cuts_a_layer_the_drawing_hides_when_an_operation_names_it(
    run: Any, tmp_path: Path
) -> None:
    import ezdxf

    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    doc.layers.add("GUIDE").off()  # switched off in the CAD program
    doc.modelspace().add_circle((10, 10), 5, dxfattribs={"layer": "GUIDE"})
    doc.modelspace().add_circle((30, 10), 5, dxfattribs={"layer": "PART"})
    drawing = tmp_path / "d.dxf"
    doc.saveas(drawing)
    job = tmp_path / "j.toml"
    job.write_text(
        '[[tools]]\nid = 1\ntype = "end-mill"\ndiameter = 2.0\nfeed = 300\n'
        '[[operations]]\ntype = "profile"\ntool = 1\nlayers = ["guide"]\nside = "outside"\n'
        "depth = 1.0\n"
    )
    out = tmp_path / "d.ngc"
    code, _, err = run("post", str(drawing), "-t", "linuxcnc", "--job", str(job), "-o", str(out))
    assert code == 0, err
    # the outside profile of the R5 circle at (10, 10) with a 2 mm tool: two halves of R6
    text = out.read_text()
    assert "X16.000 Y10.000 I6.000 J0.000" in text and "X4.000 Y10.000 I-6.000 J0.000" in text
    assert "not cut: 1 contour(s) on layer 'PART'" in err and "off or frozen" not in err
    code, _, err = run("post", str(drawing), "-t", "linuxcnc", "-o", str(tmp_path / "all.ngc"))
    assert code == 0 and "skipped 1 entity on layer(s) 'GUIDE', off or frozen" in err
