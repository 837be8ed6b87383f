r"""The i8751 host link: packets, 'F' after each, 'A' at the end, and a simulated interface.

Design notes: docs/internals.md, ``postprocessors/i8751/link.py``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from camtool.link.device import Device
from camtool.link.spec import LinkHooks, LinkSpec, WireBlock
from camtool.model.errors import InputError
from camtool_postprocessors.i8751.dialect import is_text
from camtool_postprocessors.i8751.packets import (
    ACCESS_KEY,
    BACKWARD,
    END_DATA,
    END_PACKET,
    FORWARD,
    MOVES_PER_PACKET,
    STILL,
    WAIT,
    binary_locator,
    packet_spans,
    undump,
)

if TYPE_CHECKING:
    from camtool.model.program import Program

DONE = "F"
"""46H: the interface has run the packet; send more (Table III.2, thesis 4351–4357)."""
ENDED = "A"
"""41H: the interface acknowledges the end of data and stops (4381–4385)."""
STORED = "M"
"""4DH: "dato memorizado", after each stored direction or step byte (4445–4463)."""


def frame(code: bytes, spec: LinkSpec, source: str) -> list[WireBlock]:
    """A session's wire blocks: one per packet (answer 'F'), then the end of data (answer 'A').

    The access key is the link's ``startup`` (sent at every session, resumed
    ones too), so it is not a block. A dump is framed as the bytes it lists.

    Raises:
        ParseError: the code is off the grammar (naming the byte).
        InputError: the session does not start with the link's start-up byte.
    """
    if is_text(code):
        data, locate = undump(code.decode("utf-8"), source)
    else:
        data, locate = code, binary_locator(source)
    spans = packet_spans(data, locate)
    if not data.startswith(spec.startup):
        raise InputError(f"{source}: the session does not start with {spec.startup!r}")
    blocks = []
    for span in spans:
        last = span.first_move + span.moves - 1
        moves = f"move {last}" if span.moves == 1 else f"moves {span.first_move}–{last}"
        blocks.append(
            WireBlock(
                span.number,
                span.first_move,
                last,
                data[span.start : span.end],
                ack=DONE,
                note=f"packet {span.number}: {moves}",
            )
        )
    after = sum(span.moves for span in spans) + 1
    end = WireBlock(len(spans) + 1, after, after, bytes((END_DATA,)), ack=ENDED, note="end of data")
    return [*blocks, end]


def split_bytes(buffer: bytearray) -> list[str]:
    """Every byte received is one answer (the interface sends single bytes)."""
    out = [chr(byte) for byte in buffer]
    buffer.clear()
    return out


# -- the simulator ----------------------------------------------------------------------

_AFTER_BLOCK = {1: ("motor", 2), 2: ("mark", 1), 3: ("mark", 2)}
"""What follows motor m's block in a move: M1 M2 00H T1 M3 00H T2 (§3.7)."""


class I8751Device(Device):
    """A simulated 8751 interface: key, packets answered 'F' when run, 54H answered 'A'.

    It never speaks first (R19). Bytes before the access key are ignored
    (:attr:`denied`: the «OTRO» case). Each stored direction or step byte is
    answered 'M' (with ``confirm``). A packet (its 45H) is run by :meth:`step`:
    recorded in :attr:`executed`, answered 'F'. Bytes that come while a packet
    waits to run set :attr:`overrun` (the host did not wait for 'F'); bytes off
    the grammar set :attr:`garbled`. :meth:`program` reads the packets that ran
    back with camtool's i8751 reader, as one session.

    ``fail_at_block`` (a packet number) is a packet the interface does not run
    and never answers (it has no error answer: a stall, a power dip);
    ``drop_at_block`` closes the port when that packet arrives.

    Args:
        spec: the i8751 link.
        confirm: answer 'M' for each stored byte.
        **options: as :class:`camtool.link.device.Device`.
    """

    def __init__(self, spec: LinkSpec, *, confirm: bool = True, **options: object) -> None:
        super().__init__(spec, **options)  # type: ignore[arg-type]
        self.confirm = confirm
        self.keyed = False
        self.ended = False
        self.packet = bytearray()
        self.state: tuple[str, int] = ("move", 0)
        self.moves = 0
        self.ready: bytes | None = None
        self.overrun = False
        self.garbled = False
        self.denied = 0
        self.stalled: list[int] = []

    def connect(self) -> bytes:
        """A new session (the interface was reset): the access key is expected; it says nothing."""
        super().connect()
        self.keyed = self.ended = False
        self.packet.clear()
        self.state, self.moves, self.ready = ("move", 0), 0, None
        return b""

    def feed(self, data: bytes) -> bytes:
        """Store the bytes by their place in the grammar; answer 'M' for stored data."""
        out = bytearray()
        for byte in data:
            if self.ready is not None:
                self.overrun = True
            if self.ended:
                continue
            if not self.keyed:
                if byte == ACCESS_KEY:
                    self.keyed = True
                    self.received.append(byte)
                else:
                    self.denied += 1
                continue
            self.received.append(byte)
            self.packet.append(byte)
            if self._take(byte) and self.confirm:
                out += STORED.encode()
        return bytes(out)

    def _take(self, byte: int) -> bool:
        """Advance the grammar by one byte; True when it is stored data (answered 'M')."""
        kind, n = self.state
        if kind == "move":
            if byte == END_PACKET and self.moves:
                self.ready, self.state, self.moves = bytes(self.packet), ("move", 0), 0
                self.packet.clear()
            elif byte == END_DATA and not self.moves and len(self.packet) == 1:
                self.ready = bytes(self.packet)
                self.packet.clear()
            elif byte == 1 and self.moves < MOVES_PER_PACKET:
                self.moves += 1
                self.state = ("dir", 1)
            else:
                self.garbled = True
            return False
        if kind == "motor":
            self.garbled = self.garbled or byte != n
            self.state = ("dir", n)
            return False
        if kind == "dir":
            if byte in (FORWARD, BACKWARD):
                self.state = ("high", n)
            else:
                self.garbled = self.garbled or byte != STILL
                self.state = _AFTER_BLOCK[n]
            return True
        if kind == "high":
            self.state = ("low", n)
            return True
        if kind == "low":
            self.state = _AFTER_BLOCK[n]
            return True
        if kind == "mark":
            self.garbled = self.garbled or byte != WAIT
            self.state = ("seconds", n)
            return False
        self.state = ("motor", 3) if n == 1 else ("move", 0)
        return False

    def pending(self) -> bool:
        """A whole packet, or the end of data, waits to run."""
        return self.ready is not None

    def step(self) -> bytes:
        """Run the waiting packet and answer 'F' (the end of data: 'A', and stop)."""
        ready, self.ready = self.ready, None
        if ready is None:
            return b""
        if ready == bytes((END_DATA,)):
            self.ended = True
            return ENDED.encode()
        self.blocks.append(ready)
        number = len(self.blocks)
        if number == self.drop_at_block:
            self.dropped = True
            return b""
        if number == self.fail_at_block:
            self.stalled.append(number)
            return b""
        self.executed.append(ready)
        return DONE.encode()

    def program(self) -> Program:
        """The packets that ran, as one session, read back with camtool's i8751 reader."""
        if self.target is None:
            raise ValueError("this device has no target to read its program with")
        session = bytes((ACCESS_KEY,)) + b"".join(self.executed) + bytes((END_DATA,))
        return self.target.parse(session)


LINK = LinkHooks(frame=frame, split=split_bytes, device=I8751Device)
"""The i8751's link hooks (``camtool send -t i8751``, ``camtool simulate-device -t i8751``)."""
