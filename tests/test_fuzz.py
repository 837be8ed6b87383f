"""A seeded fuzz test of `camtool post`: mutated inputs and hostile option values.

The inputs are the bundled drawings and programs (samples/, tests/data/), mutated by a
seeded loop: byte flips, truncation, numbers replaced by nan/inf/1e308/-0/huge values,
duplicated lines and deleted sections. Hostile options (``--tool-diameter nan``,
``--step-down 1e-9``, ``--fit inf inf``...) are given to good inputs. Each case runs
``camtool.cli.main.main`` in a forked child (so a hang or a crash is contained) and must:

- answer within CPU_S seconds of CPU time (a refusal is an answer; an endless loop is the bug);
- exit 0, 2 or 3 — or 1 for a planning or dialect error of a drawing that is still valid
  (a flipped digit may move it out of the work area) — with no "internal error" and no
  traceback, and never 1 for a non-finite value (nan/inf must be refused where it enters,
  STYLE 17, as a usage (2) or input (3) error);
- leave no output file and no stray temporary file when the exit is not 0;
- when the exit is 0, have written a program that the target's own reader reads back
  (``load_target(name).post.parse(code)``) and that holds no nan/inf number.

``CAMTOOL_FUZZ_SEED`` and ``CAMTOOL_FUZZ_MUTANTS`` (mutants per input, default 4) change the
run; failures print the exact command and, for a mutant, where its input was written.
"""

from __future__ import annotations

import contextlib
import io
import multiprocessing
import multiprocessing.connection
import os
import random
import re
import resource
import signal
from dataclasses import dataclass
from pathlib import Path

import pytest

from camtool.cli.main import main
from camtool.post.registry import load_target
from tests.targets import EXTENSIONS, TARGETS

ROOT = Path(__file__).resolve().parents[1]
SEED = int(os.environ.get("CAMTOOL_FUZZ_SEED", "20251121"))
MUTANTS = int(os.environ.get("CAMTOOL_FUZZ_MUTANTS", "4"))
CPU_S = 20  # a case may use this much CPU time: a refusal is quick, an endless loop is not
WALL_S = 300.0  # backstop for a child that sleeps or deadlocks (CPU time does not grow)
FAILURES = ROOT / ".corpus" / "fuzz-failures"  # failing mutants are kept here (git-ignored)
INPUT_SUFFIXES = {".dxf", ".svg", ".csv", ".nc", ".ngc", ".tap", ".m"}
HOSTILE_NUMBERS = [
    "nan", "NaN", "inf", "-inf", "1e308", "-1e308", "1e400", "-0", "-0.0", "0",
    "1e-320", "99999999999999999999999", "-99999999999",
]  # fmt: skip
NUMBER = re.compile(rb"-?\d+\.?\d*(?:[eE][-+]?\d+)?")
NON_FINITE = re.compile(r"(?<![a-z])[-+]?(nan|inf|infinity)(?![a-z])", re.IGNORECASE)


def base_inputs() -> list[Path]:
    """The bundled drawings and programs the mutants start from, sorted."""
    found = [*(ROOT / "samples").iterdir(), *(ROOT / "tests" / "data").iterdir()]
    return sorted(p for p in found if p.suffix in INPUT_SUFFIXES)


def mutate(data: bytes, rng: random.Random) -> tuple[str, bytes]:
    """One random mutation of DATA: (its name, the mutated bytes)."""
    lines = data.splitlines(keepends=True) or [data]
    kind = rng.choice(["flip", "truncate", "number", "number", "duplicate", "delete"])
    if kind == "flip":
        buf = bytearray(data)
        for _ in range(rng.randint(1, 6)):
            i = rng.randrange(len(buf))
            buf[i] ^= rng.randint(1, 255)
        return kind, bytes(buf)
    if kind == "truncate":
        return kind, data[: rng.randrange(len(data))]
    if kind == "number":
        spans = [m.span() for m in NUMBER.finditer(data)]
        out = data
        for start, end in sorted(rng.sample(spans, min(len(spans), rng.randint(1, 3))))[::-1]:
            out = out[:start] + rng.choice(HOSTILE_NUMBERS).encode() + out[end:]
        return kind, out
    i = rng.randrange(len(lines))
    j = min(len(lines), i + rng.randint(1, max(1, len(lines) // 4)))
    if kind == "duplicate":
        return kind, b"".join(lines[:j] + lines[i:j] + lines[j:])
    return kind, b"".join(lines[:i] + lines[j:])


@dataclass(frozen=True)
class Case:
    """One fuzz case: an input (a file, or mutated bytes), a target and options."""

    name: str
    source: Path
    target: str
    options: tuple[str, ...] = ()
    data: bytes | None = None  # the mutated input; None: the source as it is


def mutant_cases() -> list[Case]:
    """MUTANTS seeded mutants of every base input, targets taken in turn."""
    rng = random.Random(SEED)
    cases = []
    for src in base_inputs():
        data = src.read_bytes()
        for n in range(MUTANTS):
            kind, mutant = mutate(data, rng)
            target = TARGETS[len(cases) % len(TARGETS)]
            cases.append(Case(f"{src.name}-{n}-{kind}-{target}", src, target, (), mutant))
    return cases


PLATE = ROOT / "samples" / "plate.dxf"
POCKET = ROOT / "samples" / "pocket.dxf"
LOGO = ROOT / "samples" / "logo.dxf"
OUTSIDE = ("--offset", "outside", "--tool-diameter", "1")
HOSTILE_OPTIONS: list[tuple[Path, str, tuple[str, ...]]] = [
    (PLATE, "grbl", ("--offset", "outside", "--tool-diameter", "nan")),
    (PLATE, "grbl", ("--offset", "outside", "--tool-diameter", "inf")),
    (PLATE, "grbl", ("--offset", "outside", "--tool-diameter", "-3")),
    (PLATE, "grbl", ("--offset", "outside", "--tool-diameter", "1e308")),
    (PLATE, "grbl", ("--offset", "inside", "--tool-diameter", "0")),
    (PLATE, "grbl", (*OUTSIDE, "--depth", "1", "--step-down", "1e-9")),
    (PLATE, "linuxcnc", (*OUTSIDE, "--depth", "nan")),
    (PLATE, "linuxcnc", (*OUTSIDE, "--depth", "inf", "--step-down", "1")),
    (PLATE, "linuxcnc", (*OUTSIDE, "--depth", "-2")),
    (PLATE, "grbl", (*OUTSIDE, "--depth", "1", "--safe-z", "nan")),
    (PLATE, "grbl", (*OUTSIDE, "--depth", "1", "--safe-z", "-5")),
    (PLATE, "grbl", (*OUTSIDE, "--depth", "3", "--tabs", "100000")),
    (PLATE, "grbl", (*OUTSIDE, "--depth", "3", "--tabs", "2", "--tab-width", "inf")),
    (PLATE, "grbl", (*OUTSIDE, "--depth", "3", "--tabs", "2", "--tab-height", "nan")),
    (PLATE, "grbl", (*OUTSIDE, "--depth", "3", "--ramp", "0")),
    (PLATE, "grbl", (*OUTSIDE, "--depth", "3", "--ramp", "nan")),
    (PLATE, "grbl", (*OUTSIDE, "--depth", "3", "--plunge-feed", "0")),
    (PLATE, "grbl", (*OUTSIDE, "--lead-in", "1e308")),
    (PLATE, "grbl", (*OUTSIDE, "--lead-in", "nan")),
    (POCKET, "grbl", ("--offset", "pocket", "--tool-diameter", "2", "--stepover", "1e-9")),
    (POCKET, "grbl", ("--offset", "pocket", "--tool-diameter", "2", "--stepover", "nan")),
    (POCKET, "grbl", ("--offset", "pocket", "--tool-diameter", "2", "--pocket-angle", "inf")),
    (POCKET, "linuxcnc", ("--offset", "pocket", "--tool-diameter", "1e-9")),
    (LOGO, "pic-mmh", ("--fit", "inf", "inf")),
    (LOGO, "pic-mmh", ("--fit", "nan", "7")),
    (LOGO, "pic-mmh", ("--fit", "0", "0")),
    (LOGO, "pic-mmh", ("--fit", "-10", "7")),
    (LOGO, "pic-mmh", ("--fit", "1e-300", "1e-300")),
    (LOGO, "grbl", ("--scale", "nan")),
    (LOGO, "grbl", ("--scale", "inf")),
    (LOGO, "grbl", ("--scale", "0")),
    (LOGO, "grbl", ("--scale", "-1")),
    (LOGO, "grbl", ("--scale", "1e-300")),
    (LOGO, "i8751", ("--scale", "1e308")),
    (LOGO, "grbl", ("--feed", "nan")),
    (LOGO, "grbl", ("--feed", "inf")),
    (LOGO, "pic-mmh", ("--feed", "0")),
    (LOGO, "valcnc", ("--feed", "-5")),
    (LOGO, "matlab-router", ("--feed", "1e308")),
    (LOGO, "grbl", ("--tolerance", "nan")),
    (LOGO, "grbl", ("--tolerance", "1e308")),
    (LOGO, "flashcut", ("--tolerance", "0")),
    (LOGO, "grbl", ("--close-gap", "inf")),
    (LOGO, "grbl", ("--spindle-rpm", "inf")),
    (LOGO, "grbl", ("--spindle-rpm", "nan")),
    (LOGO, "pic-mmh", ("--max-error-um", "nan")),
    (LOGO, "grbl", ("--units", "px", "--scale", "1e9")),
]


def option_cases() -> list[Case]:
    """Good inputs with the hostile option values above."""
    return [
        Case(f"{src.name}-{target}-{' '.join(opts)}", src, target, opts)
        for src, target, opts in HOSTILE_OPTIONS
    ]


def _child(args: list[str], conn: multiprocessing.connection.Connection) -> None:
    used = int(sum(os.times()[:2]))
    resource.setrlimit(resource.RLIMIT_CPU, (used + CPU_S, used + CPU_S + 5))
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        rc = main(args)
    conn.send((rc, err.getvalue()))


def run_forked(args: list[str]) -> tuple[int | None, str]:
    """(exit code, stderr) of ``camtool.cli.main.main(ARGS)`` in a forked child; None: no answer.

    The child may use CPU_S seconds of CPU (RLIMIT_CPU: the kernel stops it with SIGXCPU),
    which a loaded machine does not shorten as it would a wall-clock timeout.
    """
    ctx = multiprocessing.get_context("fork")
    parent, child = ctx.Pipe(duplex=False)
    proc = ctx.Process(target=_child, args=(args, child))
    proc.start()
    child.close()
    answer: tuple[int | None, str] = (None, f"no answer within {WALL_S:g} s (wall clock)")
    if parent.poll(WALL_S):
        try:
            answer = parent.recv()
        except EOFError:
            answer = (None, f"the process died (exit {proc.exitcode})")
    proc.join(1)
    if proc.is_alive():
        proc.kill()
        proc.join()
    if answer[0] is None and proc.exitcode == -signal.SIGXCPU:
        answer = (None, f"no answer within {CPU_S} s of CPU time (stopped by SIGXCPU)")
    elif answer[0] is None and proc.exitcode not in (0, None):
        answer = (None, f"the process died (exit {proc.exitcode})")
    return answer


def problems_of(case: Case, rc: int | None, stderr: str, outdir: Path, out: Path) -> list[str]:
    """What the run of CASE did wrong (empty when it kept the contract)."""
    if rc is None:
        return [stderr]
    found = []
    if "internal error" in stderr or "Traceback" in stderr:
        found.append("internal error")
    if rc not in (0, 1, 2, 3):
        found.append(f"exit {rc}")
    if rc == 1 and NON_FINITE.search(stderr):
        found.append("exit 1 on a non-finite value: it was not refused where it entered")
    if rc != 0 and "camtool: error:" not in stderr and "Error: Invalid value for" not in stderr:
        # click's own usage message names the option too ("Invalid value for '--feed'")
        found.append(f"exit {rc} without a 'camtool: error:' message")
    others = sorted(p.name for p in outdir.iterdir() if p != out)
    if others:
        found.append(f"stray files {others}")
    if rc != 0 and out.exists():
        found.append(f"exit {rc} but {out.name} was written")
    if rc == 0:
        found += check_program(out, case.target)
    return found


def check_program(out: Path, target: str) -> list[str]:
    """An exit-0 program must exist, read back with the target's reader, hold no nan/inf."""
    if not out.exists() or out.stat().st_size == 0:
        return ["exit 0 without a program"]
    code = out.read_bytes()
    try:
        load_target(target).post.parse(code, source=str(out))
    except Exception as exc:  # the reader failing on its own output is the finding
        return [f"{target}'s reader rejects the program: {type(exc).__name__}: {exc}"]
    if target != "i8751" and NON_FINITE.search(code.decode("utf-8", "replace")):
        return ["the program holds a nan/inf number"]
    return []


CASES = mutant_cases() + option_cases()


@pytest.mark.parametrize("case", CASES, ids=lambda c: c.name)
def test_post_keeps_the_cli_contract_on_hostile_input(case: Case, tmp_path: Path) -> None:
    src = case.source
    if case.data is not None:
        src = tmp_path / "in" / case.source.name
        src.parent.mkdir()
        src.write_bytes(case.data)
    outdir = tmp_path / "out"
    outdir.mkdir()
    out = outdir / f"program{EXTENSIONS[case.target]}"
    args = ["post", str(src), "-t", case.target, "-o", str(out), *case.options]
    rc, stderr = run_forked(args)
    found = problems_of(case, rc, stderr, outdir, out)
    if found and case.data is not None:  # keep the mutant: tmp_path does not last
        kept = FAILURES / f"{case.name}{case.source.suffix}"
        kept.parent.mkdir(parents=True, exist_ok=True)
        kept.write_bytes(case.data)
        args[1] = str(kept)
    assert not found, (
        f"camtool {' '.join(args)}\n  (seed {SEED}; exit {rc})\n  "
        + "\n  ".join(found)
        + f"\n  stderr: {stderr.strip()[-400:]}"
    )
