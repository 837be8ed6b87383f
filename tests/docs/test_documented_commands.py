"""Every command and Python example of README.md and docs/ runs as written.

The rules a page follows (docs/index.md, "Reading these pages") and this test reads:

- A fenced block tagged ``sh`` (``shell``, ``bash``) holds commands: each line that starts
  with ``camtool`` or ``.venv/bin/camtool`` runs (a ``\\`` continues it on the next line).
- A block without a language, or ``console``, is a transcript: ``$ camtool ...`` lines run,
  and each ``camtool: error: ...`` line after one must be what the command prints, with a
  non-zero exit. Any other ``camtool <word>`` line in such a block is an error of the page:
  tag a synopsis ``text`` (never run), a command ``sh``.
- A ``python`` block runs (unless its first line is a ``# needs ...`` comment); a block
  tagged with a file name after its language (`` ```toml my-router.toml ``) is written to
  that file before the page's commands run.
- A command exits 0 unless its comment says ``exit N`` (``exit code N``).
- Skipped, and only these: a line with a placeholder in angle brackets
  (``<your-drawing.dxf>``), and a line whose comment starts ``# needs`` (a machine on a
  serial port, a cluster).
- ``camtool simulate-device ... --pty`` starts the simulator in the background; a later
  ``--port /dev/pts/N`` on the page (the documented example path) is its port.

Each page runs in its own temporary directory holding a copy of ``samples/`` and an empty
``docs/gallery/``, so a page may use the files its earlier commands wrote. Commands run in
this process through :func:`camtool.cli.main.main` (as tests/cli does; a batch without
``--jobs`` in this process too, as ``--jobs 1``: its pool is tested in tests/jobs); a command
that needs the shell (a glob, a pipe, a variable) or a Dask cluster runs under ``bash`` with
``camtool`` on ``PATH``.
"""

from __future__ import annotations

import os
import re
import shlex
import shutil
import signal
import subprocess
import sys
import traceback
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest

from camtool.cli.main import main

ROOT = Path(__file__).parents[2]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]

SHELL_LANGS = ("sh", "shell", "bash")
TRANSCRIPT_LANGS = ("", "console")
COMMAND = re.compile(r"^(?:\.venv/bin/)?camtool(?:\s|$)")
PLACEHOLDER = re.compile(r"<[A-Za-z][^<>]*>")
EXIT = re.compile(r"\bexit(?: code)? (\d)\b")
SHELL_ONLY = re.compile(r"[*?\[\]|<>$;&`]")
EXAMPLE_PTY = re.compile(r"/dev/pts/\d+")


@dataclass
class Block:
    """One fenced block: its language, the words after it, its lines, where it starts."""

    lang: str
    info: list[str]
    lines: list[str]
    line: int  # 1-based line of the first content line


@dataclass
class Step:
    """What the test does for one documented command or example."""

    kind: str  # "run", "python", "file", "skip"
    line: int
    text: str
    expect: int | None = 0  # None: any non-zero
    errors: list[str] = field(default_factory=list)  # transcript's "camtool: error:" lines
    path: str = ""  # for "file"


def blocks(text: str) -> list[Block]:
    """The fenced blocks of a Markdown page."""
    found: list[Block] = []
    current: Block | None = None
    for number, raw in enumerate(text.splitlines(), 1):
        fence = re.match(r"^\s*```(.*)$", raw)
        if fence and current is None:
            words = fence.group(1).split()
            current = Block(words[0] if words else "", words[1:], [], number + 1)
        elif fence and current is not None:
            found.append(current)
            current = None
        elif current is not None:
            current.lines.append(raw)
    return found


def _comment(command: str) -> str:
    """The trailing ``# ...`` comment of a shell line (outside quotes), or ``""``."""
    quote = ""
    for i, ch in enumerate(command):
        if quote:
            quote = "" if ch == quote else quote
        elif ch in "'\"":
            quote = ch
        elif ch == "#" and (i == 0 or command[i - 1].isspace()):
            return command[i + 1 :].strip()
    return ""


def _shell_lines(block: Block, prefix: str) -> list[tuple[int, str, list[str]]]:
    """Commands of a block (continuations joined) with their line and the lines after them."""
    out: list[tuple[int, str, list[str]]] = []
    i = 0
    lines = block.lines
    while i < len(lines):
        raw = lines[i].strip()
        start = block.line + i
        i += 1
        if not raw.startswith(prefix) or not COMMAND.match(raw[len(prefix) :]):
            if out:
                out[-1][2].append(raw)
            continue
        command = raw[len(prefix) :]
        while command.endswith("\\") and i < len(lines):
            command = command[:-1].rstrip() + " " + lines[i].strip()
            i += 1
        out.append((start, command, []))
    return out


def steps(page: Path) -> list[Step]:
    """What to run for ``page``, in order; raises AssertionError on an ambiguous block."""
    result: list[Step] = []
    for block in blocks(page.read_text(encoding="utf-8")):
        if block.lang == "python" and block.lines[:1] and block.lines[0].startswith("# needs"):
            result.append(Step("skip", block.line, "\n".join(block.lines)))
            continue
        if block.lang == "python":
            result.append(Step("python", block.line, "\n".join(block.lines)))
            continue
        if block.info:
            result.append(
                Step("file", block.line, "\n".join(block.lines) + "\n", path=block.info[0])
            )
            continue
        if block.lang in SHELL_LANGS:
            commands = _shell_lines(block, "")
        elif block.lang in TRANSCRIPT_LANGS:
            for offset, raw in enumerate(block.lines):
                text = raw.strip()
                assert not COMMAND.match(text), (
                    f"{_name(page)}:{block.line + offset}: a camtool line in a block "
                    "without a language: tag the block `sh` (it runs), `text` (a synopsis), or "
                    "write it as a transcript line `$ camtool ...`"
                )
            commands = _shell_lines(block, "$ ")
        else:
            continue
        for start, command, after in commands:
            result.append(_step(start, command, after))
    return result


def _name(page: Path) -> str:
    return str(page.relative_to(ROOT)) if page.is_relative_to(ROOT) else str(page)


def _step(line: int, command: str, after: list[str]) -> Step:
    comment = _comment(command)
    if PLACEHOLDER.search(command) or comment.startswith("needs"):
        return Step("skip", line, command)
    errors = [text for text in after if text.startswith("camtool: error:")]
    match = EXIT.search(comment)
    expect: int | None = int(match.group(1)) if match else (None if errors else 0)
    return Step("run", line, command, expect=expect, errors=errors)


# ----------------------------------------------------------------------------- running


class Page:
    """One page's run: its directory, the simulator it started, what failed."""

    def __init__(self, page: Path, workdir: Path, capsys: Any) -> None:
        self.page = page
        self.workdir = workdir
        self.capsys = capsys
        self.failures: list[str] = []
        self.simulators: list[tuple[subprocess.Popen[str], str]] = []
        shutil.copytree(ROOT / "samples", workdir / "samples")
        (workdir / "docs" / "gallery").mkdir(parents=True)
        bindir = workdir / ".venv" / "bin"
        bindir.mkdir(parents=True)
        launcher = bindir / "camtool"
        launcher.write_text(f'#!/bin/sh\nexec "{sys.executable}" -m camtool "$@"\n')
        launcher.chmod(0o755)

    def fail(self, step: Step, message: str) -> None:
        self.failures.append(f"{_name(self.page)}:{step.line}: {step.text}\n  {message}")

    def run(self, step: Step) -> None:
        if step.kind == "file":
            (self.workdir / step.path).write_text(step.text, encoding="utf-8")
        elif step.kind == "python":
            self._python(step)
        elif step.kind == "run":
            self._command(step)

    def _python(self, step: Step) -> None:
        code = compile(step.text, f"{self.page.name}:{step.line}", "exec")
        try:
            exec(code, {"__name__": "__docs__"})
        except Exception:
            self.fail(step, traceback.format_exc(limit=-3))
        finally:
            self.capsys.readouterr()

    def _command(self, step: Step) -> None:
        command = re.sub(r"^(\.venv/bin/)?camtool", "camtool", step.text)
        if self.simulators:
            command = EXAMPLE_PTY.sub(self.simulators[-1][1], command)
        argv = shlex.split(command, comments=True)[1:]
        if argv[:1] == ["simulate-device"]:
            self._simulator(step, argv)
            return
        unquoted = re.sub(r"'[^']*'|\"[^\"]*\"", "", command.split(" #")[0])
        if SHELL_ONLY.search(unquoted) or "--scheduler" in argv:  # Dask: its own process
            code, err = self._bash(command)
        else:
            try:
                code = main(argv)
            finally:
                _, err = self.capsys.readouterr()
        self._check(step, code, err)

    def _check(self, step: Step, code: int, err: str) -> None:
        tail = err.strip().splitlines()[-3:]
        if step.expect is None and code == 0:
            self.fail(step, "the page shows an error, the command exits 0")
        elif step.expect is not None and code != step.expect:
            self.fail(step, f"exit {code}, the page says {step.expect}: {tail}")
        for line in step.errors:
            if " ".join(line.split()) not in " ".join(err.split()):
                self.fail(step, f"the page shows {line!r}; camtool printed {tail}")

    def _bash(self, command: str) -> tuple[int, str]:
        env = {
            **os.environ,
            "PATH": f"{self.workdir / '.venv' / 'bin'}{os.pathsep}{os.environ['PATH']}",
        }
        proc = subprocess.run(
            ["bash", "-c", command],
            cwd=self.workdir,
            env=env,
            capture_output=True,
            text=True,
            timeout=300,
            check=False,
        )
        return proc.returncode, proc.stderr

    def _simulator(self, step: Step, argv: list[str]) -> None:
        proc = subprocess.Popen(
            [sys.executable, "-m", "camtool", *argv],
            cwd=self.workdir,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            preexec_fn=_sigint_default,
        )
        assert proc.stdout is not None
        path = proc.stdout.readline().strip()
        self.simulators.append((proc, path))
        if not path.startswith("/dev/"):
            self.fail(step, f"the simulator printed no port: {path!r}")

    def close(self) -> None:
        for proc, _ in self.simulators:
            proc.send_signal(signal.SIGINT)
            try:
                proc.communicate(timeout=60)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.communicate()


def _sigint_default() -> None:
    signal.signal(signal.SIGINT, signal.SIG_DFL)


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_page_runs_as_written(
    page: Path, tmp_path: Path, capsys: Any, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(os, "cpu_count", lambda: 1)  # batch without --jobs: in this process
    run = Page(page, tmp_path, capsys)
    try:
        found = steps(page)
        for step in sorted(found, key=lambda s: s.kind != "file"):  # files first
            run.run(step)
    finally:
        run.close()
    assert not run.failures, "\n".join(run.failures)
    if page == GALLERY_PAGE:
        _same_pictures(tmp_path / "docs" / "gallery", ROOT / "docs" / "gallery")


GALLERY_PAGE = ROOT / "docs" / "gallery.md"


def _same_pictures(written: Path, committed: Path) -> None:
    """The gallery's commands, run as written, drew the committed pictures byte for byte.

    tests/test_docs.py checks the gallery page without making its pictures
    (``make_docs.py --without-gallery-pictures``): this is where they are checked, once.
    """
    want = sorted(p.name for p in committed.glob("*.svg"))
    assert want, f"no pictures in {committed}"
    assert sorted(p.name for p in written.glob("*.svg")) == want
    stale = [n for n in want if (written / n).read_bytes() != (committed / n).read_bytes()]
    assert not stale, f"docs/gallery/ pictures differ from what the page draws: {stale} (make docs)"


def test_only_marked_lines_are_skipped() -> None:
    # a placeholder is visible to a reader: angle brackets or a "# needs" comment
    for page in PAGES:
        for step in steps(page):
            if step.kind == "skip":
                assert PLACEHOLDER.search(step.text) or _comment(step.text).startswith("needs")


def test_the_rules_read_a_page_as_documented(tmp_path: Path) -> None:
    page = tmp_path / "page.md"
    page.write_text(
        "```sh\ncamtool post samples/logo.dxf \\\n    -t grbl -o a.gcode  # a comment\n"
        "camtool post <your-drawing.dxf> -t grbl\n"
        "camtool send a.gcode -t grbl --port /dev/ttyUSB0  # needs a machine\n"
        "camtool verify a.gcode -t grbl --max-error-um 1  # exit code 4 when worse\n```\n\n"
        "```\n$ camtool post nope.dxf -t grbl\ncamtool: error: no such file\n```\n\n"
        "```text\ncamtool post DRAWING -t NAME\n```\n\n"
        "```toml my.toml\nname = 'x'\n```\n"
    )
    found = steps(page)
    assert [s.kind for s in found] == ["run", "skip", "skip", "run", "run", "file"]
    assert found[0].text == "camtool post samples/logo.dxf -t grbl -o a.gcode  # a comment"
    assert found[3].expect == 4
    assert found[4].expect is None and found[4].errors == ["camtool: error: no such file"]
    assert found[5].path == "my.toml" and found[5].text == "name = 'x'\n"
    page.write_text("```\ncamtool post DRAWING -t NAME\n```\n")
    with pytest.raises(AssertionError, match="tag the block"):
        steps(page)
