"""The matlab-router's USB link: a job is one wire block, and the master that takes it.

Design notes: docs/internals.md, ``postprocessors/matlab_router/link.py``.
"""

from __future__ import annotations

from camtool.link.device import LineDevice
from camtool.link.spec import LinkHooks, LinkSpec, WireBlock, check_block_size
from camtool.model.errors import InputError


def frame_jobs(code: bytes, spec: LinkSpec, source: str) -> list[WireBlock]:
    """One block per job of a wire stream; ``line`` counts CR-ended records (values).

    Raises:
        InputError: the file is the script format (``.m``), or a job's ``n`` is
            not a number or its values are cut short, naming the record.
    """
    end = spec.block_end
    records = code.split(end)
    if records and records[-1] == b"":
        records.pop()
    if not records or not records[0].strip().lstrip(b"-").isdigit():
        raise InputError(
            f"{source}: not a matlab-router wire stream (it starts {code[:12]!r}); send the "
            "bytes the GUI sent: camtool post -t matlab-router --format wire"
        )
    blocks: list[WireBlock] = []
    k = 0
    while k < len(records):
        n = int(records[k])
        count = 3 + 4 * n
        if k + count > len(records):
            raise InputError(f"{source}: job {len(blocks) + 1} (record {k + 1}) is cut short")
        data = b"".join(r + end for r in records[k : k + count])
        block = WireBlock(len(blocks) + 1, k + 1, k + count, data)
        check_block_size(block, spec, source)
        blocks.append(block)
        k += count
    return blocks


class RouterDevice(LineDevice):
    """The master PIC18F4550 receiving jobs: ``n``, then ``3 + 4n`` values, each CR-ended."""

    def take_block(self) -> bytes | None:
        """A whole job from the receive queue, or ``None``."""
        end = self.spec.block_end
        first = self.rx.find(end)
        if first < 0:
            return None
        try:
            count = 3 + 4 * int(self.rx[:first])
        except ValueError:
            count = 1  # not a number: the master's atol() reads 0; keep the record
        cut, seen = -len(end), 0
        while seen < count:
            cut = self.rx.find(end, cut + len(end))
            if cut < 0:
                return None
            seen += 1
        block = bytes(self.rx[: cut + len(end)])
        del self.rx[: cut + len(end)]
        return block

    def pending(self) -> bool:
        """True when a whole job is queued."""
        if not self.rx:
            return False
        probe = bytearray(self.rx)
        block = self.take_block()
        self.rx = probe
        return block is not None


LINK = LinkHooks(frame=frame_jobs, device=RouterDevice)
"""The matlab-router's link hooks (``camtool send -t matlab-router``)."""
