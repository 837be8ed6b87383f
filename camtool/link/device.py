"""Device simulators: a controller at the other end of the link, with no hardware.

Design notes: docs/internals.md, ``camtool/link/device.py``.
"""

from __future__ import annotations

import contextlib
import errno
import os
import select
import threading
import time
import tty
from typing import TYPE_CHECKING

from camtool.link.spec import LinkSpec, link_hooks, link_spec

if TYPE_CHECKING:
    from camtool.model.program import Program
    from camtool.post.base import Target

ANSWER_END = b"\r\n"
"""What ends every answer line a simulator writes (GRBL's ``\\r\\n``)."""


class Device:
    """A controller model, sans IO (see the module docstring).

    Args:
        spec: the target's link.
        target: the target, to read :meth:`program` back (``None``: not readable).
        fail_at_block: 1-based block answered with ``error`` instead of ``ack``.
        error: the controller's error code for ``fail_at_block`` (e.g. ``"22"``).
        drop_at_block: 1-based block on whose arrival the port disappears.

    Attributes:
        received: every program byte received, in order.
        blocks: the blocks received, in order.
        executed: the blocks that ran (not those answered with an error).
        dropped: the port is to disappear now (:class:`PtyServer` closes it).
        connections: how many times a host opened the port.
    """

    def __init__(
        self,
        spec: LinkSpec,
        *,
        target: Target | None = None,
        fail_at_block: int | None = None,
        error: str = "",
        drop_at_block: int | None = None,
    ) -> None:
        self.spec = spec
        self.target = target
        self.fail_at_block = fail_at_block
        self.error = error
        self.drop_at_block = drop_at_block
        self.received = bytearray()
        self.blocks: list[bytes] = []
        self.executed: list[bytes] = []
        self.dropped = False
        self.connections = 0

    def connect(self) -> bytes:
        """What the controller writes when a host opens the port (a banner, or nothing)."""
        self.connections += 1
        return b""

    def feed(self, data: bytes) -> bytes:
        """Take bytes from the host; return what it answers at once."""
        raise NotImplementedError

    def pending(self) -> bool:
        """True when a received block waits for :meth:`step`."""
        return False

    def step(self) -> bytes:
        """Run one waiting block; return its answer (``b""``: none)."""
        return b""

    def program(self) -> Program:
        """The blocks that ran, read back with the target's own reader.

        Raises:
            ValueError: the device was built without a target.
            ParseError: the bytes are not the target's code.
        """
        if self.target is None:
            raise ValueError("this device has no target to read its program with")
        code = b"".join(self.executed)
        return self.target.parse(code if self.target.post.binary else code.decode("latin-1"))

    def position(self) -> tuple[float, float, float]:
        """Where the blocks that ran leave the tool: X, Y, Z in mm (origin before any move).

        Raises:
            ValueError, ParseError: as :meth:`program`.
        """
        program = self.program()
        x, y = (program.moves[-1].x, program.moves[-1].y) if program.moves else program.origin
        z = next((m.z for m in reversed(program.moves) if m.z is not None), 0.0)
        return (x, y, z)


class LineDevice(Device):
    """The generic controller: blocks end with ``block_end``; each is answered per the spec.

    ``flow = "ack"`` or ``"char-count"``: each block is answered with ``ack``
    (or the block itself when the spec says ``echo``), the failing one with
    ``error`` + code. ``"timed"``: no answer (a failing block is then only
    recorded as not run: such a controller has no way to say so). The spec's
    ``startup`` bytes are expected first and are not part of the program.
    """

    def __init__(self, spec: LinkSpec, **options: object) -> None:
        super().__init__(spec, **options)  # type: ignore[arg-type]
        self.rx = bytearray()
        self.startup_seen = not spec.startup

    def connect(self) -> bytes:
        """A new session: the start-up bytes are expected again."""
        self.startup_seen = not self.spec.startup
        return super().connect()

    def feed(self, data: bytes) -> bytes:
        """Queue the bytes; blocks are run by :meth:`step`."""
        self.rx += data
        size = len(self.spec.startup)
        if not self.startup_seen and bytes(self.rx[:size]) == self.spec.startup:
            del self.rx[:size]
            self.startup_seen = True
        return b""

    def pending(self) -> bool:
        """True when a whole block is queued."""
        return self.startup_seen and self.spec.block_end in self.rx

    def take_block(self) -> bytes | None:
        """The next whole block from the receive queue, or ``None``."""
        cut = self.rx.find(self.spec.block_end)
        if not self.startup_seen or cut < 0:
            return None
        end = cut + len(self.spec.block_end)
        block = bytes(self.rx[:end])
        del self.rx[:end]
        return block

    def step(self) -> bytes:
        """Run one block: record it and answer it."""
        block = self.take_block()
        if block is None:
            return b""
        return self.run_block(block)

    def run_block(self, block: bytes) -> bytes:
        """Record ``block`` (the next in order) and return its answer."""
        self.received += block
        self.blocks.append(block)
        number = len(self.blocks)
        if number == self.drop_at_block:
            self.dropped = True
            return b""
        if number == self.fail_at_block:
            if self.spec.flow == "timed" or not self.spec.error:
                return b""
            return (self.spec.error + self.error).encode("latin-1") + ANSWER_END
        self.executed.append(block)
        if self.spec.flow == "timed":
            return b""
        answer = block.rstrip(b"\r\n") if self.spec.echo else self.spec.ack.encode()
        return answer + ANSWER_END


def make_device(target: Target, **options: object) -> Device:
    """The simulator of ``target``: its ``LINK.device``, else a :class:`LineDevice`.

    Args:
        target: the target.
        **options: ``fail_at_block``, ``error``, ``drop_at_block`` and any
            option the target's device takes.

    Raises:
        LinkError: the target declares no link.
    """
    spec = link_spec(target)
    factory = link_hooks(target).device or LineDevice
    device = factory(spec, target=target, **options)
    if not isinstance(device, Device):
        raise TypeError(f"{target.name}: LINK.device gave {type(device).__name__}, not a Device")
    return device


class PtyServer:
    """Serve a :class:`Device` on a pseudo-terminal pair, in a thread.

    The host opens :attr:`path` (``/dev/pts/N``) like any serial port. The
    server notices a host opening and closing the port (the master reads EIO
    while no one holds the slave open), writes :meth:`Device.connect` on every
    opening, feeds the device, runs one block every ``block_delay_s`` (a
    controller is slower than the wire: a buffer fills), and closes the pair
    when the device drops the port.

    Args:
        device: the device to serve.
        block_delay_s: seconds between two blocks run (0: as fast as it can).
        settle_s: wait after a host opens before the device speaks (pyserial
            flushes its input when it opens the port).
    """

    def __init__(self, device: Device, *, block_delay_s: float = 0.0, settle_s: float = 0.05):
        self.device = device
        self.block_delay_s = block_delay_s
        self.settle_s = settle_s
        self.master, slave = os.openpty()
        tty.setraw(slave)
        self.path = os.ttyname(slave)
        os.close(slave)
        self.error: BaseException | None = None
        self.written = 0
        """Bytes written to the host so far."""
        self._quiet = threading.Event()
        self._alone = threading.Event()  # no host holds the port, as the server last saw
        self._alone.set()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="camtool-device", daemon=True)

    def __enter__(self) -> PtyServer:
        self.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()

    def start(self) -> None:
        """Start serving."""
        self._thread.start()

    def stop(self) -> None:
        """Stop serving and close the pair."""
        self._stop.set()
        if self._thread.is_alive():
            self._thread.join(5)
        self._close()

    def quiet(self) -> bool:
        """True when the device has taken every byte the host wrote and has nothing left to run.

        What it answered may still be on its way to the host (see :attr:`written`).
        """
        if not self._quiet.is_set() or self.master < 0:
            return False
        try:
            ready, _, _ = select.select([self.master], [], [], 0)
        except (OSError, ValueError):
            return False
        return not ready

    def wait_host_gone(self, timeout: float) -> bool:
        """Wait until the server has seen the host close the port (or ``timeout`` s).

        A host that closes the port and opens it again before the server's next poll would
        be taken for the same host: its device would not start a new session. A test that
        sends twice waits for this between the two. True if the server has seen it.
        """
        return self._alone.wait(timeout)

    def wait_closed(self, timeout: float) -> bool:
        """Wait until the device has dropped the port (or ``timeout`` s); True if it has."""
        self._thread.join(timeout)
        return not self._thread.is_alive()

    def _close(self) -> None:
        if self.master >= 0:
            with contextlib.suppress(OSError):
                os.close(self.master)
            self.master = -1

    def _run(self) -> None:
        try:
            self._serve()
        except BaseException as exc:  # kept for the test that started the thread
            self.error = exc
        finally:
            if self.device.dropped:
                self._close()
            self._alone.set()  # no longer serving: no host is held

    def _serve(self) -> None:
        self._loop()
        self._drain()

    def _drain(self) -> None:
        """On stop: take what the host wrote before it closed, and run every whole block."""
        while not self.device.dropped:
            ready, _, _ = select.select([self.master], [], [], 0)
            try:
                data = os.read(self.master, 4096) if ready else b""
            except OSError:
                data = b""
            if data:
                self._write(self.device.feed(data))
            elif self.device.pending():
                self._write(self.device.step())
            else:
                return

    def _loop(self) -> None:
        connected = False
        next_block = 0.0
        while not self._stop.is_set() and not self.device.dropped:
            wait = 0.005
            if self.device.pending():  # the next block is due then, not at the next poll
                wait = min(wait, max(0.0, next_block - time.monotonic()))
            ready, _, _ = select.select([self.master], [], [], wait)
            data = b""
            if ready:
                self._quiet.clear()
                try:
                    data = os.read(self.master, 4096)
                except OSError as exc:  # EIO: no host holds the port open
                    if exc.errno != errno.EIO:
                        raise
                    connected = False
                    self._alone.set()
                    time.sleep(0.005)
                    continue
            if not connected:
                connected = True
                self._alone.clear()
                self._quiet.clear()
                time.sleep(self.settle_s)
                self._write(self.device.connect())
            if data:
                self._write(self.device.feed(data))
            now = time.monotonic()
            if self.device.pending() and now >= next_block:
                self._quiet.clear()
                self._write(self.device.step())
                next_block = now + self.block_delay_s
            if not self.device.pending():
                self._quiet.set()

    def _write(self, data: bytes) -> None:
        if data and not self.device.dropped:
            with contextlib.suppress(OSError):  # no host holds the port: the answer is lost
                self.written += os.write(self.master, data)
