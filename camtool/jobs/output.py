"""Safe file output: nothing an input, nothing half-written, nothing replaced that is not a file.

Every command goes through this module for what it writes (see docs/cli.md, "Safety"):

Design notes: docs/internals.md, ``camtool/jobs/output.py``.
"""

from __future__ import annotations

import errno
import os
import re
import stat
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path

from camtool.model.errors import CamtoolError, UsageError

LOCK_NAME = ".camtool.lock"
"""The lock file :func:`lock_directory` keeps in a claimed folder while it runs."""
TEMP_PATTERN = re.compile(r"^\.(?P<name>.+)\.camtool-(?P<pid>[0-9]+)\.tmp$")
"""Name of a temporary file: ``.NAME.camtool-PID.tmp`` beside the output ``NAME``."""

Named = tuple[str, str | Path | None]
"""``(label, path)``: how a message names a path (``"-o"``, ``"the input"``) and the path.

``None`` is skipped; ``"-"`` is stdin (an input, skipped) or stdout (an output).
"""


def check_outputs(
    inputs: Iterable[Named],
    outputs: Iterable[Named],
    *,
    hint: str = "give each output its own name",
) -> None:
    """Refuse an output that is an input, or that another output of the same run names.

    Two paths are the same file when their :func:`os.path.realpath` (symlinks and
    ``..`` resolved) are equal, or, when both exist, when they share device and inode
    (:func:`os.path.samefile`: hard links too). An input ``"-"`` is the file standard
    input reads, when that is a regular file (``< part.dxf``: by device and inode). Two
    ``"-"`` outputs both name stdout.
    Nothing is read or written; run it before anything else.

    Args:
        inputs: ``(label, path)`` of every file the run reads, e.g.
            ``("the input", "part.dxf")``, ``("the --machine file", "m.toml")``.
        outputs: ``(label, path)`` of every file the run writes, e.g. ``("-o", "p.pic")``.
        hint: what to do about two outputs that are one file (the message's end).

    Raises:
        UsageError: an output would overwrite an input (never allowed, not even with
            ``--force``), or two outputs name the same file (or both stdout).
    """
    known_inputs = _Index()
    for label, path in _named(inputs):
        if path != "-":
            known_inputs.add(path, (label, path))
        elif (inode := _stdin_file()) is not None:
            # `camtool post - -o part.dxf < part.dxf`: stdin is that very file
            known_inputs.by_inode.setdefault(inode, (label, "- (standard input)"))
    known_outputs = _Index()
    stdout: str | None = None
    for label, path in _named(outputs):
        if path == "-":
            if stdout is not None:
                raise UsageError(
                    f"{stdout} - and {label} - both write to stdout; send one of them to a file"
                )
            stdout = label
            continue
        key = _identity(path)
        if (found := known_inputs.find(key)) is not None:
            raise UsageError(
                f"{label} {path} would overwrite {found[0]} {found[1]}; choose another "
                "name (camtool never overwrites an input, not even with --force)"
            )
        if (found := known_outputs.find(key)) is not None:
            raise UsageError(f"{found[0]} {found[1]} and {label} {path} are the same file; {hint}")
        known_outputs.add(path, (label, path), key)


def definition_inputs(target: str | None, machine_file: str | Path | None) -> list[Named]:
    """A ``--target`` or ``--machine`` that names an existing file (not a built-in name).

    Such a file is an input of the run like the drawing: no output may overwrite it.
    """
    named = [("the target file", target), ("the --machine file", machine_file)]
    return [(label, path) for label, path in named if path is not None and os.path.isfile(path)]


def check_paths(
    inputs: Iterable[Named],
    outputs: Iterable[Named],
    *,
    target: str | None = None,
    machine_file: str | Path | None = None,
) -> None:
    """:func:`check_outputs` with the target and machine files as inputs too.

    Called first thing by every command that writes (:func:`definition_inputs`). An
    output whose directory does not exist is refused too, before any work: found only
    when it is written, the run's other files would be written and this one not.

    Raises:
        UsageError: an output would overwrite an input, two outputs are one file, or an
            output's directory does not exist.
    """
    outputs = list(outputs)
    check_outputs([*inputs, *definition_inputs(target, machine_file)], outputs)
    for label, path in _named(outputs):
        folder = os.path.dirname(path)
        if path != "-" and folder and not os.path.isdir(folder):
            what = "is not a directory" if os.path.exists(folder) else "does not exist"
            raise UsageError(f"{label} {path}: {folder} {what}; create it or choose another path")


def write_file(path: str | Path, data: str | bytes) -> None:
    """``data`` to the file ``path`` (:func:`write_atomic`), stale temporary files removed.

    Temporary files of killed runs beside ``path`` go first (:func:`remove_stale_temps`),
    unless ``path`` is a device, FIFO or directory.

    Raises:
        CamtoolError: the file cannot be written, naming it and why (``x.pic: cannot
            write (no space left on device)``).
    """
    try:
        if os.path.isfile(path) or not os.path.lexists(path):  # not a device, FIFO or directory
            remove_stale_temps(Path(os.path.realpath(path)).parent)
        write_atomic(path, data)
    except OSError as exc:
        raise CamtoolError(f"{path}: cannot write ({reason(exc)})") from exc


class Staged:
    """The files of one run, written to temporaries first and published together.

    :meth:`stage` writes a regular file's data to its temporary beside it (as
    :func:`write_atomic` does, without the rename); a device or FIFO is only
    remembered. :meth:`publish` renames every temporary into place, then writes the
    devices; :meth:`discard` removes the temporaries. A run that fails on its third
    file (a full disk, a read-only folder) has replaced none of the first two.
    """

    def __init__(self) -> None:
        self._renames: list[tuple[Path, Path]] = []
        self._through: list[tuple[str | Path, bytes]] = []

    def stage(self, path: str | Path, data: str | bytes) -> None:
        """Write ``data`` for ``path`` to its temporary (or keep it, for a device).

        Raises:
            CamtoolError: the temporary cannot be written, naming ``path`` and why.
        """
        try:
            st: os.stat_result | None = os.stat(path)
        except FileNotFoundError:
            st = None
        except OSError as exc:
            raise CamtoolError(f"{path}: cannot write ({reason(exc)})") from exc
        if st is not None and stat.S_ISDIR(st.st_mode):
            raise CamtoolError(f"{path}: cannot write (is a directory)")
        if st is not None and not stat.S_ISREG(st.st_mode):
            self._through.append((path, data.encode("utf-8") if isinstance(data, str) else data))
            return
        target = Path(os.path.realpath(path))
        tmp = temp_path(target)
        try:
            remove_stale_temps(target.parent)
            fd = _create(tmp)
            try:
                if st is not None:
                    os.fchmod(fd, stat.S_IMODE(st.st_mode))
                _write_all(fd, data)
                os.fsync(fd)
            finally:
                os.close(fd)
        except BaseException as exc:  # an error, Ctrl-C or SIGTERM: no temporary left
            tmp.unlink(missing_ok=True)
            if isinstance(exc, OSError):
                raise CamtoolError(f"{path}: cannot write ({reason(exc)})") from exc
            raise
        self._renames.append((tmp, target))

    def publish(self) -> None:
        """Write the devices, then rename every staged file into place.

        Raises:
            CamtoolError: a device write (then no file is published) or a rename failed,
                naming the file.
        """
        for path, payload in self._through:
            try:
                _write_through(path, payload)
            except OSError as exc:
                self.discard()
                raise CamtoolError(f"{path}: cannot write ({reason(exc)})") from exc
        renames, self._renames = self._renames, []
        for tmp, target in renames:
            try:
                os.replace(tmp, target)
            except OSError as exc:
                for left, _ in renames:
                    left.unlink(missing_ok=True)
                raise CamtoolError(f"{target}: cannot write ({reason(exc)})") from exc

    def discard(self) -> None:
        """Remove every staged temporary: nothing of the run is published."""
        for tmp, _ in self._renames:
            tmp.unlink(missing_ok=True)
        self._renames, self._through = [], []


class _Index:
    """Named paths by real path and by (device, inode): a clash is found in O(1)."""

    def __init__(self) -> None:
        self.by_path: dict[str, tuple[str, str]] = {}
        self.by_inode: dict[tuple[int, int], tuple[str, str]] = {}

    def add(self, path: str, named: tuple[str, str], key: _Key | None = None) -> None:
        real, inode = key or _identity(path)
        self.by_path.setdefault(real, named)
        if inode is not None:
            self.by_inode.setdefault(inode, named)

    def find(self, key: _Key) -> tuple[str, str] | None:
        real, inode = key
        found = self.by_path.get(real)
        if found is None and inode is not None:
            found = self.by_inode.get(inode)
        return found


def _named(items: Iterable[Named]) -> Iterator[tuple[str, str]]:
    for label, path in items:
        if path is not None and str(path) != "":
            yield label, str(path)


_Key = tuple[str, tuple[int, int] | None]
"""A path's identity: its real path, and its (device, inode) when it exists."""


def _stdin_file() -> tuple[int, int] | None:
    """``(device, inode)`` of the regular file standard input reads, or ``None``."""
    try:
        st = os.fstat(0)
    except OSError:
        return None
    return (st.st_dev, st.st_ino) if stat.S_ISREG(st.st_mode) else None


def _identity(path: str | Path) -> _Key:
    """``(realpath, (device, inode) or None)`` of ``path``."""
    try:
        st = os.stat(path)
    except (OSError, ValueError):  # missing, or a name the OS refuses: compared by name
        return (os.path.realpath(path), None)
    return (os.path.realpath(path), (st.st_dev, st.st_ino))


def write_atomic(path: str | Path, data: str | bytes) -> None:
    r"""Write ``data`` to ``path``; a reader never sees a half-written regular file.

    Text is written as UTF-8 with ``\\n`` line ends. What ``path`` is decides how:

    - a regular file, or nothing yet: a temporary ``.NAME.camtool-PID.tmp`` in the same
      directory, written, flushed to disk (``fsync``) and renamed over ``path``. A new
      file gets the permissions ``open()`` would give it (0666 less the umask); a
      replaced one keeps its own;
    - a symlink: the same, at its target (the link stays a link);
    - anything else that exists (a character or block device such as ``/dev/null`` or
      ``/dev/stdout``, a FIFO): opened and written through, never replaced. Opening a
      FIFO waits for its reader, as a shell redirection does.

    The directory must exist.

    Raises:
        OSError: the directory is missing or not writable, ``path`` is a directory,
            or the write fails (``ENOSPC`` on a full disk or ``/dev/full``); a
            temporary file is removed again.
    """
    try:
        st: os.stat_result | None = os.stat(path)
    except FileNotFoundError:
        st = None
    if st is not None and stat.S_ISDIR(st.st_mode):
        raise IsADirectoryError(errno.EISDIR, "is a directory", str(path))
    if st is not None and not stat.S_ISREG(st.st_mode):
        _write_through(path, data.encode("utf-8") if isinstance(data, str) else data)
        return
    mode = stat.S_IMODE(st.st_mode) if st is not None else None
    _replace(Path(os.path.realpath(path)), data, mode)


def _write_through(path: str | Path, payload: bytes) -> None:
    """Open ``path`` (a device or FIFO) for writing and write all of ``payload``."""
    fd = os.open(path, os.O_WRONLY | os.O_CLOEXEC)
    try:
        view = memoryview(payload)
        while view:
            view = view[os.write(fd, view) :]
    finally:
        os.close(fd)


def _write_all(fd: int, data: str | bytes) -> None:
    """All of ``data`` to ``fd``; text encoded as UTF-8 a slice at a time.

    A slice of :data:`ENCODE_CHARS` characters is encoded, written and dropped, so a
    program's text is never held a second time as one whole ``bytes`` (the encoding of
    the slices joined is the encoding of the whole: UTF-8 encodes each character alone).
    """
    if isinstance(data, bytes):
        view = memoryview(data)
        while view:
            view = view[os.write(fd, view) :]
        return
    for start in range(0, len(data), ENCODE_CHARS):
        view = memoryview(data[start : start + ENCODE_CHARS].encode("utf-8"))
        while view:
            view = view[os.write(fd, view) :]


ENCODE_CHARS = 1 << 20
"""Characters of text encoded at a time when a file is written (:func:`_write_all`)."""


def _replace(target: Path, data: str | bytes, mode: int | None) -> None:
    """Write ``data`` to a temporary file beside ``target`` and rename it over it."""
    tmp = temp_path(target)
    fd = _create(tmp)
    try:
        try:
            if mode is not None:
                os.fchmod(fd, mode)
            _write_all(fd, data)
            os.fsync(fd)
        finally:
            os.close(fd)
        os.replace(tmp, target)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise


def temp_path(target: Path) -> Path:
    """The temporary file of this process for ``target``: ``.NAME.camtool-PID.tmp`` beside it."""
    return target.with_name(f".{target.name}.camtool-{os.getpid()}.tmp")


def _create(tmp: Path) -> int:
    """Create ``tmp`` exclusively (mode 0666 less the umask); an old one of our pid is stale."""
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_CLOEXEC
    try:
        return os.open(tmp, flags, 0o666)
    except FileExistsError:  # left by a dead process that had our pid: this process is not
        tmp.unlink()  # writing it (one output at a time), so it is stale
        return os.open(tmp, flags, 0o666)


def remove_stale_temps(directory: str | Path) -> tuple[Path, ...]:
    """Remove the temporary files in ``directory`` whose writing process is gone.

    A file named like :data:`TEMP_PATTERN` is camtool's; it is stale when no process
    with its PID exists on this host (a run killed with ``kill -9`` or by a power
    cut). Files of a live process (or of a PID now reused) are left alone. A missing
    directory has none.

    Returns:
        The files removed.

    Raises:
        OSError: the directory cannot be listed or a stale file removed (permissions).
    """
    try:
        entries = list(os.scandir(directory))
    except (FileNotFoundError, NotADirectoryError):
        return ()
    removed = []
    for entry in entries:
        match = TEMP_PATTERN.match(entry.name)
        if match and entry.is_file(follow_symlinks=False) and not _alive(int(match["pid"])):
            Path(entry.path).unlink(missing_ok=True)
            removed.append(Path(entry.path))
    return tuple(removed)


def _alive(pid: int) -> bool:
    """True when a process ``pid`` exists (this one counts; a zombie does not)."""
    if pid == os.getpid():
        return True
    if pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # someone else's process: alive
        return True
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except (OSError, IndexError):
        return True  # no /proc (not Linux): it answered the signal
    return fields[0] != "Z"


@contextmanager
def lock_directory(directory: str | Path, *, what: str = "-o") -> Iterator[Path]:
    """Claim ``directory`` for this run: an exclusive ``flock`` on its :data:`LOCK_NAME`.

    The folder is created when missing. The lock file holds this process's PID (for
    the message another run shows) and is removed when the block ends; a run killed
    with ``kill -9`` leaves it, unlocked, and the next run takes it over (the kernel
    drops a dead process's locks).

    Args:
        directory: the output folder.
        what: the option that named it, for the message.

    Yields:
        The lock file.

    Raises:
        CamtoolError: another run holds the folder (not even ``--force`` overrides it),
            or the folder or its lock file cannot be created.
    """
    import fcntl

    folder = Path(directory)
    lock = folder / LOCK_NAME
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise CamtoolError(f"{folder}: cannot write ({reason(exc)})") from exc
    fd = _take_lock(lock, what)
    try:
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{os.getpid()}\n".encode("ascii"), 0)
        yield lock
    finally:
        lock.unlink(missing_ok=True)  # still locked: a run that opened it retries
        fcntl.flock(fd, fcntl.LOCK_UN)
        os.close(fd)


def _take_lock(lock: Path, what: str) -> int:
    """An open, ``flock``-ed descriptor of ``lock`` that is still the file at that name.

    A run releasing the lock unlinks the file first, so a lock taken on a file that
    is no longer ``lock`` is worthless: try again on the new one.
    """
    import fcntl

    while True:
        try:
            fd = os.open(lock, os.O_RDWR | os.O_CREAT | os.O_CLOEXEC, 0o666)
        except OSError as exc:
            raise CamtoolError(f"{lock}: cannot write ({reason(exc)})") from exc
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            owner = os.pread(fd, 32, 0).decode("ascii", "replace").strip()
            os.close(fd)
            by = f" (pid {owner})" if owner.isdigit() else ""
            raise CamtoolError(
                f"{what} {lock.parent}: another camtool run{by} is writing into this folder; "
                f"wait for it to finish, or choose another {what}"
            ) from None
        try:
            same = os.path.samestat(os.fstat(fd), os.stat(lock))
        except FileNotFoundError:
            same = False
        if same:
            return fd
        os.close(fd)


def reason(exc: OSError) -> str:
    """Why ``exc`` happened, for a message: ``no space left on device``."""
    text = exc.strerror or str(exc)
    return text[:1].lower() + text[1:]
