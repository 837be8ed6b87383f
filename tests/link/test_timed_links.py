"""ValCNC and matlab-router over a pseudo-terminal pair: the links with no answer.

ValCNC (Munoz-22 S004-R17): ``C\\n`` on open, then one block at a time; the bytes
after ``C\\n`` equal the posted file. matlab-router (Angel-11 §2.7): CR-ended
numbers, one job per connection. Waits are scaled to 0 (``time_scale``): these
links pace themselves by the timing model, which the verifier tests cover.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest

from camtool.cli.main import main
from camtool.link.plan import prepare_send
from camtool.link.sender import Progress, open_port, send_plan
from camtool.link.spec import WireBlock
from camtool.model.errors import InputError, LinkError
from camtool.post.registry import load_target

# A 20 x 10 mm rectangle and an arc in the ValCNC dialect (Munoz-22 Table 7: G00-G03 X Y Z I J,
# no spaces); the tool ends at X5 Y5 Z5.
VALCNC = (
    "G00Z5\nG00X5Y5\nG01Z-1\nG01X25Y5Z-1\nG01X25Y15Z-1\nG01X5Y15Z-1\nG01X5Y5Z-1\n"
    "G02X15Y5I5J0\nG03X5Y5I-5J0\nG00Z5\n"
)
PACED_S = 1e6
"""A block time far longer than any test (11 days), s: the host waits on, whatever the load."""


def send(path: str, name: str, code: str | bytes, **options: Any) -> Any:
    plan = prepare_send(code, load_target(name), from_line=options.pop("from_line", None))
    port = open_port(path, plan.spec.baud)
    try:
        return send_plan(
            port,
            plan,
            port_name=path,
            time_scale=options.pop("time_scale", 0),
            reopen=lambda: open_port(path, plan.spec.baud),
            **options,
        )
    finally:
        port.close()


def test_valcnc_gets_c_then_the_file(simulate: Any) -> None:
    sim = simulate("valcnc")
    send(sim.path, "valcnc", VALCNC)
    sim.server.stop()
    assert bytes(sim.device.received) == VALCNC.encode()
    assert sim.device.startup_seen
    assert sim.device.position() == pytest.approx((5.0, 5.0, 5.0))


def test_valcnc_a_posted_file_arrives_byte_for_byte(simulate: Any, tmp_path: Path) -> None:
    out = tmp_path / "star.ngc"
    assert main(["post", "samples/star.csv", "-t", "valcnc", "-o", str(out)]) == 0
    sim = simulate("valcnc")
    send(sim.path, "valcnc", out.read_text())
    sim.server.stop()
    assert bytes(sim.device.received) == out.read_bytes()


class PauseOnce:
    def __init__(self, at: int) -> None:
        self.at = at
        self.pause_requested = False
        self.seen: list[Progress] = []

    def progress(self, p: Progress) -> None:
        self.pause_requested = self.pause_requested or p.done == self.at

    def paused(self, progress: Progress) -> str:
        self.seen.append(progress)
        return "resume"

    def between_blocks(self, prompt: str, done: WireBlock, following: WireBlock) -> bool:
        return True


def test_valcnc_pause_and_resume_never_split_a_block(simulate: Any) -> None:
    sim = simulate("valcnc")
    control = PauseOnce(4)
    send(sim.path, "valcnc", VALCNC, control=control, progress=control.progress)
    sim.server.stop()
    assert [p.done for p in control.seen] == [4]
    assert bytes(sim.device.received) == VALCNC.encode()
    assert sim.device.blocks == [line.encode() for line in VALCNC.splitlines(True)]


def test_valcnc_lost_port_then_from_line_ends_where_a_whole_run_ends(simulate: Any) -> None:
    sim = simulate("valcnc", drop_at_block=6)
    # the port goes as block 6 arrives, while the host waits out block 6's time: that time
    # is made far longer than the test (the others none), so the host notices the drop
    # before it may write block 7 however slowly this machine runs the simulator's thread
    # (paced by the real times, a loaded machine let the host write blocks 7-9 first)
    plan = prepare_send(VALCNC, load_target("valcnc"))
    times = [PACED_S if block.line == 6 else 0.0 for block in plan.blocks]
    port = open_port(sim.path, plan.spec.baud)
    try:
        with pytest.raises(LinkError, match="disappeared") as info:
            send_plan(port, replace(plan, block_time_s=times), port_name=sim.path)
    finally:
        port.close()
    assert "the last block sent was line 6" in str(info.value)
    assert "--from-line 6 if line 6 did not run" in str(info.value)
    # no answer on this link: the earlier lines ran only if the machine kept the paced time
    assert "the lines before line 6 ran only if the machine kept that pace" in str(info.value)
    # the simulator dropped the port as block 6 arrived: it did not run; resume there
    resumed = simulate("valcnc")
    send(resumed.path, "valcnc", VALCNC, from_line=6)
    resumed.server.stop()
    ran = b"".join(sim.device.executed) + b"".join(resumed.device.executed)
    assert ran == VALCNC.encode()
    assert resumed.device.position() == pytest.approx((5.0, 5.0, 5.0))


def test_valcnc_refuses_a_plunge_deeper_than_its_limit() -> None:
    from camtool.model.errors import DialectError

    with pytest.raises(DialectError, match=r"line 3: Z -2 mm is deeper than the 1 mm"):
        prepare_send(VALCNC.replace("Z-1", "Z-2"), load_target("valcnc"))
    assert prepare_send(VALCNC.replace("Z-1", "Z-2"), load_target("valcnc"), max_depth_mm=2)


@pytest.fixture
def router_wire(tmp_path: Path) -> bytes:
    """Two strokes (two jobs) posted in the wire format."""
    drawing = tmp_path / "two.csv"
    drawing.write_text("x,y\n10,10\n60,10\n60,40\n\n100,100\n150,120\n")
    out = tmp_path / "two.txt"
    code = main(["post", str(drawing), "-t", "matlab-router", "--format", "wire", "-o", str(out)])
    assert code == 0
    return out.read_bytes()


def test_router_jobs_arrive_byte_for_byte_one_per_connection(
    simulate: Any, router_wire: bytes
) -> None:
    plan = prepare_send(router_wire, load_target("matlab-router"))
    assert len(plan.blocks) == 2
    # each job is n, x1, y1 and 4n values, every one ended by CR (Angel-11 §2.7)
    for block in plan.blocks:
        n = int(block.data.split(b"\r")[0])
        assert block.data.count(b"\r") == 3 + 4 * n
    sim = simulate("matlab-router")
    control = PauseOnce(-1)
    send(sim.path, "matlab-router", router_wire, control=control)
    sim.server.stop()
    assert bytes(sim.device.received) == router_wire
    assert sim.device.blocks == [b.data for b in plan.blocks]


def test_router_without_an_operator_stops_after_a_job(simulate: Any, router_wire: bytes) -> None:
    sim = simulate("matlab-router")
    with pytest.raises(LinkError, match="reset the master") as info:
        send(sim.path, "matlab-router", router_wire)
    second = prepare_send(router_wire, load_target("matlab-router")).blocks[1]
    assert f"--from-line {second.line}" in str(info.value)
    send(sim.path, "matlab-router", router_wire, from_line=second.line)
    sim.server.stop()
    assert bytes(sim.device.received) == router_wire


def test_router_from_line_inside_a_job_is_refused(router_wire: bytes) -> None:
    from camtool.model.errors import UsageError

    with pytest.raises(UsageError, match="inside block 1"):
        prepare_send(router_wire, load_target("matlab-router"), from_line=3)


def test_router_script_format_is_refused(tmp_path: Path) -> None:
    out = tmp_path / "star.m"
    assert main(["post", "samples/star.csv", "-t", "matlab-router", "-o", str(out)]) == 0
    with pytest.raises(InputError, match="--format wire"):
        prepare_send(out.read_bytes(), load_target("matlab-router"))


def test_a_dwell_is_timed_on_its_own_block_not_on_the_next_move() -> None:
    # G4 P2 runs after the spindle starts and before the first move: the sender must wait its
    # 2 s after the G4 block (GRBL: P is seconds, gnea/grbl doc/markdown/commands.md), and the
    # move's block keeps only the move's own time.
    code = "G21 G90\nM3 S1000\nG4 P2\nG1 X1 F600\nM5\n"
    plain = prepare_send(code.replace("G4 P2\n", "(no dwell)\n"), load_target("grbl"))
    dwell = prepare_send(code, load_target("grbl"))
    lines = [b.line for b in dwell.blocks]
    at = {line: t for line, t in zip(lines, dwell.block_time_s, strict=True)}
    assert at[3] == pytest.approx(2.0)
    assert at[4] == pytest.approx(dict(zip(lines, plain.block_time_s, strict=True))[4])
