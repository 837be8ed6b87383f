"""The word-address writer holds its blocks as text, not as a string a block.

tracemalloc, with wide margins: writing a program of 80 000 blocks takes, beside the
code it returns, about one more copy of the code (its blocks joined 4096 at a time,
then the pieces joined); it used to hold every block as a string of its own (~70 bytes
a block of 20) and join them at the end.
"""

from __future__ import annotations

import tracemalloc

from camtool.model.program import Linear, Program, Rapid
from camtool.post.registry import load_target


def _square_passes(moves: int) -> Program:
    corners = [(10.0, 0.0), (10.0, 10.0), (0.0, 10.0), (0.0, 0.0)]
    out: list[Rapid | Linear] = [Rapid(0.0, 0.0, 5.0, contour=1)]
    out += [Linear(*corners[k % 4], 600.0, contour=1) for k in range(moves)]
    return Program(tuple(out))


def test_writing_holds_the_code_not_a_string_per_block() -> None:
    target = load_target("grbl")
    target.emit(_square_passes(1000))  # caches and imports first
    program = _square_passes(80_000)
    tracemalloc.start()
    try:
        result = target.emit(program)
        current, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    code = result.code
    assert isinstance(code, str) and result.blocks > 80_000
    # about 2.3× now, 5.2× when each block was a string of its own
    assert peak - current < 3.5 * len(code), (peak - current, len(code))


def test_block_numbers_in_messages_count_the_blocks_joined_already() -> None:
    """After thousands of blocks, the block a message names is still the file's line."""
    from camtool.post.wordaddress import WordAddressPost
    from camtool.post.wordaddress_write import BlockWriter

    target = load_target("grbl")
    post = target.post
    assert isinstance(post, WordAddressPost)
    writer = BlockWriter(post.spec, target.machine)
    code = writer.write(_square_passes(10_000))
    lines = code.count("\n")
    assert writer.count == lines > 10_000
    assert writer.where(contour=0) == f"block {lines + 1}"
