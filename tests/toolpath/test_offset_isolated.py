"""OpenCASCADE's offsets are made in a forked child that a crash cannot take the job down with.

OCCT's 2D offset segfaulted on real drawings (Tango's ``filequickprint.svg`` and
``mail-mark-junk.svg`` with ``--offset outside --tool-diameter 1``): the process died with
SIGSEGV, no message. :func:`camtool.toolpath.offset.offset_all` makes the offsets in
workers forked by a child; a job whose worker dies gets a ToolpathError (the planner falls
back to shapely's buffer, with a warning) and the jobs after it are made by a new worker
of the same child. The answers are those of the parent, bit for bit.
"""

from __future__ import annotations

import os
import pickle
import signal
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from camtool.model.errors import ToolpathError
from camtool.model.shapes import Contour
from camtool.toolpath import offset as offset_module
from camtool.toolpath.compensate import compensate
from camtool.toolpath.offset import offset_all, offset_pieces
from camtool.toolpath.options import PlanOptions
from camtool.toolpath.order import nesting
from tests.corpus.conftest import CORPUS, FETCH_HINT, load_manifest
from tests.toolpath.contours import circle, dumbbell, l_shape, rect

pytestmark = pytest.mark.skipif(not offset_module.FORK, reason="offsets in a child: Linux only")

JOBS = [(circle(0, 0, 5), 1.0), (rect(0, 0, 10, 5), 0.5), (l_shape(), -1.0), (dumbbell(), -1.2)]


def _same(a: list[Contour] | ToolpathError, b: list[Contour] | ToolpathError) -> bool:
    """Bit for bit: the same pieces (every float) or the same error message."""
    if isinstance(a, ToolpathError) or isinstance(b, ToolpathError):
        return str(a) == str(b)
    return pickle.dumps([p.segments for p in a]) == pickle.dumps([p.segments for p in b])


def test_the_child_answers_what_this_process_answers(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    here, made_by = _made_elsewhere(monkeypatch, tmp_path, JOBS)
    monkeypatch.setattr(offset_module, "_workers", lambda jobs: 1)
    there = offset_all(JOBS)
    assert len(there) == len(JOBS)
    assert all(_same(x, y) for x, y in zip(here, there, strict=True))
    pids = made_by()
    assert len(pids) == len(JOBS) and len(set(pids)) == 1  # one worker made them all
    maker, its_parent = pids[0].split(":")
    assert str(os.getpid()) not in (maker, its_parent)  # a child's, not this process


def _noting(made_by: Path) -> Any:
    """OCCT's offset, noting ``pid:parent pid`` of the process that makes each."""
    real = offset_module._occt_offset

    def occt(contour: Contour, amount: float) -> Any:
        with made_by.open("a") as note:
            note.write(f"{os.getpid()}:{os.getppid()}\n")
        return real(contour, amount)

    return occt


def _made_elsewhere(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, jobs: list[tuple[Contour, float]]
) -> tuple[list[list[Contour] | ToolpathError], Callable[[], list[str]]]:
    """``jobs``' offsets made here first (the expected answers), then OpenCASCADE's offset
    patched to note ``pid:parent pid`` of each process making one; gives the answers and
    the reader of those notes."""
    here = [offset_pieces(c, a) for c, a in jobs]
    made_by = tmp_path / "pids"
    monkeypatch.setattr(offset_module, "_occt_offset", _noting(made_by))
    return here, lambda: made_by.read_text().split()


def _segfault_on(amount: float) -> Any:
    real = offset_module._occt_offset

    def occt(contour: Contour, asked: float) -> Any:
        if asked == amount:
            os.kill(os.getpid(), signal.SIGSEGV)  # what OCCT did to the whole job
        return real(contour, asked)

    return occt


@pytest.mark.parametrize("ahead", [False, True], ids=["forked-then", "started-ahead"])
def test_a_crash_in_the_child_fails_its_job_only(
    monkeypatch: pytest.MonkeyPatch, ahead: bool
) -> None:
    expected = [offset_pieces(c, a) for c, a in JOBS]
    monkeypatch.setattr(offset_module, "_occt_offset", _segfault_on(0.5))
    if ahead:
        monkeypatch.setattr(offset_module, "CHILDREN", offset_module._Children())
        monkeypatch.setattr(offset_module, "_occt_here", lambda: False)  # a fresh job
        offset_module.start_ahead()
        assert offset_module.CHILDREN.ahead is not None
    got = offset_all(JOBS)
    assert offset_module.CHILDREN.ahead is None
    assert len(got) == len(JOBS)
    crashed = got[1]
    assert isinstance(crashed, ToolpathError)
    assert "crashed (SIGSEGV, signal 11)" in str(crashed) and "+0.5 mm" in str(crashed)
    for k in (0, 2, 3):  # before it, and made by a new child after it
        assert _same(got[k], expected[k])


def _endless_on(amount: float) -> Any:
    """OpenCASCADE running on without end for ``amount`` (as it ran 362 s on a gear of
    boxes.py's Planetary2 example before failing)."""
    real = offset_module._occt_offset

    def occt(contour: Contour, asked: float) -> Any:
        if asked == amount:
            signal.pause()  # until the worker is killed
        return real(contour, asked)

    return occt


@pytest.mark.parametrize("workers", [1, 2])
def test_a_job_past_its_limit_is_stopped_and_the_others_answered(
    monkeypatch: pytest.MonkeyPatch, workers: int
) -> None:
    """The endless job gets an error naming its limit; the jobs after it, this process's
    answers (made by a new worker); the limit of every other job is an hour (no timing)."""
    expected = [offset_pieces(c, a) for c, a in JOBS]
    stuck = JOBS[1][0]
    monkeypatch.setattr(offset_module, "_occt_offset", _endless_on(JOBS[1][1]))
    monkeypatch.setattr(offset_module, "occt_limit", lambda c: 1.0 if c == stuck else 3600.0)
    monkeypatch.setattr(offset_module, "_workers", lambda jobs: workers)
    got = offset_all(JOBS)
    assert len(got) == len(JOBS)
    late = got[1]
    assert isinstance(late, ToolpathError)
    assert "offset by +0.5 mm stopped: OpenCASCADE did not finish it within 1 s" in str(late)
    for k in (0, 2, 3):
        assert _same(got[k], expected[k])


def test_the_planner_falls_back_where_a_job_was_stopped(monkeypatch: pytest.MonkeyPatch) -> None:
    contours = [rect(0, 0, 20, 20), circle(10, 10, 3)]  # a plate with a hole
    options = PlanOptions(offset="outside", tool_diameter=2.0, feed_mm_min=100.0)
    monkeypatch.setattr(offset_module, "_occt_offset", _endless_on(-1.0))  # the hole's
    hole = contours[1]
    monkeypatch.setattr(offset_module, "occt_limit", lambda c: 1.0 if c == hole else 3600.0)
    monkeypatch.setattr(offset_module, "_workers", lambda jobs: 2)
    stage = compensate(contours, nesting(contours), options)
    (fallback,) = [f for f in stage.findings if f.kind == "offset-fallback"]
    assert "did not finish it within 1 s" in fallback.message
    assert "used shapely's buffer" in fallback.message
    assert any(c.group == 1 for c in stage.cuts)  # the hole is still cut


MANY = [(circle(0, 0, 1 + k), 0.25 + k / 64) for k in range(24)]
CRASHING = {0.25 + k / 64 for k in range(24) if k % 3 != 1}  # 16 of 24, the first and last


@pytest.mark.parametrize("workers", [1, 2])
def test_many_crashes_are_answered_by_one_child(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path, workers: int
) -> None:
    """Each crash costs a new worker of the same child, not a new child (issue 17).

    Inkscape's ``filters.svg`` fitted to 299 × 199 mm and grown by 1 mm crashed OCCT on 438
    of 1 752 contours; each crash forked a new child of the job's 1.3 GB process, which
    loaded OpenCASCADE again and was sent every job left: over 25 minutes. Here two jobs in
    three crash, with one worker or two at once: every crash is its job's error, every
    other job is this process's answer, in order, and only one child was started.
    """
    expected = [offset_pieces(c, a) for c, a in MANY]
    real = offset_module._occt_offset

    def occt(contour: Contour, asked: float) -> Any:
        if asked in CRASHING:
            os.kill(os.getpid(), signal.SIGSEGV)
        return real(contour, asked)

    started = []

    class Counted(offset_module._Child):
        def __init__(self) -> None:
            super().__init__()
            started.append(self.pid)

    monkeypatch.setattr(offset_module, "_occt_offset", occt)
    monkeypatch.setattr(offset_module, "_Child", Counted)
    monkeypatch.setattr(offset_module, "_workers", lambda jobs: workers)
    got = offset_all(MANY)
    assert len(started) == 1
    assert len(got) == len(MANY)
    for (_, amount), answer, here in zip(MANY, got, expected, strict=True):
        if amount in CRASHING:
            assert isinstance(answer, ToolpathError)
            assert f"offset by {amount:+.4g} mm crashed (SIGSEGV, signal 11)" in str(answer)
        else:
            assert _same(answer, here)


def test_a_large_job_is_made_by_two_workers_at_once(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    """Jobs of PARALLEL_SEGMENTS or more on two cores: two workers, the same answers in order."""
    expected, made_by = _made_elsewhere(monkeypatch, tmp_path, MANY)
    monkeypatch.setattr(offset_module, "default_jobs", lambda: 2)
    monkeypatch.setattr(offset_module, "in_worker", lambda: False)
    segments = sum(len(c.segments) for c, _ in MANY)
    monkeypatch.setattr(offset_module, "PARALLEL_SEGMENTS", segments)
    assert offset_module._workers(MANY) == 2
    assert offset_module._workers(MANY[1:]) == 1  # one contour fewer: too few segments
    got = offset_all(MANY)
    assert all(_same(x, y) for x, y in zip(got, expected, strict=True))
    makers = {line.split(":")[0] for line in made_by()}
    assert len(makers) == 2 and str(os.getpid()) not in makers


TWO_WORKERS = """
import time
from camtool.toolpath import offset
from tests.toolpath.contours import circle, rect
jobs = [(circle(0, 0, 5), 1.0), (rect(0, 0, 10, 5), 0.5)]
here = [offset.offset_pieces(c, a) for c, a in jobs]
real = offset._occt_offset
def occt(contour, asked):
    if asked == 0.5:
        time.sleep(0.5)  # the second job is slow: the first worker is ended first
    return real(contour, asked)
offset._occt_offset = occt
offset._workers = lambda jobs: 2
got = offset.offset_all(jobs)
print([[p.segments for p in a] for a in got] == [[p.segments for p in a] for a in here])
"""


def test_two_workers_end_whichever_finishes_first() -> None:
    """The first worker done is ended while the second still works: no deadlock.

    The second worker was forked holding the first one's pipe of job indices: ending the
    first left its pipe open there, and the child waited for it for ever (LinuxCNC's
    ``Chip_Linuxcnc.svg`` with ``--offset outside`` hung one run in two). In a fresh
    interpreter of its own session, killed whole if it hangs.
    """
    root = Path(__file__).resolve().parents[2]
    run = subprocess.Popen(
        [sys.executable, "-c", TWO_WORKERS],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=root,
        start_new_session=True,
    )
    try:
        out, err = run.communicate(timeout=120)
    except subprocess.TimeoutExpired:
        os.killpg(run.pid, signal.SIGKILL)  # it, its child and the workers
        run.communicate()
        pytest.fail("offset_all with two workers hung")
    assert run.returncode == 0, err[-2000:]
    assert out.split() == ["True"]


def _same_result(a: Any, b: Any) -> bool:
    """Two OffsetResults bit for bit: the same pieces (every float), the same fallback."""
    return pickle.dumps((a.pieces, a.fallback)) == pickle.dumps((b.pieces, b.fallback))


@pytest.mark.parametrize("workers", [1, 2])
def test_with_a_tolerance_the_workers_answer_the_checked_offset(
    monkeypatch: pytest.MonkeyPatch, workers: int
) -> None:
    """offset_all(…, tolerance) answers offset_checked's result, fallbacks included.

    The l-shape's offset is refused (OpenCASCADE's error), so its worker falls back to the
    fitted buffer there; every result equals this process's offset_checked bit for bit.
    """
    real = offset_module._occt_offset

    def refuses_the_l(contour: Contour, amount: float) -> Any:
        if amount == -1.0:
            raise RuntimeError("StdFail_NotDone")
        return real(contour, amount)

    monkeypatch.setattr(offset_module, "_occt_offset", refuses_the_l)
    monkeypatch.setattr(offset_module, "_workers", lambda jobs: workers)
    here = [offset_module.offset_checked(c, a, 0.01) for c, a in JOBS]
    assert here[2].fallback is not None and here[0].fallback is None
    got = offset_all(JOBS, tolerance=0.01)
    assert all(isinstance(g, offset_module.OffsetResult) for g in got)
    assert all(_same_result(g, h) for g, h in zip(got, here, strict=True))


def test_a_check_that_raises_in_the_worker_is_made_again_here(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Where offset_checked raised in the worker, the answer is OpenCASCADE's own pieces,
    so that the job's process checks them itself and meets the error at its place."""

    def broken(*args: Any) -> Any:
        raise ArithmeticError("a check that fails")

    monkeypatch.setattr(offset_module, "_disagreement", broken)
    (got,) = offset_all(JOBS[:1], tolerance=0.01)
    assert isinstance(got, list) and _same(got, offset_pieces(*JOBS[0]))


def test_an_error_in_the_child_comes_back_as_the_error(monkeypatch: pytest.MonkeyPatch) -> None:
    def refuses(contour: Contour, amount: float) -> Any:
        raise RuntimeError("StdFail_NotDone")

    monkeypatch.setattr(offset_module, "_occt_offset", refuses)
    (got,) = offset_all(JOBS[:1])
    assert isinstance(got, ToolpathError)
    with pytest.raises(ToolpathError) as here:
        offset_pieces(*JOBS[0])
    assert str(got) == str(here.value)


def test_an_edge_occt_cannot_measure_is_a_toolpath_error(monkeypatch: pytest.MonkeyPatch) -> None:
    """OCCT's Standard_ConstructionError measuring an edge escaped as an internal error."""

    def unmeasurable(edge: Any, contour: Contour) -> Any:
        raise ArithmeticError("Standard_ConstructionError")

    monkeypatch.setattr(offset_module, "_from_edge", unmeasurable)
    with pytest.raises(ToolpathError, match=r"cannot measure \(ArithmeticError\)"):
        offset_pieces(*JOBS[0])


def test_the_planner_falls_back_where_the_child_crashed(monkeypatch: pytest.MonkeyPatch) -> None:
    contours = [rect(0, 0, 20, 20), circle(10, 10, 3)]  # a plate with a hole
    options = PlanOptions(offset="outside", tool_diameter=2.0, feed_mm_min=100.0)
    calm = compensate(contours, nesting(contours), options)
    assert not any(f.kind == "offset-fallback" for f in calm.findings)
    monkeypatch.setattr(offset_module, "_occt_offset", _segfault_on(-1.0))  # the hole's
    stage = compensate(contours, nesting(contours), options)
    (fallback,) = [f for f in stage.findings if f.kind == "offset-fallback"]
    assert "crashed (SIGSEGV, signal 11)" in fallback.message
    assert "used shapely's buffer" in fallback.message
    plate = [c for c in stage.cuts if c.group == 0]
    assert [c.path.segments for c in plate] == [c.path.segments for c in calm.cuts if c.group == 0]
    assert any(c.group == 1 for c in stage.cuts)  # the hole is still cut


TANGO = CORPUS / "pkg" / "tango-icon-theme" / "usr" / "share" / "icons" / "Tango" / "scalable"


@pytest.mark.parametrize("icon", ["actions/filequickprint.svg", "actions/mail-mark-junk.svg"])
def test_tango_icons_that_crashed_opencascade_are_posted(icon: str, tmp_path: Path) -> None:
    source = TANGO / icon
    if load_manifest() is None or not source.exists():
        pytest.skip(FETCH_HINT)
    out = tmp_path / "icon.gcode"
    done = subprocess.run(
        [
            *(sys.executable, "-m", "camtool", "post", str(source), "--target", "grbl"),
            *("--tool-diameter", "1", "--offset", "outside", "-o", str(out)),
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    assert "crashed (SIGSEGV, signal 11)" in done.stderr
    assert out.read_text().count("\n") > 100


ONE_JOB = """
import sys
from camtool.toolpath.offset import offset_all
from tests.toolpath.contours import circle, rect
jobs = [(circle(0, 0, 5), 1.0), (rect(0, 0, 10, 5), 0.5)]
first = offset_all(jobs)
held = "OCP" in sys.modules
second = offset_all(jobs)
same = [[p.segments for p in a] for a in first] == [[p.segments for p in a] for a in second]
print(held, "OCP" in sys.modules, same)
"""


def test_one_job_leaves_opencascade_to_its_child() -> None:
    """The process of one job never loads OCP (~230 MB); one that offsets again loads it once.

    A fresh interpreter, since this one may hold OCP from other tests: after the first
    ``offset_all`` OCP is not in ``sys.modules``, after the second it is (so the children
    of a ``batch --jobs 1`` inherit it), and both give the same pieces.
    """
    root = Path(__file__).resolve().parents[2]
    done = subprocess.run(
        [sys.executable, "-c", ONE_JOB], capture_output=True, text=True, cwd=root, timeout=300
    )
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.split() == ["False", "True", "True"]


def test_a_child_started_ahead_makes_the_offsets(
    monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    """start_ahead's child (OpenCASCADE loaded while the job reads and plans) makes them all.

    The same pieces as this process makes, bit for bit, made by one worker that very child
    forked; it is used once and gone afterwards.
    """
    here, made_by = _made_elsewhere(monkeypatch, tmp_path, JOBS)
    monkeypatch.setattr(offset_module, "_workers", lambda jobs: 1)
    monkeypatch.setattr(offset_module, "CHILDREN", offset_module._Children())
    monkeypatch.setattr(offset_module, "_occt_here", lambda: False)  # a fresh job
    offset_module.start_ahead()
    ahead = offset_module.CHILDREN.ahead
    assert ahead is not None
    pid = ahead.pid
    there = offset_all(JOBS)
    assert all(_same(x, y) for x, y in zip(here, there, strict=True))
    makers = made_by()
    assert len(makers) == len(JOBS) and len(set(makers)) == 1  # one worker of that child
    assert pid is not None and makers[0].split(":")[1] == str(pid)
    assert offset_module.CHILDREN.ahead is None and ahead.pid is None  # used, then waited for
    offset_module.start_ahead()  # not again: this process has made its offsets
    assert offset_module.CHILDREN.ahead is None


def test_a_child_started_ahead_and_not_used_is_stopped(monkeypatch: pytest.MonkeyPatch) -> None:
    """A drawing with nothing to offset: stop_ahead ends the child, no process is left."""
    monkeypatch.setattr(offset_module, "CHILDREN", offset_module._Children())
    monkeypatch.setattr(offset_module, "_occt_here", lambda: False)  # a fresh job
    contours = [rect(0, 0, 20, 20)]
    with_tool = PlanOptions(offset="outside", tool_diameter=2.0, feed_mm_min=100.0)
    from camtool.toolpath.compensate import offsets_ahead

    with offsets_ahead(PlanOptions(offset="on", feed_mm_min=100.0)):
        assert offset_module.CHILDREN.ahead is None  # --offset on: no offsets to make
    with offsets_ahead(with_tool):
        ahead = offset_module.CHILDREN.ahead
        assert ahead is not None
        pid = ahead.pid
        assert pid is not None
    assert offset_module.CHILDREN.ahead is None
    with pytest.raises(ChildProcessError):
        os.waitpid(pid, os.WNOHANG)  # already waited for: no such child
    with offsets_ahead(with_tool):
        stage = compensate(contours, nesting(contours), with_tool)
    assert offset_module.CHILDREN.ahead is None
    assert not any(f.kind == "offset-fallback" for f in stage.findings)


BATCH_ONE_BY_ONE = """
import sys
from collections.abc import Callable
from pathlib import Path
from camtool.cli.main import main
from camtool.toolpath import offset
from tests.shapes import rectangle_dxf

started = []
class Noted(offset._Children):
    @property
    def ahead(self):
        return self._ahead
    @ahead.setter
    def ahead(self, child):
        if child is not None:
            started.append(child.pid)
        self._ahead = child
offset.CHILDREN = Noted()
src = Path(sys.argv[1])
for k in range(3):
    rectangle_dxf(src / f"r{k}.dxf", 10.0 + k, 5.0)
args = ["batch", str(src), "-t", "grbl", "-o", str(src / "out"), "--jobs", "1"]
code = main([*args, "--offset", "outside", "--tool-diameter", "1"])
print(code, len(started), offset.CHILDREN.calls, "OCP.BRepOffsetAPI" in sys.modules)
"""


def test_a_batch_one_file_after_another_loads_opencascade_once_and_starts_no_child_ahead(
    tmp_path: Path,
) -> None:
    """``batch --jobs 1`` posts in its own process: OpenCASCADE is loaded there once, so
    each job's child inherits it; no child is started ahead (a small job only waited for
    its load, then the next job loaded it again: 20 LibreCAD parts 1.86 → 2.2 s)."""
    root = Path(__file__).resolve().parents[2]
    done = subprocess.run(
        [sys.executable, "-c", BATCH_ONE_BY_ONE, str(tmp_path)],
        capture_output=True,
        text=True,
        cwd=root,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.split() == ["0", "0", "3", "True"]
    assert len(list((tmp_path / "out").glob("*.gcode"))) == 3
