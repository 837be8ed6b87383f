"""The i8751 link over a pseudo-terminal pair: packets, 'F' and 'A', stalls, resume, DTR/DSR.

Expected values come from Intf8751 §3.7 (reference/Intf8751.md: access key
13H, packets of at most 5 moves ending 45H, 'F' after each, 54H answered 'A')
and from the programs themselves (the summed step counts), never from
camtool's output.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import pytest

from camtool.link.device import make_device
from camtool.link.plan import prepare_send
from camtool.link.sender import open_port, send_plan
from camtool.model.errors import LinkError
from camtool.post.registry import load_target
from camtool_postprocessors.i8751.packets import Record, encode_stream
from tests.link.controls import PauseAt

# 12 moves, 3 packets (5 + 5 + 2): X +100 steps each, Y alternating +50 / -30, one Z plunge
# and lift; at the profile's 100 steps/mm the tool ends at X 12, Y 6*0.5 - 6*0.3 = 1.2, Z 0.
RECORDS = [Record((100, 50 if k % 2 == 0 else -30, 0), 0, 0) for k in range(12)]
RECORDS[3] = Record((100, -30, -50), 0, 1)
RECORDS[7] = Record((100, -30, 50), 0, 0)
SESSION = encode_stream(RECORDS)
END = (12.0, 1.2, 0.0)


SILENT_S = 5.0
"""The response timeout of a test that waits it out, s: the simulator's thread must answer the
packets before the silent one within it, and a loaded machine deschedules it for a good part of
a second (0.3 s, the bound before, failed then)."""


def plan_for(code: bytes, **options: Any) -> Any:
    plan = prepare_send(code, load_target("i8751"), source="job.bin", **options)
    return plan


def run(sim: Any, code: bytes = SESSION, timeout_s: float | None = None, **options: Any) -> Any:
    """Send ``code`` to the simulated device ``sim``; return once it has seen the port closed.

    The wait makes the next send a new session for the device, however soon it opens the
    port again (the server would not see a close and an open between two of its polls).
    """
    plan = plan_for(code, from_line=options.pop("from_line", None))
    if timeout_s is not None:
        plan = dataclasses.replace(
            plan, spec=dataclasses.replace(plan.spec, response_timeout_s=timeout_s)
        )
    port = open_port(sim.path, plan.spec.baud)
    try:
        return send_plan(port, plan, port_name=sim.path, time_scale=0.0, **options)
    finally:
        port.close()
        assert sim.server.wait_host_gone(60.0), "the device never saw the port closed"


def test_the_session_is_three_packets_and_the_end_of_data() -> None:
    plan = plan_for(SESSION)
    # the key 13H is the start-up (sent at every session); packets of 5, 5 and 2 moves
    assert plan.spec.startup == b"\x13"
    assert [(b.line, b.last_line, b.ack) for b in plan.blocks] == [
        (1, 5, "F"),
        (6, 10, "F"),
        (11, 12, "F"),
        (13, 13, "A"),
    ]
    assert all(b.data[-1] == 0x45 for b in plan.blocks[:3])
    assert plan.blocks[-1].data == b"\x54"
    assert plan.spec.startup + b"".join(b.data for b in plan.blocks) == SESSION


def test_the_interface_receives_the_file_byte_for_byte(simulate: Any) -> None:
    sim = simulate("i8751")
    result = run(sim)
    assert bytes(sim.device.received) == SESSION
    assert sim.device.ended and not sim.device.overrun and not sim.device.garbled
    assert len(sim.device.executed) == 3
    assert sim.device.position() == pytest.approx(END)
    # the 'M' per stored byte is logged, never a message; no modem lines on a pty: a note
    assert "M" not in result.messages
    assert any("DTR/DSR handshake was skipped" in m for m in result.messages)


def test_a_posted_file_arrives_byte_for_byte(simulate: Any, tmp_path: Path) -> None:
    from camtool.cli.main import main

    out = tmp_path / "plate.bin"
    assert main(["post", "samples/plate.dxf", "-t", "i8751", "-o", str(out)]) == 0
    sim = simulate("i8751")
    run(sim, out.read_bytes())
    assert bytes(sim.device.received) == out.read_bytes()
    assert not sim.device.overrun


def test_a_dump_is_sent_as_the_bytes_it_lists(simulate: Any, tmp_path: Path) -> None:
    from camtool.cli.main import main

    binary, dump = tmp_path / "plate.bin", tmp_path / "plate.txt"
    assert main(["post", "samples/plate.dxf", "-t", "i8751", "-o", str(binary)]) == 0
    dumped = ["post", "samples/plate.dxf", "-t", "i8751", "--format", "dump", "-o", str(dump)]
    assert main(dumped) == 0
    sim = simulate("i8751")
    run(sim, dump.read_bytes())
    assert bytes(sim.device.received) == binary.read_bytes()


def test_pause_comes_between_packets_then_resumes(simulate: Any) -> None:
    sim = simulate("i8751", block_delay_s=0.002)
    control = PauseAt(1, "resume")
    run(sim, control=control, progress=control.progress)
    (pause,) = control.pauses
    assert pause.in_flight == 0 and pause.done == 1 and pause.line == 1
    assert bytes(sim.device.received) == SESSION
    assert not sim.device.overrun


def test_stop_at_a_pause_sends_whole_packets_and_from_line_finishes(simulate: Any) -> None:
    sim = simulate("i8751", block_delay_s=0.002)
    control = PauseAt(2, "stop")
    with pytest.raises(LinkError, match="stopped by the operator after block 2") as info:
        run(sim, control=control, progress=control.progress)
    # packets 1 and 2 whole: the key, then each packet's 4 moves without Z (14 bytes: 4 + 4
    # + 2 + 2 (m 05H) + 2), one with Z (16 bytes) and its 45H
    first = SESSION[: 1 + 2 * (4 * 14 + 16 + 1)]
    assert first[-1] == 0x45
    assert bytes(sim.device.received) == first
    assert "--from-line 11" in str(info.value)
    run(sim, from_line=11)
    # the second session starts with the key again and holds packet 3 and the end
    assert bytes(sim.device.received) == first + b"\x13" + SESSION[len(first) :]
    assert sim.device.position() == pytest.approx(END)


def test_a_packet_never_answered_stops_naming_it_and_from_line_continues(simulate: Any) -> None:
    sim = simulate("i8751", fail_at_block=2)
    with pytest.raises(LinkError) as info:
        run(sim, timeout_s=SILENT_S)
    message = str(info.value)
    assert "block 2 (line 6) was sent and not confirmed" in message
    assert "--from-line 6" in message
    assert len(sim.device.blocks) == 2  # nothing after the packet that was not answered
    run(sim, from_line=6)
    assert sim.device.connections == 2
    assert sim.device.position() == pytest.approx(END)


def test_from_line_inside_a_packet_is_refused() -> None:
    from camtool.model.errors import UsageError

    with pytest.raises(UsageError, match="resume at line 6"):
        plan_for(SESSION, from_line=8)


def test_a_port_that_disappears_is_a_link_error(simulate: Any) -> None:
    sim = simulate("i8751", drop_at_block=2)
    with pytest.raises(LinkError, match="disappeared"):  # noticed at once: the bound never runs out
        run(sim, timeout_s=60.0)


class InProcessPort:
    """A port whose other end is an in-process device; ``dsr`` as given (None: no modem lines)."""

    def __init__(self, dsr: bool | None) -> None:
        self.device = make_device(load_target("i8751"))
        self.device.connect()
        self._dsr = dsr
        self.dtr = self.rts = False
        self.timeout: float = 0
        self.out = bytearray()
        self.written = bytearray()

    @property
    def dsr(self) -> bool:
        if self._dsr is None:
            raise OSError(25, "Inappropriate ioctl for device")
        return self._dsr and self.dtr

    @property
    def in_waiting(self) -> int:
        return len(self.out)

    def write(self, data: bytes) -> int:
        self.written += data
        self.out += self.device.feed(data)
        while self.device.pending():
            self.out += self.device.step()
        return len(data)

    def flush(self) -> None:
        pass

    def read(self, size: int) -> bytes:
        data = bytes(self.out[:size])
        del self.out[:size]
        return data


def test_no_dsr_after_dtr_sends_nothing() -> None:
    plan = plan_for(SESSION)
    plan = dataclasses.replace(plan, spec=dataclasses.replace(plan.spec, response_timeout_s=0.1))
    port = InProcessPort(dsr=False)
    with pytest.raises(LinkError, match="no DSR") as info:
        send_plan(port, plan, port_name="COM1")
    assert "nothing was sent" in str(info.value)
    assert port.dtr and not port.written


def test_dsr_answering_dtr_lets_the_session_go() -> None:
    port = InProcessPort(dsr=True)
    result = send_plan(port, plan_for(SESSION), port_name="COM1", time_scale=0.0)
    assert bytes(port.written) == SESSION
    assert not any("skipped" in m for m in result.messages)
    assert port.device.position() == pytest.approx(END)


def test_the_cli_sends_and_dry_runs(simulate: Any, tmp_path: Path, capsys: Any) -> None:
    from camtool.cli.main import main

    job = tmp_path / "job.bin"
    job.write_bytes(SESSION)
    assert main(["send", str(job), "-t", "i8751", "--dry-run"]) == 0
    out = capsys.readouterr().out
    # packet 3: moves 11 and 12, 14 bytes each, and its 45H
    assert "block 3 line 11: 29 bytes" in out and "end of data" in out
    sim = simulate("i8751")
    log = tmp_path / "bytes.log"
    assert main(["send", str(job), "-t", "i8751", "--port", sim.path, "--log", str(log)]) == 0
    assert bytes(sim.device.received) == SESSION
    logged = log.read_text()
    assert "> 13 |" in logged and "> 54 |T|" in logged and "< 41 |A|" in logged
    assert logged.count("F|") == 3  # 'F' after each of the 3 packets (after its 'M's)


def test_the_cli_names_a_lost_port_with_exit_1(simulate: Any, tmp_path: Path, capsys: Any) -> None:
    from camtool.cli.main import main

    job = tmp_path / "job.bin"
    job.write_bytes(SESSION)
    sim = simulate("i8751", drop_at_block=1)
    code = main(["send", str(job), "-t", "i8751", "--port", sim.path])
    err = capsys.readouterr().err
    assert code == 1
    assert "Traceback" not in err and "i8751" in err
