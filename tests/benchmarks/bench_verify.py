"""Benchmark of ``camtool verify`` on a multi-million-step program (not collected by pytest).

Run as ``python tests/benchmarks/bench_verify.py`` (or through ``run_all.py``). The job is
the CLI as a user runs it: ``camtool verify BIG.pic -t pic-mmh --report R.json`` in a
subprocess (``sys.executable -m camtool``, PYTHONPATH the tree's root), timed wall-clock,
its peak memory taken from ``RUSAGE_CHILDREN`` of a small runner process spawned for that
one measurement. BIG.pic is written deterministically to a temporary directory: a
pic-mmh program (UNAM-GMM's fixed-width µm dialect) of :data:`LINES` long lines zig-zagging
across the 10 × 7 mm work area, 13.2 M motor steps (x 12 860 771, y 361 911) and 13.2 M
trace rows, over the 3 M rows above which the error budget is skipped (as it is for a
user's big program). pic-mmh because its controller's line is the UNAM-GMM A.3 DDA, the
loop the C peer runs: the C peer is ``tests/benchmarks/c/dda.c`` (``cc -O2``, compiled at
run time) on the same lines in steps, and the ratio is camtool's whole-verify steps/s over
the C DDA loop's steps/s. The demo logo (``samples/logo.dxf`` posted to pic-mmh, as
``make demo``) is verified too (time only).

Three rows first (:func:`budget_rows`): ``camtool verify`` with the error budget against
``--no-budget`` on 40 of these lines (2.58 M steps, under the budget's 3 M rows) without
backlash (``--machine`` overlay: one source, the interpolation) and with the profile's (two
sources), and on one contour of 40 half circles (:func:`arcs_program`, 2.45 M rows, no
backlash). The goal: with the budget, at most 1.5 times the wall and CPU time of
``--no-budget`` and at most 250 MB, the larger of the largest process's peak and the
peak of the whole process tree's summed proportional set size (:func:`tree_pss`, one
more untimed run: the error budget may re-simulate its sources in forked workers, whose
memory the largest process's peak leaves out).

Set ``CAMTOOL_BENCH_BASE=/path/to/old/tree`` to run the same two jobs on another tree
(e.g. the code before issue 17) in the same run: its times and memory are printed, and
the reports must be byte-identical (the row notes it).

A second row verifies a program of :data:`BIG_LINES` lines (66.2 M steps) on this tree
only (the code before issue 17 would hold ~10 GB), once. The start-up (Python, camtool,
scipy, shapely and numba's cached kernels, :data:`STARTUP`) is measured on its own, and
each row's note gives the time per step after it.

The rows' ratio is issue 44's: camtool's steps/s after the start-up (the whole run's time
less :data:`STARTUP`'s) over the C loop's; the note gives the whole run's too.

Measurements: docs/performance.md (this script's rows, and its earlier notes).
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(HERE))

from bench_interpolators import cc_version, compiler  # noqa: E402
from table import camtool_env, row  # noqa: E402

LINES = int(os.environ.get("CAMTOOL_BENCH_LINES", "200"))
"""Long lines of the big program (``CAMTOOL_BENCH_LINES`` to change; 200 ≈ 13.2 M steps)."""
BIG_LINES = int(os.environ.get("CAMTOOL_BENCH_BIG_LINES", "1000"))
"""Lines of the second, bigger program (1000 ≈ 66 M steps; 0 leaves that row out)."""
REPEATS = 2
"""Runs of each CLI job (the best wall time is kept; memory is the largest)."""
SPM = 1e6 / 140.0
"""pic-mmh steps/mm (140 nm/step, UNAM-GMM S000-12)."""

RUNNER = """
import resource, subprocess, sys, time
start = time.perf_counter()
rc = subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL).returncode
wall = time.perf_counter() - start
use = resource.getrusage(resource.RUSAGE_CHILDREN)
print(wall, rc, use.ru_maxrss, use.ru_utime + use.ru_stime)
"""


def big_program(lines: int) -> tuple[str, list[tuple[int, int]]]:
    """The big pic-mmh program and its line moves in steps (for the C peer).

    Zig-zag lines from x = 0.5 mm to 9.5 mm and back, each 0.137 mm higher (modulo 6 mm),
    F08 (0.8 mm/min, UNAM-GMM's own example feed).
    """
    out = ["G54;", "G90;", "G00X00500.00Y00500.00;"]
    moves: list[tuple[int, int]] = []
    x0, y0 = 500, 500
    for k in range(lines):
        y = 500 + (k * 137) % 6000
        x = 9500 if k % 2 == 0 else 500
        out.append(f"G01X{x:08.2f}Y{y:08.2f}F08;")
        moves.append((_steps(x) - _steps(x0), _steps(y) - _steps(y0)))
        x0, y0 = x, y
    return "\n".join(out) + "\n", moves


def arcs_program(half_circles: int, radius_um: float = 3000.0) -> str:
    """One contour of ``half_circles`` clockwise half circles round (5, 3.5) mm, F08.

    A circle cut again and again (a hole in many passes): UNAM-GMM's direct-search arcs,
    2.45 M rows for 40 half circles of 3 mm, its diameter fitted over every row.
    """
    cx, cy = 5000.0, 3500.0
    out = ["G54;", "G90;", f"G00X{cx - radius_um:08.2f}Y{cy:08.2f};"]
    for k in range(half_circles):
        x = cx + radius_um if k % 2 == 0 else cx - radius_um
        out.append(f"G02X{x:08.2f}Y{cy:08.2f}I{cx:08.2f}J{cy:08.2f}F08;")
    return "\n".join(out) + "\n"


NO_BACKLASH = """[machine.backlash]
true_um = [0.0, 0.0, 0.0]
compensation_um = [0.0, 0.0, 0.0]
regions = []
"""
"""A ``--machine`` overlay without backlash: the budget's one source is the interpolation."""
BUDGET_LINES = 40
"""Lines of the budget rows' program (40: 2.58 M steps, under the budget's 3 M rows)."""


PSS_RUNNER = """
import glob, subprocess, sys, time
child = subprocess.Popen(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
def tree(pid):
    found = [pid]
    for name in glob.glob(f"/proc/{pid}/task/*/children"):
        try:
            with open(name) as f:
                kids = f.read().split()
        except OSError:
            continue
        for kid in kids:
            found += tree(int(kid))
    return found
peak = 0
while child.poll() is None:
    total = 0
    for pid in tree(child.pid):
        try:
            with open(f"/proc/{pid}/smaps_rollup") as f:
                total += sum(int(line.split()[1]) for line in f if line.startswith("Pss:"))
        except OSError:
            pass
    peak = max(peak, total)
    time.sleep(0.01)
print(child.returncode, peak)
"""
"""Runs ``ARGS`` and prints the exit code and the largest sum of its process tree's
proportional set sizes (KiB, ``Pss`` of ``/proc/PID/smaps_rollup`` every 10 ms: pages a
fork shares counted once, a forked worker's own counted): ``0`` without ``/proc``."""


def tree_pss(tree: Path, args: list[str]) -> float | None:
    """The peak memory of ``camtool ARGS``'s whole process tree (MB, :data:`PSS_RUNNER`).

    An untimed run (the sampling costs CPU): ``RUSAGE_CHILDREN``'s peak is the largest one
    process's, which leaves out workers forked beside it. ``None`` where there is no
    ``/proc`` to read.
    """
    out = subprocess.run(
        [sys.executable, "-c", PSS_RUNNER, sys.executable, "-m", "camtool", *args],
        capture_output=True,
        text=True,
        env=camtool_env(tree, PYCACHE),
        cwd=tree,
        check=True,
    )
    kib = int(out.stdout.split()[1])
    return kib / 1024.0 if kib else None


def budget_rows(tmp: Path, base: str | None) -> None:
    """The error budget on against ``--no-budget``: wall and CPU ratio and peak, three programs.

    40 of the big program's lines without backlash (one source, the interpolation), the
    same with the profile's backlash (two sources), and 40 half circles without backlash.
    With ``base``, the same jobs on that tree: its figures in the note, reports compared.
    """
    (tmp / "lines.pic").write_text(big_program(BUDGET_LINES)[0])
    (tmp / "arcs.pic").write_text(arcs_program(40))
    (tmp / "no-backlash.toml").write_text(NO_BACKLASH)
    jobs = [
        ("40 DDA lines, no backlash (1 source)", "lines.pic", True),
        ("40 DDA lines, the profile's backlash (2 sources)", "lines.pic", False),
        ("40 half circles, no backlash (1 source)", "arcs.pic", True),
    ]
    trees = {"after": ROOT} | ({"before": Path(base)} if base else {})
    for job, name, bare in jobs:
        args = ["verify", str(tmp / name), "-t", "pic-mmh"]
        if bare:
            args += ["--machine", str(tmp / "no-backlash.toml")]
        got = {}
        for label, tree in trees.items():
            report = tmp / f"budget-{label}-{name}.json"
            warm(tree, [*args, "--report", str(report)])  # numba's cache of the budget's kernels
            warm(tree, [*args, "--no-budget"])
            on = measure_cpu(tree, [*args, "--report", str(report)])
            off = measure_cpu(tree, [*args, "--no-budget"])
            got[label] = (on, off, report, tree_pss(tree, [*args, "--report", str(report)]))
        (wall, rc, rss, cpu), (off_wall, _rc, off_rss, off_cpu), report, pss = got["after"]
        ratio = max(wall / off_wall, cpu / off_cpu)
        whole = "n/a" if pss is None else f"{pss:.0f} MB"
        note = (
            f"exit {rc}; budget on {wall:.2f} s, {cpu:.2f} s CPU, {rss:.0f} MB (the process "
            f"tree's summed Pss {whole}); --no-budget {off_wall:.2f} s, {off_cpu:.2f} s CPU, "
            f"{off_rss:.0f} MB; wall {wall / off_wall:.2f}x, CPU {cpu / off_cpu:.2f}x"
        )
        memory = max(rss, pss or 0.0)
        met = rc == 0 and ratio <= 1.5 and memory <= 250.0
        if base:
            (bwall, _brc, brss, bcpu), (bo_wall, _b, bo_rss, bo_cpu), breport, bpss = got["before"]
            same = breport.read_bytes() == report.read_bytes()
            met = met and same
            bwhole = "n/a" if bpss is None else f"{bpss:.0f} MB"
            note += (
                f"; before ({base}): on {bwall:.2f} s, {bcpu:.2f} s CPU, {brss:.0f} MB "
                f"(tree {bwhole}), off "
                f"{bo_wall:.2f} s, {bo_cpu:.2f} s CPU, {bo_rss:.0f} MB; reports "
                + ("identical" if same else "DIFFER")
            )
        row(
            f"camtool verify with the error budget, {job} (CLI)",
            f"{wall:.2f} s, {cpu:.2f} s CPU, {memory:.0f} MB",
            "the same with --no-budget",
            f"{off_wall:.2f} s, {off_cpu:.2f} s CPU",
            ratio,
            "time",
            "≤ 1.5× (wall and CPU), ≤ 250 MB",
            met,
            note,
        )


def _steps(um: int) -> int:
    """µm → pic-mmh steps, rounded half up (the profile's ``rounding``)."""
    return int(um / 1000.0 * SPM + 0.5)


PYCACHE = Path(tempfile.gettempdir()) / "camtool-bench-verify-pycache"
"""Where the runs' bytecode is cached (``PYTHONPYCACHEPREFIX``; :func:`table.camtool_env`)."""


def warm(tree: Path, args: list[str]) -> None:
    """One untimed run of ``camtool ARGS`` in ``tree``: the bytecode it needs is written.

    Run with the arguments that are then timed: a kernel the timed runs need that numba
    has not cached is compiled in the first of them, which then holds LLVM's memory
    (more peak memory than the runs after it).
    """
    subprocess.run(
        [sys.executable, "-m", "camtool", *args],
        env=camtool_env(tree, PYCACHE),
        cwd=tree,
        capture_output=True,
        check=False,
    )


def measure(tree: Path, args: list[str], repeats: int = REPEATS) -> tuple[float, int, float]:
    """Best wall time (s), exit code and largest peak RSS (MB) of ``camtool ARGS`` in ``tree``."""
    wall, rc, rss, _cpu = measure_cpu(tree, args, repeats)
    return wall, rc, rss


def measure_cpu(
    tree: Path, args: list[str], repeats: int = REPEATS
) -> tuple[float, int, float, float]:
    """:func:`measure` and the best CPU time (user + sys, s, helpers included)."""
    env = camtool_env(tree, PYCACHE)
    best, rss, rc, cpu = float("inf"), 0.0, 0, float("inf")
    for _ in range(repeats):
        out = subprocess.run(
            [sys.executable, "-c", RUNNER, sys.executable, "-m", "camtool", *args],
            capture_output=True,
            text=True,
            env=env,
            cwd=tree,
            check=True,
        )
        wall, code, kib, used = out.stdout.split()
        best, rc, rss = min(best, float(wall)), int(code), max(rss, int(kib) / 1024.0)
        cpu = min(cpu, float(used))
    return best, rc, rss, cpu


def c_dda_rate(moves: list[tuple[int, int]], tmp: Path) -> tuple[float, str] | None:
    """Motor steps per second of the C A.3 loop on ``moves`` (best of 3), and the compiler."""
    cc = compiler()
    if cc is None:
        return None
    exe = tmp / "dda"
    subprocess.run([cc, "-O2", "-o", str(exe), str(HERE / "c" / "dda.c"), "-lm"], check=True)
    data = tmp / "lines.txt"
    data.write_text("".join(f"{dx} {dy}\n" for dx, dy in moves))
    out = subprocess.run([str(exe), str(data), "3"], capture_output=True, text=True, check=True)
    _it, pulses, _sum, secs = out.stdout.split()
    return int(pulses) / float(secs), cc_version(cc)


STARTUP = """
import time
t0 = time.perf_counter()
import numpy as np
import camtool.cli.main, camtool.verify.verifier, scipy.spatial, shapely
from camtool.verify.dda import compiled, dda_line
k = compiled()
dda_line(3, 2)
k.play_runs(np.zeros((2, 2), np.int8), 0, 0)
k.play_axis_from(np.zeros((2, 2), np.int8), 0, np.zeros(0, np.int64), np.zeros(0, np.int8),
                 np.zeros(0), np.zeros(5), 0, 0.0, 1.0, np.zeros((2, 2)))
k.exact_sum_squares(np.zeros(2), np.zeros(k.EXACT_BINS, np.int64))
k.extent(np.zeros((2, 2)))
k.to_line(np.zeros((2, 2)), 0.0, 0.0, 1.0, 0.0, np.zeros(2))
print(time.perf_counter() - t0)
"""
"""The fixed start-up of a streamed verify: Python, camtool, scipy, shapely, numba's kernels."""


def startup_s(tree: Path) -> float:
    """Best wall time (s) of :data:`STARTUP` (the interpreter's own start added) in ``tree``."""
    env = camtool_env(tree, PYCACHE)
    best = float("inf")
    for _ in range(REPEATS):
        t0 = time.perf_counter()
        subprocess.run(
            [sys.executable, "-c", STARTUP], env=env, cwd=tree, check=True, capture_output=True
        )
        best = min(best, time.perf_counter() - t0)
    return best


def verify_row(
    tmp: Path, lines: int, base: str | None, start: float, repeats: int = REPEATS
) -> None:
    """Verify the program of ``lines`` lines (and, with ``base``, on that tree too): one row."""
    text, moves = big_program(lines)
    program = tmp / f"big-{lines}.pic"
    program.write_text(text)
    trees = {"after": ROOT} | ({"before": Path(base)} if base else {})
    results = {}
    for label, tree in trees.items():
        report = tmp / f"{label}-{lines}.json"
        args = ["verify", str(program), "-t", "pic-mmh", "--report", str(report)]
        warm(tree, args)  # every kernel this program needs is in numba's cache, not compiled
        results[label] = (*measure(tree, args, repeats), report)
    wall, rc, rss, report = results["after"]
    data = json.loads(report.read_text()) if rc == 0 else {}
    steps = sum(data.get("steps", {}).values())
    rate = steps / wall if wall else 0.0
    per_step = (wall - start) / steps * 1e9 if steps else 0.0
    note = (
        f"{lines} lines, {steps:,} steps, {data.get('iterations', 0):,} iterations; "
        f"exit {rc}; budget: {data.get('error_budget', {}).get('skipped', '—')}; "
        f"start-up {start:.2f} s, then {per_step:.0f} ns a step "
        f"({steps / max(wall - start, 1e-9) / 1e6:.1f} M steps/s without the start-up)"
    )
    if base:
        bwall, brc, brss, breport = results["before"]
        same = brc == rc and breport.read_bytes() == report.read_bytes()
        note += (
            f"; before ({base}): {bwall:.2f} s, {brss:.0f} MB, "
            f"{steps / bwall / 1e6:.2f} M steps/s; reports " + ("identical" if same else "DIFFER")
        )
    peer = c_dda_rate(moves, tmp)
    camtool = f"{wall:.2f} s, {rate / 1e6:.2f} M steps/s, {rss:.0f} MB"
    job = f"camtool verify of a {steps / 1e6:.1f} M-step pic-mmh program (CLI)"
    if peer is None:
        row(
            job,
            camtool,
            "C cc -O2: not installed (apt-get install gcc)",
            "—",
            None,
            "speed",
            "≥ 0.05×, < 250 MB",
            False,
            note,
        )
        return
    c_rate, version = peer
    # issue 44's rule: the steps/s after the start-up, against the C loop's
    after = steps / max(wall - start, 1e-9)
    ratio = after / c_rate
    note += f"; with the start-up {rate / c_rate:.3f}× C"
    row(
        job,
        f"{camtool}; {after / 1e6:.1f} M steps/s after the start-up",
        f"C {version} -O2, A.3 loop on the same lines",
        f"{c_rate / 1e6:.0f} M steps/s",
        ratio,
        "speed",
        "≥ 0.05× after the start-up, < 250 MB",
        rc == 0 and ratio >= 0.05 and rss < 250.0,
        note,
    )


def main() -> None:
    """Run the jobs and print their rows."""
    t0 = time.perf_counter()
    base = os.environ.get("CAMTOOL_BENCH_BASE")
    with tempfile.TemporaryDirectory(prefix="camtool-bench-verify-") as name:
        tmp = Path(name)
        (tmp / "warm.pic").write_text(big_program(60)[0])  # streamed: every module it needs
        warm(ROOT, ["verify", str(tmp / "warm.pic"), "-t", "pic-mmh"])
        start = startup_s(ROOT)
        budget_rows(tmp, base)
        verify_row(tmp, LINES, base, start)
        if BIG_LINES:  # not on the tree before issue 17: it would hold ~10 GB
            verify_row(tmp, BIG_LINES, None, start)

        logo = tmp / "logo.pic"
        logo_args = [
            "post",
            str(ROOT / "samples" / "logo.dxf"),
            "--target",
            "pic-mmh",
            "-o",
            str(logo),
            "--verify",
            "--report",
            str(tmp / "logo-after.json"),
        ]
        warm(ROOT, logo_args)
        lwall, lrc, lrss = measure(ROOT, logo_args)
        lnote = f"exit {lrc}; most of the time is planning, along_path and the error budget"
        met = lrc == 0
        if base:
            logo_args[-1] = str(tmp / "logo-before.json")
            warm(Path(base), logo_args)
            bwall, _brc, brss = measure(Path(base), logo_args)
            same = (tmp / "logo-before.json").read_bytes() == (tmp / "logo-after.json").read_bytes()
            met = met and same and lrss <= brss * 1.05
            lnote += f"; before: {bwall:.2f} s, {brss:.0f} MB; reports " + (
                "identical" if same else "DIFFER"
            )
        row(
            "post --verify of samples/logo.dxf on pic-mmh (make demo), CLI",
            f"{lwall:.2f} s, {lrss:.0f} MB",
            "—",
            "—",
            None,
            "absolute",
            "no numba start-up, no more memory; report identical",
            met,
            lnote,
        )
    print(f"bench_verify: {time.perf_counter() - t0:.1f} s", file=sys.stderr)
    shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
