"""camtool batch on a Dask cluster: the same bytes as ``--jobs 1``, a killed worker, targets.

One ``LocalCluster`` of 2 worker processes (one thread each, no dashboard) serves the
module. The reference for every output is the same batch run with ``jobs=1`` in this
process: a batch on Dask must give the same files, byte for byte, and the same report
but for where it ran (``scheduler``) and where it wrote (``output_dir``, ``outputs``).
The drawings are the bundled samples, small pic-mmh parts inside its 10 × 7 mm work
area (UNAM-GMM §2.1), a G-code program, a corrupt file, and a slice of the
real-drawing corpus when it is fetched (docs/corpus.md).
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from collections import Counter
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from distributed import Client, LocalCluster, WorkerPlugin

import camtool
import camtool.jobs.batch
import camtool.jobs.batch_dask
from camtool.cli.main import main
from camtool.jobs.batch import run
from camtool.jobs.batch_plan import BatchResult
from camtool.jobs.batch_report import batch_report
from camtool.jobs.pipeline import post_file
from camtool.model.errors import UsageError
from tests.corpus.conftest import CORPUS, corpus_files, load_manifest
from tests.shapes import rectangle_dxf

ROOT = Path(__file__).parents[2]
SAMPLES = ROOT / "samples"
# An L along the axes at the pic-mmh feed F08 = 0.8 mm/min (UNAM-GMM L1731).
L_PROGRAM = "G21 G90\nG0 X1 Y1\nG1 X2 Y1 F0.8\nG1 X2 Y2\nM30\n"
VICTIM = "victim.dxf"
"""The drawing whose first run kills its worker (:class:`KillOnce`)."""


@pytest.fixture(scope="module")
def client() -> Iterator[Client]:
    with (
        LocalCluster(
            n_workers=2, processes=True, threads_per_worker=1, dashboard_address=None
        ) as cluster,
        Client(cluster) as dask_client,
    ):
        yield dask_client


@pytest.fixture
def drawings(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """drawings/: the bundled samples, small parts, a program and a corrupt DXF."""
    monkeypatch.chdir(tmp_path)
    root = Path("drawings")
    (root / "parts").mkdir(parents=True)
    for sample in sorted(SAMPLES.iterdir()):
        if sample.suffix in (".dxf", ".csv"):
            shutil.copy(sample, root / sample.name)
    rectangle_dxf(root / "parts" / "rect.dxf", 2, 1)
    rectangle_dxf(root / "parts" / "small.dxf", 1, 1)
    (root / "parts" / "l.ngc").write_text(L_PROGRAM)
    (root / "parts" / "bad.dxf").write_text("hello\n")
    return root


def tree(folder: Path) -> dict[str, bytes]:
    """Every file below ``folder`` by its relative path, with its bytes."""
    return {
        p.relative_to(folder).as_posix(): p.read_bytes()
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


def comparable(result: BatchResult | Path) -> dict[str, Any]:
    """The batch report (or a report file) without what says where it ran and wrote."""
    report = json.loads(result.read_text()) if isinstance(result, Path) else batch_report(result)
    for name in ("output_dir", "scheduler"):
        report["options"].pop(name)
    out = report["options"]
    for row in report["files"]:
        outputs = row.pop("outputs")
        row["written"] = {k: v is not None for k, v in outputs.items()}
    return {**report, "options": out}


def same_as_jobs_one(inputs: list[str], client: Client, **options: Any) -> BatchResult:
    """Run the batch with ``jobs=1`` into ref/ and on ``client`` into dask/; assert they agree.

    The reports too, as returned and as written (``ref.json``, ``dask.json``).
    """
    ref = run(inputs, output_dir="ref", jobs=1, report="ref.json", **options)
    on_dask = run(inputs, output_dir="dask", client=client, report="dask.json", **options)
    assert comparable(on_dask) == comparable(ref) == comparable(Path("ref.json"))
    assert comparable(Path("dask.json")) == comparable(ref)
    assert tree(Path("dask")) == tree(Path("ref"))
    assert batch_report(on_dask)["options"]["scheduler"] == client.scheduler.address
    return on_dask


# -- the same outputs as --jobs 1 -------------------------------------------------------------


def test_samples_on_dask_equal_jobs_one(drawings: Path, client: Client) -> None:
    result = same_as_jobs_one(["drawings"], client, targets="pic-mmh", verify=True, preview="svg")
    rows = {row.file: row for row in result.rows}
    assert rows[str(drawings / "parts" / "rect.dxf")].status == "ok"
    assert rows[str(drawings / "parts" / "l.ngc")].status == "ok"  # a program, re-posted
    bad = rows[str(drawings / "parts" / "bad.dxf")]
    assert (bad.status, bad.exit_code) == ("error", 3) and "not a readable DXF" in bad.error
    # samples/plate.dxf is 40 × 30 mm: larger than the 10 × 7 mm travel (UNAM-GMM §2.1)
    assert "larger than the 10 × 7 mm travel" in rows[str(drawings / "plate.dxf")].error
    assert result.exit_code == 1
    assert [p for p in Path("dask").rglob(".*")] == []  # no temp file, no lock left


def test_samples_for_grbl_with_png_previews(drawings: Path, client: Client) -> None:
    # the 2D samples fit GRBL's work area; PNG previews are drawn on the workers too
    same_as_jobs_one(["drawings"], client, targets="grbl", preview="png")
    assert (Path("dask") / "plate.png").read_bytes().startswith(b"\x89PNG\r\n\x1a\n")


def test_a_corpus_slice_on_dask_equals_jobs_one(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, client: Client
) -> None:
    manifest = load_manifest()
    if manifest is None:
        pytest.skip("no corpus: run `python tests/corpus/fetch_corpus.py`")
    monkeypatch.chdir(tmp_path)
    files = [f for f in corpus_files(manifest) if f.endswith(".dxf")]
    files += [f for f in corpus_files(manifest) if "/Tango/" in f][:5]
    assert len({Path(f).name for f in files}) == len(files)  # distinct outputs
    result = same_as_jobs_one([str(CORPUS / f) for f in files], client, targets=["grbl", "valcnc"])
    statuses = Counter(row.status for row in result.rows)
    assert statuses["ok"] >= len(files)  # most real drawings post (docs/corpus.md)


# -- a worker killed mid-batch ----------------------------------------------------------------


class KillOnce(WorkerPlugin):
    """In each worker: the first run of :data:`VICTIM` kills its worker, after posting it.

    The marker file (created exclusively, so one run wins) says the kill happened; a
    second marker that the file was posted again, by the worker that took it over.
    """

    def __init__(self, markers: str) -> None:
        self.markers = markers

    def setup(self, worker: Any) -> None:
        import camtool.jobs.batch as batch

        original = batch._outputs
        markers = Path(self.markers)

        def outputs(task: Any, options: Any, job: Any) -> Any:
            result = original(task, options, job)
            if Path(task.file).name == VICTIM:
                try:
                    fd = os.open(markers / "killed", os.O_CREAT | os.O_EXCL | os.O_WRONLY)
                except FileExistsError:
                    (markers / "posted-again").touch()
                else:
                    os.close(fd)
                    os.kill(os.getpid(), signal.SIGKILL)
            return result

        self.original = original
        batch._outputs = outputs  # type: ignore[assignment]

    def teardown(self, worker: Any) -> None:
        import camtool.jobs.batch as batch

        batch._outputs = self.original  # type: ignore[assignment]


def test_a_killed_worker_loses_nothing_and_writes_nothing_twice(
    drawings: Path, client: Client, monkeypatch: pytest.MonkeyPatch
) -> None:
    for i in range(8):
        rectangle_dxf(drawings / "parts" / f"r{i}.dxf", 1 + i % 5, 1)
    rectangle_dxf(drawings / "parts" / VICTIM, 3, 2)
    ref = run(["drawings"], targets="pic-mmh", output_dir="ref", jobs=1, verify=True)
    markers = Path("markers").resolve()
    markers.mkdir()
    writes: Counter[str] = Counter()
    write = camtool.jobs.batch._write

    def counted(path: str, data: str | bytes) -> None:
        writes[path] += 1
        write(path, data)

    monkeypatch.setattr(camtool.jobs.batch, "_write", counted)
    pids = set(client.run(os.getpid).values())
    client.register_plugin(KillOnce(str(markers)), name="kill-once")
    try:
        result = run(["drawings"], targets="pic-mmh", output_dir="dask", client=client, verify=True)
    finally:
        client.unregister_worker_plugin("kill-once")
    assert (markers / "killed").exists() and (markers / "posted-again").exists()
    client.wait_for_workers(2, timeout=60)  # the nanny restarts the killed worker
    assert pids - set(client.run(os.getpid).values())  # one worker process is gone
    assert comparable(result) == comparable(ref)  # every file, the victim too
    assert tree(Path("dask")) == tree(Path("ref"))
    written = [out for row in result.rows for out in (row.code_path, row.report_path) if out]
    assert sorted(writes) == sorted(written) and set(writes.values()) == {1}
    assert [p for p in Path("dask").rglob(".*")] == []  # no partial file


# -- a task that never comes back (dask/distributed#6074) ---------------------------------------


def _stranding(client: Client, monkeypatch: pytest.MonkeyPatch, runs: int) -> list[str]:
    """Make the first ``runs`` submissions of :data:`VICTIM` wait for ever; their log.

    Each asks for a resource no worker has, so the scheduler never runs it and the
    cluster goes idle with the task unfinished: what the client sees when a result is
    lost as a worker dies. Returns the files of every submission, in order.
    """
    submitted: list[str] = []
    submit = client.submit

    def stranding(work: Any, *args: Any, **kwargs: Any) -> Any:
        name = Path(args[0].file).name
        submitted.append(name)
        if name == VICTIM and submitted.count(VICTIM) <= runs:
            kwargs["resources"] = {"nowhere": 1}
        return submit(work, *args, **kwargs)

    monkeypatch.setattr(client, "submit", stranding)
    monkeypatch.setattr(camtool.jobs.batch_dask, "STALL_S", 2.0)
    monkeypatch.setattr(camtool.jobs.batch_dask, "POLL_S", 0.2)
    return submitted


def test_a_task_stranded_on_an_idle_cluster_is_submitted_again(
    drawings: Path, client: Client, monkeypatch: pytest.MonkeyPatch
) -> None:
    rectangle_dxf(drawings / "parts" / VICTIM, 3, 2)
    ref = run(["drawings"], targets="pic-mmh", output_dir="ref", jobs=1)
    submitted = _stranding(client, monkeypatch, runs=1)
    start = time.monotonic()
    result = run(["drawings"], targets="pic-mmh", output_dir="dask", client=client)
    assert time.monotonic() - start < 60  # before the fix: waits for ever
    assert submitted.count(VICTIM) == 2  # stranded once, then run
    assert comparable(result) == comparable(ref)  # every file, the victim too
    assert tree(Path("dask")) == tree(Path("ref"))


def test_a_task_that_never_comes_back_is_its_files_error(
    drawings: Path, client: Client, monkeypatch: pytest.MonkeyPatch
) -> None:
    rectangle_dxf(drawings / "parts" / VICTIM, 3, 2)
    ref = run(["drawings"], targets="pic-mmh", output_dir="ref", jobs=1)
    runs = 1 + camtool.jobs.batch_dask.RESUBMITS
    submitted = _stranding(client, monkeypatch, runs=runs)
    result = run(["drawings"], targets="pic-mmh", output_dir="dask", client=client)
    assert submitted.count(VICTIM) == runs  # then given up on, not submitted for ever
    rows = {Path(row.file).name: row for row in result.rows}
    victim = rows.pop(VICTIM)
    assert (victim.status, victim.exit_code) == ("error", 1)
    assert victim.error.startswith("worker failed: LostTask: the cluster sat idle for 2 s")
    assert f"{runs} times" in victim.error
    others = {Path(row.file).name: row for row in ref.rows if Path(row.file).name != VICTIM}
    assert {n: (r.status, r.error) for n, r in rows.items()} == {
        n: (r.status, r.error) for n, r in others.items()
    }
    expected = {k: v for k, v in tree(Path("ref")).items() if Path(k).stem != Path(VICTIM).stem}
    assert tree(Path("dask")) == expected  # the others written, the victim not
    assert result.exit_code == 1


# -- several targets --------------------------------------------------------------------------


def test_several_targets_write_a_folder_each(
    drawings: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    args = ["batch", "drawings/parts", "-t", "pic-mmh", "-t", "grbl", "-o", "out", "-j", "2"]
    code = main([*args, "--report", "-"])
    out, err = capsys.readouterr()
    assert code == 3, err  # bad.dxf is unreadable for both
    for target, ending in (("pic-mmh", ".pic"), ("grbl", ".gcode")):
        for name in ("rect", "small", "l"):
            source = next((drawings / "parts").glob(f"{name}.*"))
            code_path = Path("out") / target / f"{name}{ending}"
            assert code_path.read_text() == post_file(source, target).result.code
    report = json.loads(out)
    assert report["options"]["target"] == ["pic-mmh", "grbl"]
    assert [(f["target"], Path(f["file"]).name) for f in report["files"]] == [
        (t, n) for t in ("pic-mmh", "grbl") for n in ("bad.dxf", "l.ngc", "rect.dxf", "small.dxf")
    ]
    assert list(report["files"][0])[:3] == ["file", "target", "status"]
    assert report["totals"]["files"] == 8 and report["totals"]["error"] == 2
    table = err[err.index("\nfile ") :].splitlines()
    assert table[1].split()[:3] == ["file", "target", "status"]
    assert any(line.split()[1:3] == ["grbl", "ok"] for line in table if "rect.dxf" in line)
    assert "bad.dxf for grbl: not a readable DXF" in err  # the progress line names it


def test_several_targets_on_dask_equal_jobs_one(drawings: Path, client: Client) -> None:
    same_as_jobs_one(["drawings/parts"], client, targets=["pic-mmh", "grbl"], verify=True)
    assert sorted(p.name for p in Path("dask").iterdir()) == ["grbl", "pic-mmh"]


def test_one_target_keeps_the_flat_layout(drawings: Path, client: Client) -> None:
    run(["drawings/parts"], targets=["pic-mmh"], output_dir="dask", client=client)
    assert sorted(p.name for p in Path("dask").iterdir()) == ["l.pic", "rect.pic", "small.pic"]


def test_a_target_named_twice_is_refused(drawings: Path) -> None:
    with pytest.raises(UsageError, match="--target grbl is given twice"):
        run(["drawings"], targets=["grbl", "pic-mmh", "grbl"], output_dir="out")
    assert not Path("out").exists()


# -- the library entry point and the command line ---------------------------------------------


def test_camtool_batch_is_the_batch_module(drawings: Path, client: Client) -> None:
    assert camtool.batch is camtool.jobs.batch
    result = camtool.batch.run(
        "drawings/parts/rect.dxf", targets="pic-mmh", output_dir="o", client=client
    )
    assert [row.status for row in result.rows] == ["ok"]
    with pytest.raises(UsageError, match="a Dask client and jobs both say where"):
        camtool.batch.run(
            "drawings/parts", targets="pic-mmh", output_dir="p", client=client, jobs=2
        )


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--scheduler", "local:2", "-j", "2"], "--jobs 2 and --scheduler local:2 both say"),
        (["--scheduler", "local:0"], "give a Dask scheduler's address (tcp://HOST:8786"),
        (["--scheduler", "8786"], "or local:N to start N workers on this machine"),
    ],
)
def test_scheduler_usage_errors(
    drawings: Path, capsys: pytest.CaptureFixture[str], args: list[str], message: str
) -> None:
    code = main(["batch", "drawings", "-t", "pic-mmh", "-o", "out", *args])
    err = capsys.readouterr().err
    assert code == 2 and message in err and "Traceback" not in err
    assert not Path("out").exists()


def test_the_command_with_a_scheduler_address(
    drawings: Path, client: Client, capsys: pytest.CaptureFixture[str]
) -> None:
    # as on another host: `dask scheduler` prints tcp://HOST:PORT, workers joined it
    address = client.scheduler.address
    assert address.startswith("tcp://")
    args = ["batch", "drawings/parts", "-t", "pic-mmh", "--report", "-"]
    assert main([*args, "-o", "ref", "-j", "1"]) == 3
    ref = json.loads(capsys.readouterr().out)
    assert main([*args, "-o", "out", "--scheduler", address]) == 3
    out, err = capsys.readouterr()
    report = json.loads(out)
    assert report["options"]["scheduler"] == address
    assert sorted(line.split("]")[0] for line in err.splitlines() if line[:1] == "[") == [
        "[1/4",
        "[2/4",
        "[3/4",
        "[4/4",
    ]
    assert report["files"] == [
        {
            **row,
            "outputs": {k: v and v.replace("ref/", "out/", 1) for k, v in row["outputs"].items()},
        }
        for row in ref["files"]
    ]
    assert tree(Path("out")) == tree(Path("ref"))


def test_a_scheduler_without_workers_is_an_error(
    drawings: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    from camtool.jobs import batch_dask

    monkeypatch.setattr(batch_dask, "WORKER_WAIT_S", 0.5)
    with LocalCluster(n_workers=0, processes=False, dashboard_address=":0") as empty:
        address = empty.scheduler_address
        code = main(["batch", "drawings", "-t", "pic-mmh", "-o", "out", "--scheduler", address])
    err = capsys.readouterr().err
    assert code == 1 and "Traceback" not in err
    assert f"--scheduler {address}: no worker joined the scheduler within 0.5 s; " in err
    assert f"start one with `dask worker {address}`" in err
    assert not Path("out").exists()  # nothing claimed, nothing written


def test_local_workers_die_with_a_killed_batch(drawings: Path) -> None:
    """kill -9 of `batch --scheduler local:2` must not leave its Dask workers running."""
    from tests.jobs.test_batch import alive, children

    for i in range(40):
        shutil.copy(SAMPLES / "logo.dxf", drawings / f"logo{i}.dxf")
    argv = [sys.executable, "-m", "camtool", "batch", "drawings", "-t", "pic-mmh", "-o", "out"]
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]),
    }
    parent = subprocess.Popen(
        [*argv, "--verify", "--scheduler", "local:2"], stderr=subprocess.PIPE, env=env, text=True
    )
    workers: list[int] = []
    try:
        assert parent.stderr is not None
        lines = iter(parent.stderr.readline, "")
        assert any(line.startswith("[1/") for line in lines)  # a file done: the workers run
        workers = children(parent.pid)
        assert len(workers) >= 2
        parent.kill()
        parent.wait()
        deadline = time.monotonic() + 10
        while any(alive(pid) for pid in workers) and time.monotonic() < deadline:
            time.sleep(0.1)
        assert not [pid for pid in workers if alive(pid)]
        assert [p for p in Path("out").rglob("*.tmp")] == []
    finally:
        for pid in workers:
            if alive(pid):
                os.kill(pid, signal.SIGKILL)
        parent.kill()


def _camtool(code: str) -> subprocess.CompletedProcess[str]:
    """Run ``code`` in a fresh interpreter (here) with this checkout first on the path."""
    paths = [str(ROOT), *filter(None, [os.environ.get("PYTHONPATH")])]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(paths)}
    return subprocess.run(
        [sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=300
    )


def test_the_command_with_a_local_cluster(drawings: Path) -> None:
    args = ["batch", "drawings/parts", "-t", "pic-mmh", "--verify"]
    assert main([*args, "-o", "ref", "-j", "1"]) == 3  # bad.dxf
    argv = [*args, "-o", "out", "--scheduler", "local:2"]
    proc = _camtool(f"import sys\nfrom camtool.cli.main import main\nsys.exit(main({argv!r}))")
    assert proc.returncode == 3, proc.stderr
    assert proc.stdout == "" and "Traceback" not in proc.stderr
    assert "4 file(s): 3 ok, 0 over the limit, 1 error(s)" in proc.stderr
    assert tree(Path("out")) == tree(Path("ref"))


def test_without_dask_the_pool_works_and_scheduler_says_how_to_install(
    drawings: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # sys.modules[name] = None makes `import distributed` fail as if it were not installed
    blocked = "import sys\nsys.modules['distributed'] = sys.modules['dask'] = None\n"
    run_main = "from camtool.cli.main import main\nsys.exit(main({!r}))"
    pool = ["batch", "drawings/parts/rect.dxf", "-t", "pic-mmh", "-o", "pool"]
    proc = _camtool(blocked + run_main.format(pool))
    assert proc.returncode == 0, proc.stderr
    proc = _camtool(blocked + run_main.format([*pool[:-1], "dask", "--scheduler", "local:2"]))
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.startswith(
        "camtool: error: --scheduler runs the batch on Dask, which is not installed: "
        "pip install 'camtool[cluster]'"
    )
    assert not Path("dask").exists()
    # the library says the same, before it touches the output folder
    from camtool.jobs import batch_dask

    real = batch_dask.importlib.util.find_spec
    monkeypatch.setattr(
        batch_dask.importlib.util,
        "find_spec",
        lambda name, *a: None if name == "distributed" else real(name, *a),
    )
    with pytest.raises(UsageError, match=r"pip install 'camtool\[cluster\]'"):
        run(["drawings"], targets="pic-mmh", output_dir="lib", scheduler="local:2")
    assert not Path("lib").exists()


def test_local_n_starts_no_more_workers_than_files() -> None:
    # a hostile local:1000 for one drawing must not start 1000 processes (--jobs caps the same way)
    from camtool.jobs.batch_dask import connect

    with connect("local:3", most_workers=1) as client:
        assert len(client.scheduler_info()["workers"]) == 1
