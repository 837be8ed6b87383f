"""A helper process started ahead: it loads a slow library on an idle core, then answers once.

A command that will need a slow import late (matplotlib for a PNG: ~0.3 s) forks a
:class:`Helper` early; told to :meth:`~Helper.load` where this process leaves a core idle, it
imports what it needs; asked once, it answers and leaves. A streamed helper takes requests
as this process makes them (:meth:`~Helper.send`) and answers each in parts, which this
process takes as it needs them (:meth:`~Helper.take`) while the helper makes the next.
Where there is no ``fork``, in a worker process, when the fork fails or the helper dies,
the caller does the work itself (the same answer). :class:`HelperAhead` holds a process's
one helper of a kind.
"""

from __future__ import annotations

import contextlib
import os
import queue
import signal
import threading
import time
from collections.abc import Callable, Iterator
from typing import Any

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
        answer: run in the helper on the one request's bytes; its bytes are sent back. A
            ``streamed`` helper's runs on the requests as they come (an iterator, ended by
            :meth:`end`) and yields the parts of its answers, each sent back as it comes.
        streamed: requests and answers by parts (:meth:`send`, :meth:`end`, :meth:`take`)
            rather than one :meth:`ask`.

    Raises:
        OSError: it cannot be forked now (:func:`~camtool.accel.cores.fork_with_pipes`).
    """

    def __init__(
        self, prepare: Callable[[], None], answer: Callable[[Any], Any], *, streamed: bool = False
    ) -> None:
        def serve(inbox: int, out: int) -> None:  # in the helper
            signal.signal(signal.SIGINT, signal.SIG_IGN)  # the parent handles Ctrl-C
            quiet_crashes()
            if os.read(inbox, 1) != _LOAD:
                return  # the pipe ended first: the job ended or failed
            if streamed:
                requests = _requests(inbox)  # read as they come, even while loading
                prepare()
                for part in answer(requests):
                    write_record(out, part)
                return
            prepare()
            data = read_record(inbox)
            if data is not None:
                write_record(out, answer(data))

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

    def send(self, request: bytes) -> bool:
        """Send a streamed helper one more request; ``False`` (and it is ended) if it died."""
        self.load()
        if self.inbox is None:
            return False
        try:
            write_record(self.inbox, request)
        except OSError:
            self.close()
            return False
        return True

    def end(self) -> bool:
        """Tell a streamed helper that no request follows (:meth:`send`)."""
        return self.send(b"")

    def take(self) -> bytes | None:
        """A streamed helper's next part, in the order it made them.

        Waited for until :func:`~camtool.accel.cores.patience` from the fork; ``None`` when
        it sends no more (it died, hung, or was ended): it is then ended.
        """
        part = None if self.out is None else read_record(self.out, patience(self.started))
        if part is None:
            self.close()
        return part

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
        self, prepare: Callable[[], None], answer: Callable[[Any], Any], *, streamed: bool = False
    ) -> None:
        self.prepare, self.answer, self.streamed = prepare, answer, streamed
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
            self.helper = Helper(self.prepare, self.answer, streamed=self.streamed)

    def load(self) -> None:
        """Tell the helper to load now: call it where this process leaves a core idle."""
        if self.helper is not None:
            self.helper.load()

    def ask(self, request: bytes) -> bytes | None:
        """The helper's answer (it then leaves); ``None``: no helper, or no answer."""
        helper, self.helper = self.helper, None
        return None if helper is None else helper.ask(request)

    def send(self, request: bytes) -> bool:
        """:meth:`Helper.send` to the streamed helper; ``False``: no helper (any more)."""
        return self.helper is not None and self._kept(self.helper.send(request))

    def end(self) -> bool:
        """:meth:`Helper.end`; ``False``: no helper (any more)."""
        return self.helper is not None and self._kept(self.helper.end())

    def take(self) -> bytes | None:
        """:meth:`Helper.take`; ``None``: no helper (any more), or no more parts."""
        part = None if self.helper is None else self.helper.take()
        self._kept(part is not None)
        return part

    def _kept(self, alive: bool) -> bool:
        """``alive``, the helper dropped (it was ended) when not."""
        if not alive:
            self.stop()
        return alive

    def stop(self) -> None:
        """End the helper if it was not used or its parts not all taken (idempotent).

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


def _requests(inbox: int) -> Iterator[bytes]:
    """In a streamed helper: the requests from ``inbox`` in order, read by a thread.

    The thread reads each as it comes, so this process's :meth:`Helper.send` never waits
    for the helper to take the last request (while it writes a part this process has not
    taken yet, both would wait for ever). It ends at the empty request (:meth:`Helper.end`)
    or at the end of the pipe.
    """
    arrived: queue.SimpleQueue[bytes | None] = queue.SimpleQueue()

    def read() -> None:
        while True:
            request = read_record(inbox)
            arrived.put(request or None)
            if not request:
                return

    threading.Thread(target=read, daemon=True).start()
    return iter(arrived.get, None)
