"""A helper process started ahead: it loads a slow library on an idle core, then answers once.

A command that will need a slow import late (matplotlib for a PNG: ~0.3 s) forks a
:class:`Helper` early; told to :meth:`~Helper.load` where this process leaves a core idle, it
imports what it needs; asked once, it answers and leaves. An answer may come in parts
(:meth:`~Helper.parts`), each taken as this process needs it while the helper makes the
next. Where there is no ``fork``, in a worker process, when the fork fails or the helper
dies, the caller does the work itself (the same answer). :class:`HelperAhead` holds a
process's one helper of a kind.
"""

from __future__ import annotations

import contextlib
import os
import signal
import time
from collections.abc import Callable, Generator, Iterable

from camtool.accel.cores import (
    FORK,
    end_process,
    fork_with_pipes,
    in_worker,
    patience,
    quiet_crashes,
    read_record,
    write_record,
)

_LOAD = b"L"
"""The byte that tells the helper to load (then a request may follow)."""


class Helper:
    """The forked helper and this process's ends of its two pipes.

    Args:
        prepare: run in the helper when it is told to load (an import).
        answer: run in the helper on the one request's bytes; its bytes are sent back, or
            each of the parts it yields, in order (for :meth:`parts`).

    Raises:
        OSError: it cannot be forked now (:func:`~camtool.accel.cores.fork_with_pipes`).
    """

    def __init__(
        self, prepare: Callable[[], None], answer: Callable[[bytes], bytes | Iterable[bytes]]
    ) -> None:
        def serve(inbox: int, out: int) -> None:  # in the helper
            signal.signal(signal.SIGINT, signal.SIG_IGN)  # the parent handles Ctrl-C
            quiet_crashes()
            if os.read(inbox, 1) != _LOAD:
                return  # the pipe ended first: the job ended or failed
            prepare()
            data = read_record(inbox)
            if data is not None:
                answered = answer(data)
                for part in [answered] if isinstance(answered, bytes) else answered:
                    write_record(out, part)

        pid, inbox, out = fork_with_pipes(serve)
        self.started = time.monotonic()
        self.pid: int | None = pid
        self.inbox: int | None = inbox
        self.out: int | None = out
        self.loading = False

    def fds(self) -> tuple[int, ...]:
        """This process's ends of the pipes, while open."""
        return tuple(fd for fd in (self.inbox, self.out) if fd is not None)

    def load(self) -> None:
        """Have it load now (once; a dead helper is found by :meth:`ask`)."""
        if not self.loading and self.inbox is not None:
            self.loading = True
            with contextlib.suppress(OSError):
                os.write(self.inbox, _LOAD)

    def ask(self, request: bytes) -> bytes | None:
        """Its answer to ``request``; ``None`` when it could not send one. It then leaves."""
        self.load()
        assert self.inbox is not None and self.out is not None
        try:
            write_record(self.inbox, request)
            return read_record(self.out)
        except Exception:  # it died before it read the request, or cut its answer short
            return None
        finally:
            self.close()

    def parts(self, request: bytes, count: int) -> Generator[bytes, None, None]:
        """The ``count`` parts of its answer to ``request``, each read when asked for.

        The request is sent now; each part is waited for until
        :func:`~camtool.accel.cores.patience` from the fork. The parts stop early where it
        sent no more (it died, or hung). It leaves after the last part, or when the
        iteration is closed (or :meth:`close` is called).
        """
        self.load()
        assert self.inbox is not None and self.out is not None
        out = self.out
        try:
            write_record(self.inbox, request)
        except OSError:  # it died before it read the request: no parts
            self.close()
        return self._parts(out, count)

    def _parts(self, out: int, count: int) -> Generator[bytes, None, None]:
        try:
            for _ in range(count):
                if self.out != out:  # closed meanwhile: the fd may be another file's now
                    return
                part = read_record(out, patience(self.started))
                if part is None:
                    return
                yield part
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


class HelperAhead:
    """A process's one :class:`Helper` of a kind: started ahead, used by one request.

    Args:
        prepare: the helper's load (see :class:`Helper`).
        answer: the helper's answer (see :class:`Helper`).

    Attributes:
        helper: the helper started and not yet used, else ``None``.
    """

    def __init__(
        self, prepare: Callable[[], None], answer: Callable[[bytes], bytes | Iterable[bytes]]
    ) -> None:
        self.prepare, self.answer = prepare, answer
        self.helper: Helper | None = None
        self._hooked = False

    def start(self) -> None:
        """Start the helper (Linux; one at a time).

        Nothing is started without ``fork``, in a worker process (a batch's or Dask's,
        whose cores are busy with other files) or when the fork fails (a process limit,
        no memory): the caller then does the work itself.
        """
        if not FORK or self.helper is not None or in_worker():
            return
        if not self._hooked:  # once, and only in a process that starts a helper
            os.register_at_fork(after_in_child=self._forget_in_child)
            self._hooked = True
        with contextlib.suppress(OSError):  # no fork now: the work is done here
            self.helper = Helper(self.prepare, self.answer)

    def load(self) -> None:
        """Tell the helper to load now: call it where this process leaves a core idle."""
        if self.helper is not None:
            self.helper.load()

    def ask(self, request: bytes) -> bytes | None:
        """The helper's answer (it then leaves); ``None``: no helper, or no answer."""
        helper, self.helper = self.helper, None
        return None if helper is None else helper.ask(request)

    def parts(self, request: bytes, count: int) -> Generator[bytes, None, None] | None:
        """The helper's answer in ``count`` parts (:meth:`Helper.parts`); ``None``: no helper.

        The helper stays this object's (:meth:`stop` ends it) until its last part is read.
        """
        helper = self.helper
        if helper is None:
            return None
        parts = helper.parts(request, count)

        def taken() -> Generator[bytes, None, None]:
            try:
                yield from parts
            finally:
                if self.helper is helper:
                    self.helper = None

        return taken()

    def stop(self) -> None:
        """End the helper if it was not used or its parts not all read (idempotent).

        A command's ``finally``.
        """
        helper, self.helper = self.helper, None
        if helper is not None:
            helper.close()

    def _forget_in_child(self) -> None:
        """In a process forked after the helper: close this process's ends of its pipes."""
        if self.helper is not None:
            for fd in self.helper.fds():
                with contextlib.suppress(OSError):
                    os.close(fd)
        self.helper = None
