"""Benchmark of the verifier's interpolators against the same loops in C (not collected).

Run as ``python tests/benchmarks/bench_interpolators.py`` (or through ``run_all.py``).
Two jobs, each measured on camtool and on its C peer in the same run, on the same inputs:

- linear DDA (UNAM-GMM §4.2, annex A.3): random lines of up to 200 000 steps, 10 M
  iterations in all; camtool's :func:`camtool.verify.dda.dda_line`;
- DSM (UNAM-GMM §4.5, annex A.6): a full circle of radius 2 000 000 steps (11.3 M
  iterations); camtool's :func:`camtool.verify.interpolators.dsm_arc`.

The C peers (``tests/benchmarks/c/dda.c``, ``dsm.c``) are the thesis loops straight from
the pseudocode of reference/UNAM-GMM.md §4.2 and §4.5, compiled at run time with
``cc -O2`` into a temporary directory; they write the same rows (two int8 per iteration)
into a buffer, time their own loop (best of 3) and print the iteration and pulse counts
and a checksum of the rows, which this script compares with camtool's rows: equal
checksums show that the peer did the same work. camtool is timed in-process, best of 3
(the arrays it returns are the same rows). Without a C compiler the rows say so. The plain
pure-Python loops (``*_reference``) are timed on a smaller sample and given as notes.
Target: the whole script well under 1 min.

Measurements: docs/performance.md (this script's rows, and its earlier notes).
"""

from __future__ import annotations

import os
import random
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(HERE))

from table import row  # noqa: E402

from camtool.verify import dda  # noqa: E402
from camtool.verify import interpolators as itp  # noqa: E402

TOTAL = 10_000_000
"""DDA iterations (at least) per measurement."""
DSM_RADIUS = 2_000_000
"""Radius of the DSM circle, steps (the issue's figure)."""
REFERENCE_TOTAL = 300_000
"""Iterations run through each pure-Python reference loop (a note, not a goal)."""
REPEATS = 3

Case = tuple[int, ...]


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
        cases.append((cx, cy + radius, cx, cy + radius, cx, cy, int(rng.random() < 0.5)))
    return cases


def checksum(parts: Sequence[np.ndarray]) -> int:
    """The C peers' checksum (tests/benchmarks/c/common.h) of camtool's step arrays."""
    total = 0
    for rows in parts:
        r = rows.astype(np.int64)
        weights = np.arange(1, len(r) + 1, dtype=np.uint64)
        values = (3 * r[:, 0] + r[:, 1]).astype(np.uint64)  # negatives wrap as in C
        total = (total * 1000003 + int((weights * values).sum(dtype=np.uint64))) % (1 << 64)
    return total


def timed(fn: Callable[..., np.ndarray], cases: Sequence[Case]) -> tuple[list[np.ndarray], float]:
    """camtool's rows for ``cases`` and the best of :data:`REPEATS` times, s."""
    best = float("inf")
    parts: list[np.ndarray] = []
    for _ in range(REPEATS):
        parts = []
        start = time.perf_counter()
        for case in cases:
            parts.append(fn(*case))
        best = min(best, time.perf_counter() - start)
    return parts, best


def compiler() -> str | None:
    """The C compiler (``$CC`` or ``cc``), or None."""
    return shutil.which(os.environ.get("CC", "cc"))


def cc_version(cc: str) -> str:
    """First line of ``cc --version``."""
    out = subprocess.run([cc, "--version"], capture_output=True, text=True, check=False)
    return (out.stdout.splitlines() or ["cc"])[0]


def run_c(cc: str, source: str, cases: Sequence[Case], tmp: Path) -> tuple[int, int, int, float]:
    """Compile ``c/<source>`` with ``cc -O2`` and run it on ``cases``.

    Returns:
        ``(iterations, pulses, checksum, best seconds)`` as the C program prints them.
    """
    exe = tmp / Path(source).stem
    subprocess.run(
        [cc, "-O2", "-o", str(exe), str(HERE / "c" / source), "-lm"], check=True, cwd=tmp
    )
    data = tmp / f"{exe.name}.txt"
    data.write_text("".join(" ".join(str(v) for v in c) + "\n" for c in cases))
    out = subprocess.run([str(exe), str(data), str(REPEATS)], capture_output=True, text=True)
    if out.returncode:
        raise RuntimeError(f"{exe.name} failed: {out.stderr.strip()}")
    it, pulses, sums, secs = out.stdout.split()
    return int(it), int(pulses), int(sums), float(secs)


def reference_rate(fn: Callable[..., np.ndarray], cases: Sequence[Case]) -> float:
    """Iterations per second of a pure-Python reference loop."""
    start = time.perf_counter()
    it = sum(len(fn(*case)) for case in cases)
    return it / (time.perf_counter() - start)


def first_call_s() -> float:
    """Wall time of the first DDA + DSM call in a fresh process (numba import + cache)."""
    code = (
        "import time; t = time.perf_counter()\n"
        "from camtool.verify import dda, interpolators as i\n"
        "dda.compiled()\n"  # load the kernels now (a big job would)
        "dda.dda_line(3, 4); dda.dda_line(3, 5); i.dsm_arc(0, 30, 0, 30, 0, 0, True)\n"
        "print(time.perf_counter() - t)\n"
    )
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, check=True)
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True)
    return float(out.stdout.strip() or "nan")


def job(
    name: str,
    fn: Callable[..., np.ndarray],
    ref: Callable[..., np.ndarray],
    cases: Sequence[Case],
    ref_cases: Sequence[Case],
    source: str,
    goal: float,
    cc: str | None,
    tmp: Path,
    extra: str,
) -> None:
    """Measure one interpolator and its C peer; print one table row."""
    parts, secs = timed(fn, cases)
    iterations = sum(len(p) for p in parts)
    pulses = sum(int(np.count_nonzero(p)) for p in parts)
    rate = iterations / secs
    ours = checksum(parts)
    ref_rate = reference_rate(ref, ref_cases)
    note = (
        f"{iterations:,} iterations, {pulses:,} pulses; pure-Python reference loop "
        f"{ref_rate / 1e6:.2f} M it/s ({rate / ref_rate:.0f}× slower than camtool); {extra}"
    )
    camtool = f"{rate / 1e6:.1f} M it/s"
    if cc is None:
        row(
            name,
            camtool,
            "C cc -O2: not installed (apt-get install gcc)",
            "—",
            None,
            "speed",
            f"≥ {goal}×",
            False,
            note,
        )
        return
    c_it, c_pulses, c_sum, c_secs = run_c(cc, source, cases, tmp)
    c_rate = c_it / c_secs
    same = (c_it, c_pulses, c_sum) == (iterations, pulses, ours)
    note += (
        "; C rows identical (checksum)"
        if same
        else (f"; C rows DIFFER: C {c_it:,} it, {c_pulses:,} pulses, checksum {c_sum} vs {ours}")
    )
    ratio = rate / c_rate
    row(
        name,
        camtool,
        f"C {cc_version(cc)} -O2",
        f"{c_rate / 1e6:.1f} M it/s",
        ratio,
        "speed",
        f"≥ {goal}×",
        ratio >= goal and same,
        note,
    )


def main() -> None:
    """Run both jobs and print their rows."""
    t0 = time.perf_counter()
    first = first_call_s()
    # load the kernels before timing (a big job does so itself; a tree before issue 17 has none)
    if getattr(dda, "compiled", lambda: None)() is None:
        print("numba not installed: the plain numpy / Python paths are timed", file=sys.stderr)
    extra = f"first call in a fresh process (numba import + cached loops) {first:.2f} s"
    cc = compiler()
    with tempfile.TemporaryDirectory(prefix="camtool-bench-c-") as tmp:
        job(
            "linear DDA (UNAM-GMM A.3), 10 M iterations, in-process",
            dda.dda_line,
            dda.dda_line_reference,
            lines(TOTAL, 200_000, seed=1),
            lines(REFERENCE_TOTAL, 20_000, seed=2),
            "dda.c",
            0.3,
            cc,
            Path(tmp),
            extra,
        )
        job(
            f"DSM arc (UNAM-GMM A.6), full circle R = {DSM_RADIUS:,} steps, in-process",
            itp.dsm_arc,
            itp.dsm_arc_reference,
            circles(TOTAL, DSM_RADIUS, 5.64, seed=4),
            circles(REFERENCE_TOTAL, 20_000, 5.64, seed=5),
            "dsm.c",
            0.1,
            cc,
            Path(tmp),
            extra,
        )
    print(f"bench_interpolators: {time.perf_counter() - t0:.1f} s", file=sys.stderr)


if __name__ == "__main__":
    main()
