"""Safe output files: never an input, atomic, devices written through, stale temps, locks."""

from __future__ import annotations

import errno
import os
import re
import stat
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from camtool.cli.main import main
from camtool.jobs.output import (
    LOCK_NAME,
    TEMP_PATTERN,
    check_outputs,
    lock_directory,
    remove_stale_temps,
    temp_path,
    write_atomic,
)
from camtool.model.errors import CamtoolError, UsageError

ROOT = Path(__file__).parents[2]


def test_written_files_get_the_permissions_open_would_give(tmp_path: Path) -> None:
    old = os.umask(0o022)
    try:
        write_atomic(tmp_path / "a.nc", "G0 X1\n")
        write_atomic(tmp_path / "b.bin", b"\x13\x54")
    finally:
        os.umask(old)
    for name in ("a.nc", "b.bin"):
        assert stat.S_IMODE((tmp_path / name).stat().st_mode) == 0o644
    assert (tmp_path / "b.bin").read_bytes() == b"\x13\x54"
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []


# -- check_outputs: an output is never an input, nor another output ---------------------------


@pytest.fixture
def drawing(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """tmp_path as the working directory, with part.dxf, sub/ and link.dxf → part.dxf."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "part.dxf").write_text("0\nEOF\n")
    (tmp_path / "sub").mkdir()
    (tmp_path / "link.dxf").symlink_to("part.dxf")
    return tmp_path / "part.dxf"


@pytest.mark.parametrize(
    "out",
    [
        "part.dxf",
        "./sub/../part.dxf",
        "link.dxf",  # a symlink to the input
        "hard.dxf",  # a hard link: same inode
        "{abs}",  # the absolute name
    ],
)
def test_an_output_that_is_the_input_is_refused(drawing: Path, out: str) -> None:
    os.link(drawing, "hard.dxf")
    out = out.format(abs=drawing)
    with pytest.raises(UsageError, match=rf"-o {re.escape(out)} would overwrite the input"):
        check_outputs([("the input", "part.dxf")], [("-o", out)])
    assert drawing.read_text() == "0\nEOF\n"


def test_an_input_named_through_a_symlink_is_still_the_input(drawing: Path) -> None:
    with pytest.raises(UsageError, match=r"would overwrite the input link\.dxf"):
        check_outputs([("the input", "link.dxf")], [("--preview", "sub/../part.dxf")])


def test_two_outputs_naming_one_file_are_refused(drawing: Path) -> None:
    with pytest.raises(UsageError, match=r"-o a\.pic and --report \./a\.pic are the same file"):
        check_outputs([("the input", "part.dxf")], [("-o", "a.pic"), ("--report", "./a.pic")])
    with pytest.raises(UsageError, match="-o - and --report - both write to stdout"):
        check_outputs([], [("-o", "-"), ("--report", "-")])


def test_distinct_outputs_stdin_and_missing_names_pass(drawing: Path) -> None:
    check_outputs(
        [("the input", "-"), ("the input", "missing.dxf"), ("the --machine file", None)],
        [("-o", "-"), ("--report", "r.json"), ("--preview", "sub/p.svg"), ("x", None)],
    )


# -- write_atomic: what the output is decides how it is written --------------------------------


def test_a_device_is_written_through_and_stays_a_device(tmp_path: Path) -> None:
    null = tmp_path / "null"
    try:  # a null device of our own (root can mknod), else the system's
        os.mknod(null, stat.S_IFCHR | 0o666, os.stat("/dev/null").st_rdev)
    except PermissionError:
        null = Path("/dev/null")
    write_atomic(null, "G0 X1\n")
    assert stat.S_ISCHR(null.stat().st_mode)
    assert stat.S_ISCHR(os.stat("/dev/null").st_mode)
    assert [p.name for p in tmp_path.iterdir()] == (["null"] if null.parent == tmp_path else [])


def test_a_full_device_is_an_error_naming_it() -> None:
    with pytest.raises(OSError) as info:
        write_atomic("/dev/full", "G0 X1\n")
    assert info.value.errno == errno.ENOSPC
    assert stat.S_ISCHR(os.stat("/dev/full").st_mode)


def test_a_fifo_is_written_through_to_its_reader(tmp_path: Path) -> None:
    fifo = tmp_path / "pipe"
    os.mkfifo(fifo)
    got: list[bytes] = []
    reader = threading.Thread(target=lambda: got.append(fifo.read_bytes()))
    reader.start()
    write_atomic(fifo, b"\x13\x54" * 50_000)  # more than a pipe buffer (64 KiB)
    reader.join(timeout=10)
    assert got == [b"\x13\x54" * 50_000]
    assert stat.S_ISFIFO(fifo.lstat().st_mode)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["pipe"]


def test_a_symlink_stays_and_its_target_is_replaced(tmp_path: Path) -> None:
    (tmp_path / "real").mkdir()
    target = tmp_path / "real" / "prog.nc"
    target.write_text("old\n")
    target.chmod(0o600)
    link = tmp_path / "prog.nc"
    link.symlink_to(target)
    write_atomic(link, "G0 X1\n")
    assert link.is_symlink() and os.readlink(link) == str(target)
    assert target.read_text() == "G0 X1\n"
    assert stat.S_IMODE(target.stat().st_mode) == 0o600  # a replaced file keeps its mode
    dangling = tmp_path / "new.nc"
    dangling.symlink_to(tmp_path / "real" / "new.nc")
    write_atomic(dangling, "G0 X2\n")
    assert dangling.is_symlink() and (tmp_path / "real" / "new.nc").read_text() == "G0 X2\n"
    assert [p.name for p in tmp_path.rglob(".*")] == []


def test_a_directory_is_refused(tmp_path: Path) -> None:
    with pytest.raises(IsADirectoryError):
        write_atomic(tmp_path, "x")


def test_a_failed_write_leaves_nothing(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    (tmp_path / "a.nc").write_text("previous\n")

    def full(fd: int) -> None:
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(os, "fsync", full)
    with pytest.raises(OSError, match="No space left"):
        write_atomic(tmp_path / "a.nc", "G0 X1\n")
    assert (tmp_path / "a.nc").read_text() == "previous\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.nc"]


# -- temporary files of killed runs ------------------------------------------------------------


def dead_pid() -> int:
    """The pid of a process that has exited and been reaped."""
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    return proc.pid


def test_temp_files_say_whose_they_are(tmp_path: Path) -> None:
    assert temp_path(tmp_path / "logo.pic").name == f".logo.pic.camtool-{os.getpid()}.tmp"
    assert TEMP_PATTERN.match(temp_path(tmp_path / "logo.pic").name)


def test_stale_temp_files_of_dead_processes_are_removed(tmp_path: Path) -> None:
    dead = tmp_path / f".logo.pic.camtool-{dead_pid()}.tmp"
    mine = temp_path(tmp_path / "logo.pic")
    live_parent = tmp_path / f".a.pic.camtool-{os.getppid()}.tmp"
    user = tmp_path / ".logo.pic.tmp"  # not camtool's name: never touched
    for path in (dead, mine, live_parent, user):
        path.write_text("half\n")
    assert remove_stale_temps(tmp_path) == (dead,)
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        p.name for p in (mine, live_parent, user)
    )
    assert remove_stale_temps(tmp_path / "missing") == ()


def test_a_killed_write_is_cleaned_by_the_next_run(tmp_path: Path) -> None:
    """kill -9 in the middle of a write: the next write beside it removes the leftover."""
    out = tmp_path / "big.pic"
    script = (
        "import os, sys; from camtool.jobs import output\n"
        "def stop(fd): os.kill(os.getpid(), 9)\n"
        "os.fsync = stop\n"
        f"output.write_atomic({str(out)!r}, 'G0 X1\\n' * 1000)\n"
    )
    proc = subprocess.run([sys.executable, "-c", script], check=False, cwd=ROOT)
    assert proc.returncode == -9
    (left,) = tmp_path.iterdir()
    match = TEMP_PATTERN.match(left.name)
    assert match and match["name"] == "big.pic" and not out.exists()
    code = main(["post", str(ROOT / "samples" / "logo.dxf"), "-t", "pic-mmh", "-o", str(out)])
    assert code == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == ["big.pic"]


# -- lock_directory: one run per output folder -------------------------------------------------


def test_a_locked_folder_is_refused_and_released(tmp_path: Path) -> None:
    folder = tmp_path / "out"
    with lock_directory(folder) as lock:
        assert lock.read_text() == f"{os.getpid()}\n"
        with (
            pytest.raises(CamtoolError, match=rf"another camtool run \(pid {os.getpid()}\)"),
            lock_directory(folder),
        ):
            pass
    assert list(folder.iterdir()) == []  # the lock file goes with the lock
    with lock_directory(folder):
        pass


def test_the_lock_of_a_killed_run_is_taken_over(tmp_path: Path) -> None:
    folder = tmp_path / "out"
    script = (
        "import os; from camtool.jobs.output import lock_directory\n"
        f"with lock_directory({str(folder)!r}): os.kill(os.getpid(), 9)\n"
    )
    proc = subprocess.run([sys.executable, "-c", script], check=False, cwd=ROOT)
    assert proc.returncode == -9 and (folder / LOCK_NAME).exists()
    with lock_directory(folder):
        assert (folder / LOCK_NAME).read_text() == f"{os.getpid()}\n"


def test_text_is_written_in_slices_byte_for_byte(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import camtool.jobs.output as output

    # slices of 7 characters cut through the two- and three-byte UTF-8 characters
    monkeypatch.setattr(output, "ENCODE_CHARS", 7)
    text = "(é)\nG1 X1.000 (ø…)\n" * 50
    for name, write in (("atomic.ngc", write_atomic), ("staged.ngc", None)):
        path = tmp_path / name
        if write is not None:
            write(path, text)
        else:
            staged = output.Staged()
            staged.stage(path, text)
            staged.publish()
        assert path.read_bytes() == text.encode("utf-8")


def test_writing_a_long_program_holds_no_second_whole_copy(tmp_path: Path) -> None:
    import tracemalloc

    text = "G1 X1.000 Y2.000\n" * 500_000  # 8.5 MB
    tracemalloc.start()
    try:
        write_atomic(tmp_path / "big.ngc", text)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    # one slice and its bytes at a time (~2 MiB), not the whole text encoded again
    assert peak < len(text) // 2, peak
    assert (tmp_path / "big.ngc").stat().st_size == len(text)
