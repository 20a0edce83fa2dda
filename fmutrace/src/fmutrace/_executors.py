"""Where a campaign's cases run, behind one interface: an Executor takes
the cases to do and calls finished(i, outcome) as each one ends.

InProcess       one after the other in this process (jobs=1)
LocalProcesses  in local worker processes, as many as pay for themselves
                or as asked (workers.Pool): a case that crashes its process
                or hangs (the per-case timeout) fails alone
Dask            in batches on a Dask scheduler's workers

A Dask task carries a batch of cases and the FMU's bytes (sent once to
every worker) and returns the outcomes with their results and plots, so
workers need the same Python packages (fmutrace itself is uploaded to
them) but no shared file system; the report is written by the caller.
"""

import atexit
import functools
import hashlib
import shutil
import tempfile
import time
import zipfile
from dataclasses import dataclass
from pathlib import Path

from ._cases import case_texts
from ._errors import InputError, require_extra
from ._outcome import CaseOutcome, Status
from ._runner import Runner
from ._worker import CaseSettings, FmuFile, Target, run_case, run_cases
from ._workers import Pool
from .recordings import is_recording

BATCH_CASES = 256  # cases per Dask task at most
DASK_BATCH_SECONDS = 1.0  # of measured work per Dask task
BATCH_TEXT_BYTES = 2_000_000  # of case files' text per task at most, when they are sent
BATCH_ATTEMPTS = 3  # a batch lost with its worker is sent again, so many times in all
# Dask keeps its last messages for its developers (distributed.admin.low-level-log-length, 1000): a
# message that sends a batch keeps the batch's cases, so a campaign's client would grow with the first
# 1000 batches. A few are enough here.
SHORT_LOGS = {"distributed.admin.low-level-log-length": 16}


@dataclass(frozen=True)
class RunOptions:
    """Where and how long a campaign's cases run.

    jobs             None (the default): local worker processes, as
                     many as the work pays for, up to one per core; N:
                     N local worker processes; 1: in this process (an
                     FMU that crashes takes the caller with it)
    scheduler        address of a Dask scheduler to run on (instead of
                     this process or local workers)
    shared_files     the scheduler's workers see the case folders at the
                     same paths (they read the files; else they are sent
                     the texts)
    case_timeout     seconds a case may run (None: no bound): a case over
                     it is stopped and reported (jobs=1 then runs them
                     in one worker process)
    cluster_timeout  seconds to wait for a cluster's results (None: no bound)
    """

    jobs: int | None = None
    scheduler: str | None = None
    shared_files: bool = False
    case_timeout: float | None = None
    cluster_timeout: float | None = None

    def __post_init__(self):
        if self.jobs is not None and (not isinstance(self.jobs, int) or self.jobs < 1):
            raise InputError(f"jobs must be a whole number of at least 1, or None, not {self.jobs!r}")
        for name in ("case_timeout", "cluster_timeout"):
            value = getattr(self, name)
            if value is not None and not value > 0:  # (0 would stop every case at once)
                raise InputError(f"{name} must be more than 0 seconds, or None, not {value!r}")


@dataclass(frozen=True)
class Work:
    """What every case of a campaign is run with."""

    fmu_bytes: dict  # FMU path -> the file's bytes
    fmus: dict  # FMU path -> its FmuFile
    settings: CaseSettings


class Executor:
    where = ""  # for the headline: "1 process", "Dask, 2 workers (local processes)", ...

    def run(self, todo, work: Work, finished):
        """Run todo, (i, fmu, folder, name) of each case; finished(i, outcome) as each ends."""
        raise NotImplementedError


class InProcess(Executor):
    where = "1 process"

    def run(self, todo, work, finished):
        runners = {}
        try:
            for i, fmu, folder, name in todo:
                if fmu.path not in runners:
                    runners[fmu.path] = Runner(work.fmu_bytes[fmu.path])
                target = Target(runners[fmu.path], fmu, work.fmus[fmu.path].labels)
                finished(i, run_case(folder, name, None, target, work.settings))
        finally:
            for runner in runners.values():
                runner.close()


class _ForWorkers:
    """A campaign's todo as workers.Pool takes it, read as it goes."""

    def __init__(self, todo):
        self.todo = todo

    def __len__(self):
        return len(self.todo)

    def __iter__(self):
        return ((i, fmu.path, (str(folder), name, None)) for i, fmu, folder, name in self.todo)


class LocalProcesses(Executor):
    """Local worker processes (workers.Pool): jobs of them, or None: as
    many as pay for themselves."""

    def __init__(self, jobs: int | None):
        self.jobs = jobs

    def run(self, todo, work, finished):
        fmus = {path: (work.fmu_bytes[path], work.fmus[path]) for path in work.fmus}
        pool = Pool(fmus, work.settings, self.jobs)
        try:
            pool.run(_ForWorkers(todo), finished)
        finally:
            self.where = f"{pool.peak} local process{'es' if pool.peak != 1 else ''}"
            if pool.lost:
                self.where += f", {pool.lost} lost with a case"


def run_batch(items, fmu_bytes, fmu: FmuFile, settings: CaseSettings, isolate: bool):
    """A Dask task: the outcomes of the cases [(folder, name, texts or
    None)] of one FMU, run in this worker, or (isolate) in a worker
    process of its own."""
    if not isolate:
        return list(run_cases(items, fmu_bytes, fmu, settings))
    outcomes: dict = {}
    Pool({fmu.path: (fmu_bytes, fmu)}, settings, 1).run(
        [(i, fmu.path, item) for i, item in enumerate(items)], outcomes.__setitem__
    )
    return [outcomes[i] for i in range(len(items))]


class Dask(Executor):
    """The cases in batches on a Dask scheduler's workers, at most a few
    batches per worker in flight (the client's memory stays flat). Workers
    that see the same files (shared_files) read the cases themselves;
    others get the files' texts. cluster_timeout bounds the wait."""

    def __init__(self, options: RunOptions):
        assert options.scheduler is not None
        _check_address(options.scheduler)
        self.scheduler, self.shared_files, self.cluster_timeout = (
            options.scheduler,
            options.shared_files,
            options.cluster_timeout,
        )

    def run(self, todo, work, finished):
        import dask
        from dask.distributed import Client

        with dask.config.set(SHORT_LOGS), Client(self.scheduler, timeout=self.cluster_timeout or 60) as client:
            workers = self._run(client, todo, work, finished)
        self.where = f"Dask, {workers} workers at {self.scheduler}"

    def _run(self, client, todo, work, finished):
        from dask.distributed import as_completed

        client.upload_file(str(package_zip()))  # fmutrace to every worker: nothing to install there but packages
        workers = len(client.scheduler_info()["workers"])
        shared = {path: client.scatter(data, broadcast=True) for path, data in work.fmu_bytes.items()}
        # about DASK_BATCH_SECONDS of measured work per batch (one case before any is measured), at most
        # BATCH_CASES, and at least 8 batches per worker: a task costs its round trip and the scheduler's work
        share = max(1, -(-len(todo) // (8 * workers)))
        measured = [0.0, 0]  # seconds and count of the cases finished

        def size():
            if not measured[1]:
                return 1
            return max(1, min(BATCH_CASES, share, round(DASK_BATCH_SECONDS * measured[1] / max(measured[0], 1e-9))))

        batches = _batches(todo, size, ship_texts=not self.shared_files)
        in_flight = as_completed()
        submitted = {}  # future -> (fmu, batch, isolated, attempt)

        # the scheduler runs a task whose worker died again by itself (its allowed-failures), counting the deaths
        # (TaskState.suspicious): asked as each batch finishes (its result is on a worker: its state is kept)
        def deaths(key):
            return client.run_on_scheduler(
                lambda dask_scheduler: getattr(dask_scheduler.tasks.get(key), "suspicious", 0)
            )

        def submit(fmu, batch, isolated, attempt, why=""):
            items = [(folder, name, texts) for _, folder, name, texts in batch]
            future = client.submit(
                run_batch, items, shared[fmu.path], work.fmus[fmu.path], work.settings, isolated, pure=False
            )
            submitted[future] = fmu, batch, isolated, attempt, why
            in_flight.add(future)

        def submit_next():
            for fmu, batch in batches:  # with a per-case timeout every batch runs isolated: a hang needs a process
                submit(fmu, batch, work.settings.case_timeout is not None, 1)  # to kill
                return

        for _ in range(3 * workers):
            submit_next()
        timeout = self.cluster_timeout
        deadline = None if timeout is None else time.monotonic() + timeout
        while in_flight.count():
            remaining = None if deadline is None else max(0.0, deadline - time.monotonic())
            future = next(in_flight) if remaining is None else _next_within(in_flight, remaining, timeout)
            fmu, batch, isolated, attempt, why = submitted.pop(future)
            died = deaths(future.key)
            if died:
                why = f"its Dask worker died while it held the case's batch ({died} time{'s' if died > 1 else ''})"
            try:
                outcomes = future.result()
            except Exception as error:  # its worker died (an FMU crashed it?), or the result was lost with a worker
                if attempt < BATCH_ATTEMPTS:
                    # the FMU's bytes again too: the copies may have gone with the workers
                    shared[fmu.path] = client.scatter(work.fmu_bytes[fmu.path], broadcast=True)
                    # isolated: a crashing case fails alone
                    submit(fmu, batch, True, attempt + 1, f"lost with its Dask worker: {type(error).__name__}: {error}")
                    continue
                outcomes = [
                    CaseOutcome(
                        name,
                        **work.fmus[fmu.path].labels,
                        status=Status.ERROR,
                        messages=[f"lost with its Dask worker {attempt} times: {type(error).__name__}: {error}"],
                    )
                    for _, _, name, _ in batch
                ]
            for (i, _, _, _), outcome in zip(batch, outcomes, strict=True):
                measured[0] += outcome.seconds
                measured[1] += 1
                outcome.retried = outcome.retried or why  # (a case run again in its own process says why itself)
                finished(i, outcome)
            del outcomes
            submit_next()
        return workers


def _check_address(address):
    """InputError for a scheduler address Dask cannot take (an unknown
    scheme, a host that does not parse), before any connection."""
    try:
        from distributed.comm.addressing import parse_address, parse_host_port
        from distributed.comm.registry import get_backend
    except ImportError:  # (Dask not installed: running on it says so)
        return
    try:
        scheme, location = parse_address(address)
        get_backend(scheme)
        if scheme in ("tcp", "tls"):
            parse_host_port(location)
    except (ValueError, TypeError) as error:
        raise InputError(
            f"scheduler {address!r}: not the address of a Dask scheduler ({error}); such as tcp://host:8786"
        ) from None


def executor_for(options: RunOptions) -> Executor:
    """The executor the run options choose."""
    if options.scheduler is not None:
        require_extra("distributed", "dask", "a campaign on a Dask scheduler")
        return Dask(options)
    if options.jobs == 1 and options.case_timeout is None:
        return InProcess()
    return LocalProcesses(options.jobs)


@functools.cache
def package_zip() -> Path:
    """fmutrace as a zip (for Dask's upload_file), made once per process in
    a folder of its own, removed at exit, and named by its sources' hash:
    a scheduler's workers keep an upload by its name and import fmutrace
    from it. A zip named by the
    process id in the shared temporary folder was found again by a later
    process that got the same id, with another fmutrace inside."""
    package = Path(__file__).resolve().parent
    sources = [(s, f"fmutrace/{s.relative_to(package).as_posix()}") for s in sorted(package.rglob("*.py"))]
    digest = hashlib.sha256()
    for source, name in sources:  # its subpackages too
        digest.update(name.encode() + b"\0" + source.read_bytes() + b"\0")
    folder = tempfile.mkdtemp(prefix="fmutrace-package-")
    atexit.register(shutil.rmtree, folder, ignore_errors=True)
    target = Path(folder) / f"fmutrace-{digest.hexdigest()[:16]}.zip"
    with zipfile.ZipFile(target, "w") as z:
        for source, name in sources:
            z.write(source, name)
    return target


def _batches(todo, size, ship_texts):
    """Consecutive runs of one FMU's cases, [(fmu, [(i, folder, name, texts)])]:
    at most size() cases (asked as each batch starts), and with their
    files' texts (ship_texts) at most BATCH_TEXT_BYTES of them, so that a
    worker's queue stays small."""
    batch: list[tuple] = []
    current, volume, most = None, 0, 1
    for i, fmu, folder, name in todo:
        texts = case_texts(folder, fmu.model) if ship_texts and not is_recording(folder) else None
        if batch and (fmu is not current or len(batch) >= most or volume >= BATCH_TEXT_BYTES):
            yield current, batch
            batch, volume = [], 0
        if not batch:
            most = size()
        current = fmu
        volume += sum(map(len, texts.values())) if texts else 0
        batch.append((i, str(folder), name, texts))
    if batch:
        yield current, batch


def _next_within(in_flight, seconds, timeout):
    """The next finished future, or TimeoutError once the campaign's bound is up."""
    deadline = time.monotonic() + seconds
    while not in_flight.has_ready():
        if time.monotonic() > deadline:
            raise TimeoutError(f"the cluster did not finish the campaign within {timeout} s")
        time.sleep(0.01)
    return next(in_flight)
