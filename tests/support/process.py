"""Child processes with a bound on every wait.

subprocess.run(..., capture_output=True, timeout=T) is not bounded: after
the timeout it kills the child, then reads its pipes to the end, and a
grandchild that inherited them (a server the child started) keeps them open
for ever. Here the child gets a session of its own, its output goes to
files, and on timeout the whole session is killed."""

import os
import signal
import subprocess
import tempfile
from dataclasses import dataclass


@dataclass
class Finished:
    args: list
    returncode: int
    stdout: str
    stderr: str


class Timeout(AssertionError):
    """A wait ran out; the message says what was waited for."""


def tail(text, limit=3000):
    return text if len(text) <= limit else "..." + text[-limit:]


def kill_session(process):
    """SIGKILL the process's session (it and everything it started)."""
    try:
        os.killpg(process.pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass
    try:
        process.wait(timeout=30)
    except subprocess.TimeoutExpired:
        pass


LIVE = set()  # the sessions run() is waiting for, from any thread


def kill_all():
    """Kill every session run() is waiting for (a caller that is itself stopped leaves none behind)."""
    for process in list(LIVE):
        kill_session(process)


def run(args, *, timeout, what, check=False, **popen):
    """Run args to the end within timeout seconds, output kept as text.
    Timeout: the session is killed and Timeout raised, naming what and
    showing the output so far. check: a non-zero exit raises an
    AssertionError with the output."""
    with tempfile.TemporaryFile() as out, tempfile.TemporaryFile() as err:
        stdin = popen.pop("stdin", subprocess.DEVNULL)  # a file to read, or nothing
        process = subprocess.Popen(args, stdin=stdin, stdout=out, stderr=err, start_new_session=True, **popen)
        LIVE.add(process)
        try:
            process.wait(timeout=timeout)
            timed_out = False
        except subprocess.TimeoutExpired:
            timed_out = True
        finally:
            LIVE.discard(process)
        # anything the child left running in its session goes with it
        kill_session(process)
        out.seek(0)
        err.seek(0)
        stdout = out.read().decode(errors="replace")
        stderr = err.read().decode(errors="replace")
    if timed_out:
        raise Timeout(
            f"{what}: no end within {timeout} s, killed\n"
            f"command: {' '.join(map(str, args))}\nstdout:\n{tail(stdout)}\nstderr:\n{tail(stderr)}"
        )
    finished = Finished(list(args), process.returncode, stdout, stderr)
    if check and finished.returncode != 0:
        raise AssertionError(
            f"{what}: exit status {finished.returncode}\n"
            f"command: {' '.join(map(str, args))}\nstdout:\n{tail(stdout)}\nstderr:\n{tail(stderr)}"
        )
    return finished
