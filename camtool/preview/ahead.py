"""A child that will draw this job's PNG, started ahead so matplotlib loads on an idle core.

Design notes: docs/internals.md, ``camtool/preview/ahead.py``.
"""

from __future__ import annotations

import contextlib
import os
import pickle
import signal
from typing import TYPE_CHECKING

from camtool.accel.cores import (
    FORK,
    end_process,
    fork_with_pipes,
    in_worker,
    quiet_crashes,
    read_record,
    write_record,
)

if TYPE_CHECKING:
    from camtool.preview.scene import Scene

__all__ = ["draw_ahead", "load_ahead", "start_ahead", "stop_ahead"]

_LOAD = b"L"
"""The byte that tells the child to load matplotlib (then a scene may follow)."""


class _Drawer:
    """The forked child (:func:`_serve`) and this process's ends of its two pipes."""

    def __init__(self) -> None:
        """Fork it.

        Raises:
            OSError: it cannot be forked now (:func:`~camtool.accel.cores.fork_with_pipes`).
        """
        pid, inbox, out = fork_with_pipes(_serve)
        self.pid: int | None = pid
        self.inbox: int | None = inbox
        self.out: int | None = out
        self.loading = False

    def fds(self) -> tuple[int, ...]:
        """This process's ends of the pipes, while open."""
        return tuple(fd for fd in (self.inbox, self.out) if fd is not None)

    def load(self) -> None:
        """Have it load matplotlib now (once; a dead child is found by :meth:`draw`)."""
        if not self.loading and self.inbox is not None:
            self.loading = True
            with contextlib.suppress(OSError):
                os.write(self.inbox, _LOAD)

    def draw(self, scene: Scene) -> bytes | None:
        """The PNG bytes it draws for ``scene``; ``None`` when it could not send them."""
        self.load()
        assert self.inbox is not None and self.out is not None
        try:
            write_record(self.inbox, pickle.dumps(scene, protocol=pickle.HIGHEST_PROTOCOL))
            return read_record(self.out)
        except Exception:  # it died before it read the scene, or the scene did not pickle
            return None
        finally:
            self.close()

    def close(self) -> None:
        """Close the pipes, end it (if it has not) and wait for it (idempotent)."""
        for fd in self.fds():
            with contextlib.suppress(OSError):
                os.close(fd)
        self.inbox = self.out = None
        if self.pid is not None:
            with contextlib.suppress(ChildProcessError):  # a test waited for it already
                end_process(self.pid, kill=True)
            self.pid = None


def _serve(inbox: int, out: int) -> None:
    """In the child: wait for the word to load matplotlib, load it, draw the scene sent.

    It leaves, without drawing, when ``inbox`` ends first (the job ended or failed).
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the parent handles Ctrl-C and ends it
    quiet_crashes()
    if os.read(inbox, 1) != _LOAD:
        return
    from camtool.preview.raster import preload, scene_png

    preload()
    data = read_record(inbox)
    if data is not None:
        write_record(out, scene_png(pickle.loads(data)))


_AHEAD: list[_Drawer] = []
"""The child :func:`start_ahead` started, until :func:`draw_ahead` uses it (at most one)."""
_HOOKED: list[bool] = []
"""Whether :func:`_close_in_forked_child` is registered to run in every later fork."""


def start_ahead() -> None:
    """Start the child that will draw this process's next PNG (Linux; once at a time).

    Nothing is started without ``fork``, in a worker process (a batch's or Dask's, whose
    cores are busy with other files) or when the fork fails (a process limit, no memory):
    the picture is then drawn here, as before.
    """
    if FORK and not _AHEAD and not in_worker():
        if not _HOOKED:  # once, and only in a process that starts a child
            os.register_at_fork(after_in_child=_close_in_forked_child)
            _HOOKED.append(True)
        with contextlib.suppress(OSError):  # no fork now: the picture is drawn here
            _AHEAD.append(_Drawer())


def load_ahead() -> None:
    """Tell the child to load matplotlib now: call it where this process leaves a core idle."""
    for drawer in _AHEAD:
        drawer.load()


def draw_ahead(scene: Scene) -> bytes | None:
    """The PNG bytes of ``scene`` drawn by the child, which then leaves.

    ``None`` when there is no child, or it sent nothing back: the caller draws it itself
    (:func:`camtool.preview.raster.scene_png`), the same bytes.
    """
    if not _AHEAD:
        return None
    return _AHEAD.pop().draw(scene)


def stop_ahead() -> None:
    """End the child if it was not used (idempotent; a command's ``finally``)."""
    while _AHEAD:
        _AHEAD.pop().close()


def _close_in_forked_child() -> None:
    """In a process forked after the child: close this process's ends of its pipes."""
    for drawer in _AHEAD:
        for fd in drawer.fds():
            with contextlib.suppress(OSError):
                os.close(fd)
    _AHEAD.clear()
