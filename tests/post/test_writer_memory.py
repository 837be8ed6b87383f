"""The word-address writer holds its blocks as text, not as a string a block.

tracemalloc, with wide margins: writing a program of 80 000 blocks takes, beside the
code it returns, about one more copy of the code (its blocks joined 4096 at a time,
then the pieces joined); it used to hold every block as a string of its own (~70 bytes
a block of 20) and join them at the end.
"""

from __future__ import annotations

import gc
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


def test_the_number_texts_kept_for_many_distinct_coordinates_stay_few() -> None:
    """100 000 distinct X values: the texts the writer and the number formats keep between
    calls (caches by value) stay a few MB. Measured 4.2 MB kept and a 6.2 MB peak beside a
    1.8 MB code; 21.7 MB and 27.5 MB when a format's rounding kept 65 536 texts and the
    writer 65 536 per letter (~330 and ~190 bytes each)."""
    target = load_target("grbl")
    target.emit(_square_passes(1000))  # caches and imports first
    moves: list[Rapid | Linear] = [Rapid(0.0, 0.0, 5.0, contour=1)]
    moves += [Linear(1.0 + k * 0.001, float(k % 2), 600.0, contour=1) for k in range(100_000)]
    program = Program(tuple(moves))
    gc.collect()
    tracemalloc.start()
    try:
        result = target.emit(program)
        peak = tracemalloc.get_traced_memory()[1]
        gc.collect()
        kept = tracemalloc.get_traced_memory()[0]
    finally:
        tracemalloc.stop()
    assert isinstance(result.code, str) and len(result.code) < 2_000_000
    assert kept < 10_000_000, kept  # the code and the bounded caches
    assert peak < 12_000_000, peak
