"""Benchmark of the verifier's interpolators (not collected by pytest).

Run as ``python tests/benchmarks/bench_interpolators.py``. Each interpolator
simulates at least 10 million iterations (one row of the step array each; the
motor pulses are also counted) over many long lines or large circles; the plain
pure-Python reference loop of the same algorithm runs on a smaller sample in the
same process, and the ratio of the two rates is printed. Target: under ~2 min.
"""

from __future__ import annotations

import random
import sys
import time
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from camtool.verify import interpolators as itp
from camtool.verify.interpolators import dsm_arc_reference

TOTAL = 10_000_000
"""Iterations simulated per interpolator (at least)."""
REFERENCE_TOTAL = 600_000
"""Iterations run through each reference loop."""

Case = tuple[int, ...]
Interp = Callable[..., np.ndarray]


def lines(total: int, length: int, seed: int) -> list[Case]:
    """Random lines of about ``length`` steps until ``total`` iterations are covered."""
    rng = random.Random(seed)
    cases: list[Case] = []
    covered = 0
    while covered < total:
        a, b = rng.randint(length // 2, length), rng.randint(0, length)
        cases.append((a * rng.choice((-1, 1)), b * rng.choice((-1, 1))))
        covered += max(a, b)
    return cases


def circles(total: int, radius: int, per_radius: float, seed: int) -> list[Case]:
    """Full circles about random centres; ``per_radius`` iterations per step of radius."""
    rng = random.Random(seed)
    count = max(1, -(-total // int(per_radius * radius)))
    cases: list[Case] = []
    for _ in range(count):
        cx, cy = rng.randint(-1000, 1000), rng.randint(-1000, 1000)
        cases.append((cx, cy + radius, cx, cy + radius, cx, cy, rng.random() < 0.5))
    return cases


def run(fn: Interp, cases: Sequence[Case]) -> tuple[int, int, float]:
    """Iterations, motor pulses and seconds for ``fn`` over ``cases``."""
    iterations = pulses = 0
    start = time.perf_counter()
    for case in cases:
        steps = fn(*case)
        iterations += len(steps)
        pulses += int(np.count_nonzero(steps))
    return iterations, pulses, time.perf_counter() - start


def report(
    name: str, fast: Interp, ref: Interp | None, cases: Sequence[Case], ref_cases: Sequence[Case]
) -> None:
    """Print one benchmark line: rates of the implementation and of its reference."""
    it, pulses, secs = run(fast, cases)
    rate = it / secs
    line = f"{name:24s} {it:>11,d} it {pulses:>11,d} pulses {secs:6.2f} s {rate / 1e6:7.2f} M it/s"
    if ref is None:
        print(f"{line} | pure Python: it is its own reference")
        return
    rit, _pulses, rsecs = run(ref, ref_cases)
    rrate = rit / rsecs
    print(
        f"{line} | reference {rit:>9,d} it {rrate / 1e6:6.2f} M it/s | ratio {rate / rrate:6.1f}x"
    )


def main() -> None:
    """Run every benchmark and print iterations (steps) per second."""
    t0 = time.perf_counter()
    long_lines = lines(TOTAL, 200_000, seed=1)
    ref_lines = lines(REFERENCE_TOTAL, 20_000, seed=2)
    print(f"lines: {len(long_lines)} of up to 200000 steps; references on {len(ref_lines)} lines")
    report("dda_line (A.3)", itp.dda_line, itp.dda_line_reference, long_lines, ref_lines)
    report(
        "accumulator_dda_line",
        itp.accumulator_dda_line,
        itp.accumulator_dda_reference,
        long_lines,
        ref_lines,
    )
    report("bresenham_line", itp.bresenham_line, itp.bresenham_reference, long_lines, ref_lines)
    report(
        "corte_recto_line", itp.corte_recto_line, itp.corte_recto_reference, long_lines, ref_lines
    )
    short = lines(TOTAL, 100, seed=3)
    print(f"short lines: {len(short)} of up to 100 steps (per-call overhead dominates)")
    report("dda_line (short)", itp.dda_line, itp.dda_line_reference, short, short[:5000])
    radius = 200_000
    print(f"arcs: full circles of radius {radius} steps; DSM reference on radius 20000")
    report(
        "dsm_arc (A.6)",
        itp.dsm_arc,
        dsm_arc_reference,
        circles(TOTAL, radius, 5.64, seed=4),
        circles(REFERENCE_TOTAL, 20_000, 5.64, seed=5),
    )
    staircase = circles(TOTAL, radius, 8.0, seed=6)
    report("staircase_arc (A.5)", itp.staircase_arc, None, staircase, [])
    dda_circles = circles(TOTAL, radius, 6.28, seed=7)
    report("circular_dda_arc (A.4)", itp.circular_dda_arc, None, dda_circles, [])
    print(f"total {time.perf_counter() - t0:.1f} s")


if __name__ == "__main__":
    main()
