"""camtool batch: input expansion, outputs, one bad file among good ones, exit codes, report.

Drawings are small pic-mmh parts inside its 10 × 7 mm work area (UNAM-GMM §2.1): a 2 × 1 mm
rectangle at (1, 1) and an L of two axis-parallel lines as a G-code program.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from camtool.cli.main import main
from camtool.jobs.batch import BatchOptions, plan_batch, post_one, run_batch
from camtool.jobs.batch_plan import BatchRow, batch_exit_code
from camtool.jobs.batch_report import batch_report, progress_line, summary_table
from camtool.jobs.inputs import expand_inputs
from camtool.jobs.pipeline import post_file
from camtool.model.errors import InputError, UsageError
from tests.shapes import rectangle_dxf

ROOT = Path(__file__).parents[2]
SAMPLES = ROOT / "samples"
# An L along the axes at the pic-mmh feed F08 = 0.8 mm/min (UNAM-GMM L1731).
L_PROGRAM = "G21 G90\nG0 X1 Y1\nG1 X2 Y1 F0.8\nG1 X2 Y2\nM30\n"
HALF_STEP_UM = 0.07  # ½ BLU of the 140 nm step (UNAM-GMM §2.1; DDA lines, §4.2, §4.7)


@pytest.fixture
def tree(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """drawings/ with a rectangle, a nested rectangle, a program, and files a batch skips."""
    monkeypatch.chdir(tmp_path)
    root = Path("drawings")
    (root / "parts" / "deep").mkdir(parents=True)
    (root / ".cache").mkdir()
    rectangle_dxf(root / "rect.dxf", 2, 1)
    rectangle_dxf(root / "parts" / "deep" / "small.DXF", 1, 1)
    (root / "parts" / "l.ngc").write_text(L_PROGRAM)
    (root / "parts" / "notes.md").write_text("not a drawing\n")
    (root / ".cache" / "old.dxf").write_text("hidden\n")
    return root


def run(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    code = main(["batch", *args])
    out, err = capsys.readouterr()
    return code, out, err


# -- inputs -----------------------------------------------------------------------------------


def test_directory_is_searched_recursively_skipping_hidden_and_unknown(tree: Path) -> None:
    found = expand_inputs([str(tree)])
    assert [i.relative.as_posix() for i in found] == [
        "parts/deep/small.DXF",
        "parts/l.ngc",
        "rect.dxf",
    ]
    assert found[2].path == tree / "rect.dxf"


def test_symbolic_links_in_a_loop_are_one_failed_row_not_an_internal_error(
    tree: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # not: "internal error: RuntimeError: Symlink loop" (Path.resolve) before any file
    # was posted. A file link and a folder link that loop, and one to nothing.
    os.symlink("b.dxf", tree / "a.dxf")
    os.symlink("a.dxf", tree / "b.dxf")
    os.symlink("loop", tree / "loop")
    os.symlink("nowhere.svg", tree / "dangling.svg")
    code, _out, err = run([str(tree), "-t", "grbl", "-o", "out"], capsys)
    assert code == 3, err
    for name in ("a.dxf", "b.dxf", "dangling.svg"):
        assert f"{tree / name}: a symbolic link that leads to no file (or round a loop)" in err
    assert "internal error" not in err
    written = sorted(p.name for p in Path("out").rglob("*.gcode"))
    assert written == ["l.gcode", "rect.gcode", "small.gcode"]


def test_a_text_note_beside_the_drawings_is_passed_over_a_point_list_is_not(tree: Path) -> None:
    """A README or a licence saved as .txt holds no row of numbers and no G-code block:
    found in a folder or a glob it is no point list to post (it was an error in the
    batch's table); a point list, a program saved as .txt, or a note named on the command
    line are posted (the last two with their own error)."""
    (tree / "README.txt").write_text("Cut from 6 mm plywood with a 3 mm end mill.\n")
    (tree / "parts" / "LICENSE.txt").write_text("CC-BY 4.0\n", encoding="utf-16")
    (tree / "parts" / "trace.txt").write_text("# x y\n0 0\n10 0\n")
    (tree / "parts" / "eu.txt").write_text("x;y\n0,5;0\n")  # a bad point list, posted
    (tree / "parts" / "cambam.txt").write_text("G21 G90\nG0 X0 Y0\n")  # a program as .txt
    (tree / "parts" / "cmm.txt").write_text("sep=,\nid,name,x,y,z\n1,P1,0,0,0\n")  # a table
    (tree / "parts" / "notes.txt").write_text("Parts\n\nX and Y\n2024 is the year\n")
    for found in (expand_inputs([str(tree)]), expand_inputs(["drawings/**/*.txt"])):
        names = {i.path.name for i in found}
        assert {"trace.txt", "eu.txt", "cambam.txt", "cmm.txt"} <= names
        assert not {"README.txt", "LICENSE.txt", "notes.txt"} & names
    named = expand_inputs(["drawings/README.txt"])
    assert [i.path.name for i in named] == ["README.txt"]


def test_files_and_globs_are_sorted_and_deduplicated(tree: Path) -> None:
    found = expand_inputs(["drawings/rect.dxf", "drawings/**/*.ngc", "drawings/parts", "drawings"])
    paths = [i.path.as_posix() for i in found]
    assert paths == sorted(paths) and len(paths) == len(set(paths)) == 3
    by_path = {i.path.as_posix(): i.relative.as_posix() for i in found}
    assert by_path["drawings/rect.dxf"] == "rect.dxf"  # a file: its own name
    assert by_path["drawings/parts/l.ngc"] == "parts/l.ngc"  # below the glob's fixed part
    assert by_path["drawings/parts/deep/small.DXF"] == "deep/small.DXF"  # below drawings/parts


def test_glob_with_double_star_keeps_paths_below_its_root(tree: Path) -> None:
    found = expand_inputs(["drawings/**/*.DXF"])
    assert [i.relative.as_posix() for i in found] == ["parts/deep/small.DXF"]


@pytest.mark.parametrize(
    ("given", "error", "message"),
    [
        ("drawings/missing.dxf", InputError, "drawings/missing.dxf: no such file or directory"),
        ("drawings/*.svg", InputError, "drawings/*.svg: matches no file camtool reads (.dxf"),
        ("empty", InputError, "empty: holds no file camtool reads"),
        ("-", UsageError, "a batch reads files, not stdin"),
    ],
)
def test_an_input_that_matches_nothing_is_an_error(
    tree: Path, given: str, error: type[Exception], message: str
) -> None:
    Path("empty").mkdir()
    (Path("empty") / "readme.md").write_text("x\n")
    with pytest.raises(error, match=message.replace("*", r"\*").replace("(", r"\(")):
        expand_inputs(["drawings", given])


def test_the_output_directory_is_never_searched(tree: Path) -> None:
    (tree / "out").mkdir()
    rectangle_dxf(tree / "out" / "previous.dxf")
    assert len(expand_inputs(["drawings"], exclude=tree / "out")) == 3
    assert len(expand_inputs(["drawings/**/*.dxf"], exclude=tree / "out")) == 1
    assert len(expand_inputs(["drawings"])) == 4


# -- outputs ----------------------------------------------------------------------------------


def test_outputs_keep_the_path_below_the_input(tree: Path) -> None:
    options = BatchOptions(target="pic-mmh", output_dir=Path("out"), preview="svg")
    tasks = {t.file: t for t in plan_batch(["drawings"], options).tasks}
    small = tasks[str(Path("drawings/parts/deep/small.DXF"))]
    assert Path(small.code_path) == Path("out/parts/deep/small.pic")  # the pic-mmh ending
    assert Path(small.preview_path or "") == Path("out/parts/deep/small.svg")
    assert small.report_path is None  # a preview alone does not verify
    checked = BatchOptions(target="pic-mmh", output_dir=Path("out"), max_error_um=20)
    tasks = {t.file: t for t in plan_batch(["drawings"], checked).tasks}
    assert Path(tasks[small.file].report_path or "") == Path("out/parts/deep/small.json")
    assert tasks[small.file].preview_path is None


def test_existing_outputs_are_refused_before_any_work_unless_forced(tree: Path) -> None:
    Path("out").mkdir()
    Path("out/rect.pic").write_text("previous\n")
    options = BatchOptions(target="pic-mmh", output_dir=Path("out"), jobs=1)
    with pytest.raises(UsageError, match=r"1 output\(s\) exist already: out/rect.pic; use --force"):
        plan_batch(["drawings"], options)
    assert sorted(p.name for p in Path("out").iterdir()) == ["rect.pic"]  # nothing else written
    forced = BatchOptions(target="pic-mmh", output_dir=Path("out"), jobs=1, force=True)
    assert run_batch(plan_batch(["drawings"], forced)).exit_code == 0
    assert Path("out/rect.pic").read_text().startswith("G54;")


def test_the_refusal_lists_only_the_first_few(tree: Path) -> None:
    for i in range(7):
        rectangle_dxf(tree / f"r{i}.dxf", 1, 1)
        (Path("out") / f"r{i}.pic").parent.mkdir(exist_ok=True)
        (Path("out") / f"r{i}.pic").write_text("x\n")
    with pytest.raises(UsageError, match=r"7 output\(s\) exist already: .*r4.pic and 2 more"):
        plan_batch(["drawings"], BatchOptions(target="pic-mmh", output_dir=Path("out")))


def test_two_files_writing_one_output_are_refused(tree: Path) -> None:
    (tree / "rect.csv").write_text("x_mm,y_mm\n1,1\n2,1\n2,2\n")
    with pytest.raises(
        UsageError,
        match=r"rect\.csv → out/rect\.pic and .*rect\.dxf → out/rect\.pic are the same file",
    ):
        plan_batch(["drawings"], BatchOptions(target="pic-mmh", output_dir=Path("out")))


def test_an_output_never_overwrites_an_input_even_forced(tree: Path) -> None:
    shutil.copy(tree / "rect.dxf", tree / "rect.svg")  # its preview would be drawings/rect.svg
    options = BatchOptions(target="pic-mmh", output_dir=tree, preview="svg", force=True)
    with pytest.raises(UsageError, match=r"rect\.svg would overwrite the input .*rect\.svg"):
        plan_batch([str(tree / "rect.dxf"), str(tree / "rect.svg")], options)


# -- running ----------------------------------------------------------------------------------


def test_one_corrupt_file_among_good_ones(tree: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tree / "parts" / "bad.dxf").write_text("hello\n")
    code, out, err = run(["drawings", "-t", "pic-mmh", "-o", "out", "-j", "1"], capsys)
    assert code == 3 and out == ""  # an unreadable input, nothing worse
    for name in ("out/rect.pic", "out/parts/l.pic", "out/parts/deep/small.pic"):
        assert Path(name).read_text().startswith("G54;"), name
    assert not Path("out/parts/bad.pic").exists()  # a failed file leaves nothing behind
    table = err[err.index("\nfile ") :]
    bad = next(line for line in table.splitlines() if "bad.dxf" in line)
    assert "error" in bad and "not a readable DXF" in bad
    assert "4 file(s): 3 ok, 0 over the limit, 1 error(s)" in err
    assert err.rstrip().endswith("camtool: error: 1 of 4 file(s) failed (see the table above)")
    assert "Traceback" not in err


def test_blocks_match_camtool_post(tree: Path) -> None:
    plan = plan_batch(["drawings/rect.dxf"], BatchOptions(target="pic-mmh", output_dir=Path("o")))
    (row,) = run_batch(plan).rows
    job = post_file("drawings/rect.dxf", "pic-mmh")
    assert row.blocks == job.result.blocks
    assert Path("o/rect.pic").read_text() == job.result.code
    # Without verification the time is the cut at its programmed feed: 6 mm at 0.8 mm/min.
    assert row.time_s == pytest.approx(6.0 / 0.8 * 60.0)
    assert row.max_error_um is None and not row.verified


def test_a_target_that_writes_no_feed_has_no_time_without_verification(tree: Path) -> None:
    """valcnc runs every step at 166.667 µs whatever F says (and writes no F): the time at
    programmed feeds is no estimate of its time, so it is left out, and said in the totals."""
    from camtool.jobs.batch_report import totals_line

    options = BatchOptions(target="valcnc", output_dir=Path("o"), jobs=1)
    result = run_batch(plan_batch(["drawings/rect.dxf"], options))
    (row,) = result.rows
    assert row.status == "ok" and row.time_s is None
    assert "(1 written without a time: --verify times them)" in totals_line(result)
    timed = BatchOptions(target="valcnc", output_dir=Path("v"), jobs=1, verify=True)
    (verified,) = run_batch(plan_batch(["drawings/rect.dxf"], timed)).rows
    assert verified.time_s is not None and verified.time_s > 0


def test_a_worker_exception_becomes_that_files_error_row(
    tree: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import camtool.jobs.batch

    def boom(file: str, options: BatchOptions) -> None:
        raise RuntimeError(f"bug on {file}")

    monkeypatch.setattr(camtool.jobs.batch, "_post_job", boom)
    plan = plan_batch(["drawings/rect.dxf"], BatchOptions(target="pic-mmh", output_dir=Path("o")))
    row = post_one(plan.tasks[0], plan.options)
    assert (row.status, row.exit_code) == ("error", 1)
    assert row.error == "internal error: RuntimeError: bug on drawings/rect.dxf"


def test_memory_running_out_on_one_file_is_its_error_row(
    tree: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import camtool.jobs.batch

    def too_large(file: str, options: BatchOptions) -> None:
        raise MemoryError("Unable to allocate 763. MiB for an array")

    monkeypatch.setattr(camtool.jobs.batch, "_post_job", too_large)
    plan = plan_batch(["drawings/rect.dxf"], BatchOptions(target="pic-mmh", output_dir=Path("o")))
    row = post_one(plan.tasks[0], plan.options)
    assert (row.status, row.exit_code) == ("error", 1)
    assert row.error.startswith("out of memory (Unable to allocate 763. MiB for an array): ")
    assert "internal error" not in row.error


def test_jobs_two_gives_the_same_outputs_as_jobs_one(tree: Path) -> None:
    reports = []
    for jobs in (1, 2):
        options = BatchOptions(target="pic-mmh", output_dir=Path(f"out{jobs}"), jobs=jobs)
        result = run_batch(plan_batch(["drawings"], options))
        report = batch_report(result)
        for row in report["files"]:
            row.pop("outputs")
        report["options"].pop("output_dir")
        reports.append(report)
    assert reports[0] == reports[1]
    codes = sorted(p.relative_to("out1") for p in Path("out1").rglob("*") if p.is_file())
    assert codes == sorted(p.relative_to("out2") for p in Path("out2").rglob("*") if p.is_file())
    assert len(codes) == 3
    for rel in codes:
        assert (Path("out1") / rel).read_bytes() == (Path("out2") / rel).read_bytes()


def test_progress_is_called_once_per_file(tree: Path) -> None:
    seen: list[tuple[int, int, str]] = []
    options = BatchOptions(target="pic-mmh", output_dir=Path("out"), jobs=2)
    run_batch(
        plan_batch(["drawings"], options), progress=lambda d, n, r: seen.append((d, n, r.file))
    )
    assert [(d, n) for d, n, _ in seen] == [(1, 3), (2, 3), (3, 3)]
    assert len({f for *_, f in seen}) == 3


# -- exit codes -------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("setup", "args", "exit_code", "message"),
    [
        (None, [], 0, "3 file(s): 3 ok"),
        ("corrupt", [], 3, "not a readable DXF"),
        ("corrupt+big", [], 1, "larger than the 10 × 7 mm travel"),  # UNAM-GMM §2.1
        (None, ["--target", "nope"], 2, "unknown target 'nope'"),
        (None, ["--jobs", "0"], 2, "Invalid value for '--jobs'"),
        (None, ["--preview", "gif"], 2, "Invalid value for '--preview'"),
        (None, ["--offset", "outside"], 2, "needs --tool-diameter"),
        ("existing", [], 2, "exist already: out/rect.pic"),
        ("program+scale", [], 2, "already a toolpath (G-code): --scale"),
        (None, ["drawings/*.svg"], 3, "matches no file camtool reads"),
    ],
)
def test_exit_code_matrix(
    tree: Path,
    capsys: pytest.CaptureFixture[str],
    setup: str | None,
    args: list[str],
    exit_code: int,
    message: str,
) -> None:
    if setup in ("corrupt", "corrupt+big"):
        (tree / "bad.dxf").write_text("hello\n")
    if setup == "corrupt+big":
        rectangle_dxf(tree / "big.dxf", 20, 1)
    if setup == "existing":
        Path("out").mkdir()
        Path("out/rect.pic").write_text("previous\n")
    if setup == "program+scale":
        args = ["--scale", "2"]
    argv = ["drawings", "-o", "out", "-j", "1", *args]
    code, out, err = run(argv if "--target" in args else [*argv, "-t", "pic-mmh"], capsys)
    assert code == exit_code, err
    assert message in err and out == "" and "Traceback" not in err


def test_usage_errors_write_nothing(tree: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, _, _ = run(["drawings", "-t", "pic-mmh", "-o", "out", "--target", "nope"], capsys)
    assert code == 2 and not Path("out").exists()


def test_over_the_limit_exits_4_and_keeps_the_outputs(
    tree: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # The L program's axis-parallel lines stay within half a step of the path; the drawn
    # rectangles reverse both axes, and the pic-mmh backlash compensation (204/178 µm,
    # UNAM-GMM §5.2) leaves them tens of µm off: a 1 µm limit passes the L, stops the rest.
    code, _, err = run(
        ["drawings", "-t", "pic-mmh", "-o", "out", "-j", "1", "--max-error-um", "1"], capsys
    )
    assert code == 4, err
    rows = {line.split()[0]: line.split()[1] for line in err.splitlines() if "drawings/" in line}
    assert rows["drawings/parts/l.ngc"] == "ok"
    assert rows["drawings/rect.dxf"] == rows["drawings/parts/deep/small.DXF"] == "over-limit"
    assert Path("out/rect.pic").exists() and Path("out/rect.json").exists()
    assert "exceeds --max-error-um 1" in err
    assert err.rstrip().endswith("2 of 3 over the limit (see the table above)")


def test_exit_code_rule_is_the_smallest_failure() -> None:
    def row(code: int) -> BatchRow:
        return BatchRow(file="f", status="ok" if code == 0 else "error", exit_code=code)

    assert batch_exit_code([row(0), row(0)]) == 0
    assert batch_exit_code([row(0), row(4)]) == 4
    assert batch_exit_code([row(4), row(3), row(0)]) == 3
    assert batch_exit_code([row(4), row(3), row(1), row(2)]) == 1


# -- report, table, progress ------------------------------------------------------------------


def test_report_json(tree: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tree / "bad.dxf").write_text("hello\n")
    args = ["drawings", "-t", "pic-mmh", "-o", "out", "-j", "1", "--verify", "--report", "-"]
    code, out, _ = run(args, capsys)
    assert code == 3
    report = json.loads(out)  # stdout carries the report only
    assert set(report) == {"camtool", "options", "files", "totals", "exit_code"}
    assert report["exit_code"] == 3
    assert report["options"]["target"] == "pic-mmh" and report["options"]["verify"] is True
    assert "jobs" not in report["options"]
    files = {f["file"]: f for f in report["files"]}
    assert list(files) == sorted(files)
    ok = files[str(Path("drawings/parts/l.ngc"))]
    assert set(ok) == {
        "file",
        "status",
        "exit_code",
        "blocks",
        "max_error_um",
        "time_s",
        "verified",
        "outputs",
        "warnings",
        "error",
    }
    assert ok["status"] == "ok" and ok["verified"] is True
    assert 0 <= ok["max_error_um"] < HALF_STEP_UM  # axis-parallel lines: within half a step
    per_file = json.loads(Path(ok["outputs"]["report"]).read_text())
    assert per_file["deviation_um"]["max"] == pytest.approx(ok["max_error_um"], abs=1e-4)
    assert per_file["time_s"] == pytest.approx(ok["time_s"], abs=1e-3)
    bad = files[str(Path("drawings/bad.dxf"))]
    assert (
        bad["status"] == "error" and bad["exit_code"] == 3 and "not a readable DXF" in bad["error"]
    )
    assert bad["outputs"] == {"code": None, "report": None, "preview": None}
    totals = report["totals"]
    assert (totals["files"], totals["ok"], totals["error"], totals["over_limit"]) == (4, 3, 1, 0)
    assert totals["blocks"] == sum(f["blocks"] or 0 for f in report["files"])
    assert totals["max_error_um"] == max(f["max_error_um"] or 0 for f in report["files"])


def test_report_file_and_deterministic_bytes(
    tree: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    args = ["drawings/parts", "-t", "pic-mmh", "-o", "out", "--report", "out/batch.json"]
    assert run([*args, "-j", "1"], capsys)[0] == 0
    first = Path("out/batch.json").read_bytes()
    assert run([*args, "-j", "2"], capsys)[0] == 2  # refuses to overwrite, batch.json included
    assert run([*args, "-j", "2", "--force"], capsys)[0] == 0
    assert Path("out/batch.json").read_bytes() == first


def test_non_tty_progress_lines(tree: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tree / "bad.dxf").write_text("hello\n")
    code, _, err = run(["drawings", "-t", "pic-mmh", "-o", "out", "-j", "2"], capsys)
    assert code == 3
    lines = [line for line in err.splitlines() if line.startswith("[")]
    assert sorted(line.split("]")[0] for line in lines) == ["[1/4", "[2/4", "[3/4", "[4/4"]
    rect = next(line for line in lines if "drawings/rect.dxf" in line)
    blocks = post_file("drawings/rect.dxf", "pic-mmh").result.blocks
    assert (
        rect.split("] ")[1]
        == f"ok  drawings/rect.dxf → out/rect.pic  {blocks} blocks  450.0 s machining"
    )
    bad = next(line for line in lines if "bad.dxf" in line)
    assert bad.split("] ")[1].startswith("error  drawings/bad.dxf: not a readable DXF")


def test_summary_table_columns() -> None:
    from camtool.jobs.batch_plan import BatchResult

    rows = (
        BatchRow(
            file="a.dxf", status="ok", exit_code=0, blocks=8, max_error_um=29.44, time_s=539.6
        ),
        BatchRow(file="b.dxf", status="error", exit_code=3, error="b.dxf: not a readable DXF"),
    )
    text = summary_table(BatchResult(BatchOptions(target="t", output_dir=Path("o")), rows))
    assert text.splitlines() == [
        "file   status      blocks     max µm  machining s  note",
        "a.dxf  ok               8      29.44        539.6",
        "b.dxf  error            -          -            -  not a readable DXF",
        "2 file(s): 1 ok, 0 over the limit, 1 error(s); 8 blocks; max 29.44 µm; 539.6 s machining",
    ]
    assert progress_line(2, 2, rows[1]) == "[2/2] error  b.dxf: not a readable DXF"


def test_preview_is_written_per_file(tree: Path) -> None:
    options = BatchOptions(target="pic-mmh", output_dir=Path("out"), preview="svg", jobs=1)
    (row,) = run_batch(plan_batch(["drawings/rect.dxf"], options)).rows
    assert row.status == "ok" and not row.verified
    plain = Path(row.preview_path or "").read_text()
    assert 'id="cuts"' in plain and 'id="trace"' not in plain
    verified = dataclasses.replace(options, verify=True, force=True)
    (row,) = run_batch(plan_batch(["drawings/rect.dxf"], verified)).rows
    assert row.verified and 'id="trace"' in Path(row.preview_path or "").read_text()


# -- nothing lost -------------------------------------------------------------------------------


def test_a_report_naming_an_input_is_refused_even_forced(
    tree: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    before = (tree / "rect.dxf").read_bytes()
    for force in ([], ["--force"]):
        args = ["drawings", "-t", "pic-mmh", "-o", "out", "--report", "drawings/rect.dxf"]
        code, _, err = run([*args, *force], capsys)
        assert code == 2, err
        assert "--report drawings/rect.dxf would overwrite the input drawings/rect.dxf" in err
        assert "use --force" not in err
        assert (tree / "rect.dxf").read_bytes() == before and not Path("out").exists()


def test_a_report_naming_an_output_is_refused(
    tree: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    args = ["drawings", "-t", "pic-mmh", "-o", "out", "--report", "out/rect.pic", "--force"]
    code, _, err = run(args, capsys)
    assert code == 2 and "--report out/rect.pic and drawings/rect.dxf → out/rect.pic" in err


def test_a_folder_another_batch_writes_into_is_refused(
    tree: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from camtool.jobs.output import lock_directory

    with lock_directory("out"):
        for force in ([], ["--force"]):
            code, _, err = run(["drawings", "-t", "pic-mmh", "-o", "out", *force], capsys)
            assert code == 1
            assert f"-o out: another camtool run (pid {os.getpid()}) is writing" in err
            assert sorted(p.name for p in Path("out").iterdir()) == [".camtool.lock"]
    assert run(["drawings", "-t", "pic-mmh", "-o", "out", "-j", "1"], capsys)[0] == 0
    assert not Path("out/.camtool.lock").exists()


def test_two_batches_started_together_never_both_write(tree: Path) -> None:
    """Exactly one run posts; the other says why it did not; every output is whole."""
    for i in range(12):
        rectangle_dxf(tree / f"r{i:02}.dxf", 1 + i % 5, 1)
    argv = [sys.executable, "-m", "camtool", "batch", "drawings", "-t", "pic-mmh", "-o", "out"]
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    runs = [
        subprocess.Popen([*argv, "-j", "2"], stderr=subprocess.PIPE, text=True, env=env)
        for _ in range(2)
    ]
    results = [(proc.wait(timeout=300), proc.stderr.read() if proc.stderr else "") for proc in runs]
    codes = sorted(code for code, _ in results)
    assert codes[0] == 0 and codes[1] in (1, 2), results
    loser = next(err for code, err in results if code)
    assert "another camtool run" in loser or "exist already" in loser, loser
    for item in expand_inputs(["drawings"]):
        code_path = Path("out") / item.relative.with_suffix(".pic")
        assert code_path.read_text() == post_file(item.path, "pic-mmh").result.code
    assert [p for p in Path("out").rglob(".*")] == []  # no temp file, no lock left


def test_workers_die_with_a_killed_batch(tree: Path) -> None:
    """kill -9 of `batch -j 2` must not leave its workers running (and holding its pipes)."""
    shutil.rmtree(tree)
    tree.mkdir()
    for name in ("a.ngc", "b.ngc"):
        os.mkfifo(tree / name)  # a worker reading a FIFO waits for a writer: busy forever
    argv = [sys.executable, "-m", "camtool", "batch", "drawings", "-t", "pic-mmh", "-o", "out"]
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    parent = subprocess.Popen([*argv, "-j", "2"], stderr=subprocess.DEVNULL, env=env)
    workers: list[int] = []
    try:
        deadline = time.monotonic() + 60
        while len(workers) < 2 and time.monotonic() < deadline:
            time.sleep(0.2)
            workers = children(parent.pid)
        assert len(workers) == 2, "the batch did not start its workers"
        parent.kill()
        parent.wait()
        deadline = time.monotonic() + 5
        while any(alive(pid) for pid in workers) and time.monotonic() < deadline:
            time.sleep(0.1)
        assert not [pid for pid in workers if alive(pid)]
    finally:
        for pid in workers:
            if alive(pid):
                os.kill(pid, signal.SIGKILL)
        parent.kill()


def children(pid: int) -> list[int]:
    """Child pids of ``pid`` (Linux /proc)."""
    found: list[int] = []
    for task in Path(f"/proc/{pid}/task").glob("*"):
        with contextlib.suppress(OSError):
            found += [int(c) for c in (task / "children").read_text().split()]
    return found


def alive(pid: int) -> bool:
    """True while ``pid`` runs (a zombie waiting to be reaped has stopped running)."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (OSError, IndexError):
        return False
    return state != "Z"


def test_a_glob_climbing_out_with_dotdot_writes_inside_the_output_folder(tree: Path) -> None:
    Path("other").mkdir()
    rectangle_dxf(Path("other/o.dxf"), 1, 1)
    options = BatchOptions(target="pic-mmh", output_dir=Path("out"), jobs=1)
    plan = plan_batch(["drawings/*/../../other/*.dxf"], options)
    assert [Path(t.code_path) for t in plan.tasks] == [Path("out/o.pic")]
    assert run_batch(plan).exit_code == 0
    assert sorted(p.as_posix() for p in Path(".").rglob("*.pic")) == ["out/o.pic"]


def test_an_output_resolving_outside_the_output_folder_is_refused(tree: Path) -> None:
    Path("elsewhere").mkdir()
    Path("out").mkdir()
    Path("out/parts").symlink_to(Path("elsewhere").resolve())
    options = BatchOptions(target="pic-mmh", output_dir=Path("out"), force=True)
    outside = r"out/parts/deep/small\.pic would be written outside -o out"
    with pytest.raises(UsageError, match=outside):
        plan_batch(["drawings"], options)
    assert list(Path("elsewhere").iterdir()) == []


def test_a_batch_removes_temp_files_of_killed_runs(tree: Path) -> None:
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    Path("out/parts").mkdir(parents=True)
    stale = Path(f"out/parts/.l.pic.camtool-{proc.pid}.tmp")
    stale.write_text("half\n")
    options = BatchOptions(target="pic-mmh", output_dir=Path("out"), jobs=1)
    assert run_batch(plan_batch(["drawings"], options)).exit_code == 0
    assert not stale.exists()
    assert [p for p in Path("out").rglob(".*")] == []


def test_batch_judges_the_limit_as_post_does_with_and_without_strict(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # the plate's 2 mm hole and notch corners cannot be cut as drawn with a 3 mm tool: the
    # limit judges what was cut unless --strict (the same rule as `camtool post`)
    from camtool.cli.main import main

    plate = str(Path(__file__).resolve().parents[2] / "samples" / "plate.dxf")
    args = ["batch", plate, "-t", "grbl", "--offset", "outside", "--tool-diameter", "3"]
    limit = ["--max-error-um", "50", "--jobs", "1"]
    assert main([*args, *limit, "-o", str(tmp_path / "a")]) == 0
    assert main([*args, *limit, "--strict", "-o", str(tmp_path / "b")]) == 4
    assert "with --strict" in capsys.readouterr().err
