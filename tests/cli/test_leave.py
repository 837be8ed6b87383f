"""The command line leaves without the interpreter's teardown, but does what an exit must.

:func:`camtool.__main__.leave` (issue 17: 0.15 s after a big verify): the exit functions
run, buffered output reaches stdout and stderr, the exit code is the command's; with
another thread alive it is Python's own exit, which waits for it, unless that thread is a
daemon (the progress line's timer), which Python's own exit does not wait for either.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap


def _run(code: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)],
        capture_output=True,
        text=True,
        timeout=60,
    )


def test_leave_runs_the_exit_functions_and_flushes() -> None:
    done = _run(
        """
        import atexit, sys, tempfile
        from camtool.__main__ import leave
        atexit.register(print, "exit function", file=sys.stderr)
        d = tempfile.TemporaryDirectory()
        print(d.name, file=sys.stderr)
        sys.stdout.write("data without a newline")
        leave(4)
        """
    )
    assert done.returncode == 4
    assert done.stdout == "data without a newline"
    name, said = done.stderr.splitlines()[:2]
    assert said == "exit function"
    assert not os.path.exists(name)  # tempfile's finalizer ran


def test_leave_waits_for_a_thread_still_running() -> None:
    done = _run(
        """
        import threading, time, sys
        from camtool.__main__ import leave
        def late():
            time.sleep(0.3)
            print("thread done", flush=True)
        threading.Thread(target=late).start()
        leave(5)
        """
    )
    assert done.returncode == 5
    assert done.stdout == "thread done\n"


def test_a_daemon_thread_does_not_bring_back_the_teardown() -> None:
    # the teardown clears the modules' globals, so the object's __del__ would print
    done = _run(
        """
        import threading, time
        from camtool.__main__ import leave
        class Torn:
            def __del__(self):
                print("torn down", flush=True)
        kept = Torn()
        threading.Thread(target=time.sleep, args=(30,), daemon=True).start()
        leave(6)
        """
    )
    assert done.returncode == 6
    assert "torn down" not in done.stdout


def test_the_console_script_leaves_with_the_commands_code() -> None:
    done = subprocess.run(
        [sys.executable, "-m", "camtool", "verify", "/no/such/file.pic", "-t", "pic-mmh"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 3
    assert done.stderr.startswith("camtool: error: /no/such/file.pic")
