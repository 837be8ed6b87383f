"""The link's protocol state, with no I/O: which block may go, what an answer means, what ran.

Also the driver's time (:class:`Clock`), the operator (:class:`Control`) and the byte log.
Design notes: docs/internals.md, ``camtool/link/sender.py``.
"""

from __future__ import annotations

import time
from array import array
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from typing import IO, TYPE_CHECKING, Any, Protocol

from camtool.link.spec import Status, WireBlock

if TYPE_CHECKING:
    from camtool.link.plan import SendPlan

POLL_S = 0.02
"""Longest wait for bytes from the port in one turn of the driver, s."""
STATUS_PERIOD_S = 0.2
"""Status queries while waiting, at most 5 per second (GRBL interface.md)."""


class Clock(Protocol):
    """The driver's time and its waits: :class:`WallClock`, or a test's simulated time.

    Every deadline of :func:`send_plan` is read from :meth:`monotonic`, and every wait
    goes through :meth:`sleep` or :meth:`read`, so a test can run a controller that
    stops answering through its bounds without waiting them out.
    """

    def monotonic(self) -> float:
        """Seconds from any fixed start, never going back."""
        ...

    def sleep(self, seconds: float) -> None:
        """Let ``seconds`` pass."""
        ...

    def read(self, port: Any, seconds: float) -> bytes:
        """The bytes ``port`` has, waiting up to ``seconds`` for the first (``b""``: none)."""
        ...


class WallClock:
    """The real clock: :func:`time.monotonic`, :func:`time.sleep`, the port's own timeout."""

    def monotonic(self) -> float:
        """:func:`time.monotonic`."""
        return time.monotonic()

    def sleep(self, seconds: float) -> None:
        """:func:`time.sleep`."""
        time.sleep(seconds)

    def read(self, port: Any, seconds: float) -> bytes:
        """One read of ``port`` with ``seconds`` as its timeout."""
        port.timeout = seconds
        data: bytes = port.read(max(1, port.in_waiting))
        return data


@dataclass(frozen=True)
class Progress:
    """Where a job is, for a progress bar.

    Attributes:
        done: blocks confirmed (answered, or sent and timed out in timed flow).
        total: blocks to send in this run.
        line: source line of the last block done (0: none yet).
        time_left_s: estimated time of the rest, s.
        in_flight: blocks sent and not yet answered.
    """

    done: int
    total: int
    line: int
    time_left_s: float
    in_flight: int = 0


class Control(Protocol):
    """How the operator steers a job (the CLI's prompt; tests script it)."""

    pause_requested: bool
    """Set (from a signal handler, say) to pause: with a feed hold where the link has
    one (GRBL ``!``), else after the current block."""

    def paused(self, progress: Progress) -> str:
        """The job is paused between blocks: return ``"resume"`` or ``"stop"``."""
        ...

    def between_blocks(self, prompt: str, done: WireBlock, following: WireBlock) -> bool:
        """The link needs the operator after ``done``: True to send ``following``."""
        ...


class StopAtPause:
    """A :class:`Control` for no operator: a pause stops; between blocks, stop."""

    def __init__(self) -> None:
        self.pause_requested = False
        self.stop_requested = False

    def paused(self, progress: Progress) -> str:
        """Always ``"stop"``."""
        return "stop"

    def between_blocks(self, prompt: str, done: WireBlock, following: WireBlock) -> bool:
        """Always False."""
        return False


class ByteLog:
    """Every byte exchanged, timestamped, hex and text: ``--log FILE``.

    One line per read or write: seconds since the log started, ``>`` host to
    controller or ``<`` controller to host, the bytes in hex, and as text.
    """

    def __init__(self, stream: IO[str], clock: Callable[[], float] = time.monotonic) -> None:
        self.stream = stream
        self.clock = clock
        self.start = clock()

    def record(self, direction: str, data: bytes) -> None:
        """Log ``data`` going ``direction`` (``">"`` or ``"<"``)."""
        if data:
            text = data.decode("latin-1").encode("unicode_escape").decode("ascii")
            stamp = self.clock() - self.start
            self.stream.write(f"{stamp:10.6f} {direction} {data.hex(' ')} |{text}|\n")

    def note(self, text: str) -> None:
        """A line of context (``#`` …)."""
        self.stream.write(f"{self.clock() - self.start:10.6f} # {text}\n")


class Stream:
    """The protocol state of one job, no I/O (see the module docstring).

    Args:
        plan: the checked blocks and their times.
        time_scale: multiplies the waits of timed flow (1: real time; 0: no
            waiting, for simulators and tests).
    """

    def __init__(self, plan: SendPlan, *, time_scale: float = 1.0) -> None:
        self.plan = plan
        self.spec = plan.spec
        self.queue: deque[int] = deque(range(len(plan.blocks)))
        self.in_flight: deque[int] = deque()
        self.buffered = 0
        self.done = 0
        self.answered = 0
        self.last_done: WireBlock | None = None
        self.ready_at = 0.0
        self.time_scale = time_scale
        self.failure: str | None = None
        self.failed_block: WireBlock | None = None
        self.failed_at: int | None = None
        self.refused: set[int] = set()
        self.attempted: int | None = None
        self.max_buffered = 0
        self.feedback = plan.hooks.feedback
        self.head_acked = False
        self.events_left = 0
        self.events = 0
        self.quiet_since = 0.0
        self.status: Status | None = None
        self.status_answered = 0
        self.queue_size = 0
        self.synced = 0
        self.cum = array("d", [0.0])
        for seconds in plan.block_time_s:
            self.cum.append(self.cum[-1] + seconds)

    def block(self, k: int) -> WireBlock:
        """Block ``k`` of the plan."""
        return self.plan.blocks[k]

    def next_block(self, now: float) -> int | None:
        """The block that may go now, or ``None`` (flow control, a failure, the end)."""
        if not self.queue or self.failure or now < self.ready_at:
            return None
        k = self.queue[0]
        flow = self.spec.flow
        if flow == "char-count":
            size = len(self.block(k).data)
            if self.in_flight and self.buffered + size > self.spec.rx_buffer_bytes:
                return None
        elif flow == "ack" and self.in_flight:
            return None
        return k

    def sending(self, k: int) -> None:
        """Block ``k`` is being written (should the port fail now, it may have gone)."""
        self.attempted = k

    def sent(self, k: int, now: float) -> None:
        """Block ``k`` went on the wire at ``now``."""
        self.queue.popleft()
        self.attempted = None
        block = self.block(k)
        if self.spec.flow == "timed":
            wait = self.plan.block_time_s[k] * (1.0 + self.spec.pace_margin)
            self.ready_at = now + self.time_scale * (wait + self.plan.wire_time_s(block))
            self.answered += 1
            self._done(k)
            return
        self.in_flight.append(k)
        self.buffered += len(block.data)
        self.max_buffered = max(self.max_buffered, self.buffered)

    @property
    def sent_count(self) -> int:
        """Blocks written whole, and the one being written when the port failed."""
        written = len(self.plan.blocks) - len(self.queue)
        return written + (1 if self.attempted is not None else 0)

    def _done(self, k: int) -> None:
        self.done += 1
        self.last_done = self.block(k)

    def answer(self, text: str, now: float | None = None) -> str:
        """What an answer from the controller means.

        Returns ``"ack"`` (a block is done), ``"answer"`` (a block was accepted
        and runs: its feedback events follow), ``"event"`` (one feedback event),
        ``"ignore"`` (an answer the link only logs), ``"error"``, ``"alarm"``
        or ``"push"`` (anything else). An ``"error"`` or ``"alarm"`` sets
        :attr:`failure`: an echo that is not the block sent is an error, and so
        is a feedback event when no accepted block is running (the controller
        moves more than camtool's interpolator says the block takes).
        """
        spec = self.spec
        now = time.monotonic() if now is None else now
        if spec.alarm and text.startswith(spec.alarm):
            self.failure = self.failure or text
            return "alarm"
        if self.feedback is not None and self.feedback(text):
            return self._event(text, now)
        if text in spec.ignore:
            return "ignore"
        if not self.in_flight or self.head_acked:
            return "push"
        block = self.block(self.in_flight[0])
        if spec.echo:
            if text == block.text:
                return self._acked(now)
            if text.startswith(("<", "[")) or not text:
                return "push"
            k = self.in_flight[0]
            self._acked(now, failed=f"echo {text!r} is not the block sent")
            self.queue.appendleft(k)  # the controller did not get it as sent: resume at it
            return "error"
        if text == (block.ack or spec.ack):
            return self._acked(now)
        if spec.error and text.startswith(spec.error):
            self._acked(now, failed=text)
            return "error"
        return "push"

    def _acked(self, now: float, failed: str | None = None) -> str:
        k = self.in_flight[0]
        self.answered = k + 1
        if failed is not None:
            self.in_flight.popleft()
            self.buffered -= len(self.block(k).data)
            self.refused.add(k)
            if self.failure is None:
                self.failure, self.failed_block, self.failed_at = failed, self.block(k), k
            return "error"
        if self.block(k).sync:
            self.synced = k + 1
        if self.block(k).events or self.block(k).quiet_end:
            self.head_acked, self.events_left = True, self.block(k).events
            self.quiet_since = now
            return "answer"
        self._complete(now)
        return "ack"

    def _event(self, text: str, now: float) -> str:
        """One feedback event: counted against the running block's events."""
        self.events += 1
        if not self.in_flight or not self.head_acked:
            last = self.last_done
            after = (
                f"after block {last.index} (line {last.line}) had made all its "
                f"{last.events} reported steps"
                if last is not None and not self.in_flight
                else "before the controller accepted the block"
            )
            self.failure = self.failure or (
                f"feedback event {text.encode('latin-1').hex()}H came {after}: the controller "
                "moves other than camtool's interpolator predicts"
            )
            return "error"
        if self.block(self.in_flight[0]).quiet_end:
            self.quiet_since = now  # its count is not known: only silence ends it
            return "event"
        self.events_left -= 1
        if self.events_left:
            return "event"
        self._complete(now)
        return "ack"

    def quiet(self, now: float) -> bool:
        """Whether the running block of unknown step count has ended by ``now``; completes it.

        A :attr:`~camtool.link.spec.WireBlock.quiet_end` block, answered, is done once no
        event has come for the link's ``quiet_end_s`` (real seconds, never scaled: the
        next block sent while it still moves would abort it).
        """
        if not self.in_flight or not self.head_acked:
            return False
        if not self.block(self.in_flight[0]).quiet_end:
            return False
        if now - self.quiet_since < self.spec.quiet_end_s:
            return False
        self._complete(now)
        return True

    def _complete(self, now: float) -> None:
        """The head block is done (answered, all its feedback in); the controller may stay busy."""
        k = self.in_flight.popleft()
        block = self.block(k)
        self.buffered -= len(block.data)
        self.head_acked = False
        self._done(k)
        wait = block.busy_s * self.time_scale + (self.spec.settle_s if block.events else 0.0)
        if wait:
            self.ready_at = max(self.ready_at, now + wait)

    def report(self, status: Status) -> None:
        """A status report arrived: what it says holds for the blocks answered before it.

        Answers and reports come in the order the controller wrote them, so every
        block answered so far was in its queue (or run) when it wrote the report.
        """
        self.status, self.status_answered = status, self.answered
        if status.queue_free is not None:
            self.queue_size = max(self.queue_size, status.queue_free)

    def surely_run(self) -> int:
        """How many leading blocks are surely run to their end (or refused), by what is known.

        ``"ack"`` flow: a block's answer says it ran (an echo and all its
        feedback, an 'F'). ``"timed"``: the last block sent may still be
        running. ``"char-count"``: an answer says only that the block was queued
        (GRBL's ``ok``); the blocks up to a ``sync`` block's answer ran, and the
        last status report's free queue entries (GRBL ``Bf:``) say how many
        queue entries the newest answered blocks still held: counted back from
        the newest with each block's ``queued`` (a lower bound, so the count
        never reaches too early a block), plus one entry while the controller
        moves (GRBL's stepper segment buffer still runs the block it last took
        out of the planner; standing, ``Idle`` or ``Hold:0``, it has run it).
        """
        flow = self.spec.flow
        if flow == "ack":
            return self.answered - (1 if self.head_acked else 0)
        if flow == "timed":
            return max(0, self.done - 1)
        known = self.synced
        status = self.status
        if status is None or status.queue_free is None or not self.queue_size:
            return known
        standing = status.state in ("Idle", "Hold:0")
        held = self.queue_size - status.queue_free + (0 if standing else 1)
        k = self.status_answered
        while k > known and held > 0:
            if k - 1 not in self.refused:
                held -= self.block(k - 1).queued
            k -= 1
        return max(k, known)

    def time_s(self, first: int, last: int) -> float:
        """Estimated time of blocks ``first`` to ``last - 1``, s."""
        last = max(first, min(last, len(self.plan.blocks)))
        return self.cum[last] - self.cum[first]

    def idle(self, now: float) -> bool:
        """True when nothing is in flight (timed: the last block's time is over)."""
        return not self.in_flight and now >= self.ready_at

    @property
    def finished(self) -> bool:
        """Every block sent and done."""
        return not self.queue and not self.in_flight

    def progress(self) -> Progress:
        """Where the job is now."""
        line = self.last_done.line if self.last_done else 0
        return Progress(
            self.done,
            len(self.plan.blocks),
            line,
            self.plan.time_left_s(self.done),
            len(self.in_flight),
        )

    def resume_line(self) -> int | None:
        """The ``--from-line`` that continues after the last block done (``None``: all done)."""
        rest = [self.block(k) for k in (*self.in_flight, *self.queue)]
        return next((b.line for b in rest if b.index), None)

    def first_line_from(self, k: int) -> int | None:
        """Source line of the first program block from block ``k`` on (``None``: none)."""
        blocks = self.plan.blocks
        return next((blocks[j].line for j in range(k, len(blocks)) if blocks[j].index), None)
