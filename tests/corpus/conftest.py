"""The corpus harness: post a third-party drawing as a new user would, follow the remedy.

Shared by test_corpus.py (every file on every target) and test_rs274.py (LinuxCNC's own
interpreter reads the linuxcnc programs). Posting is memoised per session, so the two test
files share one run of each (file, target). The corpus comes from
``python tests/corpus/fetch_corpus.py`` (``make corpus``); without it the tests skip.

``CAMTOOL_CORPUS=full`` runs every fetched file instead of the deterministic sample, and
``CAMTOOL_CORPUS=off`` skips the corpus (e.g. for a quick local run).

The corpus is only read: the programs a run writes, and its ``results.json``, go to a
folder of this pytest run (:func:`out_root`, under pytest's ``tmp_path_factory``), so two
runs at once (two worktrees, CI and a developer) never write the same file.
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import json
import os
import re
import shlex
import signal
import tempfile
import time
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import click
import pytest

from camtool.cli.main import cli, main
from camtool.post.registry import load_target
from tests.targets import EXTENSIONS, TARGETS

ROOT = Path(__file__).resolve().parents[2]
CORPUS = Path(os.environ.get("CAMTOOL_CORPUS_DIR", ROOT / ".corpus"))
MANIFEST = CORPUS / "manifest.json"
MODE = os.environ.get("CAMTOOL_CORPUS", "sample")
DEADLINE_S = float(os.environ.get("CAMTOOL_CORPUS_DEADLINE", "60"))
MAX_REMEDIES = 3  # a remedy may lead to a second message with a second remedy
# An input with no geometry (text, images, filters only: several Inkscape examples) is
# refused with exit 3 and this message, which says what camtool reads; no option helps.
NOTHING_TO_CUT = "nothing to cut; camtool reads"
# An SVG whose clip, mask or viewport hides part of a shape (an icon's design, a frame its
# artwork reaches out of) is refused with exit 3 and one of these: the drawing must be
# edited, no option helps (camtool/importers/svgclip.py).
CLIPPED = (
    "and camtool cuts whole shapes: the hidden part would be cut",
    "whose region camtool cannot work out",
    "which camtool cannot read as a clip",
)
# A DXF with no entity in model space (LibreCAD's library keeps a few: templates/empty.dxf,
# elektro/audio/s1.dxf and speak2.dxf) is refused with exit 3 and one of these: there is no
# drawing to read, and no option helps (camtool/importers/dxf.py).
EMPTY = ("the drawing is empty (no entity in model space)", "with nothing left in model space")
FETCH_HINT = "run `python tests/corpus/fetch_corpus.py` (make corpus) to fetch it"


def load_manifest() -> dict[str, Any] | None:
    """The fetched manifest, or None when the corpus is absent or switched off."""
    if MODE == "off" or not MANIFEST.exists():
        return None
    return json.loads(MANIFEST.read_text())


def skip_reason() -> str:
    """Why the corpus tests skip (when load_manifest() is None)."""
    if MODE == "off":
        return "CAMTOOL_CORPUS=off"
    return f"no corpus at {CORPUS}: {FETCH_HINT}"


def corpus_files(manifest: dict[str, Any] | None) -> list[str]:
    """Corpus files (relative to CORPUS) this run posts: the sample, or all with =full."""
    if manifest is None:
        return []
    pick = "full" if MODE == "full" else "sample"
    return [f for kind in ("dxf", "svg") for f in manifest.get(kind, {}).get(pick, [])]


def case_id(rel: str) -> str:
    """A short test id for a corpus file: source package and file name."""
    parts = Path(rel).parts
    return f"{parts[1] if len(parts) > 1 else ''}:{Path(rel).name}"


class Deadline(BaseException):
    """A case used DEADLINE_S of CPU (a BaseException: cli.main must not swallow it)."""


@dataclass
class Run:
    """One in-process `camtool post` run."""

    args: list[str]
    rc: int
    stderr: str
    seconds: float
    output: Path
    stray: list[str]  # files in the output folder other than the output

    @property
    def error(self) -> str:
        """The first error line of stderr ('' when none).

        ``camtool: error:`` lines first: a progress line of a slow run (``camtool: reading
        dialog-error.svg…``) may hold the word too.
        """
        lines = [ln for ln in self.stderr.splitlines() if "error" in ln]
        errors = [ln for ln in lines if ln.startswith("camtool: error:")]
        return (errors or lines or [""])[0]

    def command(self) -> str:
        """The run as a user types it."""
        return "camtool " + shlex.join(self.args)


@dataclass
class Outcome:
    """A (file, target) case: the first run, the remedy runs, and the verdict."""

    rel: str
    target: str
    runs: list[Run] = field(default_factory=list)
    status: str = ""  # "first-try", "after-remedy", "refused" (nothing to cut, or clipped)
    # or "failed"
    problems: list[str] = field(default_factory=list)

    @property
    def final(self) -> Run:
        """The last run made."""
        return self.runs[-1]


def _on_alarm(signum: int, frame: Any) -> None:
    raise Deadline()


def run_post(src: Path, target: str, outdir: Path, extra: list[str]) -> Run:
    """Run ``camtool post SRC -t TARGET -o OUT EXTRA...`` in-process, DEADLINE_S of CPU at most.

    ``seconds`` is the CPU time the run used (``time.process_time``).
    """
    outdir.mkdir(parents=True, exist_ok=True)
    for old in outdir.iterdir():
        old.unlink()
    out = outdir / f"{src.stem}{EXTENSIONS[target]}"
    args = ["post", str(src), "-t", target, "-o", str(out), *extra]
    err = io.StringIO()
    previous = signal.signal(signal.SIGPROF, _on_alarm)
    signal.setitimer(signal.ITIMER_PROF, DEADLINE_S)  # CPU time: a loaded machine is no hang
    start = time.process_time()
    try:
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            rc = main(args)
    except Deadline:
        rc = -1
        err.write(f"harness: no answer within {DEADLINE_S:g} s of CPU time\n")
    finally:
        signal.setitimer(signal.ITIMER_PROF, 0)
        signal.signal(signal.SIGPROF, previous)
    seconds = time.process_time() - start
    stray = sorted(p.name for p in outdir.iterdir() if p != out)
    return Run(args, rc, err.getvalue(), seconds, out, stray)


def _post_options() -> dict[str, click.Option]:
    command = cli.commands["post"]  # type: ignore[attr-defined]
    return {
        name: p
        for p in command.params
        if isinstance(p, click.Option)
        for name in p.opts
        if name.startswith("--")
    }


OPTION = re.compile(r"--[a-z][a-z0-9-]*")
STRIP = "`'\"“”‘’()[]{},;:."
PLACEHOLDER = re.compile(r"[A-Z][A-Z0-9_]*(\.[a-z]+)?")


def suggested_flags(message: str) -> list[list[str]] | str:
    """The option sets a message suggests, each with its values, as it names them.

    Each ``--name`` of `camtool post` that the message mentions is taken with exactly as
    many following words as the option takes values (``--fit 10 7``, ``--origin
    lower-left``, ``--tolerance 0.01``); a flag takes none. Words are stripped of quotes and
    trailing punctuation. Returns the alternatives in the order mentioned, or a string
    saying why the message's remedy cannot be followed as written (no option named, or an
    option without usable values, such as a bare "use --fit").
    """
    options = _post_options()
    found: list[list[str]] = []
    why: list[str] = []
    joined_at = -1  # where the last option's values ended: an option right after it joins it
    for match in OPTION.finditer(message):
        name = match.group(0)
        option = options.get(name)
        if option is None:
            continue
        if option.is_flag:
            words: list[str] = []
        else:
            words = [w.strip(STRIP) for w in message[match.end() :].split()][: option.nargs]
            if any(PLACEHOLDER.fullmatch(w) for w in words):
                continue  # "--machine FILE.toml": a pointer to an option, not a value to use
            try:
                if len(words) < option.nargs or any(w.startswith("--") for w in words):
                    raise click.BadParameter("too few values")
                option.type_cast_value(None, words if option.nargs > 1 else words[0])  # type: ignore[arg-type]
            except click.BadParameter:
                why.append(f"{name!r} without usable values (next words {words!r})")
                continue
        # "--fit 10 7 --origin lower-left" is one remedy: options written one after the other
        between = message[joined_at : match.start()] if joined_at >= 0 else "x"
        if found and not between.strip(" `'\"“”‘’"):
            found[-1] += [name, *words]
        else:
            found.append([name, *words])
        end = match.end()
        for word in words:
            end = message.index(word, end) + len(word)
        joined_at = end
    if found:
        return found
    if why:
        return "the message names " + "; ".join(why)
    return "the message names no option of `camtool post` to follow"


def check_run(run: Run, target: str) -> list[str]:
    """Contract problems of one run (empty when it keeps the CLI contract)."""
    problems = []
    if "internal error" in run.stderr or "Traceback" in run.stderr:
        problems.append(f"internal error: {run.error or run.stderr.strip()[-300:]}")
    if run.rc == -1:
        problems.append(f"no answer within {DEADLINE_S:g} s of CPU time")
    elif run.rc not in (0, 1, 2, 3):
        problems.append(f"exit code {run.rc} (expected 0, 1, 2 or 3)")
    if run.rc != 0 and run.output.exists():
        problems.append(f"exit {run.rc} but the output {run.output.name} was written")
    if run.rc not in (0, -1) and "camtool: error:" not in run.stderr:
        problems.append(f"exit {run.rc} without a 'camtool: error:' message")
    if run.stray:
        problems.append(f"stray files in the output folder: {run.stray}")
    if run.rc == 0:
        problems += check_read_back(run.output, target)
    return problems


def check_read_back(output: Path, target: str) -> list[str]:
    """The target's own reader must read what its post-processor wrote."""
    if not output.exists() or output.stat().st_size == 0:
        return [f"exit 0 but no program in {output.name}"]
    try:
        load_target(target).post.parse(output.read_bytes(), source=str(output))
    except Exception as exc:  # the reader failing on its own output is the finding
        return [f"{target}'s reader rejects its own output: {type(exc).__name__}: {exc}"]
    return []


def resolve(rel: str, target: str) -> Outcome:
    """Post REL for TARGET; on failure follow the message's remedy (up to MAX_REMEDIES)."""
    src = CORPUS / rel
    digest = hashlib.sha1(rel.encode()).hexdigest()[:8]
    outdir = out_root() / target / f"{src.stem}-{digest}"
    outcome = Outcome(rel, target)
    extra: list[str] = []
    for attempt in range(MAX_REMEDIES + 1):
        run = run_post(src, target, outdir, extra)
        outcome.runs.append(run)
        outcome.problems += [f"{run.command()}: {p}" for p in check_run(run, target)]
        if run.rc == 0:
            outcome.status = "first-try" if attempt == 0 else "after-remedy"
            break
        if run.rc == -1 or "internal error" in run.stderr:
            break
        if run.rc == 3 and NOTHING_TO_CUT in run.error:
            outcome.status = "refused"  # text or images only: no option can help
            break
        if run.rc == 3 and any(text in run.error for text in (*CLIPPED, *EMPTY)):
            outcome.status = "refused"  # what it shows is not what it holds, or nothing
            break
        remedy = _follow(src, target, outdir, extra, run, outcome)
        if remedy is None:
            break
        extra = remedy
    if outcome.status == "":
        outcome.status = "failed"
    if outcome.status == "failed" and not outcome.problems:
        outcome.problems.append(
            f"{outcome.final.command()}: exit {outcome.final.rc}: {outcome.final.error}"
        )
    return outcome


def _follow(
    src: Path, target: str, outdir: Path, extra: list[str], run: Run, outcome: Outcome
) -> list[str] | None:
    """The flags to run with next, following RUN's message; None when there is none.

    Alternatives ("--origin lower-left or --fit 10 7") are tried one by one; the first that
    posts wins, else the last tried is kept (its message may suggest the next remedy).
    """
    choices = suggested_flags(run.error)
    if isinstance(choices, str):
        outcome.problems.append(f"{run.command()}: exit {run.rc}: {run.error} ({choices})")
        return None
    for flags in choices[:-1]:
        candidate = [*extra, *flags]
        trial = run_post(src, target, outdir, candidate)
        outcome.problems += [f"{trial.command()}: {p}" for p in check_run(trial, target)]
        if trial.rc == 0:
            return candidate
    last = [*extra, *choices[-1]]
    if last == extra or choices[-1][0] in extra:
        outcome.problems.append(
            f"{run.command()}: exit {run.rc}: {run.error} (the remedy was already followed)"
        )
        return None
    return last


_OUTCOMES: dict[tuple[str, str], Outcome] = {}
_OUT: list[Path] = []  # this run's output folder, once made


def out_root() -> Path:
    """This run's folder for the programs and results.json (never inside the corpus).

    Set by the :func:`_corpus_out` fixture to a folder of pytest's ``tmp_path_factory``;
    made with :func:`tempfile.mkdtemp` when the harness is used outside pytest.
    """
    if not _OUT:
        _OUT.append(Path(tempfile.mkdtemp(prefix="camtool-corpus-")))
    return _OUT[0]


@pytest.fixture(autouse=True, scope="session")
def _corpus_out(tmp_path_factory: pytest.TempPathFactory) -> None:
    """Make :func:`out_root` a folder of this pytest run (kept as pytest keeps its temp)."""
    if not _OUT:
        _OUT.append(tmp_path_factory.mktemp("corpus-out"))


def outcome_for(rel: str, target: str) -> Outcome:
    """The memoised outcome of (REL, TARGET) for this session."""
    key = (rel, target)
    if key not in _OUTCOMES:
        _OUTCOMES[key] = resolve(rel, target)
    return _OUTCOMES[key]


def _this_run() -> dict[str, Any] | None:
    """This process's cases as ``results.json`` keeps them, its slowest run and its folder."""
    if not _OUTCOMES:
        return None
    slowest = max((r for o in _OUTCOMES.values() for r in o.runs), key=lambda r: r.seconds)
    return {
        "folder": str(out_root()),
        "slowest": [slowest.seconds, slowest.command()],
        "results": {
            "mode": MODE,
            "counts": dict(Counter(o.status for o in _OUTCOMES.values())),
            "cases": [
                {
                    "file": o.rel,
                    "target": o.target,
                    "status": o.status,
                    "runs": [
                        {"args": r.args, "rc": r.rc, "s": round(r.seconds, 2)} for r in o.runs
                    ],
                    "problems": o.problems,
                }
                for o in _OUTCOMES.values()
            ],
        },
    }


def pytest_sessionfinish(session: pytest.Session) -> None:
    """Keep this process's cases in its folder's ``results.json``; a worker also sends them."""
    run = _this_run()
    if run is None:
        return
    (Path(run["folder"]) / "results.json").write_text(json.dumps(run["results"], indent=1) + "\n")
    workeroutput = getattr(session.config, "workeroutput", None)
    if workeroutput is not None:
        workeroutput["camtool_corpus"] = json.dumps(run)


def pytest_terminal_summary(terminalreporter: Any) -> None:
    """Print the corpus counts of this process and where they are kept (not under xdist:
    its workers' cases are printed by tests/conftest.py with :func:`print_summary`)."""
    mine = _this_run()
    if mine is not None and not hasattr(terminalreporter.config, "workerinput"):
        print_summary(terminalreporter, [mine])


def print_summary(terminalreporter: Any, runs: list[dict[str, Any]]) -> None:
    """The counts of the cases of ``runs`` (each a :func:`_this_run`), by target, the slowest
    run, and the folders that keep them."""
    cases = [case for run in runs for case in run["results"]["cases"]]
    counts = Counter(case["status"] for case in cases)
    by_target: dict[str, Counter[str]] = {}
    for case in cases:
        by_target.setdefault(case["target"], Counter())[case["status"]] += 1
    seconds, command = max(run["slowest"] for run in runs)
    terminalreporter.write_sep("-", f"camtool corpus ({MODE})")
    terminalreporter.write_line(
        f"{len(cases)} cases: {counts['first-try']} ok first try, "
        f"{counts['after-remedy']} ok after the suggested remedy, "
        f"{counts['refused']} refused (nothing to cut, or clipped), {counts['failed']} failed"
    )
    for target in TARGETS:
        if target in by_target:
            c = by_target[target]
            terminalreporter.write_line(
                f"  {target:14s} {c['first-try']:4d} first try {c['after-remedy']:4d} "
                f"after remedy {c['refused']:4d} refused {c['failed']:4d} failed"
            )
    terminalreporter.write_line(f"slowest run {seconds:.1f} s: {command}")
    for run in runs:
        terminalreporter.write_line(f"cases and programs kept in {run['folder']}")
