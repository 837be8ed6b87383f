"""Work done while waiting for another process (``cores.meanwhile``, ``cores.wait_readable``).

The other process is stood in for by a pipe: written to, it has answered; left empty, it
is still working. The expected order and counts follow from the contract alone.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator

import pytest

from camtool.accel import cores

# the accel layer's own tests: on, whatever the suite runs (one test switches it off)
pytestmark = pytest.mark.usefixtures("accel_on")


@pytest.fixture
def pipe() -> Iterator[tuple[int, int]]:
    read, write = os.pipe()
    try:
        yield read, write
    finally:
        os.close(read)
        os.close(write)


def _recorder(done: list[str], name: str) -> Callable[[], None]:
    return lambda: done.append(name)


def test_an_answered_wait_runs_no_task(pipe: tuple[int, int]) -> None:
    read, write = pipe
    os.write(write, b"x")
    done: list[str] = []
    with cores.meanwhile([_recorder(done, "a"), _recorder(done, "b")]):
        cores.wait_readable(read)
    assert done == []


def test_a_long_wait_runs_every_task_once_in_order(pipe: tuple[int, int]) -> None:
    read, _ = pipe
    done: list[str] = []
    with cores.meanwhile([_recorder(done, "a"), _recorder(done, "b"), _recorder(done, "c")]):
        cores.wait_readable(read)  # nothing answers: every task runs, then it returns
        cores.wait_readable(read)  # none is left to run a second time
    assert done == ["a", "b", "c"]


def test_the_wait_stops_running_tasks_once_answered(pipe: tuple[int, int]) -> None:
    read, write = pipe
    done: list[str] = []

    def answer() -> None:  # the other process answers while the first task runs
        done.append("a")
        os.write(write, b"x")

    with cores.meanwhile([answer, _recorder(done, "b")]):
        cores.wait_readable(read)
        assert done == ["a"]  # "b" waits for a later wait
        os.read(read, 1)
        cores.wait_readable(read)
    assert done == ["a", "b"]


def test_tasks_no_wait_ran_are_dropped_on_leaving(pipe: tuple[int, int]) -> None:
    read, _ = pipe
    done: list[str] = []
    with cores.meanwhile([_recorder(done, "a")]):
        pass
    cores.wait_readable(read)
    assert done == []


def test_a_failing_task_is_dropped_and_the_wait_goes_on(pipe: tuple[int, int]) -> None:
    read, _ = pipe
    done: list[str] = []

    def fail() -> None:
        done.append("fail")
        raise RuntimeError("a preload that does not load")

    with cores.meanwhile([fail, _recorder(done, "b")]):
        cores.wait_readable(read)
    assert done == ["fail", "b"]


def test_an_interrupt_in_a_task_is_not_swallowed(pipe: tuple[int, int]) -> None:
    read, _ = pipe

    def interrupt() -> None:
        raise KeyboardInterrupt

    with cores.meanwhile([interrupt]), pytest.raises(KeyboardInterrupt):
        cores.wait_readable(read)


@pytest.mark.skipif(not cores.FORK, reason="forked workers: Linux only")
def test_waiting_for_forked_work_runs_the_tasks(monkeypatch: pytest.MonkeyPatch) -> None:
    """``ForkedWork.answers`` waits for its workers by running the tasks; answers unchanged."""
    import time

    monkeypatch.setattr(cores, "default_jobs", lambda: 2)
    done: list[str] = []

    def slow(x: int) -> int:
        time.sleep(0.3)
        return x * x

    with cores.meanwhile([_recorder(done, "a"), _recorder(done, "b")]):
        work = cores.ForkedWork(slow, [1, 2, 3])
        assert done == []  # nothing runs until this process waits
        assert work.answers() == [1, 4, 9]
    assert done == ["a", "b"]
