"""``camtool send`` and ``camtool simulate-device``: a program to the machine over its link.

The library does the work (:mod:`camtool.link`); here: options, the progress bar
and the operator's prompts on stderr, Ctrl-C as "pause after the current block".
"""

from __future__ import annotations

import contextlib
import signal
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any

import click

from camtool.cli.common import MACHINE, WholeNumber, number_range, warn
from camtool.model.errors import UsageError

if TYPE_CHECKING:
    from camtool.link.sender import Progress
    from camtool.link.spec import WireBlock


@click.command()
@click.argument("program")
@click.option("-t", "--target", required=True, help="Target name (see 'camtool targets').")
@click.option(
    "--port",
    default=None,
    metavar="DEVICE|URL",
    help="Serial device (/dev/ttyUSB0, COM3, /dev/pts/N) or pyserial URL (socket://HOST:PORT).",
)
@click.option("--baud", type=WholeNumber(min=1), default=None, help="Override the link's baud.")
@click.option("--dry-run", is_flag=True, help="Check and print the protocol plan; open no port.")
@click.option("--verify", is_flag=True, help="Predict the machined error before sending.")
@click.option(
    "--max-error-um",
    type=number_range(min=0),
    default=None,
    metavar="N",
    help="With --verify: send nothing (exit 4) when the predicted error exceeds N µm.",
)
@click.option(
    "--max-depth",
    type=number_range(min=0),
    default=None,
    metavar="MM",
    help="Refuse a Z deeper than MM below zero (default: the link's max_depth_mm).",
)
@click.option(
    "--from-line",
    type=WholeNumber(min=1),
    default=None,
    metavar="N",
    help="Resume at source line N (the modal state before it is restored where the link can).",
)
@click.option("--log", default=None, metavar="FILE", help="Log every byte both ways to FILE.")
@MACHINE
def send(
    program: str,
    target: str,
    port: str | None,
    baud: int | None,
    dry_run: bool,
    verify: bool,
    max_error_um: float | None,
    max_depth: float | None,
    from_line: int | None,
    log: str | None,
    machine_file: Path | None,
) -> None:
    """Stream PROGRAM (a posted file) to the machine over the target's own link.

    The program is read back with the target's reader and checked first (work
    area, plunge depth, with --verify the predicted error). Ctrl-C pauses (GRBL:
    a feed hold; other links after the current block); SIGTERM, or 'stop' at the
    pause, stops (GRBL: feed hold, then reset). A controller error, an alarm, a
    lost port or a controller that stops answering end the job naming the lines
    that surely ran and the --from-line that resumes it (exit 1).
    """
    from camtool.jobs.inputs import check_not_drawing, read_code
    from camtool.jobs.output import check_paths
    from camtool.jobs.pipeline import load_target_checked
    from camtool.link.plan import prepare_send

    check_paths([("the program", program)], [("--log", log)], target=target)
    chosen = load_target_checked(target, machine_file=machine_file)
    check_not_drawing(program, chosen, "send PROGRAM")
    code = read_code(program, binary=chosen.post.binary)
    plan = prepare_send(
        code,
        chosen,
        source=program,
        from_line=from_line,
        verify=verify,
        max_error_um=max_error_um,
        max_depth_mm=max_depth,
    )
    warn(list(plan.warnings))
    if plan.verification is not None:
        from camtool.verify.report import summary_lines

        for line in summary_lines(plan.verification):
            click.echo(f"camtool: {line}", err=True)
    if dry_run:
        for line in plan.describe_lines():
            click.echo(line)
        return
    if port is None:
        raise UsageError("--port is required to send (or give --dry-run)")
    _run(plan, port, baud, log)


def _run(plan: Any, port: str, baud: int | None, log: str | None) -> None:
    from camtool.link.sender import ByteLog, open_port, send_plan

    control = _Operator(interactive=sys.stdin.isatty() and sys.stderr.isatty())
    bar = _Bar(sys.stderr)
    serial_port = open_port(port, baud or plan.spec.baud)
    with _log_file(log) as stream, _pause_on_ctrl_c(control), contextlib.closing(serial_port):
        byte_log = ByteLog(stream) if stream is not None else None
        click.echo(
            f"camtool: sending {len(plan.blocks)} blocks to {plan.target} on {port} "
            f"(about {_duration(plan.estimated_time_s)})",
            err=True,
        )
        try:
            result = send_plan(
                serial_port,
                plan,
                port_name=port,
                control=control,
                progress=bar.update,
                log=byte_log,
                reopen=lambda: open_port(port, baud or plan.spec.baud),
            )
        finally:
            bar.close()
    for message in result.messages:
        click.echo(f"camtool: {plan.target}: {message}", err=True)
    click.echo(
        f"camtool: sent {result.blocks} blocks ({result.bytes} bytes) in "
        f"{_duration(result.elapsed_s)}",
        err=True,
    )


def _duration(seconds: float) -> str:
    from camtool.link.plan import duration

    return duration(seconds)


@contextlib.contextmanager
def _log_file(path: str | None) -> Iterator[IO[str] | None]:
    """The byte log, written as the job goes (a crash keeps what was exchanged)."""
    if path is None:
        yield None
        return
    try:
        stream = open(path, "w", encoding="ascii")  # noqa: SIM115 - closed below
    except OSError as exc:
        raise UsageError(f"--log {path}: cannot write ({exc.strerror or exc})") from exc
    with stream:
        yield stream


@contextlib.contextmanager
def _pause_on_ctrl_c(control: _Operator) -> Iterator[None]:
    """Ctrl-C asks for a pause (a feed hold where the link has one); SIGTERM for a stop.

    Neither kills the job: a stop is the link's own (GRBL: feed hold, then reset) and
    ends with the line to resume at, as a stop at the pause prompt does.
    """

    def pause(signum: int, frame: Any) -> None:
        if not control.pause_requested:
            click.echo("\ncamtool: pausing…", err=True)
        control.pause_requested = True

    def stop(signum: int, frame: Any) -> None:
        if not control.stop_requested:
            click.echo("\ncamtool: stopping (SIGTERM)…", err=True)
        control.stop_requested = True

    try:
        previous = {sig: signal.signal(sig, h) for sig, h in ((signal.SIGINT, pause),)}
        previous[signal.SIGTERM] = signal.signal(signal.SIGTERM, stop)
    except ValueError:  # not the main thread (a test runner): no handler
        yield
        return
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


class _Operator:
    """The operator at the terminal; without one, a pause stops the job."""

    def __init__(self, *, interactive: bool) -> None:
        self.interactive = interactive
        self.pause_requested = False
        self.stop_requested = False

    def paused(self, progress: Progress) -> str:
        if not self.interactive:
            return "stop"
        click.echo(
            f"\ncamtool: paused after line {progress.line} ({progress.done} of "
            f"{progress.total} blocks)",
            err=True,
        )
        choice = click.prompt(
            "resume or stop", type=click.Choice(["r", "s"]), default="r", err=True
        )
        return "resume" if choice == "r" else "stop"

    def between_blocks(self, prompt: str, done: WireBlock, following: WireBlock) -> bool:
        if not self.interactive:
            return False
        click.echo(f"\ncamtool: block {done.index} (line {done.line}) sent. {prompt}.", err=True)
        return click.confirm(
            f"go on with block {following.index} (line {following.line})?", default=False, err=True
        )


class _Bar:
    """Blocks done / total and the time left, on one stderr line (a terminal only)."""

    def __init__(self, stream: IO[str]) -> None:
        self.stream = stream
        self.tty = stream.isatty()
        self.shown = 0.0

    def update(self, p: Progress) -> None:
        now = time.monotonic()
        if not self.tty or (now - self.shown < 0.1 and p.done < p.total):
            return
        self.shown = now
        width = 30
        filled = width * p.done // max(p.total, 1)
        self.stream.write(
            f"\r[{'#' * filled}{'.' * (width - filled)}] {p.done}/{p.total} blocks, "
            f"line {p.line}, {_duration(p.time_left_s)} left  "
        )
        self.stream.flush()

    def close(self) -> None:
        if self.tty and self.shown:
            self.stream.write("\n")


@click.command("simulate-device")
@click.option("-t", "--target", required=True, help="Target whose controller to simulate.")
@click.option("--pty", "use_pty", is_flag=True, required=True, help="Serve on a pseudo-terminal.")
@click.option("--fail-at-block", type=WholeNumber(min=1), default=None, metavar="N")
@click.option("--error", default="", metavar="CODE", help="The controller's error code there.")
@click.option("--drop-at-block", type=WholeNumber(min=1), default=None, metavar="N")
@click.option(
    "--block-delay-ms",
    type=number_range(min=0),
    default=1.0,
    metavar="MS",
    help="Time the simulated controller takes per block.",
)
def simulate_device(
    target: str,
    use_pty: bool,
    fail_at_block: int | None,
    error: str,
    drop_at_block: int | None,
    block_delay_ms: float,
) -> None:
    """Simulate TARGET's controller on a pseudo-terminal: prints its path, serves until Ctrl-C.

    Point 'camtool send --port' at the printed path. What it received is
    summarised on stderr at the end (blocks, bytes, where the tool stands).
    """
    from camtool.jobs.pipeline import load_target_checked
    from camtool.link.device import PtyServer, make_device

    if not use_pty:
        raise UsageError("give --pty (the only transport so far)")
    device = make_device(
        load_target_checked(target),
        fail_at_block=fail_at_block,
        error=error,
        drop_at_block=drop_at_block,
    )
    with PtyServer(device, block_delay_s=block_delay_ms / 1000.0) as server:
        click.echo(server.path)
        sys.stdout.flush()
        try:
            while not server.wait_closed(0.2):
                pass
            click.echo("camtool: the simulated port was dropped, as asked", err=True)
        except KeyboardInterrupt:
            pass
    click.echo(
        f"camtool: received {len(device.blocks)} blocks ({len(device.received)} bytes), "
        f"ran {len(device.executed)}",
        err=True,
    )
