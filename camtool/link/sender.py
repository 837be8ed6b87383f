"""The host side of a link: :func:`send_plan` drives the stream over a serial port.

The protocol state is :class:`~camtool.link.stream.Stream` (no I/O); the port is
:mod:`camtool.link.port`. Design notes: docs/internals.md, ``camtool/link/sender.py``.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, NoReturn

from camtool.link.advice import lost_hint, unsure
from camtool.link.port import Garbled, _PortGone, _Wire, open_port, split_lines
from camtool.link.spec import Status
from camtool.link.stream import (
    POLL_S,
    STATUS_PERIOD_S,
    ByteLog,
    Clock,
    Control,
    Progress,
    StopAtPause,
    Stream,
    WallClock,
)
from camtool.model.errors import LinkError

if TYPE_CHECKING:
    from camtool.link.plan import SendPlan

__all__ = [
    "ByteLog",
    "Clock",
    "Control",
    "Progress",
    "SendResult",
    "StopAtPause",
    "Stream",
    "WallClock",
    "open_port",
    "send_plan",
    "split_lines",
]


@dataclass(frozen=True)
class SendResult:
    """A job that ran to its end.

    Attributes:
        blocks: blocks sent.
        bytes: bytes sent (blocks only).
        elapsed_s: wall time, s.
        max_buffered: most bytes in flight at once (character counting).
        messages: the controller's push messages, in order.
    """

    blocks: int
    bytes: int
    elapsed_s: float
    max_buffered: int
    messages: tuple[str, ...] = ()


def send_plan(
    port: Any,
    plan: SendPlan,
    *,
    port_name: str = "",
    control: Control | None = None,
    progress: Callable[[Progress], None] | None = None,
    log: ByteLog | None = None,
    time_scale: float = 1.0,
    reopen: Callable[[], Any] | None = None,
    clock: Clock | None = None,
) -> SendResult:
    """Send ``plan`` over an open ``port`` (see the module docstring).

    Every wait has a bound that follows from the program: an answer may take
    :data:`WAIT_FACTOR` times the estimated time of the blocks the controller
    may still have to run before it, plus the link's ``response_timeout_s``; a
    controller that reports ``Idle`` with blocks unanswered (a lost line end:
    two lines taken as one, one answer fewer) is stopped after
    :data:`IDLE_GRACE_S` plus the head block's own time. A job succeeds only
    when every block was answered as accepted.

    Args:
        port: an open pyserial port (:func:`open_port`) or anything with its
            ``write``, ``flush``, ``read``, ``in_waiting`` and ``timeout``.
        plan: the checked program (:func:`camtool.link.plan.prepare_send`).
        port_name: the port's name for messages.
        control: the operator (default: :class:`StopAtPause`).
        progress: called after every block done.
        log: where every byte goes.
        time_scale: multiplies timed-flow waits, a block's ``busy_s`` and the silence
            allowed for the blocks in flight (0 for simulators and tests).
        reopen: opens the port again after the operator's turn between blocks
            (``operator_between_blocks``: the device was reset, as the
            matlab-router master is after every job); ``None``: keep the port.
        clock: time and waits (default: :class:`WallClock`).

    Returns:
        What was sent.

    Raises:
        LinkError: no banner or answer in time, the controller in alarm, an
            error or alarm during the job, the port gone, a controller that
            stopped answering or went idle with blocks unanswered, or the
            operator stopped; the message says which lines surely ran, which
            may have run in part, and which ``--from-line`` resumes.
    """
    driver = _Driver(
        port, plan, port_name, control or StopAtPause(), progress, log, time_scale, clock
    )
    driver.reopen = reopen
    return driver.run()


WAIT_FACTOR = 3.0
"""An answer may take this many times the timing model's estimate (plus the link's
``response_timeout_s``) before the controller counts as lost: the estimate is a model,
the controller's planner may be slower (overrides, acceleration), never this much."""
MAX_MESSAGES = 1000
"""Most push messages a job keeps for its result (a wrong baud rate on a link whose
answers are single bytes makes one of every byte); the rest are counted."""
IDLE_GRACE_S = 0.5
"""Reports of ``Idle`` (every :data:`STATUS_PERIOD_S`) with blocks unanswered for this
long, beyond the head block's own time, mean the controller will not answer them."""


class _Driver:
    def __init__(
        self,
        port: Any,
        plan: SendPlan,
        name: str,
        control: Control,
        progress: Callable[[Progress], None] | None,
        log: ByteLog | None,
        time_scale: float,
        clock: Clock | None = None,
    ) -> None:
        self.plan, self.spec, self.control = plan, plan.spec, control
        self.clock = clock or WallClock()
        self.wire = _Wire(port, name or "port", log, plan.hooks.split, self.clock)
        self.log = log
        self.stream = Stream(plan, time_scale=time_scale)
        self.report = progress or (lambda p: None)
        self.messages: list[str] = []
        self.last_status = 0.0
        self.turns = 0
        self.reopen: Callable[[], Any] | None = None
        self.answer_since = self.clock.monotonic()
        self.idle_since: float | None = None
        self.put_back: list[str] = []
        self.unknown: list[str] = []  # the last five
        self.untold = 0  # messages past MAX_MESSAGES, counted, not kept
        self.held_by_controller = ""  # the hold state it reported, not asked for by camtool
        self.resumed_head: int | None = None  # resumed with it first in flight: a Hold
        # reported while it still is may be from before the resume
        hooks = plan.hooks
        self.can_halt = bool(self.spec.hold and self.spec.reset and self.spec.status)
        self.can_halt = self.can_halt and (hooks.status or hooks.status_state) is not None

    def run(self) -> SendResult:
        start = self.clock.monotonic()
        try:
            try:
                self._start_up()
            except Garbled as exc:  # before the program: nothing of it is in flight
                raise LinkError(f"{exc}; nothing of the program was sent") from exc
            self._stream()
            self._finish()
        except _PortGone as exc:
            raise LinkError(f"{exc}; {lost_hint(self.stream, self.plan)}") from exc
        except LinkError:
            self._restore_settings()
            raise
        self._restore_settings()
        return SendResult(
            len(self.plan.blocks),
            self.plan.total_bytes,
            self.clock.monotonic() - start,
            self.stream.max_buffered,
            tuple(self._told()),
        )

    def _told(self) -> list[str]:
        if not self.untold:
            return self.messages
        return [*self.messages, f"… and {self.untold} more messages, not kept"]

    # -- start-up -------------------------------------------------------------------

    def _start_up(self) -> None:
        spec = self.spec
        if spec.handshake == "dtr-dsr":
            self._modem_handshake()
        if spec.banner and not self._wait_banner():
            raise LinkError(
                f"{spec.target}: no answer on {self.wire.name!r} (no {spec.banner!r} banner "
                f"within {spec.banner_timeout_s:g} s): is it the {spec.target} controller, "
                f"powered, at {spec.baud} baud?"
            )
        if spec.status and self._reads_status():
            state = self._query_state("before the job")
            if state.startswith("Alarm"):
                raise LinkError(
                    f"{spec.target} is in alarm state ({state}): nothing was sent; clear it "
                    "at the machine (home it or unlock it) and send again"
                )
        if self.plan.hooks.setup is not None:
            self.put_back = self.plan.hooks.setup(self._ask)
            if spec.status and self._reads_status():
                self._query_state("before the job")
        if spec.startup:
            self.wire.write(spec.startup, "at start-up")
        self.answer_since = self.clock.monotonic()

    def _reads_status(self) -> bool:
        hooks = self.plan.hooks
        return hooks.status is not None or hooks.status_state is not None

    def _ask(self, line: str) -> list[str]:
        """Send one command line outside the program; its answers up to the ack.

        Raises:
            LinkError: an error answer, or none within ``response_timeout_s``.
        """
        spec = self.spec
        where = f"asking {line!r}"
        self.wire.write(line.encode("latin-1") + spec.block_end, where)
        out: list[str] = []
        deadline = self.clock.monotonic() + spec.response_timeout_s
        while self.clock.monotonic() < deadline:
            got = self.wire.lines(POLL_S, where)
            for n, answer in enumerate(got):
                if answer == spec.ack:
                    self.wire.put_back(got[n + 1 :])
                    return out
                if spec.error and answer.startswith(spec.error):
                    decode = self.plan.hooks.decode
                    words = decode(answer) if decode else answer
                    raise LinkError(f"{spec.target} refused {line!r}: {words}; nothing was sent")
                if self._status_of(answer) is None:
                    out.append(answer)
        said = f" (it said only {', '.join(repr(a) for a in out[-5:])})" if out else ""
        raise LinkError(
            f"{spec.target}: no {spec.ack!r} to {line!r} within {spec.response_timeout_s:g} s"
            f"{said}; nothing was sent"
        )

    def _restore_settings(self) -> None:
        """Put back the settings :attr:`LinkHooks.setup` changed (best effort)."""
        lines, self.put_back = self.put_back, []
        for line in lines:
            try:
                self._ask(line)
            except LinkError as exc:
                self.messages.append(f"could not put back {line!r}: {exc}")
                return

    def _modem_handshake(self) -> None:
        """DTR out, DSR back (Intf8751 §3.2); skipped, with a note, on a port without them."""
        spec, wire = self.spec, self.wire
        answered = wire.modem_handshake(spec.response_timeout_s)
        if answered is None:
            note = (
                f"{wire.name!r} has no modem lines (a pseudo-terminal or a URL): the DTR/DSR "
                "handshake was skipped; the controller's first answer shows it is there"
            )
            self.messages.append(note)
            if self.log:
                self.log.note(note)
        elif not answered:
            raise LinkError(
                f"{spec.target}: no DSR on {wire.name!r} within {spec.response_timeout_s:g} s "
                "of raising DTR: is the interface powered, and the cable wired for DTR/DSR? "
                "nothing was sent"
            )
        elif self.log:
            self.log.note("DTR raised, DSR answered")

    def _wait_banner(self) -> bool:
        spec = self.spec
        for wake in (b"", spec.wake):
            if wake:
                self.wire.write(wake, "at start-up")
            deadline = self.clock.monotonic() + spec.banner_timeout_s
            while self.clock.monotonic() < deadline:
                got = self.wire.lines(POLL_S, "at start-up")
                for n, line in enumerate(got):
                    why = self.plan.hooks.firmware and self.plan.hooks.firmware(line)
                    if why:
                        raise LinkError(f"{spec.target}: {why}; nothing was sent")
                    if _is_banner(line, spec.banner) or (wake and self._status_of(line)):
                        self.wire.put_back(got[n + 1 :])
                        return True
                    self.messages.append(line)
            if not spec.wake:
                break
        return False

    def _status_of(self, line: str) -> Status | None:
        hooks = self.plan.hooks
        if hooks.status is not None:
            return hooks.status(line)
        if hooks.status_state is not None:
            state = hooks.status_state(line)
            return Status(state) if state is not None else None
        return None

    def _query_state(self, where: str) -> str:
        self.wire.write(self.spec.status, where)
        self.last_status = self.clock.monotonic()
        deadline = self.clock.monotonic() + self.spec.response_timeout_s
        while self.clock.monotonic() < deadline:
            got = self.wire.lines(POLL_S, where)
            for n, line in enumerate(got):
                status = self._status_of(line)
                if status is not None:
                    self.stream.report(status)
                    self.wire.put_back(got[n + 1 :])
                    return status.state
                self._take(line)
        raise LinkError(
            f"{self.spec.target}: no status report on {self.wire.name!r} within "
            f"{self.spec.response_timeout_s:g} s {where}; {unsure(self.stream, self.plan)}"
        )

    # -- the blocks -------------------------------------------------------------------

    def _where(self) -> str:
        s = self.stream
        last = s.last_done
        done = f"after block {last.index} (line {last.line})" if last and last.index else "before"
        return f"{done}, {s.done} of {len(self.plan.blocks)} blocks done"

    def _stream(self) -> None:
        s, control = self.stream, self.control
        pausing = False
        while not s.finished or not s.idle(self.clock.monotonic()):
            now = self.clock.monotonic()
            if s.failure:
                self._fail()
            if getattr(control, "stop_requested", False):
                self._operator_stop()
            if self.held_by_controller:
                self._controller_hold()
                continue
            pausing = pausing or control.pause_requested
            if pausing and self.can_halt:
                pausing = self._hold_pause()
                continue
            if pausing or self._operator_turn():
                if s.idle(now):
                    pausing = self._pause(pausing)
                else:
                    self._read(now)
                continue
            k = s.next_block(now)
            if k is not None:
                self._send(k)
            else:
                self._read(now)
        if s.failure:  # the last answer was an error: the loop ended with nothing in flight
            self._fail()
        if s.done != len(self.plan.blocks):  # pragma: no cover - a job ends only when all are done
            raise LinkError(f"{self.spec.target}: the job ended {self._where()}")

    def _send(self, k: int) -> None:
        s = self.stream
        block = s.block(k)
        if not s.in_flight:
            self.answer_since = self.clock.monotonic()
        s.sending(k)
        self.wire.write(block.data, f"while sending block {block.index} (line {block.line})")
        s.sent(k, self.clock.monotonic())
        if self.spec.flow == "timed":
            self.report(s.progress())

    def _operator_turn(self) -> bool:
        """True when the operator must act before the next block (``operator_between_blocks``)."""
        s = self.stream
        last = s.last_done
        turn = self.spec.operator_between_blocks and s.queue and last is not None and last.index
        return bool(turn) and s.done > self.turns

    def _pause(self, pausing: bool) -> bool:
        """Ask the operator at a block boundary; returns whether still pausing."""
        s, control = self.stream, self.control
        if pausing:
            control.pause_requested = False
            if control.paused(s.progress()) == "resume":
                self.answer_since = self.clock.monotonic()
                return False
            self._operator_stop()
        following = s.block(s.queue[0])
        assert s.last_done is not None
        if not control.between_blocks(self.spec.operator_between_blocks, s.last_done, following):
            self._stop(f"{self.spec.operator_between_blocks}; then")
        self.turns = s.done
        if self.reopen is not None:
            with contextlib.suppress(Exception):
                self.wire.port.close()
            self.wire.port = self.reopen()
            if self.spec.startup:
                self.wire.write(self.spec.startup, "at start-up")
        self.answer_since = self.clock.monotonic()
        return False

    def _hold_pause(self) -> bool:
        """Pause with the link's feed hold (GRBL ``!``); resume with its resume byte (``~``)."""
        s, control = self.stream, self.control
        control.pause_requested = False
        self.wire.write(self.spec.hold, "pausing (feed hold)")
        state = self._wait_held("pausing")
        if not state.startswith(("Hold", "Idle")):
            self._halt_and_raise(f"the feed hold was not confirmed (state {state})")
        if control.paused(s.progress()) != "resume":
            self._operator_stop()
        self._resume()
        return False

    def _controller_hold(self) -> None:
        """The controller holds on its own: the program's pause (GRBL ``M0``) or its button.

        GRBL answers an ``M0`` only once the operator resumes it (gcode.c: a feed hold
        inside the line's execution), so the wait for its answer has no bound: the
        operator is asked (:meth:`Control.between_blocks`, with the comment before the
        pause, a tool change's) and yes resumes it (cycle start, ``~``); no, or no
        operator at the terminal, stops the job where it stands.
        """
        s, control = self.stream, self.control
        state, self.held_by_controller = self.held_by_controller, ""
        k = s.in_flight[0]
        head = s.block(k)
        said = f"{self.spec.target} holds ({state}) at block {head.index} (line {head.line}: "
        said += f"{head.text!r}"
        before = s.block(k - 1).text if k > 0 else ""
        if before.startswith(("(", ";")):
            said += f", after {before!r}"
        said += "), the program's pause or the machine's feed hold"
        following = s.block(k + 1) if k + 1 < len(self.plan.blocks) else head
        prompt = f"{said}: do what it asks, then resume it (cycle start)"
        if not control.between_blocks(prompt, head, following):
            self._operator_stop(f"{said}; not resumed: stopped")
        self._resume()

    def _resume(self) -> None:
        """Send the resume byte (cycle start) and restart the clocks of every wait."""
        self.wire.write(self.spec.resume, "resuming (cycle start)")
        now = self.clock.monotonic()
        self.answer_since = now
        self.idle_since = None
        self.wire.last_rx = now  # the operator's time was no silence of the controller
        self.resumed_head = self.stream.in_flight[0] if self.stream.in_flight else None

    def _wait_held(self, where: str) -> str:
        """After a feed hold: poll until the controller says it stands (``Hold:0``, ``Idle``).

        Answers that come meanwhile are taken (lines the controller still
        queues). Bounded by ``response_timeout_s`` (a deceleration takes far
        less); returns the last state seen.
        """
        state = ""
        deadline = self.clock.monotonic() + self.spec.response_timeout_s
        while self.clock.monotonic() < deadline:
            self.wire.write(self.spec.status, where)
            until = self.clock.monotonic() + STATUS_PERIOD_S
            while self.clock.monotonic() < until:
                got = self.wire.lines(POLL_S, where)
                for n, line in enumerate(got):
                    status = self._status_of(line)
                    if status is None:
                        self._take(line)
                        continue
                    self.stream.report(status)
                    state = status.state
                    if state in ("Hold:0", "Idle") or state.startswith("Alarm"):
                        self.wire.put_back(got[n + 1 :])
                        return state
        return state

    def _take(self, line: str) -> None:
        """An answer read outside the stream's own turn: counted as the stream counts it."""
        kind = self.stream.answer(line, self.clock.monotonic())
        if kind == "ack":
            self.answer_since = self.clock.monotonic()
            self.report(self.stream.progress())
        elif kind == "push":
            self._push(line)

    def _read(self, now: float) -> None:
        s = self.stream
        wait = POLL_S if s.in_flight or not s.queue else max(0.0, min(POLL_S, s.ready_at - now))
        try:
            lines = self.wire.lines(wait, f"while sending ({self._where()})")
        except Garbled as exc:
            self._halt_and_raise(str(exc))
        for line in lines:
            status = self._status_of(line)
            if status is not None:
                s.report(status)
                self._watch_idle(status)
                self._watch_hold(status)
                continue
            kind = s.answer(line, self.clock.monotonic())
            if kind in ("ack", "answer", "event", "error"):
                self.answer_since = self.clock.monotonic()
                self.idle_since = None
            if kind == "ack":
                self.report(s.progress())
            elif kind == "push":
                self._push(line)
        read = self.clock.monotonic()  # after the lines: the silence runs to here
        if s.quiet(read):
            self.answer_since = read
            self.report(s.progress())
        if s.in_flight and not s.failure:
            self._keep_alive()

    def _push(self, line: str) -> None:
        if self._status_of(line) is None:
            if len(self.messages) < MAX_MESSAGES:
                self.messages.append(line)
            else:
                self.untold += 1
            self.unknown = [*self.unknown[-4:], line]

    def _watch_hold(self, status: Status) -> None:
        """A hold camtool did not ask for, with blocks unanswered: the operator's turn."""
        in_flight = self.stream.in_flight
        if not status.state.startswith("Hold"):
            self.resumed_head = None
        elif in_flight and in_flight[0] != self.resumed_head and self.can_halt:
            self.held_by_controller = status.state

    def _watch_idle(self, status: Status) -> None:
        """A controller that says Idle while blocks wait for their answer will not answer them."""
        s = self.stream
        rx_empty = status.rx_free is None or status.rx_free >= self.spec.rx_buffer_bytes
        queue_empty = status.queue_free is None or status.queue_free >= s.queue_size
        if status.state != "Idle" or not s.in_flight or not (rx_empty and queue_empty):
            self.idle_since = None
            return
        now = self.clock.monotonic()
        if self.idle_since is None:
            self.idle_since = now
            return
        head = s.in_flight[0]
        allowed = IDLE_GRACE_S + WAIT_FACTOR * s.time_s(head, head + 1)
        if now - self.idle_since > allowed:
            lines = self._lines_of(list(s.in_flight))
            self._halt_and_raise(
                f"{self.spec.target} is idle and has not answered {lines}: it took "
                "them as fewer lines than were sent (a line end lost on the wire) or "
                "never received them"
            )

    def _keep_alive(self) -> None:
        """Poll the status while waiting; every wait for an answer has a bound."""
        now = self.clock.monotonic()
        s = self.stream
        if self.spec.status and now - self.last_status >= STATUS_PERIOD_S:
            self.wire.write(self.spec.status, f"while sending ({self._where()})")
            self.last_status = now
        if now - self.wire.last_rx > self.spec.response_timeout_s + self._in_flight_time():
            stopped = self._abort()
            block = s.block(s.in_flight[0])
            unsure = (
                f"block {block.index} (line {block.line}) was sent and not confirmed: it may "
                "have run in part, so check where the tool stands; "
            )
            raise LinkError(
                f"{self.spec.target} stopped answering on {self.wire.name!r} "
                f"({self._where()}){stopped}; {unsure}{self._resume_hint()}"
            )
        allowed = self._answer_bound()
        if now - self.answer_since > allowed:
            lines = self._lines_of(list(s.in_flight))
            words = ""
            if self.unknown:
                shown = ", ".join(repr(w) for w in dict.fromkeys(self.unknown[-5:]))
                words = f" (what it said instead: {shown})"
            self._halt_and_raise(
                f"{self.spec.target} has not answered {lines} in {now - self.answer_since:.0f} s, "
                f"{WAIT_FACTOR:g} times the estimated time of what it had to run first plus "
                f"{self.spec.response_timeout_s:g} s{words}"
            )

    def _answer_bound(self) -> float:
        """Longest wait for the head block's answer: the blocks it may wait on, ×, + timeout."""
        s = self.stream
        head = s.in_flight[0]
        first = min(s.surely_run(), head)
        return WAIT_FACTOR * s.time_s(first, head + 1) + self.spec.response_timeout_s

    def _lines_of(self, ks: list[int]) -> str:
        blocks = [self.stream.block(k) for k in ks if self.stream.block(k).index]
        if not blocks:
            return "the restore blocks"
        first, last = blocks[0], blocks[-1]
        if first is last:
            return f"block {first.index} (line {first.line}: {first.text!r})"
        return f"blocks {first.index}–{last.index} (lines {first.line}–{last.last_line})"

    def _abort(self) -> str:
        """Send the link's ``abort`` bytes (the controller may be moving): what became of them.

        With an echoing link, waits ``response_timeout_s`` for the abort's own
        echo, the controller's word that it got the stop. Returns ``""`` when
        the link has no abort, else a clause for the error message.
        """
        spec = self.spec
        if not spec.abort:
            return ""
        text = spec.abort.decode("latin-1").rstrip("\r\n")
        try:
            self.wire.write(spec.abort, "stopping the controller")
            if not spec.echo:
                return f"; {text!r} sent to stop the controller"
            deadline = self.clock.monotonic() + spec.response_timeout_s
            while self.clock.monotonic() < deadline:
                if text in self.wire.lines(POLL_S, "stopping the controller"):
                    return f"; {text!r} sent and echoed: the controller stopped"
        except LinkError:
            return f"; {text!r} could not be sent: stop the machine by hand"
        return f"; {text!r} sent but not echoed: stop the machine by hand"

    def _halt(self) -> str:
        """Stop the machine the link's way: feed hold, wait for it to stand, then reset.

        GRBL: ``!`` decelerates to a stop keeping the position (``Hold:0``); a
        reset (Ctrl-X) then empties its buffers and turns the spindle and the
        coolant off (mc_reset), with no alarm since nothing moves (checked on
        GRBL 1.1h: ``Idle`` after the banner, machine position kept). A
        controller that does not confirm the hold within ``response_timeout_s``
        is reset all the same (it then raises ``ALARM:3``: position lost).
        Links without a hold: their ``abort`` bytes. Returns a clause for the
        error message.
        """
        if not self.can_halt:
            return self._abort()
        spec, s = self.spec, self.stream
        try:
            self.wire.write(spec.hold, "stopping (feed hold)")
            state = self._wait_held("stopping")
            self.wire.write(spec.reset, "stopping (reset)")
            deadline = self.clock.monotonic() + spec.response_timeout_s
            banner = False
            while not banner and self.clock.monotonic() < deadline:
                for line in self.wire.lines(POLL_S, "stopping (reset)"):
                    banner = banner or (bool(spec.banner) and _is_banner(line, spec.banner))
                    if not banner:
                        self._take(line)
        except LinkError:
            return "; the stop (feed hold, reset) could not be sent: stop the machine by hand"
        s.in_flight.clear()
        s.buffered = 0
        held = state in ("Hold:0", "Idle")
        how = "stopped it" if held else f"did not confirm the hold (state {state!r}): reset it"
        return (
            f"; camtool {how} with a feed hold, then a reset (spindle and coolant off"
            + (", position kept" if held else ", position may be lost: home it")
            + ")"
        )

    def _halt_and_raise(self, why: str) -> NoReturn:
        stopped = self._halt()
        raise LinkError(f"{why}{stopped}; {unsure(self.stream, self.plan)}")

    def _in_flight_time(self) -> float:
        s = self.stream
        if self.spec.status:
            return 0.0
        return self.stream.time_scale * sum(self.plan.block_time_s[k] for k in s.in_flight)

    def _drain(self) -> None:
        """Wait for the answers of the blocks still in flight (they run on the controller)."""
        s = self.stream
        deadline = self.clock.monotonic() + self.spec.response_timeout_s
        while s.in_flight and self.clock.monotonic() < deadline:
            for line in self.wire.lines(POLL_S, "while finishing the blocks in flight"):
                if s.answer(line, self.clock.monotonic()) == "push":
                    self._push(line)

    def _fail(self) -> None:
        s = self.stream
        failed, message = s.failed_block, s.failure or ""
        if self.can_halt:
            stopped = self._halt()
        else:
            stopped = self._abort()
            if failed is not None:  # an alarm empties the controller's buffer: nothing to wait for
                self._drain()
        decode = self.plan.hooks.decode
        words = decode(message) if decode else message
        if failed is not None:
            what = f"block {failed.index} (line {failed.line}: {failed.text!r})"
            if not failed.index:
                what = f"the restore block {failed.text!r}"
            head = f"{self.spec.target} refused {what}: {words}"
        else:
            head = f"{self.spec.target}: {words} ({self._where()})"
        if self.can_halt or self.spec.flow == "char-count":
            raise LinkError(f"{head}{stopped}; {unsure(self.stream, self.plan)}")
        raise LinkError(f"{head}{stopped}; the job stopped {self._where()}; {self._resume_hint()}")

    def _resume_hint(self) -> str:
        line = self.stream.resume_line()
        if line is None:
            return "every block had been sent"
        return f"fix the cause, then resume with --from-line {line}"

    def _operator_stop(self, why: str = "stopped by the operator") -> None:
        """The operator stopped the job (Ctrl-C, SIGTERM, 'stop' or 'no' at a pause)."""
        if self.can_halt:
            stopped = self._halt()
            raise LinkError(f"{why} {self._where()}{stopped}; {unsure(self.stream, self.plan)}")
        self._drain()
        self._wait_idle()
        line = self.stream.resume_line()
        rest = f"resume with --from-line {line}" if line else "every block had been sent"
        raise LinkError(f"{why} {self._where()}; {rest}")

    def _stop(self, why: str) -> None:
        self._drain()
        self._wait_idle()
        raise LinkError(f"{why} {self._where()}; {self._resume_hint()}")

    # -- the end ---------------------------------------------------------------------

    def _finish(self) -> None:
        self._wait_idle()

    def _wait_idle(self) -> None:
        """With status reports: wait until the controller says its motion is over.

        Bounded by :data:`WAIT_FACTOR` times the estimated time of the blocks not
        surely run, plus ``response_timeout_s``: a controller still in ``Run``
        after that is stopped (:meth:`_halt`).
        """
        if not (self.spec.status and self._reads_status()):
            return
        s = self.stream
        start = self.clock.monotonic()
        allowed = WAIT_FACTOR * s.time_s(s.surely_run(), len(self.plan.blocks))
        allowed += self.spec.response_timeout_s
        while True:
            state = self._query_state("at the end of the job")
            if state == "Idle":
                return
            if state.startswith("Alarm"):
                raise LinkError(f"{self.spec.target} went into alarm ({state}) {self._where()}")
            waited = self.clock.monotonic() - start
            if waited > allowed:
                self._halt_and_raise(
                    f"{self.spec.target} still reports {state!r} {waited:.0f} s "
                    f"after its last answer, {WAIT_FACTOR:g} times the estimated time of what "
                    f"it had left plus {self.spec.response_timeout_s:g} s"
                )
            self.clock.sleep(STATUS_PERIOD_S)


def _is_banner(line: str, banner: str) -> bool:
    """Whether ``line`` starts with the link's ``banner``, case ignored.

    GRBL's forks spell their name their own way: ``Grbl 1.1h``, ``GrblHAL 1.1f``,
    ``grblHAL 1.1f``, FluidNC's ``Grbl 3.7`` and ``GrblHal 3.4``.
    """
    return line.casefold().startswith(banner.casefold())
