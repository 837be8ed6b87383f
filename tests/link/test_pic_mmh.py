"""The pic-mmh link over a pseudo-terminal pair: echo, per-step feedback, abort on a new string.

Expected values come from UNAM-GMM (reference/UNAM-GMM.md §2.4, S000-11: every
``;``-ended string echoed, one feedback event per motor step, a new string
aborts the motion, a 35-element receive buffer), from the thesis's own G02
string (43 characters, L1731) and from the program itself (where its last
move ends), never from camtool's output.
"""

from __future__ import annotations

import dataclasses
import time
from pathlib import Path
from typing import Any

import pytest

from camtool.link.plan import prepare_send
from camtool.link.sender import open_port, send_plan
from camtool.model.errors import DialectError, LinkError
from camtool.post.registry import load_target
from tests.link.controls import PauseAt

THESIS_G02 = "G02X02969.00Y03400.00I03012.00J03040.00F08;"  # UNAM-GMM L1731, 43 characters
PROGRAM = (
    "G54;\n"
    "G90;\n"
    "G00X00100.00Y00100.00;\n"
    "G01X00150.00Y00100.00F08;\n"
    "G01X00150.00Y00150.00F08;\n"
    "G02X00100.00Y00150.00I00125.00J00150.00F08;\n"
    "G01X00100.00Y00100.00F08;\n"
    "G04P01;\n"
    "G00X00050.00Y00020.00;\n"
    "M30;\n"
)
WIRE = PROGRAM.replace("\n", "").encode()  # the strings, without the file's line ends
END = (0.05, 0.02, 0.0)  # G00X00050.00Y00020.00: µm
STEP_MM = 140e-6  # the GMM MMH-1's step: 140 nm (UNAM-GMM S000-12)


def plan_for(code: str, settle_s: float = 0.02, link: Any = None, **options: Any) -> Any:
    plan = prepare_send(code, load_target("pic-mmh"), source="job.txt", **options)
    spec = dataclasses.replace(plan.spec, settle_s=settle_s, **(link or {}))
    return dataclasses.replace(plan, spec=spec)


LINK_KEYS = ("response_timeout_s",)
"""``run``'s options that change the link's spec (a shorter wait for a silent controller)."""


def run(path: str, code: str = PROGRAM, settle_s: float = 0.02, **options: Any) -> Any:
    link = {key: options.pop(key) for key in LINK_KEYS if key in options}
    plan = plan_for(code, settle_s, link, from_line=options.pop("from_line", None))
    port = open_port(path, plan.spec.baud)
    try:
        return send_plan(port, plan, port_name=path, time_scale=0.0, **options)
    finally:
        port.close()


def test_the_thesis_g02_is_43_characters_and_longer_than_the_buffer() -> None:
    from camtool_postprocessors.pic_mmh.link import RECEIVE_BUFFER

    assert len(THESIS_G02) == 43 > RECEIVE_BUFFER == 35


def test_blocks_are_the_strings_and_motion_blocks_expect_their_steps() -> None:
    plan = plan_for(PROGRAM)
    assert b"".join(b.data for b in plan.blocks) == WIRE
    by_text = {b.text: b for b in plan.blocks}
    # 0.05 mm along X at 140 nm/step (S000-12): round(50 / 0.14) = 357 steps, one event each
    assert by_text["G01X00150.00Y00100.00F08;"].events == 357
    assert by_text["G01X00150.00Y00150.00F08;"].events == 357
    # (0, 0) -> (0.1, 0.1) mm: 714 steps on each axis
    assert by_text["G00X00100.00Y00100.00;"].events == 2 * 714
    assert by_text["G54;"].events == 0 and by_text["M30;"].events == 0
    assert by_text["G04P01;"].busy_s == 1.0


def test_the_simulator_receives_the_strings_and_no_motion_is_aborted(simulate: Any) -> None:
    sim = simulate("pic-mmh")
    run(sim.path)
    assert bytes(sim.device.received) == WIRE
    assert sim.device.aborted == [] and sim.device.stops == 0
    assert sim.device.longest == 43  # the G02 string went whole (parsed on the fly)
    assert sim.device.position() == pytest.approx(END)


def test_a_host_that_sends_early_aborts_the_motion(simulate: Any) -> None:
    sim = simulate("pic-mmh")
    port = open_port(sim.path, 9600)
    try:
        time.sleep(0.1)
        port.write(b"G00X00100.00Y00100.00;G01X00150.00Y00100.00F08;")
        deadline = time.monotonic() + 60  # a bound for a hang: the loop ends as both arrive
        while time.monotonic() < deadline and len(sim.device.blocks) < 2:
            port.read(4096)
            time.sleep(0.01)
    finally:
        port.close()
    (aborted,) = sim.device.aborted
    block, done, steps = aborted
    assert block == 1 and done < steps == 2 * 714


def test_a_posted_file_arrives_as_its_strings(simulate: Any, tmp_path: Path) -> None:
    from camtool.cli.main import main

    out = tmp_path / "plate.txt"
    small = ["--fit", "0.3", "0.2"]  # 0.3 mm: some 65 000 steps with the compensations
    assert main(["post", "samples/plate.dxf", "-t", "pic-mmh", *small, "-o", str(out)]) == 0
    sim = simulate("pic-mmh", steps_per_tick=1000)
    run(sim.path, out.read_text())
    assert bytes(sim.device.received) == out.read_bytes().replace(b"\n", b"")
    assert sim.device.aborted == []


@pytest.mark.parametrize("ticks", [1, 40, 10**6])  # the motion outlasts the echo, or not
def test_a_wrong_echo_stops_naming_the_block_and_sends_stop(simulate: Any, ticks: int) -> None:
    sim = simulate("pic-mmh", fail_at_block=5, steps_per_tick=ticks)
    with pytest.raises(LinkError) as info:
        run(sim.path)
    message = str(info.value)
    assert "line 5: 'G01X00150.00Y00150.00F08;'" in message
    assert "echo 'G01X00150.00Y00150.00F09;' is not the block sent" in message
    assert "--from-line 5" in message
    assert "'A;' sent and echoed: the controller stopped" in message
    assert sim.device.stops == 1  # "A;" right after the wrong echo
    # the misread block had started to move: the stop aborted it part way, or, on a busy
    # machine where the host read the echo late, it had already run to its end (the
    # misread digit is the feed's, so it ends where block 5 ends). Either way the job
    # resumes at block 5, as the message says: its step count from where the tool stands
    # (some of the block's, or none) is not the program's, so the silence ends it
    if sim.device.aborted:
        assert sim.device.aborted[-1][0] == 5
    else:
        assert sim.device.executed[-1].startswith(b"G01X00150.00Y00150.00F09;")
    assert sim.device.blocks[-1] == b"A;"
    before = len(sim.device.blocks)
    run(sim.path, from_line=5)  # the link's own quiet end: 1 s without a step
    assert sim.device.position() == pytest.approx(END)
    assert sim.device.blocks[before:] == [s.encode() for s in PROGRAM.splitlines()[4:]]


@pytest.mark.parametrize(
    ("stop", "advised", "resume", "stands"),
    [
        # block 4 (line 4) runs from X 100 to 150 µm: 714 to 1071 steps of 140 nm in X
        ((4, 1), 4, 4, (715 * STEP_MM, 714 * STEP_MM)),
        ((4, 200), 4, 4, (914 * STEP_MM, 714 * STEP_MM)),
        ((4, 356), 4, 4, (1070 * STEP_MM, 714 * STEP_MM)),
        # block 4 ran to its end and block 5 made no step; a machinist unsure whether
        # block 4 ran resumes at it: it runs nothing
        ((5, 0), 5, 4, (0.15, 0.1)),  # where line 4 ends, as written
        # line 7 stopped part way, resumed at the dwell of line 8: the rapid of line 9 is
        # the first motion, and starts where line 7 stopped
        ((7, 300), 7, 8, None),
    ],
)
def test_a_job_stopped_at_the_machine_resumes_from_where_the_tool_stands(
    simulate: Any,
    stop: tuple[int, int],
    advised: int,
    resume: int,
    stands: tuple[float, float] | None,
) -> None:
    """The block sent again makes only the steps left of it (or none), and the job goes on."""
    sim = simulate("pic-mmh", steps_per_tick=100)  # the stop comes at its step all the same
    sim.device.stop_after = stop
    with pytest.raises(LinkError, match=f"resume with --from-line {advised}$"):
        run(sim.path, response_timeout_s=2.0)
    assert sim.device.aborted == [(stop[0], stop[1], sim.device.aborted[0][2])]
    if stands is not None:
        assert sim.device.position()[:2] == pytest.approx(stands, abs=1e-9)
    before = len(sim.device.blocks)
    run(sim.path, from_line=resume)
    assert sim.device.position() == pytest.approx(END)
    assert sim.device.blocks[before:] == [s.encode() for s in PROGRAM.splitlines()[resume - 1 :]]
    assert len(sim.device.aborted) == 1  # nothing after the resume was cut short


def test_a_strict_35_character_buffer_truncates_the_g02_and_the_echo_shows_it(
    simulate: Any,
) -> None:
    sim = simulate("pic-mmh", on_the_fly=False)
    with pytest.raises(LinkError, match=r"refused block 6 \(line 6") as info:
        run(sim.path)
    assert "is not the block sent" in str(info.value)
    assert sim.device.lost == 43 - 35


def test_more_steps_than_camtool_predicts_stop_the_job(simulate: Any) -> None:
    sim = simulate("pic-mmh")
    plan = plan_for(PROGRAM, settle_s=0.5)
    blocks = list(plan.blocks)
    blocks[2] = dataclasses.replace(blocks[2], events=blocks[2].events - 10)
    plan = dataclasses.replace(plan, blocks=tuple(blocks))
    port = open_port(sim.path, 9600)
    try:
        with pytest.raises(LinkError, match="moves other than camtool's interpolator") as info:
            send_plan(port, plan, port_name=sim.path, time_scale=0.0)
        assert "'A;' sent and echoed" in str(info.value)
    finally:
        port.close()
    assert len(sim.device.blocks) == 3 + 1  # nothing after block 3 but the stop "A;"
    assert sim.device.blocks[-1] == b"A;"


def test_pause_waits_for_the_motion_then_resumes(simulate: Any) -> None:
    sim = simulate("pic-mmh")
    control = PauseAt(3, "resume")
    run(sim.path, control=control, progress=control.progress)
    (pause,) = control.pauses
    assert pause.in_flight == 0 and pause.done == 3
    assert bytes(sim.device.received) == WIRE and sim.device.aborted == []


def test_stop_at_a_pause_and_from_line_ends_in_the_same_place(simulate: Any) -> None:
    sim = simulate("pic-mmh")
    control = PauseAt(4, "stop")
    with pytest.raises(LinkError, match="stopped by the operator after block 4") as info:
        run(sim.path, control=control, progress=control.progress)
    assert "--from-line 5" in str(info.value)
    assert bytes(sim.device.received) == "".join(PROGRAM.splitlines()[:4]).encode()
    run(sim.path, from_line=5)
    assert sim.device.aborted == []
    assert sim.device.position() == pytest.approx(END)


def test_from_line_restores_the_spindle_only() -> None:
    code = PROGRAM.replace("G90;\n", "G90;\nM03S1000;\n")
    plan = plan_for(code, from_line=6)
    assert [b.text for b in plan.blocks if not b.index] == ["M03S1000;"]


def test_g28_is_refused_before_sending() -> None:
    with pytest.raises(DialectError, match="line 3: G28X0Y0; homes to the switches"):
        plan_for(PROGRAM.replace("G90;\n", "G90;\nG28X0Y0;\n"))


def test_a_port_that_disappears_is_a_link_error(simulate: Any) -> None:
    sim = simulate("pic-mmh", drop_at_block=4)
    with pytest.raises(LinkError, match="disappeared"):
        run(sim.path)


def test_the_cli_dry_run_and_send(simulate: Any, tmp_path: Path, capsys: Any) -> None:
    from camtool.cli.main import main

    job = tmp_path / "job.txt"
    job.write_text(PROGRAM)
    assert main(["send", str(job), "-t", "pic-mmh", "--dry-run"]) == 0
    out = capsys.readouterr().out
    assert "echo per block" in out and "357 feedback events" in out
    sim = simulate("pic-mmh", drop_at_block=3)
    assert main(["send", str(job), "-t", "pic-mmh", "--port", sim.path, "--baud", "19200"]) == 1
    err = capsys.readouterr().err
    assert "disappeared" in err and "Traceback" not in err


def test_the_resumed_block_is_not_ended_while_its_steps_still_come(simulate: Any) -> None:
    """Steps 0.3 s apart, the silence that ends the block 1 s: it runs to its end.

    Line 4 sent again from where it stopped (200 of its 357 steps made) makes its last
    157 in 8 batches of 20, one every 0.3 s once resumed (2.4 s, longer than the quiet
    end): the block ends only after the last, or the next string would cut its motion
    short (a new string aborts a motion).
    """
    code = PROGRAM.split("G01X00150.00Y00150.00F08;")[0] + "M30;\n"  # lines 1-4, then M30
    sim = simulate("pic-mmh", steps_per_tick=20)
    sim.device.stop_after = (4, 200)
    with pytest.raises(LinkError, match=r"resume with --from-line 4$"):
        run(sim.path, code, response_timeout_s=2.0)
    sim.server.block_delay_s = 0.3
    run(sim.path, code, from_line=4)
    assert len(sim.device.aborted) == 1  # the stop at the machine only
    assert sim.device.position()[:2] == pytest.approx((0.15, 0.1))
    assert sim.device.blocks[-2:] == [b"G01X00150.00Y00100.00F08;", b"M30;"]
