"""GRBL over a pseudo-terminal pair: character counting, errors, resume, pause, a lost port.

Expected values come from GRBL's documents (gnea/grbl doc/markdown/interface.md,
doc/csv/error_codes_en_US.csv) and from the programs themselves (where their
last moves end), never from camtool's output.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from camtool.link.device import PtyServer
from camtool.link.plan import prepare_send
from camtool.link.sender import StopAtPause, open_port, send_plan
from camtool.link.spec import link_spec
from camtool.model.errors import InputError, LinkError
from camtool.post.registry import load_target
from camtool_postprocessors.grbl.link import GrblDevice
from tests.link.controls import AnswersTurns, PauseAt

# 13 passes over a 10 x 10 mm square, one arc per pass: the tool ends at X10 Y0 Z5.
PASSES = "".join(
    f"G0 X10 Y0\nG1 Z-{k / 10:.1f} F100\nG1 X20 Y0 F300\nG2 X20 Y10 I0 J5\n"
    f"G1 X10 Y10\nG1 X10 Y0\nG0 Z5\n"
    for k in range(1, 14)
)
PROGRAM = "G21 G90 G94 G17\nM3 S1000\nG4 P1.5\n" + PASSES + "M5\nM2\n"
END = (10.0, 0.0, 5.0)


def run(path: str, code: str, **options: Any) -> Any:
    target = load_target("grbl")
    plan = prepare_send(code, target, source="job.gcode", from_line=options.pop("from_line", None))
    port = open_port(path, plan.spec.baud)
    try:
        return send_plan(port, plan, port_name=path, **options)
    finally:
        port.close()


def test_the_simulator_receives_the_file_and_the_buffer_stays_within_127_bytes(
    simulate: Any,
) -> None:
    sim = simulate("grbl")
    result = run(sim.path, PROGRAM)
    assert bytes(sim.device.received) == PROGRAM.encode()
    assert not sim.device.overflowed
    # the host kept GRBL's buffer full (more than one line in flight), never over 127
    assert 40 < sim.device.max_rx <= 127
    assert 40 < result.max_buffered <= 127
    assert sim.device.position() == pytest.approx(END)


def test_a_posted_file_arrives_byte_for_byte(simulate: Any, tmp_path: Path) -> None:
    from camtool.cli.main import main

    out = tmp_path / "plate.gcode"
    assert main(["post", "samples/plate.dxf", "-t", "grbl", "-o", str(out)]) == 0
    sim = simulate("grbl")
    run(sim.path, out.read_text())
    assert bytes(sim.device.received) == out.read_bytes()


def resume_line(message: str) -> int:
    return int(message.rsplit("--from-line ", 1)[1].split()[0].rstrip(":;,"))


def ran_in_order(device: Any, upto: int) -> bool:
    """Lines 1..upto of PROGRAM ran on the simulated GRBL, whole and in order."""
    lines = PROGRAM.splitlines(True)[:upto]
    return b"".join(device.executed).startswith("".join(lines).encode())


def lines_run(device: Any) -> int:
    """How many of PROGRAM's first lines the simulated GRBL ran: where its tool stands."""
    return sum(1 for k in range(1, PROGRAM.count("\n") + 1) if ran_in_order(device, k))


def test_an_error_stops_the_machine_and_names_the_line(simulate: Any) -> None:
    sim = simulate("grbl", fail_at_block=19, error="22", block_delay_s=0.002)
    with pytest.raises(LinkError) as info:
        run(sim.path, PROGRAM)
    message = str(info.value)
    assert "refused block 19 (line 19" in message
    # error_codes_en_US.csv, code 22
    assert "Undefined feed rate: Feed rate has not yet been set or is undefined." in message
    # the lines after it in GRBL's buffers would run (interface.md, RESERVATION): camtool stops
    # the machine instead, with a feed hold and then a reset (no alarm: nothing moves then)
    assert "feed hold, then a reset (spindle and coolant off, position kept)" in message
    assert sim.device.holds >= 1 and sim.device.resets == 1 and sim.device.state == "Idle"
    # the resume line is the refused line, or an earlier one that had not run to its end
    resume = resume_line(message)
    assert resume <= 19 and ran_in_order(sim.device, resume - 1)


def test_after_an_error_the_resume_line_is_the_refused_line(simulate: Any) -> None:
    # line 1 queues nothing (G21 G90 G94 G17): when GRBL refuses line 2 nothing else can run
    sim = simulate("grbl", fail_at_block=2, error="20")
    with pytest.raises(LinkError, match=r"refused block 2 \(line 2: 'M3 S1000'\)") as info:
        run(sim.path, PROGRAM)
    assert "fix the cause, then resume with --from-line 2" in str(info.value)


def test_from_line_after_an_error_ends_where_an_uninterrupted_run_ends(simulate: Any) -> None:
    sim = simulate("grbl", fail_at_block=19, error="22", block_delay_s=0.002)
    with pytest.raises(LinkError) as info:
        run(sim.path, PROGRAM)
    resume = resume_line(str(info.value))
    assert ran_in_order(sim.device, resume - 1)  # never too late
    # camtool's line is never late, but may be early (its count of GRBL's planner is a lower
    # bound): the operator resumes where the tool stands, at the first line not run, which
    # is camtool's line or a later one
    ran = lines_run(sim.device)
    assert resume <= ran + 1
    resume = ran + 1
    first = len(sim.device.blocks)
    run(sim.path, PROGRAM, from_line=resume)
    assert sim.device.connections == 2
    assert sim.device.position() == pytest.approx(END)
    # the restore blocks: the modal state lines 1..resume-1 set (units..., the feed, spindle)
    restored = [b.decode() for b in sim.device.blocks[first : first + 4]]
    assert restored[0] == "G21 G90 G94 G17\n"
    if resume > 4:  # the program's F100/F300 and M3 S1000 (and its dwell) came before it
        assert restored[1] in ("F100\n", "F300\n")
        assert "M3 S1000\n" in restored


def test_pause_is_a_feed_hold_and_resume_continues(simulate: Any) -> None:
    sim = simulate("grbl", block_delay_s=0.001)
    control = PauseAt(30, "resume")
    run(sim.path, PROGRAM, control=control, progress=control.progress)
    (pause,) = control.pauses
    assert pause.done >= 30
    # `!` then `~` (interface.md real-time commands); the whole program ran
    assert sim.device.holds == 1 and not sim.device.held and sim.device.resets == 0
    assert bytes(sim.device.received) == PROGRAM.encode()
    assert sim.device.position() == pytest.approx(END)


def test_stop_at_a_pause_halts_and_names_the_line_to_resume_at(simulate: Any) -> None:
    sim = simulate("grbl", block_delay_s=0.001)
    control = PauseAt(30, "stop")
    with pytest.raises(LinkError, match=r"stopped by the operator after block \d+") as info:
        run(sim.path, PROGRAM, control=control, progress=control.progress)
    message = str(info.value)
    assert "fix the cause" not in message
    assert "feed hold, then a reset (spindle and coolant off, position kept)" in message
    resume = resume_line(message)
    assert ran_in_order(sim.device, resume - 1)
    ran = lines_run(sim.device)
    assert resume <= ran + 1  # never late; where the tool stands decides (see above)
    # whole blocks only: what arrived is the file's first lines
    received = len(sim.device.blocks)
    assert bytes(sim.device.received) == "".join(PROGRAM.splitlines(True)[:received]).encode()
    run(sim.path, PROGRAM, from_line=ran + 1)
    assert sim.device.position() == pytest.approx(END)


def test_a_port_that_disappears_is_a_link_error(simulate: Any) -> None:
    sim = simulate("grbl", drop_at_block=25, block_delay_s=0.001)
    with pytest.raises(LinkError, match="disappeared"):
        run(sim.path, PROGRAM, control=StopAtPause())


def test_an_alarm_stops_the_job_with_grbl_words(simulate: Any) -> None:
    sim = simulate("grbl", alarm_at_block=12, block_delay_s=0.001)
    with pytest.raises(LinkError) as info:
        run(sim.path, PROGRAM)
    # alarm_codes_en_US.csv, code 1
    assert "ALARM:1 (Hard limit: Hard limit has been triggered." in str(info.value)


def test_a_controller_in_alarm_gets_nothing(simulate: Any) -> None:
    sim = simulate("grbl", alarm_at_block=3)
    with pytest.raises(LinkError):
        run(sim.path, PROGRAM)
    before = len(sim.device.received)
    with pytest.raises(LinkError, match="alarm state"):
        run(sim.path, PROGRAM)
    assert len(sim.device.received) == before


def _refused_by(device: GrblDevice) -> pytest.ExceptionInfo[LinkError]:
    """The LinkError a send of PROGRAM to ``device`` (on a pseudo-terminal) ends with."""
    server = PtyServer(device, block_delay_s=0.0005)
    server.start()
    try:
        with pytest.raises(LinkError) as info:
            run(server.path, PROGRAM)
    finally:
        server.stop()
    return info


class _Grbl09(GrblDevice):
    """GRBL 0.9j as it answers (grbl v0.9j report.c): its start-up line, and status reports
    whose fields follow the state after commas, ``<Idle,MPos:…,WPos:…>``."""

    says_banner = True

    def _banner(self) -> bytes:
        return b"\r\nGrbl 0.9j ['$' for help]\r\n" if self.says_banner else b""

    def status_report(self) -> bytes:
        return b"<Idle,MPos:0.000,0.000,0.000,WPos:0.000,0.000,0.000>\r\n"


@pytest.mark.parametrize("banner", [True, False], ids=["banner", "no-banner"])
def test_a_grbl_older_than_1_1_is_named_and_sent_nothing(banner: bool) -> None:
    # GRBL 0.9's status reports, settings and errors are not 1.1's (interface.md): the
    # send stops at start-up, naming the version, before any byte of the program
    device = _Grbl09(link_spec(load_target("grbl")), target=load_target("grbl"))
    device.says_banner = banner
    info = _refused_by(device)
    said = "is GRBL 0.9j (its start-up line" if banner else "answers in GRBL 0.9's status format"
    assert f"grbl: the controller {said}" in str(info.value)
    assert "update the firmware to GRBL 1.1" in str(info.value)
    assert str(info.value).endswith("nothing was sent")
    assert bytes(device.received).strip(b"?") == b""  # status queries at most


class _Noisy(GrblDevice):
    """A GRBL heard at the wrong baud rate from the start: its banner is bytes, no line end."""

    def _banner(self) -> bytes:
        return bytes(range(128, 256)) * 64  # 8 KiB


def test_noise_at_start_up_says_nothing_was_sent() -> None:
    device = _Noisy(link_spec(load_target("grbl")), target=load_target("grbl"))
    info = _refused_by(device)
    assert "with no answer in them" in str(info.value)
    assert str(info.value).endswith("; nothing of the program was sent")
    assert b"G21" not in bytes(device.received)


def test_an_error_on_the_last_block_fails_the_job(simulate: Any) -> None:
    # GRBL answers every line `ok` or `error:N` (interface.md); the job is done only when the
    # last line's answer has come: an `error:20` there is a failed job, not "sent N blocks"
    last = PROGRAM.count("\n")
    sim = simulate("grbl", fail_at_block=last, error="20")
    with pytest.raises(LinkError) as info:
        run(sim.path, PROGRAM)
    assert f"refused block {last} (line {last}: 'M2')" in str(info.value)
    assert "error:20 (Unsupported command" in str(info.value)


def quick(plan: Any) -> Any:
    """The plan with a 2 s response timeout: a controller that stopped answering is named fast."""
    from dataclasses import replace

    return replace(plan, spec=replace(plan.spec, response_timeout_s=2.0))


def run_quick(sim: Any, code: str) -> Any:
    """Send ``code`` to ``sim`` in simulated time: the bounds are reached without waiting."""
    plan = quick(prepare_send(code, load_target("grbl"), source="job.gcode"))
    port = open_port(sim.path, plan.spec.baud)
    try:
        return send_plan(port, plan, port_name=sim.path, clock=sim.clock())
    finally:
        port.close()


def test_a_lost_line_end_is_an_error_not_a_hang(simulate: Any) -> None:
    # line 50's `\n` lost: GRBL reads lines 50 and 51 as one and answers one `ok` fewer, then
    # reports Idle with an empty planner and RX buffer (Bf:15,128): nothing more will come
    sim = simulate("grbl", merge_at_block=50)
    with pytest.raises(LinkError, match="is idle and has not answered block 96") as info:
        run_quick(sim, PROGRAM)
    assert "line end lost" in str(info.value)


@pytest.mark.parametrize(
    ("fault", "said"),
    [
        ({"mute_at_block": 40}, "has not answered blocks 40–"),  # status reports only
        ({"ack_word": "OK"}, "no 'ok' to '$$' within 2 s (it said only '$10=1', '$12=0.002', 'OK'"),
        ({"deaf_at_block": 40}, "stopped answering"),  # nothing at all
    ],
)
def test_a_controller_that_stops_answering_is_named_within_a_bound(
    simulate: Any, fault: dict[str, Any], said: str
) -> None:
    sim = simulate("grbl", **fault)
    with pytest.raises(LinkError) as info:
        run_quick(sim, PROGRAM)
    assert said in str(info.value)
    assert "--from-line" in str(info.value) or "nothing was sent" in str(info.value)


def test_bytes_without_a_line_end_stop_the_job_not_fill_the_memory(simulate: Any) -> None:
    # a wrong baud rate reads GRBL's answers as bytes with no line end: rather than hold
    # them all while it waits for an `ok`, the sender stops the machine at 4 KiB of them
    # and says why
    sim = simulate("grbl", noise_at_block=40)
    with pytest.raises(LinkError, match="more than 4096 bytes while sending") as info:
        run_quick(sim, PROGRAM)
    message = str(info.value)
    assert "baud rate" in message and "--from-line" in message
    assert sim.device.resets == 1  # held and reset: blocks were in flight


def test_a_controller_that_says_too_much_is_counted_not_kept(simulate: Any) -> None:
    sim = simulate("grbl", chatter_at_block=10)
    result = run_quick(sim, PROGRAM)
    assert result.messages[:2] == ("[MSG:0]", "[MSG:1]")
    assert result.messages[999] == "[MSG:999]"
    assert result.messages[1000:] == ("… and 500 more messages, not kept",)
    assert sim.device.received == PROGRAM.encode()  # the job itself ran whole


def test_a_controller_that_runs_forever_is_stopped(simulate: Any) -> None:
    # the program's estimate is a few seconds; a GRBL still saying Run far beyond 3 times it
    # (plus the timeout) is held and reset
    sim = simulate("grbl", run_forever=True)
    code = "G21 G90\nG1 X1 F600\nG1 X2\n"
    with pytest.raises(LinkError, match="still reports 'Run'") as info:
        run_quick(sim, code)
    assert "feed hold, then a reset" in str(info.value)
    assert sim.device.resets == 1


def test_a_lost_port_names_the_last_line_grbl_reported_run(simulate: Any) -> None:
    # GRBL's `ok` means queued (planner: 15 blocks), not run: the resume line comes from the
    # last status report's Bf: count, never from the answers alone
    sim = simulate("grbl", drop_at_block=60, block_delay_s=0.01)
    with pytest.raises(LinkError, match="disappeared") as info:
        run(sim.path, PROGRAM)
    message = str(info.value)
    resume = resume_line(message)
    assert "may have run, whole or in part" in message
    # every line before the resume line had run on the controller when the port went
    assert ran_in_order(sim.device, resume - 1)
    # and it is well before the line after the last one answered (the old, too late, advice)
    assert resume < 60


# What GRBL 1.1h itself answers each line with: gnea/grbl v1.1h built for the host with
# grbl/grbl-sim and fed one line at a time over a pseudo-terminal (a reset and $X between lines).
GRBL_ANSWERS = {
    "M7": "error:20",  # no M7 in the default build (config.h ENABLE_M7 off)
    "M6 T1": "error:20",  # no M6 at all
    "G4 P-1": "error:4",
    "G90.1": "error:20",
    "G1.5 X1": "error:23",
    "G0 G1 X1": "error:24",
    "X1 X2": "error:25",
    "T256": "error:38",
    "A5": "error:20",
    "%": "error:1",
    "M3 M5": "error:21",
    "G61.1": "error:20",
    "G28.2": "error:20",
    "S-5": "error:4",
    "G1 X1 F-1": "error:4",
    "N-1 G0 X0": "error:4",
    "G21 " + "X1.23456" * 11: "error:11",
    "G1 X1 F100": "ok",
    "M8": "ok",
    "G91.1": "ok",
    "M1": "ok",
    "G38.2 Z-1 F10": "ok",  # taken by the parser (the probe then fails: an alarm, not an error)
}


@pytest.mark.parametrize(("line", "answer"), GRBL_ANSWERS.items())
def test_the_pre_check_refuses_what_grbl_refuses(line: str, answer: str) -> None:
    from camtool_postprocessors.grbl.link import refusal

    code = refusal(line)
    assert (f"error:{code}" if code is not None else "ok") == answer


@pytest.mark.parametrize("line", ["M7", "M6 T1", "G4 P-1"])
def test_a_line_grbl_refuses_is_refused_before_the_first_byte(line: str, simulate: Any) -> None:
    code = PROGRAM.replace("M5\n", f"{line}\nM5\n")
    number = code.splitlines().index(line) + 1
    # (the reader itself already refuses a negative dwell, naming the line the same way)
    with pytest.raises(InputError, match=rf"job.gcode(, line |:){number}: "):
        prepare_send(code, load_target("grbl"), source="job.gcode")
    sim = simulate("grbl")
    with pytest.raises(InputError):
        run(sim.path, code)
    assert not sim.device.received  # nothing was sent


def test_a_refused_line_is_refused_before_the_moves_are_timed(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # The timing simulates every step: a 400 m move at GRBL's 250 steps/mm is 10^8 rows,
    # which the refusal of its 9-digit number must not wait for.
    import camtool.link.plan as plan

    def timed(*args: Any) -> Any:
        raise AssertionError("the moves were timed before the check")

    monkeypatch.setattr(plan, "_times", timed)
    code = "G21 G90\nG0 X400000 Y0\nG1 Z-1 F100\nG1 X400000.125\nM2\n"
    with pytest.raises(InputError, match=r"far\.gcode, line 4: 'G1 X400000\.125'"):
        prepare_send(code, load_target("grbl"), source="far.gcode")


def test_a_refused_line_is_quoted_as_the_file_writes_it() -> None:
    # a no-break space between words (UTF-8 C2 A0): GRBL answers error:1 for the byte C2,
    # which the check sees (one character per byte); the message quoted the Latin-1 reading
    # of the two bytes, 'G1Â\xa0X10', a letter that is not in the file
    code = PROGRAM.replace("M5\n", "G1\u00a0X10 Y0\nM5\n")
    with pytest.raises(InputError) as refused:
        prepare_send(code.encode("utf-8"), load_target("grbl"), source="job.gcode")
    message = str(refused.value)
    assert "'G1\\xa0X10 Y0': GRBL 1.1 would refuse it with error:1" in message
    assert "\u00c2" not in message


def test_an_arc_counts_grbls_segments_as_a_lower_bound() -> None:
    import math

    from camtool_postprocessors.grbl.link import arc_blocks

    # motion_control.c mc_arc: floor(|0.5 θ r| / sqrt(tol (2r - tol))); a half circle of radius
    # 5 mm at $12 = 0.002 mm: 7.854 / 0.14141 = 55.5 -> 55 planner blocks
    assert arc_blocks(5.0, math.pi, 0.002) == 55
    plan = prepare_send(PROGRAM, load_target("grbl"))
    arc = next(b for b in plan.blocks if b.text.startswith("G2 "))
    # counted at 4 x the profile's $12 (a controller's $12 may be raised): fewer, never more
    assert arc.queued == arc_blocks(5.0, math.pi, 0.008) == 27
    # G4 waits for an empty planner (mc_dwell), M5 too once the program started the spindle
    syncs = [b.text for b in plan.blocks if b.sync]
    assert syncs == ["G4 P1.5", "M5", "M2"]


# A job's tool change by hand, as camtool writes it for GRBL (no M6: error 20).
CHANGE = "M5\n(change to T2: end-mill 3 mm)\nM0\nM3 S1000\nG0 Z5\n"
PAUSED = PROGRAM.replace("G0 Z5\n", "G0 Z5\n" + CHANGE, 1)


def test_the_programs_pause_waits_for_the_operator_then_resumes(simulate: Any) -> None:
    """GRBL answers ``M0`` only when cycle start resumes it (gcode.c: a feed hold in the line).

    Before, the unanswered M0 ran out the answer bound and the job was stopped at every
    tool change; now the operator is asked, with the change's comment, and ``~`` resumes.
    """
    sim = simulate("grbl", block_delay_s=0.001)
    control = AnswersTurns(True)
    run(sim.path, PAUSED, control=control)
    (prompt,) = control.prompts
    assert "holds (Hold:0)" in prompt and "line 13: 'M0'" in prompt
    assert "after '(change to T2: end-mill 3 mm)'" in prompt
    assert sim.device.pauses == 1 and not sim.device.held and sim.device.resets == 0
    assert bytes(sim.device.received) == PAUSED.encode()
    assert sim.device.position() == pytest.approx(END)


def test_a_pause_no_one_resumes_stops_the_job_at_the_pause(simulate: Any) -> None:
    sim = simulate("grbl", block_delay_s=0.001)
    with pytest.raises(LinkError, match=r"holds \(Hold:0\) at block 13 \(line 13: 'M0'") as info:
        run(sim.path, PAUSED, control=AnswersTurns(False))
    assert "not resumed: stopped" in str(info.value)
    assert sim.device.resets == 1  # feed hold, reset: position kept, nothing ran past M0
    received = [b.decode() for b in sim.device.blocks]
    assert received[-1] == "M0\n" or "M0\n" in received
    assert lines_run(sim.device) <= 13


class _GrblHal(GrblDevice):
    """grblHAL as it starts (grblHAL core report.c): ``GrblHAL 1.1f ['$' or '$HELP' for
    help]``; its status reports and answers are GRBL 1.1's."""

    def _banner(self) -> bytes:
        return b"\r\nGrblHAL 1.1f ['$' or '$HELP' for help]\r\n"


def test_grblhal_s_banner_starts_the_job() -> None:
    # taken for GRBL's banner: the job starts on it, not after the banner's time is out and
    # a status query answers, with the banner passed on as a message of the controller
    device = _GrblHal(link_spec(load_target("grbl")), target=load_target("grbl"))
    server = PtyServer(device, block_delay_s=0.0005)
    server.start()
    try:
        result = run(server.path, PROGRAM)
    finally:
        server.stop()
    assert bytes(device.received) == PROGRAM.encode()
    assert result.messages == ()
