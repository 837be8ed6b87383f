"""SIGTERM (``timeout``, a CI runner, ``kill``) stops any command as Ctrl-C does, exit code 143.

A program being written when the signal comes loses its temporary file, and the output file
keeps what it held before. The write is held open by a stand-in that writes a little and
waits, so the signal always comes mid-write, however fast or loaded this machine is;
nothing is timed but a generous bound on the exit.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

from camtool.accel.cores import end_process, fork_process
from camtool.jobs.batch_stop import TerminateAsInterrupt

ROOT = Path(__file__).parents[2]
BOUND_S = 300.0
"""How long the command may take to reach its write, and then to exit, s."""

STALLED_WRITE = """
import sys, time
import camtool.jobs.output as output
real = output._write_all
def stalled(fd, data):
    real(fd, data[:10])
    time.sleep(600)  # the signal comes here
output._write_all = stalled
from camtool.cli.main import main
sys.exit(main(sys.argv[1:]))
"""


def _default_signals() -> None:
    """In the child before ``exec``: SIGTERM at its default, however the suite was started."""
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


def test_sigterm_mid_write_removes_the_temporary_file_and_keeps_the_old_output(
    tmp_path: Path,
) -> None:
    out = tmp_path / "part.nc"
    out.write_text("the program of yesterday\n")
    paths = [str(ROOT), *filter(None, [os.environ.get("PYTHONPATH")])]
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(paths)}
    argv = ["post", str(ROOT / "samples" / "part.dxf"), "-t", "grbl", "-o", str(out)]
    process = subprocess.Popen(
        [sys.executable, "-c", STALLED_WRITE, *argv],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
        preexec_fn=_default_signals,
    )
    try:
        deadline = time.monotonic() + BOUND_S
        while not list(tmp_path.glob(".part.nc.camtool-*.tmp")):
            assert process.poll() is None, process.communicate()[1]
            assert time.monotonic() < deadline, "the post never began its write"
            time.sleep(0.05)
        process.send_signal(signal.SIGTERM)
        _, err = process.communicate(timeout=BOUND_S)
    finally:
        process.kill()
    assert process.returncode == 143
    assert err.splitlines()[-1] == "camtool: stopped (SIGTERM)"
    assert "Traceback" not in err and "internal error" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["part.nc"]
    assert out.read_text() == "the program of yesterday\n"


def test_a_process_forked_under_the_handler_still_ends_on_sigterm() -> None:
    """A helper forked while the handler is in place has SIGTERM's default and dies of it."""
    previous = signal.signal(signal.SIGTERM, signal.SIG_DFL)
    ready, told = os.pipe()

    def helper() -> None:
        default = signal.getsignal(signal.SIGTERM) == signal.SIG_DFL
        os.write(told, b"d" if default else b"h")
        time.sleep(600)

    try:
        with TerminateAsInterrupt() as handler:
            assert signal.getsignal(signal.SIGTERM) is handler
            pid = fork_process(helper, closing=(ready,))
            said = os.read(ready, 1)
            os.kill(pid, signal.SIGTERM)
            status = end_process(pid)
        assert signal.getsignal(signal.SIGTERM) == signal.SIG_DFL  # put back
    finally:
        signal.signal(signal.SIGTERM, previous)
        os.close(ready)
        os.close(told)
    assert said == b"d"
    assert os.WIFSIGNALED(status) and os.WTERMSIG(status) == signal.SIGTERM


def test_the_handler_leaves_an_ignored_sigterm_alone() -> None:
    """Under ``nohup``-like ignoring (or a caller's own handler) nothing is taken over."""
    previous = signal.signal(signal.SIGTERM, signal.SIG_IGN)
    try:
        with TerminateAsInterrupt():
            assert signal.getsignal(signal.SIGTERM) == signal.SIG_IGN
    finally:
        signal.signal(signal.SIGTERM, previous)
