"""Where a campaign's cases run, behind one interface: an Executor takes
the cases to do and calls finished(i, outcome) as each one ends.

InProcess       one after the other in this process
ChildProcesses  one after the other in child processes (a per-case
                timeout: a case that hangs is stopped by killing its process)
Dask            in batches on Dask workers: a local cluster of worker
                processes, or a distributed scheduler's

A Dask task carries a batch of cases and the FMU's bytes (sent once to
every worker) and returns the outcomes with their results and plots, so
workers need the same Python packages (fmutrace itself is uploaded to
them) but no shared file system; the report is written by the caller.
"""

import atexit
import contextlib
import functools
import hashlib
import logging
import os
import shutil
import tempfile
import time
import zipfile
from dataclasses import dataclass
from pathlib import Path

from ._cases import case_texts
from ._errors import InputError
from ._fmu import unpack_root
from ._isolated import run_isolated
from ._outcome import CaseOutcome, Status
from ._runner import Runner
from ._worker import CaseSettings, FmuFile, Target, run_case, run_cases
from .recordings import is_recording

BATCH_CASES = 256  # cases per Dask task at most
BATCH_TEXT_BYTES = 2_000_000  # of case files' text per task at most, when they are sent
CLUSTER_ATTEMPTS = 2  # a local cluster whose start fails (a worker lost) is started again, once
BATCH_ATTEMPTS = 3  # a batch lost with its worker is sent again, so many times in all
# Dask keeps its last messages for its developers (distributed.admin.low-level-log-length, 1000): a
# message that sends a batch keeps the batch's cases, so a campaign's client (and a local cluster's
# scheduler, in its process) would grow with the first 1000 batches. A few are enough here.
SHORT_LOGS = {"distributed.admin.low-level-log-length": 16}
# no statistical profiler in the workers (its history grows with the campaign's length)
LOCAL_CLUSTER = {"distributed.worker.profile.enabled": False, "distributed.scheduler.allowed-failures": 0}


AUTO_JOBS_FROM = 20  # RunOptions(jobs=None): a local cluster of one process per core from so many cases on


@dataclass(frozen=True)
class RunOptions:
    """Where and how long a campaign's cases run.

    jobs             1: in this process (the default); N: a local Dask
                     cluster of N processes; None: one per core for
                     AUTO_JOBS_FROM cases or more, else 1 (the command's
                     default)
    scheduler        address of a Dask scheduler to run on (instead of
                     this process or a local cluster)
    shared_files     the scheduler's workers see the case folders at the
                     same paths (they read the files; else they are sent
                     the texts)
    case_timeout     seconds a case may run (None: no bound): a case over
                     it is stopped and reported (cases then run in child
                     processes)
    cluster_timeout  seconds to wait for a cluster's results (None: no bound)
    """

    jobs: int | None = 1
    scheduler: str | None = None
    shared_files: bool = False
    case_timeout: float | None = None
    cluster_timeout: float | None = None

    def __post_init__(self):
        if self.jobs is not None and (not isinstance(self.jobs, int) or self.jobs < 1):
            raise InputError(f"jobs must be a whole number of at least 1, or None, not {self.jobs!r}")
        for name in ("case_timeout", "cluster_timeout"):
            value = getattr(self, name)
            if value is not None and not value >= 0:
                raise InputError(f"{name} must be >= 0 seconds, or None, not {value!r}")


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


class ChildProcesses(Executor):
    where = "1 process at a time (isolated)"

    def run(self, todo, work, finished):
        by_fmu: dict = {}  # Fmu -> [(i, folder, name)]
        for i, fmu, folder, name in todo:
            by_fmu.setdefault(fmu, []).append((i, folder, name))
        for fmu, cases in by_fmu.items():
            arrived = iter(cases)
            run_isolated(
                [(str(folder), name, None) for _, folder, name in cases],
                work.fmu_bytes[fmu.path],
                work.fmus[fmu.path],
                work.settings,
                on_outcome=lambda outcome, arrived=arrived: finished(next(arrived)[0], outcome),
            )


def run_batch(items, fmu_bytes, fmu: FmuFile, settings: CaseSettings, isolate: bool):
    """A Dask task: the outcomes of the cases [(folder, name, texts or
    None)] of one FMU, run in this worker, or (isolate) in child processes
    of it."""
    if isolate:
        return run_isolated(items, fmu_bytes, fmu, settings)
    return list(run_cases(items, fmu_bytes, fmu, settings))


class Dask(Executor):
    """The cases in batches on Dask workers, at most a few batches per
    worker in flight (the client's memory stays flat). Workers of a local
    cluster (scheduler None: jobs processes), or of a scheduler's that see
    the same files (shared_files), read the cases themselves; others get
    the files' texts. cluster_timeout bounds the wait for the cluster."""

    def __init__(self, jobs: int, options: RunOptions):
        self.jobs, self.scheduler, self.shared_files, self.cluster_timeout = (
            jobs,
            options.scheduler,
            options.shared_files,
            options.cluster_timeout,
        )

    def run(self, todo, work, finished):
        import dask

        with dask.config.set(SHORT_LOGS):
            for attempt in range(1, CLUSTER_ATTEMPTS + 1):
                self.submitted = False
                try:
                    cluster, client = self._connect()
                except Exception:  # a local worker lost while the cluster starts ("Nanny failed to start")
                    if self.scheduler:
                        raise
                    continue
                try:
                    workers = self._run(client, todo, work, finished)
                    break
                except Exception:
                    # lost before any batch was sent (the upload to a worker that died): once more, on a new
                    # cluster; once batches run, a lost worker costs its batch a retry (in _run)
                    if self.submitted or self.scheduler or attempt == CLUSTER_ATTEMPTS:
                        raise
                finally:
                    client.close()
                    if cluster is not None:
                        cluster.close()
            else:  # no local cluster would start: the cases in child processes of this one
                fallback = ChildProcesses()
                fallback.run(todo, work, finished)
                self.where = f"{fallback.where}, the local Dask cluster failed to start {CLUSTER_ATTEMPTS} times"
                return
        self.where = f"Dask, {workers} workers" + (f" at {self.scheduler}" if self.scheduler else " (local processes)")

    def _connect(self):
        """(cluster or None, client): the scheduler's, or a local cluster of jobs processes."""
        import dask
        from dask.distributed import Client, LocalCluster

        if self.scheduler:
            return None, Client(self.scheduler, timeout=self.cluster_timeout or 60)
        cluster = None
        unpack_root()  # the local workers unpack into this process's folder (inherited): removed however they end
        try:
            # a task whose worker dies is not tried on others: the batch is run isolated instead (_run)
            # (silent: a worker's death is reported by the campaign)
            with dask.config.set(LOCAL_CLUSTER):
                # no dashboard, and the scheduler's HTTP server (health, metrics) on a free loopback port:
                # dashboard_address=None alone still takes port 8787 (and warns where that is in use)
                cluster = LocalCluster(
                    n_workers=self.jobs,
                    threads_per_worker=1,
                    processes=True,
                    dashboard_address=None,
                    scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
                    silence_logs=logging.CRITICAL,
                )
            return cluster, Client(cluster)
        except Exception:
            if cluster is not None:
                with contextlib.suppress(Exception):
                    cluster.close()
            raise

    def _run(self, client, todo, work, finished):
        from dask.distributed import as_completed

        if self.scheduler:  # fmutrace to every worker: nothing to install there but packages. A local cluster's
            client.upload_file(str(package_zip()))  # workers share this venv: from a zip they would miss _steps
        workers = len(client.scheduler_info()["workers"])
        shared = {path: client.scatter(data, broadcast=True) for path, data in work.fmu_bytes.items()}
        # about 8 batches per worker; at most BATCH_CASES cases each (a task's cost is a few milliseconds)
        size = max(1, min(BATCH_CASES, -(-len(todo) // (8 * workers))))
        batches = _batches(todo, size, ship_texts=bool(self.scheduler) and not self.shared_files)
        in_flight = as_completed()
        submitted = {}  # future -> (fmu, batch, isolated, attempt)

        def submit(fmu, batch, isolated, attempt):
            self.submitted = True
            items = [(folder, name, texts) for _, folder, name, texts in batch]
            future = client.submit(
                run_batch, items, shared[fmu.path], work.fmus[fmu.path], work.settings, isolated, pure=False
            )
            submitted[future] = fmu, batch, isolated, attempt
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
            fmu, batch, isolated, attempt = submitted.pop(future)
            try:
                outcomes = future.result()
            except Exception as error:  # its worker died (an FMU crashed it?), or the result was lost with a worker
                if attempt < BATCH_ATTEMPTS:
                    # the FMU's bytes again too: the copies may have gone with the workers
                    shared[fmu.path] = client.scatter(work.fmu_bytes[fmu.path], broadcast=True)
                    submit(fmu, batch, True, attempt + 1)  # isolated: a crashing case fails alone
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
                finished(i, outcome)
            del outcomes
            submit_next()
        return workers


def executor_for(cases: int, options: RunOptions) -> Executor:
    """The executor the run options choose for so many cases."""
    jobs = options.jobs
    if jobs is None:  # a local cluster takes seconds to start: worth it for many cases only
        jobs = (os.cpu_count() or 1) if cases >= AUTO_JOBS_FROM else 1
    if options.scheduler is None and jobs <= 1:
        return InProcess() if options.case_timeout is None else ChildProcesses()
    return Dask(jobs, options)


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
    at most size cases, and with their files' texts (ship_texts) at most
    BATCH_TEXT_BYTES of them, so that a worker's queue stays small."""
    batch: list[tuple] = []
    current, volume = None, 0
    for i, fmu, folder, name in todo:
        texts = case_texts(folder, fmu.model) if ship_texts and not is_recording(folder) else None
        if batch and (fmu is not current or len(batch) == size or volume >= BATCH_TEXT_BYTES):
            yield current, batch
            batch, volume = [], 0
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
