"""`send --dry-run` of a long program: bounded memory, the same estimate.

The step simulation behind the timing model holds every row of the moves it is given (a
1 MB program of 2 mm moves made 15 M rows: 630 MB peak, so 7 GB for 12 MB); the plan now
times the moves in chunks and holds the program as its bytes and one offset per line.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from camtool.link import plan as plan_module
from camtool.link.plan import prepare_send
from camtool.link.spec import LineBlocks
from camtool.post.registry import load_target


def zigzag(lines: int, step_mm: float) -> str:
    """``lines`` feed moves of ``step_mm`` along X, back and forth inside GRBL's 200 mm area."""
    out = ["G21 G90 G94", "G0 X10 Y10", "G1 Z-0.5 F100"]
    for k in range(lines):
        x = 10 + step_mm if k % 2 == 0 else 10
        out.append(f"G1 X{x:.3f} Y{10 + k * 0.001:.3f} F600")
    return "\n".join([*out, "G0 Z5", "M2"]) + "\n"


def test_a_long_program_is_timed_in_chunks_with_the_same_result(monkeypatch: Any) -> None:
    code = zigzag(1200, 2.0)
    whole = prepare_send(code, load_target("grbl"))
    sizes: list[int] = []
    from camtool.verify import trace_sources

    real = trace_sources.simulate

    def counting(program: Any, machine: Any, **kw: Any) -> Any:
        sizes.append(len(program.moves))
        return real(program, machine, **kw)

    monkeypatch.setattr(plan_module, "CHUNK_MOVES", 100)
    monkeypatch.setattr(plan_module, "CHUNK_ROWS", 10**9)
    monkeypatch.setattr(trace_sources, "simulate", counting)
    chunked = prepare_send(code, load_target("grbl"))
    assert sizes and max(sizes) <= 100
    # GRBL's time model times each move alone (rest to rest): chunks change nothing
    assert list(chunked.block_time_s) == pytest.approx(list(whole.block_time_s), abs=1e-9)
    # the blocks are made from the file's bytes on demand, not held one object per line
    assert isinstance(chunked.blocks, LineBlocks)
    assert b"".join(b.data for b in chunked.blocks) == code.encode()


PEAK = """
import resource, sys
from camtool.cli.main import main
from camtool.verify.dda import COMPILE_FROM, compiled
compiled(COMPILE_FROM)  # the compiled kernels (a constant ~100 MB) in both runs alike
main(["send", sys.argv[1], "-t", "grbl", "--dry-run"])
print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss // 1024, file=sys.stderr)
"""


def peak_mb(path: Path) -> int:
    done = subprocess.run(
        [sys.executable, "-c", PEAK, str(path)], capture_output=True, text=True, timeout=600
    )
    assert done.returncode == 0, done.stderr
    return int(done.stderr.strip().splitlines()[-1])


def test_dry_run_memory_does_not_grow_with_the_rows(tmp_path: Path) -> None:
    # 10 mm moves at 250 steps/mm: 2 500 step rows a move; 4 000 moves are 10 M rows, which the
    # whole-program simulation held at once: its peak grew 214 MB from 1 000 to 4 000 moves
    # (245 -> 459 MB); timed in chunks it grows by what the program itself takes (1 MB)
    small, large = tmp_path / "small.gcode", tmp_path / "large.gcode"
    small.write_text(zigzag(1000, 10.0))
    large.write_text(zigzag(4000, 10.0))
    grown = peak_mb(large) - peak_mb(small)
    assert grown < 40, f"peak grew {grown} MB from 1 000 to 4 000 moves"
