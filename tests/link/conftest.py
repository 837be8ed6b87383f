"""Fixtures of the link tests: a simulated controller served on a pseudo-terminal pair."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest

from camtool.link.device import Device, PtyServer, make_device
from camtool.post.registry import load_target


class Simulated:
    """A device on a pty, and the port path to open."""

    def __init__(self, device: Device, server: PtyServer) -> None:
        self.device = device
        self.server = server
        self.path = server.path


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
