"""ForkedWork: a job's independent pieces in forked workers, answers in order, errors as without.

The expected values are the plain ``[fn(x) for x in items]`` run in the test's own process;
that the work was done elsewhere is shown by the pids that did it.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import threading
from collections.abc import Iterator
from pathlib import Path

import pytest

from camtool.accel import cores
from camtool.accel.cores import ForkedWork
from camtool.model.errors import InputError

pytestmark = [
    pytest.mark.skipif(not cores.FORK, reason="forked workers: Linux only"),
    # the accel layer's own tests: on, whatever the suite runs (one test switches it off)
    pytest.mark.usefixtures("accel_on"),
]


def test_answers_come_back_in_order_from_other_processes(tmp_path: Path) -> None:
    """A closure over this process's state (not picklable) runs in the workers, in order."""
    state = {"scale": 3}  # only a fork sees it: nothing is pickled on the way in
    seen = tmp_path / "pids"

    def work(x: int) -> tuple[int, float]:
        with seen.open("a") as note:
            note.write(f"{os.getpid()}\n")
        return x * state["scale"], x / 7.0

    items = list(range(9))
    told: list[int] = []
    got = ForkedWork(work, items, jobs=2).answers(told.append)
    assert got == [(x * 3, x / 7.0) for x in items]  # every float bit kept
    pids = set(seen.read_text().split())
    assert str(os.getpid()) not in pids and 1 <= len(pids) <= 2
    assert told == list(range(1, 10))


def test_one_job_or_one_item_runs_here(tmp_path: Path) -> None:
    pids: list[int] = []

    def work(x: int) -> int:
        pids.append(os.getpid())  # seen here only when it runs here
        return x + 1

    assert ForkedWork(work, [1, 2, 3], jobs=1).answers() == [2, 3, 4]
    assert ForkedWork(work, [5]).answers() == [6]
    assert pids == [os.getpid()] * 4


def test_the_first_error_is_raised_here_as_without_workers() -> None:
    """Items 2 and 4 fail in their workers; item 2's error is raised here, like a plain loop."""
    ran_here: list[int] = []

    def work(x: int) -> int:
        if x in (2, 4):
            if os.getpid() == parent:
                ran_here.append(x)
            raise InputError(f"item {x} is bad")
        return x

    parent = os.getpid()
    with pytest.raises(InputError, match="item 2 is bad"):
        ForkedWork(work, list(range(6)), jobs=2).answers()
    assert ran_here == [2]  # run again here, in order, and it stopped there


def test_a_worker_that_dies_has_its_item_made_here() -> None:
    """SIGKILL in a worker (a crash): that item is made in this process, the answers whole."""
    parent = os.getpid()

    def work(x: int) -> int:
        if x == 3 and os.getpid() != parent:
            os.kill(os.getpid(), signal.SIGKILL)
        return x * x

    assert ForkedWork(work, list(range(8)), jobs=2).answers() == [x * x for x in range(8)]


def test_an_answer_that_cannot_pickle_is_made_here() -> None:
    parent = os.getpid()

    def work(x: int) -> object:
        if os.getpid() != parent:
            return lambda: x  # a lambda does not pickle
        return ("here", x)

    assert ForkedWork(work, [1, 2], jobs=2).answers() == [("here", 1), ("here", 2)]


def _in_a_child(queue: multiprocessing.Queue) -> None:  # type: ignore[type-arg]
    queue.put((cores.in_worker(), ForkedWork(lambda x: (x, os.getpid()), [1, 2], jobs=2).answers()))


def test_a_worker_process_runs_its_items_itself() -> None:
    """In a process that is itself a worker (a batch's pool), no workers of its own."""
    context = multiprocessing.get_context("fork")
    queue = context.Queue()
    child = context.Process(target=_in_a_child, args=(queue,))
    child.start()
    worker, got = queue.get(timeout=60)
    child.join(timeout=60)
    assert worker is True
    assert [x for x, _ in got] == [1, 2] and got[0][1] == got[1][1] == child.pid
    assert not cores.in_worker()


def test_forked_work_runs_while_this_process_works(tmp_path: Path) -> None:
    """ForkedWork forks at once; its workers see the state of then, not what changes after."""
    from camtool.accel.cores import ForkedWork

    state = {"offset": 10}
    started = tmp_path / "started"

    def work(x: int) -> int:
        with started.open("a") as note:
            note.write(f"{x}\n")
        return x + state["offset"]

    with ForkedWork(work, [1, 2, 3], jobs=2) as pending:
        state["offset"] = 1000  # this process goes on; the workers were forked before
        got = pending.answers()
    assert got == [11, 12, 13]
    assert sorted(started.read_text().split()) == ["1", "2", "3"]


def test_leaving_forked_work_on_an_error_leaves_no_worker() -> None:
    """An error raised here while the workers run: the with-block stops them, none is left."""
    from camtool.accel.cores import ForkedWork

    pids: list[int] = []
    pending = ForkedWork(lambda x: x, list(range(4)), jobs=2)
    with pytest.raises(RuntimeError, match="this process failed"), pending:
        assert pending._pool is not None
        pids.extend(pending._pool._processes)  # type: ignore[attr-defined]
        raise RuntimeError("this process failed")
    assert pending._pool is None
    for pid in pids:
        with pytest.raises(ChildProcessError):
            os.waitpid(pid, os.WNOHANG)  # reaped: not a child any more


def _threads_named(name: str) -> list[threading.Thread]:
    return [t for t in threading.enumerate() if t.name == name]


def test_ahead_gives_the_items_in_order_each_made_in_its_thread(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(cores, "default_jobs", lambda: 2)
    makers: list[str] = []

    def made() -> Iterator[int]:
        for k in range(50):
            makers.append(threading.current_thread().name)
            yield k

    assert list(cores.ahead(made())) == list(range(50))
    assert set(makers) == {"camtool-ahead"}
    assert not _threads_named("camtool-ahead")  # joined


def test_ahead_raises_an_error_at_its_place(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(cores, "default_jobs", lambda: 2)

    def made() -> Iterator[int]:
        yield 1
        yield 2
        raise InputError("line 3: no")

    got: list[int] = []
    with pytest.raises(InputError, match="line 3: no"):
        for item in cores.ahead(made()):
            got.append(item)
    assert got == [1, 2]
    assert not _threads_named("camtool-ahead")


def test_leaving_ahead_early_stops_and_closes_the_maker(monkeypatch: pytest.MonkeyPatch) -> None:
    """At most one item is made past the one the caller stopped at; the generator is closed."""
    monkeypatch.setattr(cores, "default_jobs", lambda: 2)
    started: list[int] = []
    closed: list[bool] = []

    def made() -> Iterator[int]:
        try:
            for k in range(1000):
                started.append(k)
                yield k
        finally:
            closed.append(True)

    for item in cores.ahead(made()):
        if item == 3:
            break
    assert not _threads_named("camtool-ahead")
    assert closed == [True]
    assert max(started) <= 5  # 3 taken, one in the queue, one being handed


def test_ahead_makes_the_items_here_in_a_worker_or_on_one_core(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    for jobs, worker in ((1, False), (2, True)):
        monkeypatch.setattr(cores, "default_jobs", lambda jobs=jobs: jobs)
        monkeypatch.setattr(cores, "in_worker", lambda worker=worker: worker)
        makers: list[str] = []

        def made(makers: list[str] = makers) -> Iterator[int]:
            for k in range(3):
                makers.append(threading.current_thread().name)
                yield k

        assert list(cores.ahead(made())) == [0, 1, 2]
        assert set(makers) == {threading.current_thread().name}


def test_beside_makes_the_answer_in_its_thread_and_raises_its_error_where_taken(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setattr(cores, "default_jobs", lambda: 2)
    monkeypatch.setattr(cores, "in_worker", lambda: False)
    release = threading.Event()
    makers: list[str] = []

    def make() -> int:
        makers.append(threading.current_thread().name)
        release.wait(10)
        return 42

    later = cores.beside(make)
    assert _threads_named("camtool-beside")  # started at once, this thread goes on
    release.set()
    assert later.result() == 42
    assert later.result() == 42  # taken again: the same answer, not made again
    assert makers == ["camtool-beside"]
    assert not _threads_named("camtool-beside")

    def fail() -> int:
        raise InputError("tree: no")

    failed = cores.beside(fail)
    failed.join()  # waiting raises nothing: the error is the answer's
    assert not _threads_named("camtool-beside")
    with pytest.raises(InputError, match="tree: no"):
        failed.result()


@pytest.mark.parametrize("how", ["one core", "worker", "off"])
def test_beside_without_a_thread_makes_the_answer_only_when_asked(
    how: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(cores, "default_jobs", lambda: 1 if how == "one core" else 2)
    monkeypatch.setattr(cores, "in_worker", lambda: how == "worker")
    if how == "off":
        monkeypatch.setenv("CAMTOOL_ACCEL", "0")
    made: list[str] = []

    def make() -> int:
        made.append(threading.current_thread().name)
        return 7

    never = cores.beside(make)
    never.join()
    assert made == []  # not asked for: never made
    assert cores.beside(make).result() == 7
    assert made == [threading.current_thread().name]


def _no_fork() -> int:
    raise BlockingIOError(11, "Resource temporarily unavailable")


def test_a_failed_fork_leaves_no_pipe_open(monkeypatch: pytest.MonkeyPatch) -> None:
    from camtool.accel.cores import fork_with_pipes

    before = sorted(os.listdir("/proc/self/fd"))
    monkeypatch.setattr(os, "fork", _no_fork)
    with pytest.raises(BlockingIOError):
        fork_with_pipes(lambda inbox, out: None)
    assert sorted(os.listdir("/proc/self/fd")) == before


def test_fork_with_pipes_joins_the_child(monkeypatch: pytest.MonkeyPatch) -> None:
    from camtool.accel.cores import end_process, fork_with_pipes, read_record, write_record

    def echo(inbox: int, out: int) -> None:
        data = read_record(inbox)
        assert data is not None
        write_record(out, data[::-1])

    pid, to_child, from_child = fork_with_pipes(echo)
    write_record(to_child, b"G1 X1")
    assert read_record(from_child) == b"1X 1G"
    os.close(to_child)
    os.close(from_child)
    assert end_process(pid) == 0


def test_post_with_offsets_and_a_png_when_no_process_can_be_forked(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    # Under a process limit or out of memory, the offsets' child, its workers, the
    # picture's child and the budget's workers cannot start: the job is done here, the
    # same program and picture (not "internal error: BlockingIOError").
    from camtool.cli.main import main

    plate = Path(__file__).resolve().parents[2] / "samples" / "plate.dxf"
    args = ["post", str(plate), "-t", "grbl", "--offset", "outside", "--tool-diameter", "3"]
    args += ["--origin", "lower-left"]

    def run(name: str) -> tuple[bytes, bytes]:
        out, png = tmp_path / f"{name}.gcode", tmp_path / f"{name}.png"
        assert main([*args, "-o", str(out), "--preview", str(png)]) == 0, capsys.readouterr()
        return out.read_bytes(), png.read_bytes()

    forked = run("forked")
    monkeypatch.setattr(os, "fork", _no_fork)
    assert run("here") == forked


def test_switched_off_every_item_runs_here_in_order(monkeypatch: pytest.MonkeyPatch) -> None:
    """``CAMTOOL_ACCEL=0``: no worker is forked and no thread made; the same answers."""
    from camtool.accel import SWITCH

    monkeypatch.setenv(SWITCH, "0")
    monkeypatch.setattr(cores, "default_jobs", lambda: 2)
    here = os.getpid()
    assert ForkedWork(lambda x: (x, os.getpid()), [1, 2, 3], jobs=2).answers() == [
        (1, here),
        (2, here),
        (3, here),
    ]
    makers: list[str] = []

    def made() -> Iterator[int]:
        for i in range(3):
            makers.append(threading.current_thread().name)
            yield i

    assert list(cores.ahead(made())) == [0, 1, 2]
    assert set(makers) == {threading.current_thread().name}


def test_a_record_not_there_by_the_deadline_is_none() -> None:
    import time

    read, write = os.pipe()
    try:
        t0 = time.monotonic()
        assert cores.read_record(read, time.monotonic() + 0.2) is None  # nothing came
        assert time.monotonic() - t0 >= 0.2  # it waited until the deadline
        cores.write_record(write, b"answer")
        assert cores.read_record(read, time.monotonic() + 5.0) == b"answer"
        os.write(write, (6).to_bytes(8, "little") + b"ans")  # cut short: the rest never comes
        assert cores.read_record(read, time.monotonic() + 0.2) is None
    finally:
        os.close(read)
        os.close(write)


def test_patience_grows_with_the_work_done_since_the_fork(monkeypatch: pytest.MonkeyPatch) -> None:
    from types import SimpleNamespace

    monkeypatch.setattr(cores, "time", SimpleNamespace(monotonic=lambda: 1000.0))
    assert cores.patience(1000.0) == 1000.0 + cores.HELPER_PATIENCE_MIN_S  # just forked
    assert cores.patience(1000.0 - 1.0) == 1000.0 + cores.HELPER_PATIENCE_MIN_S
    assert cores.patience(1000.0 - 100.0) == 1000.0 + cores.HELPER_PATIENCE * 100.0
