"""Run every benchmark and print one table of ratios against the named peers (``make bench``).

Run as ``python tests/benchmarks/run_all.py [--only NAME ...] [--json FILE]``. Every
``tests/benchmarks/bench_*.py`` is run in turn, alone (the machine should be otherwise
quiet: two jobs at once on a 2-core machine distort both), with this interpreter. Their
own output goes to stderr as it comes; the result lines they print through
:func:`table.row` are collected, and at the end one Markdown table is printed on stdout,
headed by the machine's core count and Python version. A script that fails is listed
with its exit code and makes the run exit 1; a goal not met is marked in the table but
does not fail the run (the table is the report).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from table import PREFIX  # noqa: E402


def _run(script: Path) -> tuple[list[dict[str, object]], int, float]:
    """Run one script; forward its output to stderr and return its rows, exit code, time."""
    start = time.perf_counter()
    rows: list[dict[str, object]] = []
    with subprocess.Popen(
        [sys.executable, str(script)],
        stdout=subprocess.PIPE,
        text=True,
        encoding="utf-8",
        env={**os.environ, "PYTHONUNBUFFERED": "1"},
    ) as proc:
        assert proc.stdout is not None
        for line in proc.stdout:
            if line.startswith(PREFIX):
                rows.append(json.loads(line[len(PREFIX) :]))
            sys.stderr.write(line)
            sys.stderr.flush()
    return rows, proc.returncode, time.perf_counter() - start


def _ratio(record: dict[str, object]) -> str:
    ratio = record.get("ratio")
    if ratio is None:
        return "—"
    assert isinstance(ratio, (int, float))
    return f"{ratio:.3g}×"


def table(rows: list[dict[str, object]]) -> str:
    """The collected rows as one Markdown table."""
    head = "| job | camtool | peer | peer's figure | ratio | goal | met | note |"
    lines = [head, "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        met = "yes" if r.get("met") else "**no**"
        cells = (r["job"], r["camtool"], r["peer"], r["peer_value"], _ratio(r), r["goal"], met)
        lines.append("| " + " | ".join(str(c) for c in cells) + f" | {r.get('note', '')} |")
    return "\n".join(lines)


def main() -> int:
    """Run the benchmarks, print the table; exit 1 when a script failed."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--only", nargs="*", default=None, help="script names (bench_X or X)")
    parser.add_argument("--json", type=Path, default=None, help="also write the rows as JSON")
    args = parser.parse_args()
    scripts = sorted(HERE.glob("bench_*.py"))
    if args.only:
        wanted = {n if n.startswith("bench_") else f"bench_{n}" for n in args.only}
        wanted = {n.removesuffix(".py") for n in wanted}
        scripts = [s for s in scripts if s.stem in wanted]
    rows: list[dict[str, object]] = []
    failed: list[str] = []
    for script in scripts:
        sys.stderr.write(f"== {script.name}\n")
        got, code, secs = _run(script)
        sys.stderr.write(f"== {script.name}: exit {code}, {secs:.1f} s\n")
        rows.extend(got)
        if code != 0:
            failed.append(f"{script.name} (exit {code})")
    cores = len(os.sched_getaffinity(0))
    print(f"camtool benchmarks — nproc {cores}, Python {platform.python_version()}")
    print()
    print(table(rows))
    for name in failed:
        print(f"\nfailed: {name}")
    if args.json is not None:
        args.json.write_text(json.dumps(rows, indent=1, ensure_ascii=False) + "\n")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
