"""Cases in child processes, so that a case whose FMU crashes the process
or hangs is reported by itself and the others still run.

`run_isolated` starts a Python child running `main` below, sends it the cases
(pickled, on standard input) and reads back one outcome per case as it
finishes (length-prefixed pickles on the child's own copy of standard
output; what the FMU prints goes nowhere). When the child dies, the case it
was running gets an error naming the signal; when a case runs longer than
the per-case timeout, the child is killed and the case gets an error
saying so. Either way a new child takes the cases after it. The child says
when it starts each case (an empty record): the timeout counts from there,
so a child's start-up (imports, the FMU unpacked), slow on a loaded
machine, is never charged to a case.
"""

import ctypes
import os
import pickle
import queue
import signal
import struct
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

from ._fmu import UNPACK_ROOT, unpack_root
from ._outcome import CaseOutcome, Status
from ._worker import CaseSettings, FmuFile, run_cases

HEADER = struct.Struct("!Q")
PR_SET_PDEATHSIG = 1  # prctl(2)
PARENT = "FMUTRACE_PARENT_PID"  # in a child's environment: the process whose child it is (it dies with it)
CHILD = "import sys, fmutrace._isolated; sys.exit(fmutrace._isolated.main())"


def _package_root():
    """The folder (or zip) fmutrace is imported from: the child's PYTHONPATH."""
    return str(Path(__file__).resolve().parent.parent)


def _last_words(file):
    """'; it said: <its last line>' of what a dead child wrote to stderr."""
    file.seek(0)
    lines = [line.strip() for line in file.read()[-4000:].decode(errors="replace").splitlines() if line.strip()]
    return f"; it said: {lines[-1][:200]}" if lines else ""


STARTED = b""  # the child's message that it starts its next case (an empty record)
# the most a child may take to start a case (its Python, NumPy and fmpy imports the first time): a case's timeout
# counts from its start, so that a loaded machine's slow start-up is not charged to a case
START_SECONDS = 300.0


def _reader(stream, out):
    """Records from the child into out (STARTED, or an outcome); None at its end."""
    try:
        while True:
            header = stream.read(HEADER.size)
            if len(header) < HEADER.size:
                break
            size = HEADER.unpack(header)[0]
            out.put(pickle.loads(stream.read(size)) if size else STARTED)
    finally:
        out.put(None)


def run_isolated(items, fmu_bytes, fmu: FmuFile, settings: CaseSettings, on_outcome=None):
    """[outcome] of items [(folder, name, texts)], the cases in a child
    process; a crash or a case over settings.case_timeout seconds (None:
    no bound) fails that case only. on_outcome(outcome), if given, hears
    of each as it arrives."""
    labels, case_timeout = fmu.labels, settings.case_timeout
    outcomes = []
    remaining = list(items)
    environment = dict(
        os.environ,
        PYTHONPATH=os.pathsep.join(
            [_package_root()] + ([os.environ["PYTHONPATH"]] if os.environ.get("PYTHONPATH") else [])
        ),
        **{UNPACK_ROOT: unpack_root()},  # a child killed leaves its unpacked FMU to this process
        **{PARENT: str(os.getpid())},
    )
    while remaining:
        said = tempfile.TemporaryFile()  # the child's last words, if it dies
        child = subprocess.Popen(
            [sys.executable, "-c", CHILD], stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=said, env=environment
        )
        assert child.stdin is not None  # (a pipe: stdin=PIPE)
        child.stdin.write(pickle.dumps((remaining, fmu_bytes, fmu, settings)))
        child.stdin.close()
        arrived: queue.Queue = queue.Queue()
        threading.Thread(target=_reader, args=(child.stdout, arrived), daemon=True).start()
        for index, (_, name, _) in enumerate(remaining):
            started, running = time.monotonic(), False
            try:
                outcome = arrived.get(timeout=START_SECONDS)
                if outcome is STARTED:
                    started, running = time.monotonic(), True
                    outcome = arrived.get(timeout=case_timeout)
            except queue.Empty:
                child.kill()
                child.wait()
                why = (
                    f"stopped after the per-case timeout of {case_timeout:g} s"
                    if running
                    else f"the simulation's process did not start the case within {START_SECONDS:g} s"
                )
                outcome = CaseOutcome(
                    name, **labels, status=Status.ERROR, messages=[why], seconds=time.monotonic() - started
                )
            if outcome is None:  # the child died running this case
                code = child.wait()
                cause = f"killed by signal {signal.Signals(-code).name}" if code < 0 else f"exited with status {code}"
                outcome = CaseOutcome(
                    name,
                    **labels,
                    status=Status.ERROR,
                    messages=[f"the simulation's process was {cause} while running this case" + _last_words(said)],
                    seconds=time.monotonic() - started,
                )
            outcomes.append(outcome)
            if on_outcome:
                on_outcome(outcome)
            if outcome.status == Status.ERROR and child.poll() is not None:
                remaining = remaining[index + 1 :]
                break
        else:
            remaining = []
            child.wait()
    return outcomes


def _die_with_parent():
    """On Linux the kernel kills this child when the thread that started it
    ends, however it ends (a command killed with SIGKILL included): a case
    that hangs in the FMU does not spin on alone. (That thread waits for the
    child: run_isolated.)"""
    if not sys.platform.startswith("linux"):
        return
    libc = ctypes.CDLL(None, use_errno=True)
    libc.prctl(PR_SET_PDEATHSIG, signal.SIGKILL)
    if str(os.getppid()) != os.environ.get(PARENT):  # the parent was gone before the line above
        os._exit(1)


def main():
    """The child: the cases from standard input, the outcomes out as they finish."""
    _die_with_parent()
    out = os.fdopen(os.dup(1), "wb")
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)  # what the FMU or fmpy prints must not mix with the outcomes

    def started():
        out.write(HEADER.pack(0))
        out.flush()

    items, fmu_bytes, fmu, settings = pickle.loads(sys.stdin.buffer.read())
    for outcome in run_cases(items, fmu_bytes, fmu, settings, on_start=started):
        data = pickle.dumps(outcome)
        out.write(HEADER.pack(len(data)) + data)
        out.flush()
    return 0
