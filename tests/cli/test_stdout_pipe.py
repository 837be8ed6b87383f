"""A program written to stdout reaches it whole, or the command fails.

``camtool post … -o - | sender``: when the sender leaves part-way, the program it passed
on is cut short, and camtool must not exit 0. Python's buffered stdout reported such a
write as done on the development VM (``write(2)`` took 64 KiB of a 5.3 MB program), so
stdout is now written with ``os.write`` until every byte is taken.
"""

from __future__ import annotations

import io
import os
import subprocess
import sys
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

from camtool.cli.common import write_output
from camtool.model.errors import CamtoolError

PROGRAM = "".join(f"G1 X{k % 250}.000 Y{k % 7}.000\n" for k in range(300_000))  # ~6 MB


@contextmanager
def stdout_to_pipe(
    monkeypatch: pytest.MonkeyPatch, keep: int | None
) -> Iterator[tuple[list[bytes], threading.Thread]]:
    """stdout on a pipe whose reader takes ``keep`` bytes and leaves (``None``: takes all)."""
    read_fd, write_fd = os.pipe()
    got: list[bytes] = []

    def reader() -> None:
        with os.fdopen(read_fd, "rb") as pipe:
            if keep is None:
                got.append(pipe.read())
            else:
                got.append(pipe.read(keep))

    thread = threading.Thread(target=reader)
    thread.start()
    stream = io.TextIOWrapper(os.fdopen(write_fd, "wb"), encoding="utf-8")
    monkeypatch.setattr("sys.stdout", stream)
    try:
        yield got, thread
    finally:
        monkeypatch.undo()
        stream.close()
        thread.join()


def test_a_reader_that_leaves_early_fails_the_write(monkeypatch: pytest.MonkeyPatch) -> None:
    with stdout_to_pipe(monkeypatch, keep=100) as (got, thread):
        with pytest.raises(CamtoolError, match=r"^stdout: broken pipe$"):
            write_output(PROGRAM, "-")
        thread.join()
    assert got == [PROGRAM[:100].encode()]


def test_a_reader_that_takes_it_all_gets_every_byte(monkeypatch: pytest.MonkeyPatch) -> None:
    with stdout_to_pipe(monkeypatch, keep=None) as (got, _):
        write_output(PROGRAM, "-")
        write_output(b"\x02binary\xff", "-")
    assert got == [PROGRAM.encode() + b"\x02binary\xff"]


def test_post_to_a_pipe_whose_reader_leaves_exits_1(tmp_path: Path) -> None:
    # The command as a pipeline runs it: on the development VM the code before this
    # exited 0 here, with nothing on stderr.
    lines = (f"G1 X{k % 250}.000 Y{k % 7}.000" for k in range(150_000))
    program = tmp_path / "long.ngc"
    program.write_text("\n".join(["G21 G90 F600", "G0 X0 Y0", *lines, "M2", ""]))
    run = subprocess.Popen(
        [sys.executable, "-m", "camtool", "post", str(program), "-t", "linuxcnc", "-o", "-"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        cwd=tmp_path,
    )
    assert run.stdout is not None and run.stderr is not None
    assert run.stdout.read(100).startswith(b"(camtool ")
    run.stdout.close()
    err = run.stderr.read().decode()
    assert run.wait() == 1
    assert "camtool: error: stdout: broken pipe" in err
