"""``camtool send`` and ``simulate-device`` as a user runs them: exit codes, stdout, stderr."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from camtool.cli.main import main
from tests.link.test_grbl import PROGRAM
from tests.link.test_timed_links import VALCNC


def run(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    code = main(args)
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture
def job(tmp_path: Path) -> Path:
    path = tmp_path / "job.gcode"
    path.write_text(PROGRAM)
    return path


def test_dry_run_prints_the_plan_on_stdout(job: Path, capsys: Any) -> None:
    code, out, err = run(["send", str(job), "-t", "grbl", "--dry-run"], capsys)
    assert code == 0
    lines = out.splitlines()
    assert lines[1].startswith("link: 115200 baud 8N1")
    assert "character counting (127-byte receive buffer)" in lines[1]
    blocks = PROGRAM.count("\n")
    assert f"blocks: {blocks} ({len(PROGRAM)} bytes) of {blocks}, from line 1" in out
    assert lines[-1] == f"block {blocks} line {blocks}: 3 bytes, 0.000 s: M2"
    assert err == ""


def test_what_grbl_would_refuse_is_refused_before_sending(tmp_path: Path, capsys: Any) -> None:
    # a CamBam-style header (LinuxCNC's craftsmancnc.ngc): GRBL 1.1h has no G64 (gcode.c takes
    # G61 only) and answers this very line `error:20` (checked on GRBL 1.1h built with
    # grbl-sim): refused before the first byte, naming the line, exit 3
    path = tmp_path / "cambam.ngc"
    path.write_text("G21 G90 G64 P0.25 G40\nG0 Z5\nG0 X1 Y1\nG1 Z-0.5 F100\nG1 X2\nG0 Z5\nM2\n")
    code, _, err = run(["send", str(path), "-t", "grbl", "--dry-run"], capsys)
    assert code == 3
    assert "cambam.ngc, line 1: 'G21 G90 G64 P0.25 G40': GRBL 1.1 would refuse it" in err
    assert "error:20 (Unsupported command" in err


def test_verify_says_what_send_would_refuse(tmp_path: Path, capsys: Any) -> None:
    # The same CamBam-style header: the program verifies (the reader takes G64), and the
    # summary and the report say that GRBL stops at its first line, in send's words.
    # LinuxCNC runs it, and camtool's own grbl program passes the check.
    path = tmp_path / "cambam.ngc"
    path.write_text("G21 G90 G64 P0.25 G40\nG0 Z5\nG0 X1 Y1\nG1 Z-0.5 F100\nG1 X2\nG0 Z5\nM2\n")
    report = tmp_path / "r.json"
    code, _, err = run(["verify", str(path), "-t", "grbl", "--report", str(report)], capsys)
    assert code == 0
    said = "cambam.ngc, line 1: 'G21 G90 G64 P0.25 G40': GRBL 1.1 would refuse it with error:20"
    assert f"camtool: warning: {tmp_path}/{said}" in err
    assert "camtool send refuses the program, sending nothing" in err
    assert any(said in w for w in json.loads(report.read_text())["warnings"])
    code, _, err = run(["verify", str(path), "-t", "linuxcnc"], capsys)
    assert code == 0 and "would refuse" not in err
    posted = tmp_path / "square.gcode"
    assert main(["post", str(path), "-t", "grbl", "-o", str(posted)]) == 0
    code, _, err = run(["verify", str(posted), "-t", "grbl"], capsys)
    assert code == 0 and "would refuse" not in err


def test_a_number_grbl_would_read_short_is_refused_before_sending(
    tmp_path: Path, capsys: Any
) -> None:
    # GRBL 1.1's read_float keeps 8 digits (nuts_bolts.c MAX_INT_DIGITS): X400000.125 moves
    # to X400000.12, with no error. Six decimals lose less than 0.0005 and are sent.
    path = tmp_path / "far.gcode"
    path.write_text("G21 G90\nG0 X400000 Y0\nG1 Z-1 F100\nG1 X400000.125\nM2\n")
    code, out, err = run(["send", str(path), "-t", "grbl", "--dry-run"], capsys)
    assert code == 3 and out == ""
    assert "far.gcode, line 4: 'G1 X400000.125': GRBL 1.1 reads the first 8 digits" in err
    assert "it would read X400000.125 as X400000.12;" in err
    path.write_text("G21 G90\nG0 X12.345678 Y0\nG1 Z-1 F100\nG1 X12.3456789 Y1.0000001\nM2\n")
    code, _, err = run(["send", str(path), "-t", "grbl", "--dry-run"], capsys)
    assert code == 0, err


def test_dry_run_from_line_shows_the_restore(job: Path, capsys: Any) -> None:
    code, out, _ = run(["send", str(job), "-t", "grbl", "--dry-run", "--from-line", "8"], capsys)
    assert code == 0
    assert "restore: 16 bytes, 0.000 s: G21 G90 G94 G17" in out
    assert "restore: 9 bytes, 0.000 s: M3 S1000" in out


def test_from_line_in_an_arc_continuation_is_refused(tmp_path: Path, capsys: Any) -> None:
    path = tmp_path / "arcs.gcode"
    path.write_text("G21 G90\nG0 X10 Y0\nG2 X0 Y10 I-10 J0 F200\nX-10 Y0 I0 J-10\n")
    code, _, err = run(["send", str(path), "-t", "grbl", "--dry-run", "--from-line", "4"], capsys)
    assert code == 2
    assert "continues the arc mode G2 of line 3" in err


def test_a_target_without_a_link_says_how_its_code_gets_there(job: Path, capsys: Any) -> None:
    code, _, err = run(["send", str(job), "-t", "linuxcnc", "--port", "loop://"], capsys)
    assert code == 1
    assert "LinuxCNC runs its own files" in err


def test_no_port_is_a_usage_error(job: Path, capsys: Any) -> None:
    code, _, err = run(["send", str(job), "-t", "grbl"], capsys)
    assert code == 2 and "--port is required" in err


def test_a_port_that_cannot_open_is_exit_1(job: Path, tmp_path: Path, capsys: Any) -> None:
    code, _, err = run(["send", str(job), "-t", "grbl", "--port", str(tmp_path / "nope")], capsys)
    assert code == 1 and "cannot open port" in err and "Traceback" not in err


def test_send_to_the_simulator_and_log_every_byte(
    job: Path, tmp_path: Path, simulate: Any, capsys: Any
) -> None:
    sim = simulate("grbl")
    log = tmp_path / "job.log"
    code, out, err = run(
        ["send", str(job), "-t", "grbl", "--port", sim.path, "--log", str(log)], capsys
    )
    assert code == 0, err
    assert out == ""
    assert bytes(sim.device.received) == PROGRAM.encode()
    text = log.read_text()
    assert " > 47 32 31 20 47 39 30 20 47 39 34 20 47 31 37 0a |G21 G90 G94 G17\\n|" in text
    assert "< " in text and "Grbl 1.1h" in text


def test_a_port_that_disappears_is_exit_1_without_traceback(
    job: Path, simulate: Any, capsys: Any
) -> None:
    sim = simulate("grbl", drop_at_block=20, block_delay_s=0.002)
    code, _, err = run(["send", str(job), "-t", "grbl", "--port", sim.path], capsys)
    assert code == 1
    assert "disappeared" in err and "--from-line" in err
    assert "Traceback" not in err


def test_a_controller_error_is_exit_1_naming_line_and_words(
    job: Path, simulate: Any, capsys: Any
) -> None:
    sim = simulate("grbl", fail_at_block=5, error="20", block_delay_s=0.002)
    code, _, err = run(["send", str(job), "-t", "grbl", "--port", sim.path], capsys)
    assert code == 1
    assert "refused block 5 (line 5: 'G1 Z-0.1 F100')" in err
    # error_codes_en_US.csv, code 20
    assert "Unsupported command: Unsupported or invalid g-code command found in block." in err


def _sigint_default() -> None:
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def test_valcnc_through_simulate_device(tmp_path: Path, capsys: Any) -> None:
    job = tmp_path / "job.ngc"
    job.write_text(VALCNC)
    sim = subprocess.Popen(
        [sys.executable, "-m", "camtool", "simulate-device", "-t", "valcnc", "--pty"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        # Ctrl-C must reach it as from a terminal: a job started in the background by a
        # non-interactive shell (a CI runner's `cmd &`) inherits SIGINT ignored, and Python
        # then installs no KeyboardInterrupt handler
        preexec_fn=_sigint_default,
    )
    code, err = -1, "the simulator printed no port"
    try:
        assert sim.stdout is not None
        path = sim.stdout.readline().strip()
        if path.startswith("/dev/"):
            code, _, err = run(["send", str(job), "-t", "valcnc", "--port", path], capsys)
    finally:
        sim.send_signal(2)  # Ctrl-C: the simulator summarises and exits
        try:
            _, sim_err = sim.communicate(timeout=60)
        except subprocess.TimeoutExpired:
            sim.kill()
            _, sim_err = sim.communicate()
            sim_err = f"did not exit within 60 s of Ctrl-C; its stderr: {sim_err}"
    assert code == 0, f"send: {err}\nsimulator: {sim_err}"
    assert "one limit switch per axis" in err
    assert f"received 10 blocks ({len(VALCNC)} bytes), ran 10" in sim_err, sim_err


@pytest.mark.parametrize("refused", [41, 42])
def test_a_refused_block_is_exit_1_even_the_last(
    refused: int, tmp_path: Path, simulate: Any, capsys: Any
) -> None:
    # the logo posted for grbl has 42 lines, the last `M2`; GRBL answers a line it refuses
    # with error:N (interface.md), so the job fails whichever line that is
    logo = tmp_path / "logo.gcode"
    assert main(["post", "samples/logo.dxf", "-t", "grbl", "-o", str(logo)]) == 0
    lines = logo.read_text().splitlines()
    assert len(lines) == 42 and lines[-1] == "M2"
    capsys.readouterr()
    sim = simulate("grbl", fail_at_block=refused, error="20")
    code, _, err = run(["send", str(logo), "-t", "grbl", "--port", sim.path], capsys)
    assert code == 1, err
    assert f"refused block {refused} (line {refused}: {lines[refused - 1]!r})" in err
    assert "sent 42 blocks" not in err


SIMULATE = [sys.executable, "-m", "camtool", "simulate-device"]


def test_sigterm_stops_the_job_as_the_operator_would(job: Path) -> None:
    # SIGTERM (a service manager, `kill`) is the operator's stop: feed hold, reset, and the
    # line to resume at, exit 1 — never a silent end
    sim = subprocess.Popen(
        [*SIMULATE, "-t", "grbl", "--pty", "--block-delay-ms", "200"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=_sigint_default,
    )
    try:
        assert sim.stdout is not None
        path = sim.stdout.readline().strip()
        send = subprocess.Popen(
            [sys.executable, "-m", "camtool", "send", str(job), "-t", "grbl", "--port", path],
            stderr=subprocess.PIPE,
            text=True,
        )
        assert send.stderr is not None
        started = send.stderr.readline()  # "camtool: sending N blocks ...": the job runs
        assert "sending" in started, started
        send.send_signal(signal.SIGTERM)
        _, err = send.communicate(timeout=120)
    finally:
        sim.send_signal(2)
        sim.communicate(timeout=60)
    assert send.returncode == 1, err
    assert "stopped by the operator" in err
    assert "feed hold, then a reset (spindle and coolant off" in err
    assert "--from-line" in err and "Traceback" not in err


@pytest.mark.parametrize("key", ["rx_buffer_bytes", "max_block_bytes"])
def test_a_buffer_larger_than_any_controller_s_is_refused(
    job: Path, tmp_path: Path, key: str, capsys: Any
) -> None:
    """A buffer of 10**30 bytes would have the sender never wait for room: the real
    controller's buffer would overflow and drop characters."""
    grbl = Path(__file__).resolve().parents[2] / "postprocessors" / "grbl" / "grbl.toml"
    text = grbl.read_text().replace("[link]\n", f"[link]\n{key} = {10**30}\n", 1)
    text = text.replace("rx_buffer_bytes = 127", "") if key == "rx_buffer_bytes" else text
    target = tmp_path / "big.toml"
    target.write_text(text)
    code, out, err = run(["send", str(job), "-t", str(target), "--dry-run"], capsys)
    assert code == 3 and out == ""
    assert f"{key} must be at most 1048576 bytes" in err


@pytest.mark.parametrize(("quiet", "refused"), [(5.0, True), (4.9, False)])
def test_a_quiet_end_as_long_as_the_response_timeout_is_refused(
    job: Path, tmp_path: Path, quiet: float, refused: bool, capsys: Any
) -> None:
    """The silence that ends a resumed block must come before the one that calls the
    controller lost (grbl's response_timeout_s is 5 s)."""
    grbl = Path(__file__).resolve().parents[2] / "postprocessors" / "grbl" / "grbl.toml"
    text = grbl.read_text().replace("[link]\n", f"[link]\nquiet_end_s = {quiet}\n", 1)
    assert "response_timeout_s = 5.0" in text
    target = tmp_path / "quiet.toml"
    target.write_text(text)
    code, _, err = run(["send", str(job), "-t", str(target), "--dry-run"], capsys)
    if refused:
        assert code == 3
        assert "quiet_end_s (5 s) must be shorter than response_timeout_s (5 s)" in err
    else:
        assert code == 0, err


def test_a_quiet_end_no_longer_than_the_settle_time_is_refused(
    job: Path, tmp_path: Path, capsys: Any
) -> None:
    """pic-mmh's settle_s is 0.25 s: a quiet end as short could fall between two steps."""
    pic = Path(__file__).resolve().parents[2] / "postprocessors" / "pic_mmh" / "pic-mmh.toml"
    text = pic.read_text()
    assert "settle_s = 0.25" in text and "quiet_end_s = 1.0" in text
    target = tmp_path / "pic.toml"
    target.write_text(text.replace("quiet_end_s = 1.0", "quiet_end_s = 0.25"))
    code, _, err = run(["send", str(job), "-t", str(target), "--dry-run"], capsys)
    assert code == 3
    assert "quiet_end_s (0.25 s) must be longer than settle_s (0.25 s" in err
