"""Cases in local worker processes: as many as pay for themselves, never
more than cores, and a case whose FMU crashes its process or hangs is
reported by itself while the others go on.

A worker is a child process: forked from this one where that is safe
(Linux, no other Python thread: it starts in milliseconds with fmutrace
already imported), else a new Python running `main` below (Windows,
macOS). It reads batches of cases on a multiprocessing Connection and
writes back each case's outcome, and an empty message when it starts a
case whose start matters (pickles; what the FMU prints goes nowhere).
This process, one thread, waits on every worker's Connection with
multiprocessing.connection.wait and a deadline (the standard library's
portable wait: Windows' select() takes sockets only): a worker whose
Connection closes died; a case over the per-case timeout gets its worker
killed. Either way the rest of the batch goes back to the queue and a new
worker takes over. The timeout counts from the case's start, so a
worker's start-up (slow on a loaded machine) is never charged to a case.

A case whose worker died (killed from outside, by the OOM killer or an
operator, or crashed by the FMU) runs again once, alone, on a fresh
worker, and fails only if it kills that one too: its outcome says why it
ran again (CaseOutcome.retried). A case stopped after the per-case
timeout is not run again (it hangs).

How many: `jobs` workers if asked, else one, and more once the first
outcomes show that the work left pays for their start-up (measured: the
first worker's, to its first case). Batches hold about BATCH_SECONDS of
measured work, fewer cases near the end so that the workers finish
together.
"""

import collections
import ctypes
import gc
import math
import multiprocessing.connection
import os
import pickle
import signal
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from multiprocessing import Pipe
from multiprocessing.connection import Connection, wait
from pathlib import Path

from ._errors import InputError
from ._fmu import UNPACK_ROOT, unpack_root
from ._outcome import CaseOutcome, Status
from ._plot import load_plotting
from ._worker import CaseSettings, plotting_first, run_cases

# the end of Pipe() a spawned worker gets by its number: a named pipe's handle on Windows, a socket's descriptor
# elsewhere
ParentEnd = getattr(multiprocessing.connection, "PipeConnection", Connection)

STARTED = b""  # a worker's message that it starts its next case (an empty one)
PR_SET_PDEATHSIG = 1  # prctl(2)
PARENT = "FMUTRACE_PARENT_PID"  # in a spawned worker's environment: the process whose child it is
CHILD = "import sys, fmutrace._workers; sys.exit(fmutrace._workers.main())"
# the most a worker may take to start a case (a new Python's imports, the FMU unpacked) on a loaded machine
START_SECONDS = 300.0
STOP_SECONDS = 60.0  # the most a worker told to end may take to exit before it is killed
BATCH_SECONDS = 0.25  # of measured work per batch: the round trip to the worker is a fraction of a millisecond
START_PAYS = 2.0  # another worker starts once the work left per worker exceeds so many times a start-up


def cores() -> int:
    """The cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # (not on every platform)
        return os.cpu_count() or 1


def can_fork() -> bool:
    """A forked worker is safe here: Linux (macOS's frameworks are not
    fork-safe, Windows has no fork) and no other Python thread, whose
    locks the child would inherit held."""
    return sys.platform.startswith("linux") and threading.active_count() == 1


class _Forked:
    """A forked worker's process, as subprocess.Popen gives a spawned one's
    (kill, wait, poll; only on Linux, where can_fork() forks)."""

    def __init__(self, pid: int):
        self.pid = pid
        self.returncode: int | None = None

    def poll(self) -> int | None:
        if self.returncode is None:
            pid, status = os.waitpid(self.pid, os.WNOHANG)
            if pid:
                self.returncode = os.waitstatus_to_exitcode(status)
        return self.returncode

    def wait(self, timeout: float) -> int:
        deadline = time.monotonic() + timeout
        while (code := self.poll()) is None:
            if time.monotonic() > deadline:
                raise subprocess.TimeoutExpired(str(self.pid), timeout)
            time.sleep(0.002)
        return code

    def kill(self):
        if self.poll() is None:
            os.kill(self.pid, signal.SIGKILL)  # (Linux alone forks)


@dataclass(eq=False)
class _Worker:
    process: "_Forked | subprocess.Popen"
    connection: Connection  # this side's
    said: object  # a file with what the worker wrote to stderr (its last words, if it dies)
    started: float = field(default_factory=time.monotonic)
    fmus: set = field(default_factory=set)  # the FMUs whose bytes it has
    batch: collections.deque = field(default_factory=collections.deque)  # its cases not finished (as in todo)
    running_since: float | None = None  # the case at batch[0] started then
    sent_at: float = 0.0
    last_words: str = ""  # what it wrote last to stderr, once it ended
    first_case: bool = True  # its next outcome is its first

    def end(self, kill: bool) -> int:
        """Its exit status as subprocess gives it (negative: the signal),
        once it has ended: at once (kill), or after its last batch (killed
        if it takes longer than STOP_SECONDS)."""
        if not kill:
            try:
                self.connection.send_bytes(pickle.dumps(None))
            except OSError:
                kill = True
        if not kill:
            try:
                return self.process.wait(timeout=STOP_SECONDS)
            except subprocess.TimeoutExpired:
                pass
        self.process.kill()
        return self.process.wait(timeout=STOP_SECONDS)

    def close(self):
        self.connection.close()
        self.said.close()  # type: ignore[attr-defined]


def _start_worker(settings: CaseSettings, others: list[_Worker]) -> _Worker:
    """A new worker, forked where can_fork() says it is safe, else spawned."""
    said = tempfile.TemporaryFile()
    here, there = Pipe()
    if can_fork():
        pid = os.fork()
        if pid == 0:  # the worker: nothing of this process's but its Connection, never back into its code
            gc.freeze()  # what it inherited stays shared: the collector's passes would copy every page of it
            code = 1
            try:
                for worker in others:
                    worker.connection.close()
                here.close()
                os.dup2(said.fileno(), 2)
                _serve(there, settings)
                code = 0
            except BaseException as error:  # (os._exit prints no traceback: its reason is its last words)
                os.write(2, f"{type(error).__name__}: {error}\n".encode(errors="replace"))
            finally:
                os._exit(code)
        there.close()
        return _Worker(_Forked(pid), here, said)
    process = _spawn(there, said)
    there.close()
    worker = _Worker(process, here, said)
    try:
        here.send_bytes(pickle.dumps(settings))
    except OSError:  # it died at once: its end shows on its Connection
        pass
    return worker


def _spawn(there: Connection, said) -> subprocess.Popen:
    """A new Python running main() with the Connection's other end (the
    handle or descriptor number its command line gives), inherited alone."""
    environment = dict(
        os.environ,
        PYTHONPATH=os.pathsep.join(
            [_package_root()] + ([os.environ["PYTHONPATH"]] if os.environ.get("PYTHONPATH") else [])
        ),
        **{UNPACK_ROOT: unpack_root(), PARENT: str(os.getpid())},
    )
    command = [sys.executable, "-c", CHILD, str(there.fileno())]
    inherit: dict = {"pass_fds": [there.fileno()]}  # the Connection's end, and nothing else, goes to the child
    if sys.platform == "win32":
        os.set_handle_inheritable(there.fileno(), True)
        inherit = {"startupinfo": subprocess.STARTUPINFO(lpAttributeList={"handle_list": [there.fileno()]})}
    return subprocess.Popen(
        command, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=said, env=environment, **inherit
    )


def _package_root():
    """The folder (or zip) fmutrace is imported from: a spawned worker's PYTHONPATH."""
    return str(Path(__file__).resolve().parent.parent)


def _serve(parent: Connection, settings: CaseSettings):
    """A worker's loop: batches in, an outcome per case out, until None;
    a STARTED message before a case where its start matters (every case
    with a per-case timeout, else the worker's first: its start-up ends
    there). A message fewer saves the campaign's process a wake-up."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the campaign's to handle (it stops its workers)
    _die_with_parent()
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)  # what the FMU or fmpy prints must not mix with the outcomes (or the command's output)
    fmus: dict[str, bytes] = {}
    first = [True]

    def started():
        if first[0] or settings.case_timeout is not None:
            parent.send_bytes(STARTED)
        first[0] = False

    while True:
        try:
            message = pickle.loads(parent.recv_bytes())
        except EOFError:
            return
        if message is None:
            return
        path, data, fmu, items = message
        if data is not None:
            fmus[path] = data
        try:
            for outcome in run_cases(items, fmus[path], fmu, settings, on_start=started):
                parent.send_bytes(pickle.dumps(outcome))
        except InputError as error:  # the FMU's, not a case's (it cannot be unpacked): the campaign's to raise
            parent.send_bytes(pickle.dumps(InputError(str(error))))  # (a TraceError's pickle would not load)
            return


def _die_with_parent():
    """On Linux the kernel kills a worker when the campaign's process ends,
    however it ends (SIGKILL included): a case that hangs in the FMU does
    not spin on alone."""
    if not sys.platform.startswith("linux"):
        return
    libc = ctypes.CDLL(None, use_errno=True)
    libc.prctl(PR_SET_PDEATHSIG, signal.SIGKILL)
    parent = os.environ.get(PARENT)
    if parent is not None and str(os.getppid()) != parent:  # the parent was gone before the line above
        os._exit(1)


def main():
    """A spawned worker: its Connection's handle (or descriptor) on its
    command line, its settings and then batches on that Connection."""
    os.environ.pop(PARENT, None)  # (its own children are not its parent's)
    parent = ParentEnd(int(sys.argv[1]))
    try:
        settings = pickle.loads(parent.recv_bytes())
    except EOFError:
        return 1
    _serve(parent, settings)
    return 0


def _last_words(file):
    """'; it said: <its last line>' of what a dead worker wrote to stderr."""
    file.seek(0)
    lines = [line.strip() for line in file.read()[-4000:].decode(errors="replace").splitlines() if line.strip()]
    return f"; it said: {lines[-1][:200]}" if lines else ""


def _cause(code: int) -> str:
    """How a worker's process ended, by its exit status as subprocess gives it."""
    if code < 0:
        try:
            return f"killed by signal {signal.Signals(-code).name}"
        except ValueError:
            return f"killed by signal {-code}"
    return f"exited with status {code}"


class _Queue:
    """The cases no worker has yet: taken from todo as batches need them (a
    campaign's list of cases is never copied, so memory stays flat in its
    length), the cases a lost worker gave back first."""

    def __init__(self, todo, count: int):
        self.todo, self.left = iter(todo), count
        self.front: collections.deque = collections.deque()  # given back, or looked at

    def __len__(self):
        return self.left

    def _first(self):
        if not self.front:
            item = next(self.todo, None)
            if item is None:
                return None
            self.front.append(item)
        return self.front[0]

    def take(self, size: int) -> list:
        """Up to size cases of one FMU, in todo's order."""
        batch: list = []
        path = None
        while len(batch) < size and (item := self._first()) is not None and path in (None, item[1]):
            path = item[1]
            batch.append(self.front.popleft())
        self.left -= len(batch)
        return batch

    def give_back(self, items):
        self.front.extendleft(reversed(items))
        self.left += len(items)


class Pool:
    """Runs a campaign's cases in workers (see the module's text).

    fmus      FMU path -> (its bytes, its FmuFile)
    jobs      workers to run (None: chosen by the work, up to cores())
    """

    def __init__(self, fmus: dict, settings: CaseSettings, jobs: int | None):
        self.fmus, self.settings = fmus, settings
        self.most = jobs if jobs is not None else cores()
        self.chosen = jobs is None
        self.peak = 0  # workers at once
        self.lost = 0  # workers that died or were stopped with a case (a crash, a timeout)
        self.retried: dict[int, str] = {}  # case -> why it runs again, until its outcome comes
        self.start_up: float | None = None  # seconds from the first worker's start to its first case
        # the work's measure: seconds and count of the cases finished, each worker's first apart (it carries
        # the worker's warm-up: the FMU's first instance, lazy imports)
        self.measured = {True: [0.0, 0], False: [0.0, 0]}  # first? -> [seconds, cases]
        self.queue = _Queue((), 0)
        self.workers: dict[Connection, _Worker] = {}  # by its Connection
        self.finished: Callable = lambda i, outcome: None
        self.announced = settings.case_timeout is not None  # every case's start is said (else the first's)

    def run(self, todo, finished):
        """Runs todo, a sized iterable of (i, FMU path, (folder, name,
        texts or None)), read as it goes; finished(i, outcome) as each
        case ends."""
        self.queue = _Queue(todo, len(todo))
        self.finished = finished
        unpack_root()  # made here: the workers unpack into it, and this process removes it however they end
        if plotting_first(self.settings) and can_fork():
            load_plotting()  # once, here: every worker forked has it (else each imports it as it starts)
        try:
            for _ in range(min(len(self.queue), 1 if self.chosen else self.most)):
                self._give(self._start())
            while self.workers:
                deadlines = [(self._deadline(w), w) for w in self.workers.values()]
                wakes = [d for d, _ in deadlines if d is not None] + [self._worth_from() or math.inf]
                soonest = min(wakes)
                timeout = None if soonest == math.inf else max(0.0, soonest - time.monotonic())
                for connection in wait(list(self.workers), timeout):
                    worker = self.workers.get(connection)  # type: ignore[call-overload]
                    if worker is not None:  # (not one stopped meanwhile)
                        self._read(worker)
                now = time.monotonic()
                for deadline, worker in deadlines:
                    if self.workers.get(worker.connection) is worker and deadline is not None and now > deadline:
                        running = worker.running_since is not None
                        self._stop(worker, kill=True)
                        self._lost(worker, self._overdue(running), again=not running)
                while self._pays():
                    self._give(self._start())
        except BaseException as error:
            self._stop_all(error)
            raise
        self._stop_all(None)

    def _stop_all(self, first: BaseException | None):
        """Kills the workers left; an error doing it is raised, or (first:
        the error that ended the run) noted on the first, never hiding it."""
        problems = []
        for worker in list(self.workers.values()):
            try:
                self._stop(worker, kill=True)
            except Exception as problem:
                problems.append(problem)
        if first is not None:
            for trouble in problems:
                first.add_note(f"(stopping the workers then: {type(trouble).__name__}: {trouble})")
        elif problems:
            raise problems[0]

    def _start(self) -> _Worker:
        worker = _start_worker(self.settings, list(self.workers.values()))
        self.workers[worker.connection] = worker
        self.peak = max(self.peak, len(self.workers))
        return worker

    def _stop(self, worker: _Worker, kill=False) -> int:
        """Ends the worker (kill: at once, else after its last batch); its exit status."""
        self.workers.pop(worker.connection, None)
        try:
            return worker.end(kill)
        finally:
            worker.last_words = _last_words(worker.said)
            worker.close()

    def _batch_size(self) -> int:
        """Cases for a worker's next batch: about BATCH_SECONDS of the work
        measured so far (one case before any is measured), and no more
        than a share of what is left, so that the workers end together."""
        per_case = self._per_case()
        if per_case is None:
            return 1
        share = -(-len(self.queue) // (2 * max(1, len(self.workers))))
        return max(1, min(round(BATCH_SECONDS / per_case), share))

    def _give(self, worker: _Worker, batch: list | None = None):
        """Its next batch of one FMU's cases (batch, else from the queue),
        or its end when none is left."""
        if batch is None and not self.queue:
            self._stop(worker)
            return
        worker.batch.extend(batch if batch is not None else self.queue.take(self._batch_size()))
        path = worker.batch[0][1]
        data, file = self.fmus[path]
        first = path not in worker.fmus
        worker.fmus.add(path)
        worker.sent_at = time.monotonic()
        # its next case starts now, unless it says when (with a timeout, or as a new worker's first)
        worker.running_since = None if self.announced or worker.first_case else worker.sent_at
        message = (path, data if first else None, file, [item for _, _, item in worker.batch])
        try:
            worker.connection.send_bytes(pickle.dumps(message))
        except OSError:  # it died before it read the batch: its end shows on its Connection
            pass

    def _deadline(self, worker: _Worker) -> float | None:
        """When the worker's case is overdue: its start plus the per-case
        timeout, or its batch's sending plus START_SECONDS until it starts."""
        if worker.running_since is None:
            return worker.sent_at + START_SECONDS if worker.batch else None
        timeout = self.settings.case_timeout
        return None if timeout is None else worker.running_since + timeout

    def _pays(self) -> bool:
        """Another worker pays for its start-up: the work left, spread over
        one more worker, is START_PAYS times a start-up or more."""
        start = self._worth_from()
        return start is not None and time.monotonic() >= start

    def _worth_from(self) -> float | None:
        """When another worker starts paying for itself (None: not on what
        is known). Before a case has finished, the case running longest is
        the measure: at least as long as it has run so far (so that a
        campaign of long cases does not wait for the first to end)."""
        if not (self.chosen and self.queue and len(self.workers) < self.most) or self.start_up is None:
            return None
        per_case = self._per_case()
        # on first cases alone (their warm-up included): only when it pays ten times over
        margin = START_PAYS * (1 if self.measured[False][1] else 10) * self.start_up
        needed = margin * (len(self.workers) + 1) / len(self.queue)  # the per-case seconds that make it pay
        if per_case is not None:
            return -math.inf if per_case > needed else None
        running = [w.running_since for w in self.workers.values() if w.running_since is not None]
        return min(running) + needed if running else None

    def _per_case(self) -> float | None:
        """Seconds a case takes, measured: on the cases after each worker's
        first where there are any, else on the first ones."""
        for seconds, cases in (self.measured[False], self.measured[True]):
            if cases:
                return max(seconds / cases, 1e-6)
        return None

    def _read(self, worker: _Worker):
        """The messages the worker wrote, handled; its end if its Connection closed."""
        while self.workers.get(worker.connection) is worker:
            try:
                if not worker.connection.poll():
                    return
                record = worker.connection.recv_bytes()
            except (EOFError, OSError):  # it died: a worker ends only when stopped, and is forgotten then
                why = f"the simulation's process was {_cause(self._stop(worker, kill=True))}"
                self._lost(worker, why + " while running this case" + worker.last_words, again=True)
                return
            if not record:  # STARTED
                worker.running_since = time.monotonic()
                if self.start_up is None:
                    self.start_up = worker.running_since - worker.started
                continue
            outcome = pickle.loads(record)
            if isinstance(outcome, InputError):  # no case of the FMU can run: said once, as in this process
                raise outcome
            i = worker.batch.popleft()[0]
            worker.running_since = None if self.announced else time.monotonic()  # (the next one's start)
            measure = self.measured[worker.first_case]
            measure[0] += outcome.seconds
            measure[1] += 1
            worker.first_case = False
            outcome.retried = self.retried.pop(i, "")
            self.finished(i, outcome)
            if not worker.batch:
                self._give(worker)

    def _lost(self, worker: _Worker, why: str, again: bool):
        """The worker is gone: its running case (the first of its batch)
        runs again alone on a fresh worker (again, the first time), else
        fails saying why; the rest of the batch goes back to the queue, and
        a new worker takes over if cases are left."""
        if worker.batch:  # (else it went between two batches: no case to blame)
            self.lost += 1
            item = worker.batch.popleft()
            started = worker.running_since if worker.running_since is not None else worker.sent_at
            self.queue.give_back(list(worker.batch))
            worker.batch.clear()
            i, path, (_, name, _) = item
            if again and i not in self.retried:
                self.retried[i] = why
                self._give(self._start(), [item])
            else:
                labels = self.fmus[path][1].labels
                seconds = time.monotonic() - started
                outcome = CaseOutcome(name, **labels, status=Status.ERROR, messages=[why], seconds=seconds)
                outcome.retried = self.retried.pop(i, "")
                self.finished(i, outcome)
        if self.queue and len(self.workers) < self.most:
            self._give(self._start())

    def _overdue(self, running: bool) -> str:
        if running:
            return f"stopped after the per-case timeout of {self.settings.case_timeout:g} s"
        return f"the simulation's process did not start the case within {START_SECONDS:g} s"
