"""Benchmark of ``camtool batch`` on a process pool and on Dask (not collected by pytest).

Run as ``python tests/benchmarks/bench_batch_dask.py [N] [--target T] [--verify]``
(default: 1 000 files for grbl, posted without verification). The batch is the first
N DXF files of the real-drawing corpus (LibreCAD's parts library, ``make corpus``),
linked into ``$TMPDIR/camtool-bench-batch/in/`` with their folders; without the corpus,
the bundled samples tiled N times. It is posted twice, as the library runs it:

- ``--jobs 2``: the process pool;
- ``--scheduler local:2``: a ``LocalCluster`` of 2 worker processes; the cluster's
  start is timed apart from the batch, which gets the client.

Both write every output, and the two output trees are compared byte for byte. On a
shared machine the times vary with the load: ``--repeat K`` alternates the two K
times (the cluster kept) and keeps the best of each. The
cost per file of going through Dask is the difference of the two batch times over
N (the client reads each input and ships its bytes, the scheduler sends the task,
the worker returns the outputs' bytes, the client writes them), and the ratio of the
two times.

Measurements: docs/performance.md (this script's rows, and its earlier notes).
"""

from __future__ import annotations

import argparse
import os
import shutil
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from camtool.jobs.batch import run
from camtool.jobs.batch_dask import connect
from camtool.jobs.batch_plan import BatchResult

sys.path.insert(0, str(Path(__file__).resolve().parent))
from table import row

ROOT = Path(__file__).resolve().parents[2]
CORPUS = Path(os.environ.get("CAMTOOL_CORPUS_DIR", ROOT / ".corpus"))
LIBRARY = CORPUS / "pkg/librecad-data/usr/share/librecad/library"
SAMPLES = ("logo.dxf", "plate.dxf", "pocket.dxf")


def inputs(n: int, folder: Path) -> str:
    """``n`` drawings below ``folder`` (links to corpus files, else copies of samples)."""
    shutil.rmtree(folder, ignore_errors=True)
    folder.mkdir(parents=True)
    found = sorted(LIBRARY.rglob("*.dxf"))[:n] if LIBRARY.is_dir() else []
    if len(found) == n:
        for path in found:
            link = folder / path.relative_to(LIBRARY)
            link.parent.mkdir(parents=True, exist_ok=True)
            link.symlink_to(path)
        return f"{n} LibreCAD DXF files of the corpus"
    for i in range(n):
        name = SAMPLES[i % len(SAMPLES)]
        shutil.copy(ROOT / "samples" / name, folder / f"{i:04}-{name}")
    return f"the samples {', '.join(SAMPLES)} tiled to {n} files (no corpus at {CORPUS})"


def tree(folder: Path) -> dict[str, bytes]:
    """Every file below ``folder`` by its relative path, with its bytes."""
    return {str(p.relative_to(folder)): p.read_bytes() for p in folder.rglob("*") if p.is_file()}


def timed(label: str, batch: Callable[[], BatchResult]) -> tuple[float, BatchResult]:
    """Wall seconds of ``batch()`` and its result."""
    start = time.perf_counter()
    result = batch()
    seconds = time.perf_counter() - start
    print(f"{label:<36} {seconds:8.2f} s  {result.exit_code=}", flush=True)
    return seconds, result


def main() -> None:
    """Post the batch both ways and print the times, the cost per file and the ratio."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("n", nargs="?", type=int, default=1000)
    parser.add_argument("--target", default="grbl")
    parser.add_argument("--verify", action="store_true")
    parser.add_argument("--repeat", type=int, default=1, help="alternate runs, keep the best")
    args = parser.parse_args()
    work = Path(tempfile.gettempdir()) / "camtool-bench-batch"
    what = inputs(args.n, work / "in")
    print(f"{what}, target {args.target}, verify {args.verify}, best of {args.repeat}")
    options = {"targets": args.target, "verify": args.verify, "force": True}
    pool_s = dask_s = started_s = float("inf")
    start = time.perf_counter()
    with connect("local:2") as client:
        started_s = time.perf_counter() - start
        print(f"{'LocalCluster(2) start':<36} {started_s:8.2f} s", flush=True)
        for _ in range(args.repeat):
            seconds, pool = timed(
                "--jobs 2",
                lambda: run([str(work / "in")], output_dir=work / "pool", jobs=2, **options),
            )
            pool_s = min(pool_s, seconds)
            seconds, dask = timed(
                "--scheduler local:2 (started)",
                lambda: run([str(work / "in")], output_dir=work / "dask", client=client, **options),
            )
            dask_s = min(dask_s, seconds)
    same = tree(work / "pool") == tree(work / "dask")
    same = same and [r.error for r in pool.rows] == [r.error for r in dask.rows]
    ok = sum(row.status == "ok" for row in dask.rows)
    print(f"outputs identical: {same}; {ok} of {len(dask.rows)} files ok")
    per_file_ms = 1000.0 * (dask_s - pool_s) / args.n
    print(f"per file: pool {1000 * pool_s / args.n:.1f} ms, dask {1000 * dask_s / args.n:.1f} ms")
    print(f"cost of Dask per file: {per_file_ms:+.1f} ms; dask / pool = {dask_s / pool_s:.2f}")
    print(f"with the cluster's start: dask / pool = {(dask_s + started_s) / pool_s:.2f}")
    import dask

    row(
        f"`batch --scheduler local:2` of {args.n} files → {args.target} (library)",
        f"{dask_s:.1f} s",
        f"camtool's own process pool (--jobs 2); dask {dask.__version__}",
        f"{pool_s:.1f} s",
        dask_s / pool_s,
        "time",
        "— (cost of Dask)",
        same,
        f"{per_file_ms:+.1f} ms a file; cluster start {started_s:.1f} s; "
        f"outputs {'identical' if same else 'DIFFER'}",
    )


if __name__ == "__main__":
    main()
