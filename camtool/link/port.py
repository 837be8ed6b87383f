"""A serial port for the driver: opened by name or URL, read as lines, its errors as LinkError."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from camtool.link.stream import POLL_S, ByteLog, Clock, WallClock
from camtool.model.errors import LinkError


def _port_errors() -> tuple[type[BaseException], ...]:
    """What a failing port raises: pyserial's errors, OS errors and, on POSIX, ``termios.error``.

    ``termios.error`` is not an ``OSError``: pyserial's ``flush()`` (``tcdrain``) raises it
    when the other end of a pseudo-terminal or a USB adapter vanishes mid-write.
    """
    import serial

    errors: tuple[type[BaseException], ...] = (serial.SerialException, OSError)
    try:
        import termios
    except ImportError:  # not POSIX
        return errors
    return (*errors, termios.error)


def open_port(port: str, baud: int) -> Any:
    """A pyserial port for a device path or URL, 8N1, no flow control, non-blocking reads.

    Raises:
        LinkError: it cannot be opened (the message names it and says why).
    """
    import serial

    try:
        return serial.serial_for_url(port, baudrate=baud, timeout=0, write_timeout=10)
    except (serial.SerialException, OSError, ValueError) as exc:
        raise LinkError(f"cannot open port {port!r}: {exc}") from exc


MAX_UNENDED = 4096
"""Most bytes :class:`_Wire` holds without a whole answer in them. A controller's answers
are lines of tens of bytes (GRBL's longest, a ``$$`` setting or ``[GC:…]``, under 100);
a stream of bytes with no line end is a wrong baud rate or a wrong device, and is not
kept growing while the job waits for an answer."""


class _PortGone(LinkError):
    """The port failed under the driver (the driver adds where the job stood)."""


class Garbled(LinkError):
    """The controller sent :data:`MAX_UNENDED` bytes that make no answer.

    The driver adds where the job stood, and stops the machine when blocks are in flight.
    """


class _Wire:
    """The port with logging and errors turned into :class:`LinkError`; reads lines."""

    def __init__(
        self,
        port: Any,
        name: str,
        log: ByteLog | None,
        split: Callable[[bytearray], list[str]] | None = None,
        clock: Clock | None = None,
    ) -> None:
        self.port = port
        self.name = name
        self.log = log
        self.clock = clock or WallClock()
        self.buffer = bytearray()
        self.last_rx = self.clock.monotonic()
        self.split = split or split_lines
        self.unread: list[str] = []
        self.garbled = False

    def write(self, data: bytes, where: str) -> None:
        try:
            self.port.write(data)
            self.port.flush()
        except _port_errors() as exc:
            raise _PortGone(f"port {self.name!r} disappeared {where}: {exc}") from exc
        if self.log:
            self.log.record(">", data)

    def modem_handshake(self, timeout: float) -> bool | None:
        """Raise DTR and RTS, wait up to ``timeout`` s for DSR: True when it came.

        ``None`` when the port has no modem lines (a pseudo-terminal answers
        their ioctl with ENOTTY; pyserial URLs have none).

        Raises:
            LinkError: the port disappeared.
        """
        import errno

        import serial

        try:
            self.port.dtr = True
            self.port.rts = True
            deadline = self.clock.monotonic() + timeout
            while not self.port.dsr:
                if self.clock.monotonic() >= deadline:
                    return False
                self.clock.sleep(POLL_S)
        except OSError as exc:
            if exc.errno in (errno.ENOTTY, errno.EINVAL):
                return None
            raise LinkError(f"port {self.name!r} disappeared at start-up: {exc}") from exc
        except serial.SerialException as exc:
            raise LinkError(f"port {self.name!r} disappeared at start-up: {exc}") from exc
        except (AttributeError, NotImplementedError):
            return None
        return True

    def put_back(self, answers: list[str]) -> None:
        """Answers read but not taken: the next :meth:`lines` returns them first."""
        self.unread[:0] = answers

    def lines(self, timeout: float, where: str) -> list[str]:
        """Whole answers received within ``timeout`` s (lines, line ends stripped, by default)."""
        if self.unread:
            out, self.unread = self.unread, []
            return out
        try:
            data = self.clock.read(self.port, timeout)
        except _port_errors() as exc:
            raise _PortGone(f"port {self.name!r} disappeared {where}: {exc}") from exc
        if data:
            self.last_rx = self.clock.monotonic()
            if self.log:
                self.log.record("<", data)
            self.buffer += data
        answers = self.split(self.buffer)
        if len(self.buffer) > MAX_UNENDED:
            head = bytes(self.buffer[:24]).decode("latin-1")
            self.buffer.clear()
            if self.garbled:  # said once; the stop that follows reads on without them
                return answers
            self.garbled = True
            raise Garbled(
                f"port {self.name!r} sent more than {MAX_UNENDED} bytes {where} with no "
                f"answer in them (they begin {head!r}): is the controller set to the "
                "machine file's baud rate, and is this its port?"
            )
        return answers


def split_lines(buffer: bytearray) -> list[str]:
    """The whole lines in ``buffer`` (taken out of it), line ends stripped, empty ones dropped."""
    out = []
    while (cut := buffer.find(b"\n")) >= 0:
        out.append(buffer[:cut].decode("latin-1").strip("\r"))
        del buffer[: cut + 1]
    return [line for line in out if line]
