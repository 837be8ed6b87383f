r"""A target's link: the ``[link]`` table of its TOML, its ``LINK`` hooks, and wire blocks.

Design notes: docs/internals.md, ``camtool/link/spec.py``.
"""

from __future__ import annotations

import math
from array import array
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, overload

from camtool.model.errors import InputError, LinkError, UsageError

if TYPE_CHECKING:
    from camtool.post.base import Target

PROTOCOLS = ("stream", "none")
"""Values of ``[link] protocol``."""
FLOWS = ("char-count", "ack", "timed")
"""Values of ``[link] flow`` (see the module docstring)."""


@dataclass(frozen=True)
class WireBlock:
    """One unit of the wire: what the controller takes at once.

    Attributes:
        index: 1-based block number in the program (0: a block ``send`` adds, a
            modal restore before ``--from-line``).
        line: 1-based source line where the block starts (0 for added blocks).
        last_line: source line where it ends (a matlab-router job spans records).
        data: the exact bytes, terminator included.
        ack: the answer that accepts this block when it is not the link's
            ``ack`` (the i8751 answers a packet 'F' and the end of data 'A');
            ``""``: the link's.
        events: feedback events the controller sends after its answer while it
            runs the block (pic-mmh: one per motor step); the block is done when
            the last has come.
        busy_s: seconds the controller stays busy after that with nothing to
            say (a dwell); the next block waits them.
        note: how messages show the block when its bytes are not text (a
            binary packet); ``""``: the bytes.
        queued: fewest entries the block puts in the controller's motion
            queue once accepted (GRBL: planner blocks, one per move that makes
            a step; an arc at least one); a lower bound, so that counting the
            queue back from the newest block never calls a block run too early.
        sync: the controller answers the block only after every block before
            it has run (GRBL: ``G4``, ``M3``/``M4``/``M5``, coolant, ``M0``,
            ``M2``: protocol_buffer_synchronize); its answer says they ran.
        quiet_end: its feedback events are not known ahead, so ``events`` is only
            the estimate from the program's start: the first block a resumed job
            sends on a feedback link, which runs from wherever the stopped job left
            the tool (part way along it, or at its end). It is done once the
            controller has sent nothing for the link's ``quiet_end_s`` after its
            answer or its last event, however many came.
    """

    index: int
    line: int
    last_line: int
    data: bytes
    ack: str = ""
    events: int = 0
    busy_s: float = 0.0
    note: str = ""
    queued: int = 0
    sync: bool = False
    quiet_end: bool = False

    @property
    def text(self) -> str:
        """The block's bytes as Latin-1 text, without its terminator (or its note).

        One character per byte, as a controller counts them (the checks read this).
        """
        return self.note or self.data.decode("latin-1").rstrip("\r\n")

    @property
    def shown(self) -> str:
        """The block as the file writes it, for messages, without its terminator (or note).

        Decoded as UTF-8; a byte that is not UTF-8 is shown as a backslash escape.
        """
        return self.note or self.data.decode("utf-8", "backslashreplace").rstrip("\r\n")


class LineBlocks(Sequence[WireBlock]):
    """The blocks of a program framed one per line, made on demand from the file's bytes.

    What :func:`frame_lines` returns: a long program (hundreds of thousands of
    lines) is held as its bytes and one offset per line (``array``), not as one
    :class:`WireBlock` object per line. Block ``k`` (0-based) is line ``k + 1``.
    :meth:`with_facts` adds the ``queued`` and ``sync`` of every block the same
    way (an ``expect`` hook's result).

    Args:
        data: the program's bytes.
        starts: ``(n + 1,)`` offsets into ``data``: block ``k`` is
            ``data[starts[k]:starts[k + 1]]``.
        queued: ``(n,)`` per block, or ``None`` (all 0).
        sync: ``(n,)`` 0/1 per block, or ``None`` (all False).
    """

    def __init__(
        self,
        data: bytes,
        starts: array[int],
        queued: array[int] | None = None,
        sync: bytes | None = None,
    ) -> None:
        self.data = data
        self.starts = starts
        self.queued = queued
        self.sync = sync

    def __len__(self) -> int:
        return len(self.starts) - 1

    @overload
    def __getitem__(self, k: int) -> WireBlock: ...

    @overload
    def __getitem__(self, k: slice) -> Sequence[WireBlock]: ...

    def __getitem__(self, k: int | slice) -> WireBlock | Sequence[WireBlock]:
        if isinstance(k, slice):
            return [self[i] for i in range(*k.indices(len(self)))]
        if k < 0:
            k += len(self)
        if not 0 <= k < len(self):
            raise IndexError(k)
        line = k + 1
        return WireBlock(
            line,
            line,
            line,
            self.data[self.starts[k] : self.starts[k + 1]],
            queued=self.queued[k] if self.queued is not None else 0,
            sync=bool(self.sync[k]) if self.sync is not None else False,
        )

    def with_facts(self, queued: array[int], sync: bytes) -> LineBlocks:
        """The same blocks with each one's ``queued`` and ``sync``."""
        return LineBlocks(self.data, self.starts, queued, sync)


class Joined(Sequence[WireBlock]):
    """Some blocks before the blocks of another sequence from ``first`` on (a resume)."""

    def __init__(self, head: Sequence[WireBlock], rest: Sequence[WireBlock], first: int) -> None:
        self.head = list(head)
        self.rest = rest
        self.first = first

    def __len__(self) -> int:
        return len(self.head) + len(self.rest) - self.first

    @overload
    def __getitem__(self, k: int) -> WireBlock: ...

    @overload
    def __getitem__(self, k: slice) -> Sequence[WireBlock]: ...

    def __getitem__(self, k: int | slice) -> WireBlock | Sequence[WireBlock]:
        if isinstance(k, slice):
            return [self[i] for i in range(*k.indices(len(self)))]
        if k < 0:
            k += len(self)
        if not 0 <= k < len(self):
            raise IndexError(k)
        if k < len(self.head):
            return self.head[k]
        return self.rest[self.first + k - len(self.head)]


@dataclass(frozen=True)
class LinkSpec:
    """A target's ``[link]`` table, checked (see the module docstring for each key).

    Times in s, sizes in bytes; byte strings are the exact wire bytes.
    """

    target: str
    protocol: str
    how: str = ""
    source: str = ""
    baud: int = 9600
    block_end: bytes = b"\n"
    flow: str = "ack"
    rx_buffer_bytes: int = 0
    ack: str = ""
    error: str = ""
    alarm: str = ""
    banner: str = ""
    banner_timeout_s: float = 2.0
    wake: bytes = b""
    startup: bytes = b""
    status: bytes = b""
    hold: bytes = b""
    resume: bytes = b""
    reset: bytes = b""
    response_timeout_s: float = 5.0
    pace_margin: float = 0.1
    max_block_bytes: int = 0
    max_depth_mm: float | None = None
    operator_between_blocks: str = ""
    echo: bool = False
    warnings: tuple[str, ...] = ()
    handshake: str = ""
    ignore: tuple[str, ...] = ()
    abort: bytes = b""
    settle_s: float = 0.0
    quiet_end_s: float = 1.0

    def wire_time_s(self, nbytes: int) -> float:
        """Seconds ``nbytes`` take on the wire at :attr:`baud`, 8N1 (10 bits a byte)."""
        return nbytes * 10.0 / self.baud


@dataclass(frozen=True)
class Status:
    """What a controller's status report says (GRBL ``<Run|MPos:…|Bf:14,120|…>``).

    Attributes:
        state: the state word (``"Idle"``, ``"Run"``, ``"Hold:0"``, ``"Alarm"``).
        queue_free: free entries of the motion queue (GRBL ``Bf:`` first
            number, planner blocks); ``None``: not reported.
        rx_free: free bytes of the receive buffer (``Bf:`` second number);
            ``None``: not reported.
    """

    state: str
    queue_free: int | None = None
    rx_free: int | None = None


@dataclass(frozen=True)
class LinkHooks:
    """The Python a target's protocol needs beyond its ``[link]`` table (``LINK``).

    Attributes:
        frame: ``(code bytes, spec, source) -> blocks``; default :func:`frame_lines`.
            Raises :class:`~camtool.model.errors.InputError` naming the line.
        decode: ``controller message -> words`` ("error:22" → "undefined feed
            rate: …"); default: the message as it came.
        resume: ``(blocks before, first block sent, spec) -> restore blocks``:
            what puts the controller back in the modal state the program had
            before ``--from-line``; raises :class:`UsageError` for a line a job
            cannot resume at. Default: nothing to restore.
        device: ``(spec, **options) -> Device``: the target's simulator
            (:class:`camtool.link.device.Device`); default: the generic
            :class:`camtool.link.device.LineDevice` for the spec.
        status_state: ``line -> state word or None``: reads a status report
            (GRBL ``<Idle|MPos:…>`` → ``"Idle"``); ``None`` for any other line.
            With it and a ``status`` byte, ``send`` refuses a controller in
            ``Alarm`` before the job and waits for ``Idle`` at its end.
        split: ``buffer -> answers``: takes the whole answers out of the bytes
            received so far (it deletes what it takes from ``buffer``, a
            ``bytearray``) and returns them as latin-1 text; default: lines,
            line ends stripped, empty lines dropped.
        feedback: ``answer -> bool``: True for a feedback event (counted
            against :attr:`WireBlock.events`, never an answer).
        expect: ``(blocks, program, target) -> blocks``: the blocks with what
            the controller will report for each (``events``, ``busy_s``,
            ``queued``, ``sync``), from the program as the target's reader read
            it back. Raises :class:`~camtool.model.errors.DialectError` for a
            block whose end the sender could not tell.
        status: ``line -> Status or None``: reads a status report with its
            queue counts (GRBL ``Bf:``); takes precedence over ``status_state``.
        setup: ``ask -> lines``: settings the job needs, asked of the controller
            before the first block with ``ask(line) -> answers`` (it raises
            :class:`LinkError` for an error answer); returns the lines that put
            the controller's settings back at the end (GRBL: ``$10`` with its
            buffer-state bit, so status reports carry ``Bf:``).
        check: ``(blocks, source) -> None``: refuse what the controller would
            refuse, before the first byte: raises
            :class:`~camtool.model.errors.DialectError` naming the line (GRBL:
            words and codes its gcode.c does not take).
        firmware: ``line -> reason or None``: why the link cannot stream to the
            controller that said ``line`` at start-up (GRBL: a version before 1.1);
            ``send`` stops there, before the first byte of the program.
    """

    frame: Callable[[bytes, LinkSpec, str], Sequence[WireBlock]] | None = None
    decode: Callable[[str], str] | None = None
    resume: Callable[[Sequence[WireBlock], WireBlock, LinkSpec], list[WireBlock]] | None = None
    device: Callable[..., Any] | None = None
    status_state: Callable[[str], str | None] | None = None
    split: Callable[[bytearray], list[str]] | None = None
    feedback: Callable[[str], bool] | None = None
    expect: Callable[[Sequence[WireBlock], Any, Any], Sequence[WireBlock]] | None = None
    status: Callable[[str], Status | None] | None = None
    setup: Callable[[Callable[[str], list[str]]], list[str]] | None = None
    check: Callable[[Sequence[WireBlock], str], None] | None = None
    firmware: Callable[[str], str | None] | None = None


NO_HOOKS = LinkHooks()

_BYTES = ("block_end", "wake", "startup", "status", "hold", "resume", "reset", "abort")
_TEXT = ("how", "source", "ack", "error", "alarm", "banner", "operator_between_blocks")
HANDSHAKES = ("", "dtr-dsr")
"""Values of ``[link] handshake``."""
_POSITIVE = ("banner_timeout_s", "response_timeout_s", "quiet_end_s")
_COUNTS = ("baud", "rx_buffer_bytes", "max_block_bytes")
MAX_BUFFER_BYTES = 1 << 20
"""Largest ``rx_buffer_bytes`` and ``max_block_bytes`` taken (1 MiB): a controller's
receive buffer or line is bytes to a few KiB (GRBL's 127, grblHAL's 1 KiB); a larger
number is a typing error that would let the sender overflow the real buffer."""


def link_spec(target: Target) -> LinkSpec:
    """The checked ``[link]`` table of ``target``.

    Raises:
        LinkError: the target declares no link, or ``protocol = "none"`` (the
            message says how its programs reach the machine).
        InputError: a key is unknown or has a bad value, naming the file and key.
    """
    table = dict(target.link_table)
    where = f"{target.name}: [link]"
    if not table:
        raise LinkError(
            f"target {target.name!r} declares no link ([link] table): camtool cannot send "
            "its programs; write the file with 'camtool post' and load it the machine's own way"
        )
    spec = _spec_from_table(table, target.name, where)
    if spec.protocol == "none":
        raise LinkError(
            f"target {target.name!r} has no host link camtool can speak: {spec.how}"
            + (f" ({spec.source})" if spec.source else "")
        )
    return spec


def _spec_from_table(table: dict[str, Any], name: str, where: str) -> LinkSpec:
    known = set(LinkSpec.__dataclass_fields__) - {"target"}
    unknown = sorted(set(table) - known)
    if unknown:
        raise InputError(f"{where}: unknown key(s) {unknown}; known: {sorted(known)}")
    values: dict[str, Any] = {"target": name}
    for key, value in table.items():
        values[key] = _checked(key, value, where)
    if values.get("protocol") not in PROTOCOLS:
        raise InputError(f"{where}: protocol must be one of {list(PROTOCOLS)}")
    if values.get("handshake", "") not in HANDSHAKES:
        raise InputError(f"{where}: handshake must be one of {list(HANDSHAKES)}")
    if values.get("flow", "ack") not in FLOWS:
        raise InputError(f"{where}: flow must be one of {list(FLOWS)}")
    if values.get("flow") == "char-count" and not values.get("rx_buffer_bytes"):
        raise InputError(f"{where}: flow = 'char-count' needs rx_buffer_bytes")
    answered = values.get("flow", "ack") in ("char-count", "ack")
    unanswered = not values.get("ack") and not values.get("echo")
    if answered and values.get("protocol") == "stream" and unanswered:
        raise InputError(f"{where}: flow {values.get('flow', 'ack')!r} needs ack")
    spec = LinkSpec(**values)
    if spec.quiet_end_s >= spec.response_timeout_s:
        raise InputError(
            f"{where}: quiet_end_s ({spec.quiet_end_s:g} s) must be shorter than "
            f"response_timeout_s ({spec.response_timeout_s:g} s), after which a silent "
            "controller counts as lost"
        )
    if spec.quiet_end_s <= spec.settle_s:
        raise InputError(
            f"{where}: quiet_end_s ({spec.quiet_end_s:g} s) must be longer than settle_s "
            f"({spec.settle_s:g} s, the quiet after a block's last step): a silence that short "
            "may fall between two steps, and the next block would cut the motion short"
        )
    return spec


def _checked(key: str, value: Any, where: str) -> Any:
    """One ``[link]`` value, checked and converted (bytes as latin-1, tuples)."""
    if key in _BYTES or key in _TEXT or key in ("protocol", "flow", "handshake"):
        if not isinstance(value, str):
            raise InputError(f"{where}: {key} must be a string, not {value!r}")
        return value.encode("latin-1") if key in _BYTES else value
    if key == "echo":
        if not isinstance(value, bool):
            raise InputError(f"{where}: echo must be true or false, not {value!r}")
        return value
    if key in ("warnings", "ignore"):
        if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
            raise InputError(f"{where}: {key} must be a list of strings")
        return tuple(value)
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise InputError(f"{where}: {key} must be a number, not {value!r}")
    if key in _COUNTS:
        if value != int(value) or value <= 0:
            raise InputError(f"{where}: {key} must be a whole number > 0, not {value!r}")
        if key != "baud" and value > MAX_BUFFER_BYTES:
            raise InputError(
                f"{where}: {key} must be at most {MAX_BUFFER_BYTES} bytes (a controller's "
                f"buffer), not {value!r}"
            )
        return int(value)
    if value < 0 or (key in _POSITIVE and value == 0):
        raise InputError(f"{where}: {key} must be > 0, not {value!r}")
    return float(value)


def link_hooks(target: Target) -> LinkHooks:
    """The target's ``LINK`` hooks, or none.

    Raises:
        InputError: ``LINK`` is not a :class:`LinkHooks`.
    """
    hooks = target.link
    if hooks is None:
        return NO_HOOKS
    if not isinstance(hooks, LinkHooks):
        raise InputError(f"target {target.name!r}: LINK is a {type(hooks).__name__}, not LinkHooks")
    return hooks


def frame_lines(code: bytes, spec: LinkSpec, source: str) -> LineBlocks:
    """One block per line: the bytes up to and including each ``block_end``.

    A last line without the terminator is a block too (it is sent as written:
    the file's bytes, no more). Empty lines are blocks (GRBL answers them ``ok``).
    The blocks are made on demand (:class:`LineBlocks`).

    Raises:
        InputError: a block longer than ``max_block_bytes``, naming the line.
    """
    end = spec.block_end
    starts = array("q", [0])
    limit = spec.max_block_bytes or spec.rx_buffer_bytes
    start = 0
    while start < len(code):
        cut = code.find(end, start)
        stop = len(code) if cut < 0 else cut + len(end)
        if limit and stop - start > limit:
            line = len(starts)
            check_block_size(WireBlock(line, line, line, code[start:stop]), spec, source)
        starts.append(stop)
        start = stop
    return LineBlocks(code, starts)


def check_block_size(block: WireBlock, spec: LinkSpec, source: str) -> None:
    """Refuse a block the controller's line buffer cannot hold.

    Raises:
        InputError: longer than ``max_block_bytes`` (or than the receive buffer
            in char-count flow), naming the line.
    """
    limit = spec.max_block_bytes or spec.rx_buffer_bytes
    if limit and len(block.data) > limit:
        raise InputError(
            f"{source}, line {block.line}: block of {len(block.data)} bytes; {spec.target} "
            f"takes at most {limit} bytes a block (terminator included); shorten the line"
        )


def check_port_name(port: str) -> str:
    """``port`` checked: a device path or a pyserial URL.

    Raises:
        UsageError: empty.
    """
    if not port.strip():
        raise UsageError("--port is empty; give a device (/dev/ttyUSB0, COM3) or a URL")
    return port
