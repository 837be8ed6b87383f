"""Benchmark of the whole verifier on programs of more than 10 million steps (not collected).

Run as ``python tests/benchmarks/bench_verify.py``. For each built-in machine profile a
program of concentric circles and star lines is simulated end to end (interpolators,
compensation, backlash play, deviation, contour measures, time), and the rate is printed in
motor steps per second. The backlash play, the stage that replaces a per-step loop, is also
run as a plain pure-Python loop over the same rows in the same process, and the ratio is
printed. Finally the 5 mm logo of samples/ is verified on pic-mmh, as `post --verify` does.
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from camtool.model.machine import Machine
from camtool.model.program import ArcMove, Linear, Move, Program, Rapid
from camtool.post.registry import load_machine
from camtool.verify.simulate import _play, simulate_steps
from camtool.verify.verifier import verify_program

TOTAL_STEPS = 10_000_000


def workload(machine: Machine) -> Program:
    """Circles and star lines about the work-area centre until TOTAL_STEPS motor steps."""
    x0, y0, x1, y1 = machine.work_area_mm
    cx, cy = (x0 + x1) / 2, (y0 + y1) / 2
    size = min(x1 - x0, y1 - y0) * 0.45
    spm = machine.steps_per_mm[0]
    moves: list[Move] = []
    steps = 0.0
    k = 0
    while steps < TOTAL_STEPS:
        r = size * (0.3 + 0.7 * ((k * 0.618) % 1.0))
        moves += [Rapid(cx + r, cy), ArcMove(cx + r, cy, cx, cy, k % 2 == 0, 100.0)]
        steps += 8 * r * spm  # X + Y pulses of a full circle
        a = k * 0.7
        moves += [Linear(cx + r * math.cos(a), cy + r * math.sin(a), 100.0), Linear(cx, cy, 100.0)]
        steps += 2 * r * spm * (abs(math.cos(a)) + abs(math.sin(a)))
        k += 1
    return Program(tuple(moves), origin=(cx, cy))


def play_reference(steps: np.ndarray, band: float) -> np.ndarray:
    """The backlash play of one axis as a per-row Python loop (band [M, M + B])."""
    out = np.empty(len(steps))
    motor, carriage = 0, None
    for i, s in enumerate(steps.tolist()):
        motor += s
        if carriage is None:
            if s == 0:
                out[i] = 0.0
                continue
            carriage = 0.0 if s > 0 else float(band)
            carriage = max(carriage, motor) if s > 0 else min(carriage, motor + band)
        elif s > 0:
            carriage = max(carriage, motor)
        elif s < 0:
            carriage = min(carriage, motor + band)
        out[i] = carriage
    return out


def main() -> None:
    for name in ("mmh-gmm", "valcnc", "grbl"):
        machine = load_machine(name)
        program = workload(machine)
        t0 = time.perf_counter()
        v = verify_program(program, machine)
        elapsed = time.perf_counter() - t0
        steps = int(v.trace.block_steps[:, :2].sum())  # motor pulses, X + Y
        rows = len(v.trace.rows)
        print(
            f"{name:<8} {machine.motion.line:>15}/{machine.motion.arc:<6} {steps:>12,} steps "
            f"{rows:>12,} iterations {elapsed:6.2f} s {steps / elapsed / 1e6:7.2f} M steps/s"
        )
    machine = load_machine("mmh-gmm")
    trace = simulate_steps(workload(machine), machine)
    rows = trace.rows
    motor = np.cumsum(rows, axis=0, dtype=np.int64)
    t0 = time.perf_counter()
    _play(rows[:, 0], motor, 0, 0, machine)
    fast = len(rows) / (time.perf_counter() - t0)
    sample = np.asarray(rows[:2_000_000, 0], dtype=np.int64)
    band = 204.0 / 1000.0 * machine.steps_per_mm[0]
    t0 = time.perf_counter()
    play_reference(sample, band)
    slow = len(sample) / (time.perf_counter() - t0)
    print(
        f"backlash play, X axis: numpy runs {fast / 1e6:7.1f} M rows/s | pure-Python loop "
        f"{slow / 1e6:5.2f} M rows/s | ratio {fast / slow:5.1f}x"
    )
    from camtool.jobs.pipeline import post_file, verify_job

    job = post_file(Path(__file__).parents[2] / "samples" / "logo.dxf", "pic-mmh")
    t0 = time.perf_counter()
    v = verify_job(job)
    print(
        f"samples/logo.dxf on pic-mmh: {int(v.trace.block_steps.sum()):,} steps verified in "
        f"{time.perf_counter() - t0:.3f} s (target: well under 1 s)"
    )


if __name__ == "__main__":
    main()
