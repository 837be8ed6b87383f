"""Fixtures of the link tests: a simulated controller served on a pseudo-terminal pair."""

from __future__ import annotations

import time
from collections.abc import Iterator
from typing import Any

import pytest

from camtool.link.device import Device, PtyServer, make_device
from camtool.post.registry import load_target


class DeviceClock:
    """Simulated time for :func:`camtool.link.sender.send_plan` against a :class:`PtyServer`.

    Time passes only while the host waits and the device has nothing to say: a read that
    finds no byte advances the clock by its whole timeout once the device is quiet (every
    byte the host wrote taken, nothing left to run) and every byte it wrote has been read.
    So a controller that stops answering reaches the sender's bounds at once, and a slow
    machine (a loaded test run) never reaches them early. A read that stays unsettled for
    :attr:`GRACE_S` of real time (bytes the host dropped on opening the port) advances too,
    and those bytes are counted as gone: a banner flushed on opening cost every later read
    of the start-up its ``GRACE_S``. A server that sees no host although the host holds the
    port (its pty reads EIO) never settles: once a read has given up on it, later reads
    wait only :attr:`STALLED_S` while it still sees no host and has written nothing more.
    A server that is merely slow (a loaded machine) sees its host, so it gets the whole
    grace at every read.
    """

    GRACE_S = 2.0
    STALLED_S = 0.05
    REAL_POLL_S = 0.001

    def __init__(self, server: PtyServer) -> None:
        self.server = server
        self.now = 0.0
        self.read_bytes = 0
        self.stalled_at: int | None = None  # server.written when a read last gave up

    def monotonic(self) -> float:
        return self.now

    def _stalled(self) -> bool:
        return self.stalled_at == self.server.written and self.server.wait_host_gone(0.0)

    def sleep(self, seconds: float) -> None:
        stalled = self._stalled()
        give_up = time.monotonic() + (self.STALLED_S if stalled else self.GRACE_S)
        while not self.server.quiet() and time.monotonic() < give_up:
            time.sleep(self.REAL_POLL_S)
        self.now += seconds

    def read(self, port: Any, seconds: float) -> bytes:
        stalled = self._stalled()
        give_up = time.monotonic() + (self.STALLED_S if stalled else self.GRACE_S)
        while True:
            port.timeout = self.REAL_POLL_S
            data: bytes = port.read(max(1, port.in_waiting))
            if data:
                self.read_bytes += len(data)
                return data
            settled = self.server.quiet() and self.server.written <= self.read_bytes
            if settled or time.monotonic() > give_up:
                if not settled:  # the bytes not come in GRACE_S were dropped: do not wait again
                    self.read_bytes = max(self.read_bytes, self.server.written)
                    self.stalled_at = self.server.written
                self.now += seconds
                return b""


class Simulated:
    """A device on a pty, and the port path to open."""

    def __init__(self, device: Device, server: PtyServer) -> None:
        self.device = device
        self.server = server
        self.path = server.path

    def clock(self) -> DeviceClock:
        """Simulated time for a send to this device (see :class:`DeviceClock`)."""
        return DeviceClock(self.server)


@pytest.fixture
def simulate() -> Iterator[Any]:
    """``simulate(target_name, **device_options) -> Simulated`` (stopped after the test)."""
    servers: list[PtyServer] = []

    def start(name: str, block_delay_s: float = 0.0005, **options: Any) -> Simulated:
        device = make_device(load_target(name), **options)
        server = PtyServer(device, block_delay_s=block_delay_s)
        server.start()
        servers.append(server)
        return Simulated(device, server)

    yield start
    for server in servers:
        server.stop()
        assert server.error is None, server.error
