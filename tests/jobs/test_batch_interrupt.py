"""Ctrl-C and SIGTERM stop a batch at once, keep the files finished whole, and say what is left.

The real runs post copies of the bundled samples for GRBL with ``--verify`` (a program ending
with its program end ``M2``, GRBL's ``M2``/``M30`` rule, and a JSON report per file), plus
one input that is a FIFO nobody writes: the file reading it never finishes, so the batch is
always mid-run when the signal comes, however fast or loaded this machine is. Nothing is
timed: the test waits for an output to appear before it signals, and allows the batch a
generous :data:`EXIT_BOUND_S` to exit (the design kills the workers at once; it takes well
under a second).
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from camtool.jobs.batch import BatchOptions, plan_batch, run_batch
from camtool.jobs.batch_plan import BatchInterrupted, BatchRow
from camtool.jobs.batch_report import unwritten_lines
from camtool.jobs.batch_stop import Interrupts, Terminated
from camtool.jobs.output import LOCK_NAME
from tests.jobs.test_batch import alive, children

ROOT = Path(__file__).parents[2]
SAMPLES = ROOT / "samples"
EXIT_BOUND_S = 30.0
"""How long a signalled batch may take to exit in these tests, s (it needs a fraction of one)."""
START_BOUND_S = 300.0
"""How long a batch may take to write its first output on a loaded machine, s."""
COPIES = 6
"""Copies of each sample in the folder (4 samples: 24 drawings)."""


@pytest.fixture
def drawings(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """drawings/: copies of the samples and ``00-stuck.ngc``, a FIFO no one ever writes."""
    monkeypatch.chdir(tmp_path)
    root = Path("drawings")
    root.mkdir()
    for sample in sorted(SAMPLES.glob("*.dxf")):
        for i in range(COPIES):
            shutil.copy(sample, root / f"{sample.stem}-{i}.dxf")
    os.mkfifo(root / "00-stuck.ngc")
    return root


@pytest.fixture(autouse=True)
def _signals_as_at_a_terminal() -> Iterator[None]:
    """Ctrl-C and SIGTERM have Python's default handlers here, however the suite was started.

    A suite started in the background by a non-interactive shell inherits SIGINT ignored,
    and a batch leaves an ignored signal alone (as after ``nohup``): these tests are of a
    batch run from a terminal.
    """
    previous = {
        signal.SIGINT: signal.signal(signal.SIGINT, signal.default_int_handler),
        signal.SIGTERM: signal.signal(signal.SIGTERM, signal.SIG_DFL),
    }
    yield
    for signum, handler in previous.items():
        signal.signal(signum, handler)


def _as_at_a_terminal() -> None:
    """In a child before ``exec``: SIGINT and SIGTERM at their defaults (see above)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


def _env() -> dict[str, str]:
    paths = [str(ROOT), *filter(None, [os.environ.get("PYTHONPATH")])]
    return {**os.environ, "PYTHONPATH": os.pathsep.join(paths)}


def _first_output(out: Path, process: subprocess.Popen[str]) -> None:
    """Wait until the batch has written a program (or has ended, which fails the test)."""
    deadline = time.monotonic() + START_BOUND_S
    while not any(out.rglob("*.gcode")):
        assert process.poll() is None, f"the batch ended before any output: {process.stderr}"
        assert time.monotonic() < deadline, "the batch wrote nothing"
        time.sleep(0.05)


def _signal_batch(where: list[str], signum: int, out: Path) -> tuple[int, str, list[int]]:
    """Run ``camtool batch`` (``where``: --jobs or --scheduler), signal it mid-run.

    Returns its exit code, its stderr and its child processes as they were when signalled.
    """
    argv = [sys.executable, "-m", "camtool", "batch", "drawings", "-t", "grbl", "-o", str(out)]
    process = subprocess.Popen(
        [*argv, "--verify", *where],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        env=_env(),
        preexec_fn=_as_at_a_terminal,
    )
    workers: list[int] = []
    try:
        _first_output(out, process)
        workers = children(process.pid)
        process.send_signal(signum)
        _, err = process.communicate(timeout=EXIT_BOUND_S)
        return process.returncode, err, workers
    finally:
        process.kill()
        for pid in workers:
            if alive(pid):
                os.kill(pid, signal.SIGKILL)


def _check_what_is_left(out: Path, err: str, signum: int, stuck: str = "00-stuck") -> None:
    """No temporary or lock; every program whole; the summary names what was and was not.

    ``stuck`` is the FIFO's name (its file never finishes); it is named among the files not
    posted when it is one of the first (those are named, the rest counted).
    """
    name = signal.Signals(signum).name
    assert "Traceback" not in err
    assert [p.name for p in out.rglob(".*")] == []  # no .NAME.camtool-PID.tmp, no lock
    programs = sorted(out.rglob("*.gcode"))
    assert programs
    for program in programs:
        lines = program.read_text().splitlines()
        assert lines[-1] == "M2", program  # GRBL's program end: the file is whole
        report = json.loads(program.with_suffix(".json").read_text())  # written with it
        assert report["target"] == "grbl"
    rows = [line.split() for line in err.splitlines() if line.startswith("drawings/")]
    table = {row[0]: row[1] for row in rows}  # the summary table: file, status, ...
    written = {p.stem for p in programs}
    assert {Path(f).stem for f, status in table.items() if status == "ok"} == written
    assert f"not posted (stopped by {name}): " in err
    if stuck.startswith("00"):
        assert f"  drawings/{stuck}.ngc\n" in err  # the file that never finished
    assert not (out / f"{stuck}.gcode").exists()
    assert f"camtool: error: stopped by {name} after {len(written)} of 25 file(s): " in err


@pytest.mark.parametrize(("signum", "code"), [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_a_signal_stops_a_pool_batch_at_once_keeping_whole_files(
    drawings: Path, signum: int, code: int
) -> None:
    out = Path("out")
    exit_code, err, workers = _signal_batch(["--jobs", "2"], signum, out)
    assert exit_code == code, err
    _check_what_is_left(out, err, signum)
    assert len(workers) == 2
    assert [pid for pid in workers if alive(pid)] == []  # killed and reaped, no orphan


def test_ctrl_c_at_a_terminal_reaches_the_workers_too_and_still_stops_cleanly(
    drawings: Path,
) -> None:
    # a terminal's Ctrl-C signals the whole foreground process group, workers included
    out = Path("out")
    argv = [sys.executable, "-m", "camtool", "batch", "drawings", "-t", "grbl", "-o", str(out)]
    process = subprocess.Popen(
        [*argv, "--verify", "--jobs", "2"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        env=_env(),
        start_new_session=True,
        preexec_fn=_as_at_a_terminal,
    )
    workers: list[int] = []
    try:
        _first_output(out, process)
        workers = children(process.pid)
        os.killpg(process.pid, signal.SIGINT)
        _, err = process.communicate(timeout=EXIT_BOUND_S)
    finally:
        process.kill()
        for pid in workers:
            if alive(pid):
                os.kill(pid, signal.SIGKILL)
    assert process.returncode == 130, err
    _check_what_is_left(out, err, signal.SIGINT)
    assert "KeyboardInterrupt" not in err  # no worker died on its own with a traceback
    assert [pid for pid in workers if alive(pid)] == []


def test_a_signal_stops_a_batch_on_a_local_dask_cluster_at_once(drawings: Path) -> None:
    pytest.importorskip("distributed")
    # the batch process reads each input for the cluster: the FIFO last, so that it is
    # read (and blocks this process) only once other files are done
    (drawings / "00-stuck.ngc").rename(drawings / "zz-stuck.ngc")
    out = Path("out")
    exit_code, err, workers = _signal_batch(["--scheduler", "local:2"], signal.SIGINT, out)
    assert exit_code == 130, err
    _check_what_is_left(out, err, signal.SIGINT, stuck="zz-stuck")
    assert workers
    deadline = time.monotonic() + EXIT_BOUND_S  # the workers' own exit, not the batch's
    while any(alive(pid) for pid in workers) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert [pid for pid in workers if alive(pid)] == []


# -- in this process: the claim, the rows, the signal held while a file is written ----------


def _plan(drawings: Path, jobs: int) -> Any:
    (drawings / "00-stuck.ngc").unlink()  # in this process every file must finish
    return plan_batch(["drawings"], BatchOptions(target="grbl", output_dir=Path("out"), jobs=jobs))


@pytest.mark.parametrize("jobs", [1, 2])
def test_an_interrupted_batch_says_which_files_it_wrote_and_releases_its_folder(
    drawings: Path, jobs: int
) -> None:
    plan = _plan(drawings, jobs)
    seen: list[BatchRow] = []

    def progress(done: int, total: int, row: BatchRow) -> None:
        seen.append(row)
        if done == 3:
            os.kill(os.getpid(), signal.SIGINT)  # Ctrl-C after the third file

    with pytest.raises(BatchInterrupted) as caught:
        run_batch(plan, progress=progress)
    stop = caught.value
    assert stop.exit_code == 130 and stop.signal_name == "SIGINT"
    assert sorted(r.file for r in stop.result.rows) == sorted(r.file for r in seen)
    assert len(stop.result.rows) == 3 and len(stop.unwritten) == len(plan.tasks) - 3
    assert {t.file for t in stop.unwritten}.isdisjoint(r.file for r in seen)
    assert sorted(Path("out").rglob("*.gcode")) == sorted(Path(r.code_path) for r in seen)
    assert not (Path("out") / LOCK_NAME).exists()
    assert [p for p in Path("out").rglob(".*")] == []
    assert unwritten_lines(stop).startswith(
        f"not posted (stopped by SIGINT): {len(plan.tasks) - 3}"
    )
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # restored


def test_sigterm_raises_as_ctrl_c_does_with_its_own_exit_code(drawings: Path) -> None:
    plan = _plan(drawings, 1)

    def progress(done: int, total: int, row: BatchRow) -> None:
        os.kill(os.getpid(), signal.SIGTERM)

    with pytest.raises(BatchInterrupted) as caught:
        run_batch(plan, progress=progress)
    assert caught.value.exit_code == 143 and caught.value.signal_name == "SIGTERM"
    assert len(caught.value.result.rows) == 1
    assert signal.getsignal(signal.SIGTERM) == signal.SIG_DFL  # restored


def test_a_signal_while_a_file_is_written_waits_until_it_is_written_and_recorded() -> None:
    written: list[str] = []
    with Interrupts() as interrupts, pytest.raises(KeyboardInterrupt):
        with interrupts.held():
            os.kill(os.getpid(), signal.SIGINT)
            written.append("code")  # the signal came: the rest is still written
            os.kill(os.getpid(), signal.SIGINT)  # a second Ctrl-C changes nothing
            written.append("report")
        written.append("never")
    assert written == ["code", "report"]


def test_signals_after_the_first_are_ignored_while_the_batch_stops() -> None:
    stopped: list[str] = []
    with Interrupts():
        with pytest.raises(Terminated):
            os.kill(os.getpid(), signal.SIGTERM)
            pytest.fail("the signal did not stop the block")
        os.kill(os.getpid(), signal.SIGINT)  # while cleaning up: ignored
        stopped.append("cleaned up")
    assert stopped == ["cleaned up"]


def test_a_handler_the_caller_installed_is_left_alone() -> None:
    calls: list[int] = []
    previous = signal.signal(signal.SIGINT, lambda signum, frame: calls.append(signum))
    try:
        with Interrupts():
            os.kill(os.getpid(), signal.SIGINT)
        assert calls == [signal.SIGINT]
    finally:
        signal.signal(signal.SIGINT, previous)
