"""Progress of a long ``camtool post`` on stderr (camtool/cli/progress.py).

No timed tests: the reporter's clock is a fake one, and the CLI's threshold is forced to 0
(every job "long") or left at its default for a small file, which must then print exactly
what it printed before (no new line, stdout untouched).
"""

from __future__ import annotations

import io
import time
from pathlib import Path

import pytest

from camtool.cli import progress as progress_module
from camtool.cli.main import main
from camtool.cli.progress import StageReporter, stage_text
from camtool.model.progress import Step
from tests.importers.test_svg_pool import _svg

SAMPLES = Path(__file__).parents[2] / "samples"


class Clock:
    """A clock the test moves by hand, s."""

    def __init__(self) -> None:
        self.now = 100.0

    def __call__(self) -> float:
        return self.now


def _reporter(live: bool) -> tuple[StageReporter, io.StringIO, Clock]:
    out, clock = io.StringIO(), Clock()
    return StageReporter(after_s=2.0, stream=out, live=live, clock=clock, timer=False), out, clock


def test_quiet_before_the_threshold_then_a_line_per_stage() -> None:
    reporter, out, clock = _reporter(live=False)
    reporter(Step("reading", name="big.svg"))
    reporter(Step("reading", 10, 5712, "big.svg"))
    clock.now += 1.9
    reporter(Step("fitting", 0, 30576))
    reporter(Step("fitting", 480, 30576))
    assert out.getvalue() == ""  # 1.9 s: nothing yet
    clock.now += 0.2
    reporter(Step("fitting", 960, 30576))  # the stage running when the time is up
    reporter(Step("fitting", 1440, 30576))  # same stage: no new line into a file
    clock.now += 10.0
    reporter(Step("contours", 0, 5712))
    reporter(Step("planning", 0, 5712))
    reporter(Step("writing", 0, 232119, "grbl"))
    reporter(Step("verifying", 0, 232128, "grbl"))
    reporter.close()
    assert out.getvalue() == (
        "camtool: fitting arcs to 30576 curves…\n"
        "camtool: making contours of 5712 shapes…\n"
        "camtool: planning 5712 contours…\n"
        "camtool: writing 232119 moves for grbl…\n"
        "camtool: verifying 232128 blocks on grbl…\n"
    )
    assert "\r" not in out.getvalue()


def test_a_terminal_line_is_redrawn_at_most_four_times_a_second() -> None:
    reporter, out, clock = _reporter(live=True)
    clock.now += 3.0
    reporter(Step("fitting", 0, 1000))
    for done in range(100, 1001, 100):  # every 0.1 s
        clock.now += 0.1
        reporter(Step("fitting", done, 1000))
    reporter(Step("planning", 0, 40))
    reporter.close()
    text = out.getvalue()
    line = "camtool: fitting arcs to 1000 curves…"
    assert text == (
        f"\r{line}\x1b[K"
        f"\r{line} 300 of 1000 (30%)\x1b[K"  # 0.3 s after the first draw
        f"\r{line} 600 of 1000 (60%)\x1b[K"
        f"\r{line} 900 of 1000 (90%)\x1b[K"
        f"\r{line} 1000 of 1000 (100%)\x1b[K"  # the last count, before the line ends
        "\n"  # the next stage starts its own line
        "\rcamtool: planning 40 contours…\x1b[K"
        "\n"  # closed: the terminal's line is finished before anything else is written
    )


def test_a_stage_that_runs_on_silently_is_shown_when_the_time_is_up() -> None:
    # One step before the threshold, then none (one long GEOS buffer): the timer's tick
    # at the threshold shows it; before the threshold, or once the stage is over, not.
    reporter, out, clock = _reporter(live=False)
    reporter(Step("pocketing", 0, 1))
    clock.now += 1.0
    reporter.tick()
    assert out.getvalue() == ""
    clock.now += 1.5
    reporter.tick()
    reporter.tick()  # shown once
    reporter(Step("pocketing", 1, 1))  # the same stage: no new line
    assert out.getvalue() == "camtool: clearing 1 pocket regions…\n"
    reporter.close()
    reporter.tick()
    assert out.getvalue() == "camtool: clearing 1 pocket regions…\n"


def test_a_stage_over_before_the_time_is_up_is_never_shown() -> None:
    reporter, out, clock = _reporter(live=True)
    reporter(Step("planning", 0, 3))
    reporter.close()  # the job writes its own lines now: the stage is over
    clock.now += 5.0
    reporter.tick()
    assert out.getvalue() == ""


def test_the_timer_shows_a_silent_stage_on_its_own() -> None:
    # The real clock and thread: nothing else is told after the first step.
    out = io.StringIO()
    with StageReporter(after_s=0.05, stream=out, live=False) as reporter:
        reporter(Step("pocketing", 0, 2))
        deadline = time.monotonic() + 60.0  # generous: a loaded machine wakes threads late
        while not out.getvalue() and time.monotonic() < deadline:
            time.sleep(0.01)
    assert out.getvalue() == "camtool: clearing 2 pocket regions…\n"


def test_a_closed_stderr_silences_progress_without_failing() -> None:
    out = io.StringIO()
    reporter = StageReporter(after_s=0.0, stream=out, live=False, timer=False)
    out.close()
    reporter(Step("planning", 0, 3))  # no ValueError: progress is not worth a failure
    reporter.close()


@pytest.mark.parametrize(
    ("step", "text"),
    [
        (Step("reading", name="a.svg"), "reading a.svg"),
        (Step("reading", 3, 12, "a.svg"), "reading a.svg: 12 shapes"),
        (Step("fitting", 0, 400), "fitting arcs to 400 curves"),
        (Step("writing", 0, 7, "valcnc"), "writing 7 moves for valcnc"),
        (Step("offsetting", 2, 9), "offsetting 9 contours for the tool"),
        (Step("pocketing", 1, 12), "clearing 12 pocket regions"),
        (Step("verifying", 0, 0, "grbl"), "verifying the program on grbl"),
        (Step("simulating", 10, 1200), "simulating 1200 interpolator iterations"),
        (Step("comparing", 0, 50), "comparing 50 cutting rows with the drawing"),
    ],
)
def test_stage_text_says_how_big_the_work_is(step: Step, text: str) -> None:
    assert stage_text(step) == text


def _post(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    code = main(["post", *args])
    out, err = capsys.readouterr()
    return code, out, err


def _stage_lines(
    args: list[str], capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> list[str]:
    """``post args`` quiet, then with threshold 0: the stage lines of the second run.

    Both succeed and write the same code, and the second's other stderr lines are the
    first's: progress adds lines and changes nothing else.
    """
    monkeypatch.setattr(progress_module, "AFTER_S", 1e9)  # quiet, however loaded the machine
    code, quiet_out, quiet_err = _post(args, capsys)
    assert code == 0
    monkeypatch.setattr(progress_module, "AFTER_S", 0.0)
    code, out, err = _post(args, capsys)
    assert code == 0 and out == quiet_out
    stages = [ln for ln in err.splitlines() if ln.endswith("…")]
    assert [ln for ln in err.splitlines() if ln not in stages] == quiet_err.splitlines()
    return stages


def test_a_short_job_prints_nothing_new(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Under the threshold stderr is the warnings and notes only, as before (no stage line).

    The threshold is set far above the job, so a loaded machine cannot make it long.
    """
    monkeypatch.setattr(progress_module, "AFTER_S", 1e9)
    code, out, err = _post([str(SAMPLES / "logo.dxf"), "-t", "grbl", "--depth", "1"], capsys)
    assert code == 0 and out.startswith("(camtool")
    assert "…" not in err  # the stage lines end with an ellipsis; nothing else here does
    assert not any(
        line.startswith(f"camtool: {stage} ") for line in err.splitlines() for stage in
        ("reading", "fitting", "making", "planning", "writing", "verifying")
    )  # fmt: skip


def test_a_long_job_tells_its_stages_and_keeps_its_output(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Threshold 0: every stage's line on stderr, in order; stdout (-o -) is the same code."""
    from camtool.importers import svg as svg_module

    path = _svg(tmp_path, 12)
    args = [str(path), "-t", "grbl", "--verify", "--no-budget"]
    monkeypatch.setattr(progress_module, "AFTER_S", 1e9)  # quiet, however loaded the machine
    code, quiet_out, quiet_err = _post(args, capsys)
    assert code == 0
    monkeypatch.setattr(progress_module, "AFTER_S", 0.0)
    monkeypatch.setattr(svg_module, "MIN_CURVES", 1)  # the fits made ahead: a fitting stage
    code, out, err = _post(args, capsys)
    assert code == 0
    assert out == quiet_out
    stages = [ln for ln in err.splitlines() if ln.endswith("…")]
    assert [ln for ln in err.splitlines() if ln not in stages] == quiet_err.splitlines()
    assert stages[0] == "camtool: reading many.svg…"
    assert stages[1] == "camtool: reading many.svg: 12 shapes…"
    # the distinct curve shapes: 12 random cubics and 12 elliptical arcs, the q, s and t
    # shapes every path repeats, the zero-length cubic (tests/importers/test_svg_progress.py)
    assert stages[2] == f"camtool: fitting arcs to {12 * 2 + 3 + 1} curves…"
    assert stages[3] == "camtool: making contours of 12 shapes…"
    assert stages[4].startswith("camtool: planning ") and stages[4].endswith(" contours…")
    assert stages[5].startswith("camtool: writing ") and stages[5].endswith(" moves for grbl…")
    assert stages[6].startswith("camtool: verifying ") and stages[6].endswith(" blocks on grbl…")
    assert stages[7].startswith("camtool: comparing ") and stages[7].endswith(" with the drawing…")
    assert len(stages) == 8


def test_a_long_verification_tells_its_error_budget(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Threshold 0 and the budget on: a line for the budget after the verifying line.

    grbl's profile models interpolation, chords and (post --verify) rounding for a
    drawing with arcs: three sources. Its workers start before the drawing comparison,
    whose line comes next; the budget's line again when this process waits for them.
    The summary is what it is without progress.
    """
    stages = _stage_lines([str(_svg(tmp_path, 3)), "-t", "grbl", "--verify"], capsys, monkeypatch)
    budget = "camtool: error budget: re-simulating once per error source (3)…"
    assert stages[-4].startswith("camtool: verifying ")
    assert stages[-3] == stages[-1] == budget
    words = stages[-2].split()
    assert words[:2] == ["camtool:", "comparing"] and int(words[2]) > 0
    assert words[3:] == ["cutting", "rows", "with", "the", "drawing…"]


def test_a_long_job_with_offsets_tells_its_offsetting_stage(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """``--offset outside``: an ``offsetting`` line after ``planning``, one per closed contour.

    OpenCASCADE's offsets of Inkscape's ``filters.svg`` (1 752 contours) ran for minutes
    after "planning" with nothing said. Into a file the stage gets one line; on a terminal
    its count is redrawn up to all contours offset.
    """
    args = [str(_svg(tmp_path, 4)), "-t", "grbl", "--offset", "outside", "--tool-diameter", "1"]
    stages = _stage_lines(args, capsys, monkeypatch)
    planning = next(i for i, ln in enumerate(stages) if ln.startswith("camtool: planning "))
    drawn = int(stages[planning].split()[2])
    offsetting = stages[planning + 1].split()
    assert offsetting[:2] == ["camtool:", "offsetting"]
    assert offsetting[3:] == ["contours", "for", "the", "tool…"]
    assert 0 < int(offsetting[2]) <= drawn  # the closed ones
    assert stages[planning + 2].startswith("camtool: writing ")


def test_the_offsetting_stage_counts_every_answer() -> None:
    """compensate tells ``offsetting`` 0, 1, …, n of n, in order, n the closed contours."""
    from camtool.toolpath.compensate import compensate
    from camtool.toolpath.options import PlanOptions
    from camtool.toolpath.order import nesting
    from tests.toolpath.contours import circle, rect

    contours = [rect(0, 0, 40, 30), circle(10, 10, 3), circle(25, 10, 4), circle(30, 20, 2)]
    steps: list[Step] = []
    options = PlanOptions(offset="outside", tool_diameter=1.0, feed_mm_min=100.0)
    compensate(contours, nesting(contours), options, progress=steps.append)
    assert steps == [Step("offsetting", n, 4) for n in range(5)]
