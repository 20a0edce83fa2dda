"""Cases in local worker processes: as many as pay for themselves, never
more than cores, and a case whose FMU crashes its process or hangs is
reported by itself while the others go on.

A worker is a child process: forked from this one where that is safe
(Linux, no other Python thread: it starts in milliseconds with fmutrace
already imported), else a new Python running `main` below. It reads
batches of cases on a pipe and writes back each case's outcome, and an
empty record when it starts a case whose start matters (length-prefixed
pickles; what the FMU prints goes nowhere). This process, one thread, waits on every
worker's pipe with a deadline: a worker whose pipe closes died, and the
case it ran gets an error naming the signal; a case over the per-case
timeout gets its worker killed. Either way the rest of the batch goes
back to the queue and a new worker takes over. The timeout counts from
the case's start, so a worker's start-up (slow on a loaded machine) is
never charged to a case.

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
import os
import pickle
import selectors
import signal
import struct
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from ._errors import InputError
from ._fmu import UNPACK_ROOT, unpack_root
from ._outcome import CaseOutcome, Status
from ._plot import load_plotting
from ._worker import CaseSettings, plotting_first, run_cases

HEADER = struct.Struct("!Q")
STARTED = b""  # a worker's record that it starts its next case (an empty record)
PR_SET_PDEATHSIG = 1  # prctl(2)
PARENT = "FMUTRACE_PARENT_PID"  # in a spawned worker's environment: the process whose child it is
CHILD = "import sys, fmutrace._workers; sys.exit(fmutrace._workers.main())"
# the most a worker may take to start a case (a new Python's imports, the FMU unpacked) on a loaded machine
START_SECONDS = 300.0
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


@dataclass
class _Worker:
    pid: int
    to_worker: int  # pipe ends, this side's
    from_worker: int
    said: object  # a file with what the worker wrote to stderr (its last words, if it dies)
    process: subprocess.Popen | None = None  # a spawned worker's
    started: float = field(default_factory=time.monotonic)
    received: bytearray = field(default_factory=bytearray)
    fmus: set = field(default_factory=set)  # the FMUs whose bytes it has
    batch: collections.deque = field(default_factory=collections.deque)  # its cases not finished (as in todo)
    running_since: float | None = None  # the case at batch[0] started then
    sent_at: float = 0.0
    last_words: str = ""  # what it wrote last to stderr, once it ended
    first_case: bool = True  # its next outcome is its first

    def kill(self):
        try:
            os.kill(self.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass

    def wait(self) -> int:
        """Its exit status as subprocess gives it (negative: the signal)."""
        if self.process is not None:
            return self.process.wait()
        _, status = os.waitpid(self.pid, 0)
        return -os.WTERMSIG(status) if os.WIFSIGNALED(status) else os.WEXITSTATUS(status)

    def close(self):
        for fd in (self.to_worker, self.from_worker):
            try:
                os.close(fd)
            except OSError:
                pass
        self.said.close()  # type: ignore[attr-defined]


def _start_worker(settings: CaseSettings, others: list[_Worker]) -> _Worker:
    """A new worker, forked where can_fork() says it is safe, else spawned."""
    said = tempfile.TemporaryFile()
    if can_fork():
        down_read, down_write = os.pipe()
        up_read, up_write = os.pipe()
        pid = os.fork()
        if pid == 0:  # the worker: nothing of this process's but the pipes, never back into its code
            gc.freeze()  # what it inherited stays shared: the collector's passes would copy every page of it
            code = 1
            try:
                for worker in others:
                    worker.close()
                os.close(down_write)
                os.close(up_read)
                os.dup2(said.fileno(), 2)
                _serve(down_read, up_write, settings)
                code = 0
            except BaseException as error:  # (os._exit prints no traceback: its reason is its last words)
                os.write(2, f"{type(error).__name__}: {error}\n".encode(errors="replace"))
            finally:
                os._exit(code)
        os.close(down_read)
        os.close(up_write)
        return _Worker(pid, down_write, up_read, said)
    environment = dict(
        os.environ,
        PYTHONPATH=os.pathsep.join(
            [_package_root()] + ([os.environ["PYTHONPATH"]] if os.environ.get("PYTHONPATH") else [])
        ),
        **{UNPACK_ROOT: unpack_root(), PARENT: str(os.getpid())},
    )
    process = subprocess.Popen(
        [sys.executable, "-c", CHILD], stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=said, env=environment
    )
    assert process.stdin is not None and process.stdout is not None
    worker = _Worker(process.pid, os.dup(process.stdin.fileno()), os.dup(process.stdout.fileno()), said, process)
    process.stdin.close()
    process.stdout.close()
    _send(worker.to_worker, settings)
    return worker


def _package_root():
    """The folder (or zip) fmutrace is imported from: a spawned worker's PYTHONPATH."""
    return str(Path(__file__).resolve().parent.parent)


def _send(fd, message):
    _write_record(fd, pickle.dumps(message))


def _write_record(fd, data: bytes):
    """One length-prefixed record, whole (a pipe may take it in parts)."""
    view = memoryview(HEADER.pack(len(data)) + data)
    while view:
        view = view[os.write(fd, view) :]


def _read_exactly(fd, size) -> bytes | None:
    parts, left = [], size
    while left:
        part = os.read(fd, left)
        if not part:
            return None
        parts.append(part)
        left -= len(part)
    return b"".join(parts)


def _serve(from_parent: int, to_parent: int, settings: CaseSettings):
    """A worker's loop: batches in, an outcome per case out, until None;
    a STARTED record before a case where its start matters (every case
    with a per-case timeout, else the worker's first: its start-up ends
    there). A record fewer saves the campaign's process a wake-up."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the campaign's to handle (it stops its workers)
    _die_with_parent()
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 1)  # what the FMU or fmpy prints must not mix with the outcomes (or the command's output)
    fmus: dict[str, bytes] = {}
    first = [True]

    def started():
        if first[0] or settings.case_timeout is not None:
            _write_record(to_parent, STARTED)
        first[0] = False

    while True:
        header = _read_exactly(from_parent, HEADER.size)
        if header is None:
            return
        body = _read_exactly(from_parent, HEADER.unpack(header)[0])
        if body is None:
            return
        message = pickle.loads(body)
        if message is None:
            return
        path, data, fmu, items = message
        if data is not None:
            fmus[path] = data
        try:
            for outcome in run_cases(items, fmus[path], fmu, settings, on_start=started):
                _send(to_parent, outcome)
        except InputError as error:  # the FMU's, not a case's (it cannot be unpacked): the campaign's to raise
            _send(to_parent, InputError(str(error)))  # (a TraceError's pickle would not load: its arguments)
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
    """A spawned worker: its settings, then batches, on standard input."""
    os.environ.pop(PARENT, None)  # (its own children are not its parent's)
    from_parent, to_parent = os.dup(0), os.dup(1)
    header = _read_exactly(from_parent, HEADER.size)
    body = header and _read_exactly(from_parent, HEADER.unpack(header)[0])
    if not body:
        return 1
    _serve(from_parent, to_parent, pickle.loads(body))
    return 0


def _last_words(file):
    """'; it said: <its last line>' of what a dead worker wrote to stderr."""
    file.seek(0)
    lines = [line.strip() for line in file.read()[-4000:].decode(errors="replace").splitlines() if line.strip()]
    return f"; it said: {lines[-1][:200]}" if lines else ""


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
        self.start_up: float | None = None  # seconds from the first worker's start to its first case
        # the work's measure: seconds and count of the cases finished, each worker's first apart (it carries
        # the worker's warm-up: the FMU's first instance, lazy imports)
        self.measured = {True: [0.0, 0], False: [0.0, 0]}  # first? -> [seconds, cases]
        self.queue = _Queue((), 0)
        self.workers: dict[int, _Worker] = {}  # by its pipe from the worker
        self.selector = selectors.DefaultSelector()
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
                soonest = min(wakes) if min(wakes) < math.inf else None
                timeout = None if soonest is None else max(0.0, soonest - time.monotonic())
                for key, _ in self.selector.select(timeout):
                    worker: _Worker = key.data
                    if self.workers.get(key.fd) is worker:  # (not one stopped meanwhile)
                        self._read(worker)
                now = time.monotonic()
                for deadline, worker in deadlines:
                    if self.workers.get(worker.from_worker) is worker and deadline is not None and now > deadline:
                        why = self._overdue(worker.running_since is not None)
                        self._stop(worker, kill=True)
                        self._lost(worker, why)
                while self._pays():
                    self._give(self._start())
        finally:
            for worker in list(self.workers.values()):
                self._stop(worker, kill=True)
            self.selector.close()

    def _start(self) -> _Worker:
        worker = _start_worker(self.settings, list(self.workers.values()))
        self.workers[worker.from_worker] = worker
        os.set_blocking(worker.from_worker, False)
        self.selector.register(worker.from_worker, selectors.EVENT_READ, worker)
        self.peak = max(self.peak, len(self.workers))
        return worker

    def _stop(self, worker: _Worker, kill=False) -> int:
        """Ends the worker (kill: at once, else after its last batch); its exit status."""
        self.selector.unregister(worker.from_worker)
        del self.workers[worker.from_worker]
        if not kill:
            try:
                _send(worker.to_worker, None)
            except OSError:
                kill = True
        if kill:
            worker.kill()
        code = worker.wait()
        worker.last_words = _last_words(worker.said)
        worker.close()
        return code

    def _batch_size(self) -> int:
        """Cases for a worker's next batch: about BATCH_SECONDS of the work
        measured so far (one case before any is measured), and no more
        than a share of what is left, so that the workers end together."""
        per_case = self._per_case()
        if per_case is None:
            return 1
        share = -(-len(self.queue) // (2 * max(1, len(self.workers))))
        return max(1, min(round(BATCH_SECONDS / per_case), share))

    def _give(self, worker: _Worker):
        """Its next batch of one FMU's cases, or its end when none is left."""
        if not self.queue:
            self._stop(worker)
            return
        worker.batch.extend(self.queue.take(self._batch_size()))
        path = worker.batch[0][1]
        data, file = self.fmus[path]
        first = path not in worker.fmus
        worker.fmus.add(path)
        worker.sent_at = time.monotonic()
        # its next case starts now, unless it says when (with a timeout, or as a new worker's first)
        worker.running_since = None if self.announced or worker.first_case else worker.sent_at
        try:
            _send(worker.to_worker, (path, data if first else None, file, [item for _, _, item in worker.batch]))
        except OSError:  # it died before it read the batch: its end shows on its pipe
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
        """What the worker wrote: its records handled; its end if its pipe closed."""
        try:
            data = os.read(worker.from_worker, 1 << 20)
        except BlockingIOError:
            return
        except OSError:
            data = b""
        if not data:  # it died: a worker ends only when stopped, and is forgotten then
            code = self._stop(worker, kill=True)
            cause = f"killed by signal {signal.Signals(-code).name}" if code < 0 else f"exited with status {code}"
            self._lost(worker, f"the simulation's process was {cause} while running this case" + worker.last_words)
            return
        worker.received += data
        while len(worker.received) >= HEADER.size:
            size = HEADER.unpack_from(worker.received)[0]
            if len(worker.received) < HEADER.size + size:
                return
            record = bytes(worker.received[HEADER.size : HEADER.size + size])
            del worker.received[: HEADER.size + size]
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
            self.finished(i, outcome)
            if not worker.batch:
                self._give(worker)
                return

    def _lost(self, worker: _Worker, why: str):
        """The worker is gone: its running case (the first of its batch)
        fails saying why, the rest of the batch goes back to the queue,
        and a new worker takes over if cases are left."""
        if worker.batch:  # (else it went between two batches: no case to blame)
            self.lost += 1
            i, path, (_, name, _) = worker.batch.popleft()
            started = worker.running_since if worker.running_since is not None else worker.sent_at
            self.queue.give_back(list(worker.batch))
            worker.batch.clear()
            labels = self.fmus[path][1].labels
            seconds = time.monotonic() - started
            self.finished(i, CaseOutcome(name, **labels, status=Status.ERROR, messages=[why], seconds=seconds))
        if self.queue and len(self.workers) < self.most:
            self._give(self._start())

    def _overdue(self, running: bool) -> str:
        if running:
            return f"stopped after the per-case timeout of {self.settings.case_timeout:g} s"
        return f"the simulation's process did not start the case within {START_SECONDS:g} s"
