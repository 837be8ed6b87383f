"""The byte stream of the 8751 serial stepper interface: records, packets, dump.

Source: Intf8751 §3.7 (thesis lines 4077–4165,
4343–4415) and requirements R2–R6. The PC sends, in raw binary (``CHR$``)::

Design notes: docs/internals.md, ``postprocessors/i8751/packets.py``.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass

from camtool.model.errors import ParseError
from camtool.post.numfmt import NumberFormat

ACCESS_KEY = 0x13
"""First byte of a session (Intf8751 §3.7, 4399–4415)."""
END_PACKET = 0x45
"""End of a packet; the interface answers 'F' when it has run it (4343–4370)."""
END_DATA = 0x54
"""End of all data; the interface answers 'A' and stops (4372–4385)."""
FORWARD = 0x03
"""Direction "horario" = forward = + (4108–4119)."""
BACKWARD = 0x04
"""Direction "antihorario" = backward = − (4108–4119)."""
STILL = 0x05
""""El motor no gira": the motor's block is ``m 05H`` alone (4131–4134)."""
WAIT = 0x00
"""Marker before a wait's seconds byte (4136–4149)."""
MAX_STEPS = 0xFFFF
"""Largest step count of one block, 65 535 (FFFFH, 4222–4224)."""
MAX_WAIT_S = 0xFF
"""Longest wait of one wait pair, s."""
MOVES_PER_PACKET = 5
"""Moves per packet: "15 bloques como máximo, … 60 datos" (4129–4131, §3.7)."""
AXES = "XYZ"
"""Axis of motor 1, 2, 3."""

_HEX_WIDTH = 51
"""Width of the hex column of a dump: the longest move, 16 bytes in 5 groups."""


@dataclass(frozen=True)
class Record:
    """One move of the stream.

    Attributes:
        steps: signed step counts of motors 1, 2, 3 (X, Y, Z), each within
            ±:data:`MAX_STEPS`; + is 03H (forward), − is 04H.
        wait_t1_s: wait after X/Y and before Z, whole seconds 0–255.
        wait_t2_s: wait after Z, whole seconds 0–255.

    Raises:
        ValueError: a count or a wait out of range.
    """

    steps: tuple[int, int, int]
    wait_t1_s: int = 0
    wait_t2_s: int = 0

    def __post_init__(self) -> None:
        if any(abs(n) > MAX_STEPS for n in self.steps):
            raise ValueError(f"step counts {self.steps} exceed {MAX_STEPS} per block")
        if not (0 <= self.wait_t1_s <= MAX_WAIT_S and 0 <= self.wait_t2_s <= MAX_WAIT_S):
            raise ValueError(f"waits must be 0-{MAX_WAIT_S} s")


def encode_block(motor: int, steps: int) -> bytes:
    """The bytes of one motor's block: ``m D PH PL``, or ``m 05H`` for no move.

    Intf8751 R2: +1000 on motor 1 → ``01 03 03 E8``; 0 on motor 2 → ``02 05``.

    Raises:
        ValueError: ``|steps|`` over :data:`MAX_STEPS` or a motor not 1–3.
    """
    if motor not in (1, 2, 3) or abs(steps) > MAX_STEPS:
        raise ValueError(f"motor {motor} with {steps} steps cannot be written")
    if steps == 0:
        return bytes((motor, STILL))
    n = abs(steps)
    return bytes((motor, FORWARD if steps > 0 else BACKWARD, n >> 8, n & 0xFF))


def record_groups(record: Record) -> list[bytes]:
    """The byte groups of one move: block 1, block 2, wait T1, block 3, wait T2."""
    x, y, z = record.steps
    return [
        encode_block(1, x),
        encode_block(2, y),
        bytes((WAIT, record.wait_t1_s)),
        encode_block(3, z),
        bytes((WAIT, record.wait_t2_s)),
    ]


def packets(records: Sequence[Record]) -> list[Sequence[Record]]:
    """``records`` in packets of at most :data:`MOVES_PER_PACKET`."""
    step = MOVES_PER_PACKET
    return [records[i : i + step] for i in range(0, len(records), step)]


def encode_stream(records: Sequence[Record]) -> bytes:
    """The whole session: 13H, each packet's moves then 45H, and 54H (Intf8751 R5, R6)."""
    out = bytearray((ACCESS_KEY,))
    for packet in packets(records):
        for record in packet:
            out += b"".join(record_groups(record))
        out.append(END_PACKET)
    out.append(END_DATA)
    return bytes(out)


# -- dump ------------------------------------------------------------------------


def _hex(groups: Iterable[bytes]) -> str:
    return "  ".join(" ".join(f"{b:02X}" for b in group) for group in groups)


def _mm(steps: int, steps_per_mm: float) -> str:
    return NumberFormat(decimals=4).format(steps / steps_per_mm)


def _signed(steps: int) -> str:
    return "0" if steps == 0 else NumberFormat(decimals=0, sign="always").format(steps)


def move_note(number: int, record: Record, end: Sequence[int], spm: Sequence[float]) -> str:
    """The dump's note for move ``number``: steps and waits, then where it ends, mm.

    ``end`` is the ``(x, y, z)`` step position after the move, counted from the
    start of the stream; ``spm`` the machine's steps/mm. Example (R7's style)::

        move 1: X +1000 Y -250 | wait 2 | Z -100 | wait 0 -> X 10.0000 Y -2.5000 Z -1.0000 mm
    """
    x, y, z = (_signed(n) for n in record.steps)
    where = " ".join(f"{a} {_mm(n, s)}" for a, n, s in zip(AXES, end, spm, strict=True))
    return (
        f"move {number}: X {x} Y {y} | wait {record.wait_t1_s} | Z {z} | "
        f"wait {record.wait_t2_s} -> {where} mm"
    )


def dump_stream(records: Sequence[Record], spm: Sequence[float], header: Sequence[str]) -> str:
    """The session as a readable dump (see the module docstring).

    Args:
        records: the moves.
        spm: steps/mm of X, Y, Z, for the positions in the notes.
        header: comment lines written first (each gets a leading ``; ``).
    """
    lines = [f"; {text}" for text in header]
    offset = 0

    def add(groups: list[bytes], note: str) -> None:
        nonlocal offset
        lines.append(f"{offset:04X}  {_hex(groups):<{_HEX_WIDTH}}  ; {note}")
        offset += sum(len(g) for g in groups)

    add([bytes((ACCESS_KEY,))], "access key")
    pos = [0, 0, 0]
    number = 0
    for p, packet in enumerate(packets(records), start=1):
        for record in packet:
            number += 1
            pos = [a + b for a, b in zip(pos, record.steps, strict=True)]
            add(record_groups(record), move_note(number, record, pos, spm))
        add([bytes((END_PACKET,))], f"end of packet {p}")
    add([bytes((END_DATA,))], "end of data")
    return "\n".join(lines) + "\n"


_DUMP_LINE = re.compile(
    r"^(?P<offset>[0-9A-Fa-f]{4,})  (?P<hex>[0-9A-Fa-f]{2}(?: +[0-9A-Fa-f]{2})*) *(?:;.*)?$"
)

Locate = Callable[[int], str]
"""Names a byte offset for a message: ``"prog.bin: byte 17 (0011H)"``."""


def binary_locator(source: str) -> Locate:
    """Messages for a binary stream name the file and the byte offset."""
    return lambda offset: f"{source}: byte {offset} ({offset:04X}H)"


def undump(text: str, source: str) -> tuple[bytes, Locate]:
    """The bytes of a dump, and a locator naming the dump line of each byte.

    Raises:
        ParseError: a line that is not ``OFFSET  HEX BYTES [; note]`` or a
            comment, or an offset that is not the running byte count (a line
            missing or repeated), naming ``source`` and the line.
    """
    data = bytearray()
    line_of: list[int] = []
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line or line.startswith(";"):
            continue
        m = _DUMP_LINE.match(line)
        if m is None:
            raise ParseError(
                f"{source}:{number}: not an i8751 dump line (OFFSET  HEX BYTES  ; note): {line!r}"
            )
        if int(m["offset"], 16) != len(data):
            raise ParseError(
                f"{source}:{number}: offset {m['offset']} but the next byte is {len(data):04X}H "
                "(a line is missing or repeated)"
            )
        for token in m["hex"].split():
            data.append(int(token, 16))
            line_of.append(number)

    def locate(offset: int) -> str:
        line = line_of[min(offset, len(line_of) - 1)] if line_of else 0
        return f"{source}:{line}: byte {offset} ({offset:04X}H)"

    return bytes(data), locate


# -- reading ---------------------------------------------------------------------


class _Cursor:
    """Reads the stream byte by byte; errors name the byte offset."""

    def __init__(self, data: bytes, locate: Locate) -> None:
        self.data, self.locate, self.at = data, locate, 0

    def fail(self, offset: int, message: str) -> ParseError:
        return ParseError(f"{self.locate(offset)}: {message}")

    def peek(self, what: str) -> int:
        if self.at >= len(self.data):
            raise self.fail(self.at, f"truncated: the stream ends where {what} should come")
        return self.data[self.at]

    def take(self, what: str) -> int:
        value = self.peek(what)
        self.at += 1
        return value


def _block(cur: _Cursor, motor: int) -> int:
    at = cur.at
    got = cur.take(f"motor {motor} ({motor:02X}H)")
    if got != motor:
        raise cur.fail(
            at,
            f"expected motor {motor} ({motor:02X}H), got {got:02X}H "
            "(a move is M1 M2 00H T1 M3 00H T2, Intf8751 §3.7)",
        )
    at = cur.at
    direction = cur.take(f"the direction of motor {motor}")
    if direction == STILL:
        return 0
    if direction not in (FORWARD, BACKWARD):
        raise cur.fail(
            at,
            f"bad direction code {direction:02X}H for motor {motor}: "
            "03H (+), 04H (-) or 05H (no move)",
        )
    high = cur.take(f"the high byte (PH) of motor {motor}'s step count")
    low = cur.take(f"the low byte (PL) of motor {motor}'s step count")
    steps = high * 256 + low
    return steps if direction == FORWARD else -steps


def _wait(cur: _Cursor, what: str) -> int:
    at = cur.at
    marker = cur.take(f"the wait marker 00H of {what}")
    if marker != WAIT:
        raise cur.fail(at, f"expected the wait marker 00H of {what}, got {marker:02X}H")
    return cur.take(f"the seconds of {what}")


def _move(cur: _Cursor) -> Record:
    x = _block(cur, 1)
    y = _block(cur, 2)
    t1 = _wait(cur, "T1 (before Z)")
    z = _block(cur, 3)
    t2 = _wait(cur, "T2 (after Z)")
    return Record((x, y, z), t1, t2)


def _packet(cur: _Cursor, number: int, records: list[Record]) -> None:
    moves = 0
    while True:
        at = cur.at
        byte = cur.peek(f"a move (01H) or the end of packet {number} (45H)")
        if byte == END_PACKET:
            if moves == 0:
                raise cur.fail(at, f"packet {number} is empty (45H right after its start)")
            cur.at += 1
            return
        if byte == END_DATA:
            raise cur.fail(at, f"end of data 54H inside packet {number}: 45H missing")
        if moves == MOVES_PER_PACKET:
            raise cur.fail(
                at,
                f"packet {number} holds more than {MOVES_PER_PACKET} moves: 45H must follow "
                "the 5th (Intf8751 §3.7)",
            )
        records.append(_move(cur))
        moves += 1


def decode_stream(data: bytes, locate: Locate) -> list[Record]:
    """The moves of a session, strictly by the grammar of the module docstring.

    Raises:
        ParseError: a wrong access key, a motor out of order, a bad direction
            code, a wait without its 00H marker, more than 5 moves in a packet,
            a missing 45H or 54H, a truncated count, or bytes after 54H; the
            message names the byte offset (via ``locate``).
    """
    cur = _Cursor(data, locate)
    key = cur.take("the access key 13H")
    if key != ACCESS_KEY:
        raise cur.fail(0, f"wrong access key {key:02X}H: a session starts with 13H")
    records: list[Record] = []
    number = 0
    while True:
        byte = cur.peek("a packet (01H) or the end of data 54H")
        if byte == END_DATA:
            cur.at += 1
            break
        number += 1
        _packet(cur, number, records)
    if cur.at < len(data):
        raise cur.fail(cur.at, f"{len(data) - cur.at} byte(s) after the end of data 54H")
    return records


@dataclass(frozen=True)
class PacketSpan:
    """Where one packet lies in a session.

    Attributes:
        number: 1-based packet number.
        start: offset of its first byte; ``end``: one past its 45H.
        first_move: 1-based number of its first move (record) in the session.
        moves: how many moves it holds (1 to :data:`MOVES_PER_PACKET`).
    """

    number: int
    start: int
    end: int
    first_move: int
    moves: int


def packet_spans(data: bytes, locate: Locate) -> list[PacketSpan]:
    """The packets of a session, strictly by the grammar (as :func:`decode_stream`).

    Raises:
        ParseError: as :func:`decode_stream`.
    """
    cur = _Cursor(data, locate)
    key = cur.take("the access key 13H")
    if key != ACCESS_KEY:
        raise cur.fail(0, f"wrong access key {key:02X}H: a session starts with 13H")
    spans: list[PacketSpan] = []
    records: list[Record] = []
    while cur.peek("a packet (01H) or the end of data 54H") != END_DATA:
        start, before = cur.at, len(records)
        _packet(cur, len(spans) + 1, records)
        spans.append(PacketSpan(len(spans) + 1, start, cur.at, before + 1, len(records) - before))
    cur.at += 1
    if cur.at < len(data):
        raise cur.fail(cur.at, f"{len(data) - cur.at} byte(s) after the end of data 54H")
    return spans
