"""The child that draws a command's PNG, started ahead (``camtool.preview.ahead``).

The picture it sends back must be the bytes this process draws for the same scene
(``scene_png`` here is the independent judge), and whatever becomes of the child (never
told to load, killed, never used) the job must still get its picture and leave no process.
"""

from __future__ import annotations

import os
import signal
import sys
from pathlib import Path
from typing import cast

import pytest

from camtool.cli.common import picture_ahead
from camtool.model.program import ArcMove, Linear, Program, Rapid
from camtool.preview import ahead, render_preview
from camtool.preview.layout import Content, compose
from camtool.preview.raster import scene_png
from camtool.preview.scene import Scene

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="fork (Linux)")


def _scene() -> Scene:
    program = Program(
        (
            Rapid(1, 1, contour=1),
            Linear(3, 1, 1.0, contour=1),
            ArcMove(1, 1, 2, 1, True, 1.0, contour=1),
            Rapid(5, 5, contour=2),
            ArcMove(5, 5, 6, 5, False, 1.0, contour=2),
        )
    )
    return compose(
        Content(
            program=program,
            drawing=None,
            verification=None,
            work_area=(0, 0, 10, 7),
            target_name="",
            time=None,
            edge_radius_mm=0.0,
            title="ahead",
            width_px=240,
        )
    )


def _gone(pid: int) -> bool:
    """Whether ``pid`` has ended and been waited for (it is no child of this process now)."""
    try:
        os.waitpid(pid, os.WNOHANG)
    except ChildProcessError:
        return True
    return False


@pytest.fixture(autouse=True)
def _no_child_left() -> object:
    yield
    ahead.stop_ahead()


def test_the_child_draws_the_bytes_drawn_here_and_leaves() -> None:
    scene = _scene()
    ahead.start_ahead()
    drawer = ahead.DRAWER.helper
    assert drawer is not None
    pid = drawer.pid
    assert pid is not None
    ahead.load_ahead()
    drawn = ahead.draw_ahead(scene)
    assert drawn is not None and drawn[:8] == b"\x89PNG\r\n\x1a\n"
    assert drawn == scene_png(scene)
    assert ahead.DRAWER.helper is None and _gone(pid)
    assert ahead.draw_ahead(scene) is None  # used once: the next picture is drawn here


def test_render_preview_uses_the_child_and_a_dead_one_changes_nothing() -> None:
    program = Program((Rapid(1, 1), Linear(3, 1, 1.0), ArcMove(3, 1, 4, 1, False, 1.0)))

    def picture() -> bytes:
        return render_preview(".png", program=program, work_area=(0, 0, 10, 7), width_px=240)

    plain = picture()  # no child: drawn here
    ahead.start_ahead()
    assert picture() == plain and ahead.DRAWER.helper is None  # drawn by the child
    ahead.start_ahead()
    drawer = ahead.DRAWER.helper
    assert drawer is not None
    assert drawer.pid is not None
    os.kill(drawer.pid, signal.SIGKILL)  # dead before it is used: drawn here again
    assert picture() == plain and ahead.DRAWER.helper is None


def test_a_child_killed_while_loading_sends_nothing() -> None:
    ahead.start_ahead()
    drawer = ahead.DRAWER.helper
    assert drawer is not None
    assert drawer.pid is not None
    ahead.load_ahead()
    os.kill(drawer.pid, signal.SIGKILL)
    assert ahead.draw_ahead(_scene()) is None  # the end of its pipe, not a hang
    assert ahead.DRAWER.helper is None


def test_a_scene_that_does_not_pickle_is_drawn_here() -> None:
    """Not a camtool scene (they pickle): whatever goes wrong on the way, nothing raises."""
    ahead.start_ahead()
    drawer = ahead.DRAWER.helper
    assert drawer is not None
    pid = drawer.pid
    assert pid is not None
    assert ahead.draw_ahead(cast(Scene, lambda: None)) is None
    assert ahead.DRAWER.helper is None and _gone(pid)


def test_a_child_never_told_to_load_leaves_on_its_own_when_its_pipe_ends() -> None:
    ahead.start_ahead()
    drawer = ahead.DRAWER.helper
    assert drawer is not None
    pid = drawer.pid
    assert pid is not None and drawer.inbox is not None
    os.close(drawer.inbox)
    drawer.inbox = None
    _, status = os.waitpid(pid, 0)  # not killed: it read the end of its pipe and left
    drawer.pid = None
    assert os.WIFEXITED(status) and os.WEXITSTATUS(status) == 0


def test_an_unused_child_is_ended_by_stop_ahead() -> None:
    ahead.start_ahead()
    ahead.start_ahead()  # at most one at a time
    drawer = ahead.DRAWER.helper
    assert drawer is not None
    pid = drawer.pid
    assert pid is not None
    ahead.load_ahead()
    ahead.stop_ahead()
    ahead.stop_ahead()  # idempotent
    assert ahead.DRAWER.helper is None and _gone(pid)


def test_processes_forked_later_do_not_hold_its_pipes() -> None:
    """A later fork (an offsets' child, a budget worker) closes this process's ends of the
    child's pipes, so the child sees this process's end as the end of its pipe."""
    ahead.start_ahead()
    drawer = ahead.DRAWER.helper
    assert drawer is not None
    fds = drawer.fds()
    assert len(fds) == 2
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the forked process
        still = 0
        for fd in fds:
            try:
                os.fstat(fd)
                still += 1
            except OSError:
                pass
        os._exit(10 + still + (1 if ahead.DRAWER.helper else 0) * 5)
    _, status = os.waitpid(pid, 0)
    assert os.WEXITSTATUS(status) == 10  # none open there, and no child of its own
    for fd in fds:
        os.fstat(fd)  # still open here


@pytest.mark.parametrize(
    ("preview", "started"),
    [(None, False), ("out.svg", False), ("-", False), ("out.png", True), ("OUT.PNG", True)],
)
def test_only_a_png_preview_starts_a_child(preview: str | None, started: bool) -> None:
    with picture_ahead(preview) as load:
        assert (ahead.DRAWER.helper is not None) == started
        assert (load is ahead.load_ahead) == started  # else a call that does nothing
        load()
        pid = ahead.DRAWER.helper.pid if ahead.DRAWER.helper is not None else None
    assert ahead.DRAWER.helper is None
    if pid is not None:
        assert _gone(pid)


def test_the_cli_png_is_the_png_drawn_in_process(tmp_path: Path) -> None:
    """``post --preview x.png`` (its child draws) against the same job's picture drawn here."""
    from click.testing import CliRunner

    from camtool.cli.main import cli
    from camtool.jobs.pipeline import post_path, verify_job
    from camtool.post.registry import load_target
    from camtool.toolpath.options import PlanOptions

    sample = Path(__file__).resolve().parents[2] / "samples" / "plate.dxf"
    picture = tmp_path / "plate.png"
    result = CliRunner().invoke(
        cli,
        [
            *("post", str(sample), "--target", "grbl", "--offset", "outside"),
            *("--tool-diameter", "3", "-o", str(tmp_path / "plate.gcode")),
            *("--preview", str(picture)),
        ],
    )
    assert result.exit_code == 0, result.output
    assert ahead.DRAWER.helper is None
    job = post_path(sample, load_target("grbl"), PlanOptions(offset="outside", tool_diameter=3.0))
    v = verify_job(job)
    here = render_preview(
        ".png", verification=v, drawing=job.placed, edge_radius_mm=job.edge_radius_mm
    )
    assert picture.read_bytes() == here
