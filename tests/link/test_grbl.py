"""GRBL over a pseudo-terminal pair: character counting, errors, resume, pause, a lost port.

Expected values come from GRBL's documents (gnea/grbl doc/markdown/interface.md,
doc/csv/error_codes_en_US.csv) and from the programs themselves (where their
last moves end), never from camtool's output.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from camtool.link.plan import prepare_send
from camtool.link.sender import StopAtPause, open_port, send_plan
from camtool.model.errors import LinkError
from camtool.post.registry import load_target
from tests.link.controls import PauseAt

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


def test_an_error_stops_the_job_naming_the_line_and_grbl_words(simulate: Any) -> None:
    sim = simulate("grbl", fail_at_block=19, error="22", block_delay_s=0.002)
    with pytest.raises(LinkError) as info:
        run(sim.path, PROGRAM)
    message = str(info.value)
    assert "line 19" in message
    # error_codes_en_US.csv, code 22
    assert "Undefined feed rate: Feed rate has not yet been set or is undefined." in message
    assert "--from-line" in message
    # (a plunge: skipping it leaves the path readable)
    # the lines already in GRBL's buffer ran (interface.md, RESERVATION): nothing after them
    sent = len(sim.device.blocks)
    assert 19 < sent < PROGRAM.count("\n")
    assert f"--from-line {sent + 1}" in message


def test_from_line_after_an_error_ends_where_an_uninterrupted_run_ends(simulate: Any) -> None:
    sim = simulate("grbl", fail_at_block=19, error="22", block_delay_s=0.002)
    with pytest.raises(LinkError) as info:
        run(sim.path, PROGRAM)
    resume = int(str(info.value).rsplit("--from-line ", 1)[1].split()[0])
    run(sim.path, PROGRAM, from_line=resume)
    assert sim.device.connections == 2
    assert sim.device.position() == pytest.approx(END)
    # the restore blocks: the modal state lines 1..resume-1 set (F100 or F300, M3 S1000, dwell)
    first = resume - 1  # the blocks of the first run
    restored = [b.decode() for b in sim.device.blocks[first : first + 4]]
    assert restored[0] == "G21 G90 G94 G17\n"
    assert restored[1] in ("F100\n", "F300\n")
    assert "M3 S1000\n" in restored
    assert "G4 P1.5\n" in restored


def test_pause_waits_for_every_block_in_flight_then_resumes(simulate: Any) -> None:
    sim = simulate("grbl", block_delay_s=0.001)
    control = PauseAt(30, "resume")
    run(sim.path, PROGRAM, control=control, progress=control.progress)
    (pause,) = control.pauses
    assert pause.in_flight == 0 and pause.done >= 30
    assert bytes(sim.device.received) == PROGRAM.encode()


def test_stop_at_a_pause_names_the_line_to_resume_at(simulate: Any) -> None:
    sim = simulate("grbl", block_delay_s=0.001)
    control = PauseAt(30, "stop")
    with pytest.raises(LinkError, match=r"stopped by the operator after block \d+") as info:
        run(sim.path, PROGRAM, control=control, progress=control.progress)
    done = len(sim.device.blocks)
    assert f"--from-line {done + 1}" in str(info.value)
    # whole blocks only: what arrived is the file's first `done` lines
    assert bytes(sim.device.received) == "".join(PROGRAM.splitlines(True)[:done]).encode()
    run(sim.path, PROGRAM, from_line=done + 1)
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


def test_an_error_on_the_last_block_fails_the_job(simulate: Any) -> None:
    # GRBL answers every line `ok` or `error:N` (interface.md); the job is done only when the
    # last line's answer has come: an `error:20` there is a failed job, not "sent N blocks"
    last = PROGRAM.count("\n")
    sim = simulate("grbl", fail_at_block=last, error="20")
    with pytest.raises(LinkError) as info:
        run(sim.path, PROGRAM)
    assert f"refused block {last} (line {last}: 'M2')" in str(info.value)
    assert "error:20 (Unsupported command" in str(info.value)
