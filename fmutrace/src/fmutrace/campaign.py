"""Campaigns: every case of every FMU simulated, compared with its
reference and reported.

Cases run in this process (jobs=1) or as Dask tasks: on a local cluster
of worker processes (jobs=N) or on a Dask distributed scheduler
(scheduler=address). A task carries its case and the FMU's bytes (sent
once to every worker) and returns the outcome with its result and plot,
so workers need the same Python packages (fmutrace itself is uploaded to
them) but no shared file system; the report is written here.
"""
import hashlib
import json
import logging
import os
import sys
import tempfile
import time
import zipfile
from array import array
from bisect import bisect_right
from itertools import accumulate
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

from .cases import case_texts, find_cases, load_case
from .comparison import Comparison, Tolerance, compare as compare_traces
from .fmu import Fmu
from .isolated import run_isolated
from .journal import Journal, ReportLock, campaign_key, case_key, outcome_from
from .report import case_json, light, plot_case, write_case_files, write_junit, write_report
from .runner import Runner
from .simulation import SimulationError
from .traces import InputError, read_trace


STATUSES = ("pass", "fail", "error", "invalid")
BATCH_CASES = 256              # cases per Dask task at most
BATCH_TEXT_BYTES = 2_000_000   # of case files' text per task at most, when they are sent
# Dask keeps its last messages for its developers (distributed.admin.low-level-log-length, 1000): a
# message that sends a batch keeps the batch's cases, so a campaign's client (and a local cluster's
# scheduler, in its process) would grow with the first 1000 batches. A few are enough here.
SHORT_LOGS = {"distributed.admin.low-level-log-length": 16}
# no statistical profiler in the workers (its history grows with the campaign's length)
LOCAL_CLUSTER = {"distributed.worker.profile.enabled": False, "distributed.scheduler.allowed-failures": 0}
BATCH_ATTEMPTS = 3             # a batch lost with its worker is sent again, so many times in all


@dataclass
class CaseOutcome:
    """One case on one FMU: 'pass', 'fail' (the result differs), 'error'
    (the simulation failed) or 'invalid' (its files are bad: the message
    names file, line and column). result and png are kept for the cases
    that get a plot."""
    case: str
    fmu: str                 # the FMU's label, e.g. "RateLimiter (FMI 3)"
    fmu_file: str
    fmu_folder: str          # its folder in the report
    status: str = "pass"
    messages: list = field(default_factory=list)
    deviations: list = field(default_factory=list)  # of the failing signals
    seconds: float = 0.0
    result: object = None    # structured array
    png: bytes = b""
    csv: str = ""            # paths in the report folder
    plot: str = ""

    @property
    def passed(self):
        return self.status == "pass"


class JournaledCases(Sequence):
    """The outcomes of a campaign with a report folder, read from its
    journal when asked: the client keeps where each case's line starts (8
    bytes a case), so its memory does not grow with the campaign. A case
    with a result CSV in the report gets its result read from it (bit for
    bit the one written); light() leaves the results out."""

    def __init__(self, report_dir, journal_path, offsets, fmu_folders):
        self.report_dir, self.path = Path(report_dir), Path(journal_path)
        self.offsets, self.fmu_folders = offsets, fmu_folders

    def __len__(self):
        return len(self.offsets)

    def _outcome(self, journal, offset, results=True):
        journal.seek(offset)
        entry = json.loads(journal.readline())
        outcome = outcome_from(entry, CaseOutcome, self.fmu_folders[entry["fmu_file"]])
        if results and outcome.csv:
            outcome.result = read_trace(self.report_dir / outcome.csv)
        return outcome

    def __getitem__(self, index):
        if isinstance(index, slice):
            return [self[i] for i in range(*index.indices(len(self)))]
        with open(self.path, "rb") as journal:
            return self._outcome(journal, self.offsets[index])

    def __iter__(self, results=True):
        with open(self.path, "rb") as journal:
            for offset in self.offsets:
                yield self._outcome(journal, offset, results)

    def light(self):
        """The outcomes without their results (for the report's pages)."""
        return self.__iter__(results=False)


@dataclass
class CampaignResult:
    cases: Sequence          # of CaseOutcome, in the order of the FMUs and their cases
    tolerance: Tolerance
    where: str = ""
    seconds: float = 0.0
    report_dir: Path = None
    _counts: dict = field(default=None, repr=False)  # by status, when known

    @property
    def passed(self):
        return self.counts()["pass"] == len(self.cases)

    @property
    def exit_code(self):
        """0 every case passes, 1 one differs or failed to simulate, 2 one is invalid."""
        return 2 if self.counts()["invalid"] else 0 if self.passed else 1

    def counts(self):
        if self._counts is None:
            self._counts = dict.fromkeys(STATUSES, 0)
            for o in light(self.cases):
                self._counts[o.status] += 1
        return self._counts

    def failed(self, results=True):
        """The outcomes that did not pass; results=False leaves out what a journaled campaign must read from
        disk (each case's result), keeping the messages."""
        return [o for o in (self.cases if results else light(self.cases)) if not o.passed]

    def headline(self):
        c = self.counts()
        text = f"{c['pass']} of {len(self.cases)} cases pass"
        if not self.passed:
            text += f", {c['fail']} differ" + (f", {c['error']} failed to simulate" if c["error"] else "") + \
                (f", {c['invalid']} invalid" if c["invalid"] else "")
        return text + f" ({self.seconds:.1f} s on {self.where})."

    def summary(self):
        """The headline and every failing case with its messages."""
        lines = [self.headline()]
        for o in self.failed(results=False):
            lines.append(f"{o.status.upper()}  {o.case} on {o.fmu}")
            lines += [f"      {m}" for m in o.messages]
        return "\n".join(lines)


def run_one(folder, name, texts, runner, fmu, labels, tolerance, plots):
    """One case on one FMU, where the work happens (any worker): read and
    checked, simulated, compared, plotted if asked. labels: the CaseOutcome
    fields that name the FMU."""
    started = time.perf_counter()
    outcome = CaseOutcome(name, **labels)
    try:
        case = load_case(folder, fmu, name, texts)
    except InputError as error:
        outcome.status, outcome.messages = "invalid", [str(error)]
        outcome.seconds = time.perf_counter() - started
        return outcome
    comparison = None
    try:
        o = case.options
        result = runner.run(o["StartTime"], o["StopTime"], o["StepSize"], case.inputs, case.start_values,
                            case.outputs, o["RelTol"])
        comparison = compare_traces(result, case.reference, tolerance)
        outcome.status = "pass" if comparison.passed else "fail"
    except SimulationError as error:
        result, outcome.status = None, "error"
        comparison = Comparison(problem=str(error))
    outcome.deviations = [d for d in comparison.deviations if not d.passed]  # a passing signal says nothing more
    outcome.messages = comparison.messages()
    if result is not None and (plots == "all" or (plots == "failed" and not outcome.passed)):
        outcome.result = result
        outcome.png = plot_case(case, result, tolerance, labels["fmu"])
    outcome.seconds = time.perf_counter() - started
    return outcome


_workers_fmus = {}  # in a worker process: the FMU's content hash -> (Runner, Fmu), kept from task to task


def worker_fmu(fmu_bytes, path):
    """The Runner (one instance, reused) and the Fmu of these bytes in this
    process."""
    key = hashlib.sha256(fmu_bytes).hexdigest()
    if key not in _workers_fmus:
        runner = Runner(fmu_bytes)
        _workers_fmus[key] = runner, Fmu(path, runner.md)
    return _workers_fmus[key]


def run_batch(items, fmu_bytes, path, labels, tolerance, plots, isolate=False, case_timeout=None):
    """A Dask task: the cases [(folder, name, texts or None)] of one FMU, in
    this worker, or (isolate) in child processes of it."""
    if isolate:
        return run_isolated(items, fmu_bytes, path, labels, tolerance, plots, case_timeout, CaseOutcome)
    runner, fmu = worker_fmu(fmu_bytes, path)
    return [run_one(folder, name, texts, runner, fmu, labels, tolerance, plots) for folder, name, texts in items]


class Progress:
    """A progress bar on a terminal, from the moment a campaign has taken
    a few seconds; nothing when the stream is not a terminal."""

    AFTER_SECONDS = 2.0

    def __init__(self, total, stream=None):
        self.total, self.stream = total, stream or sys.stderr
        self.enabled = hasattr(self.stream, "isatty") and self.stream.isatty()
        self.started = time.monotonic()
        self.shown = False

    def update(self, done, failed):
        elapsed = time.monotonic() - self.started
        if not self.enabled or (elapsed < self.AFTER_SECONDS and done < self.total):
            return
        if not self.shown and done == self.total:
            return
        width = 30
        filled = width * done // max(1, self.total)
        self.stream.write(f"\r[{'#' * filled}{'.' * (width - filled)}] {done}/{self.total} cases, "
                          f"{failed} failing, {elapsed:.0f} s ")
        self.stream.flush()
        self.shown = True

    def close(self):
        if self.shown:
            self.stream.write("\n")
            self.stream.flush()


def package_zip():
    """fmutrace as a zip (for Dask's upload_file), made once per process."""
    target = Path(tempfile.gettempdir()) / f"fmutrace-package-{os.getpid()}.zip"
    if not target.exists():
        package = Path(__file__).resolve().parent
        with zipfile.ZipFile(target, "w") as z:
            for source in sorted(package.glob("*.py")):
                z.write(source, f"fmutrace/{source.name}")
    return target


def _report_folders(fmus):
    folders = {}
    for fmu in fmus:
        folder = f"{fmu.model}-fmi{fmu.fmi_version}"
        n = 2
        while folder in folders.values():
            folder, n = f"{fmu.model}-fmi{fmu.fmi_version}-{n}", n + 1
        folders[fmu.path] = folder
    return folders


class Plan(Sequence):
    """(fmu, folder, name) of every FMU's cases, one after the other: the
    FMUs' case lists (CaseList) indexed through, not copied; folders as text."""

    def __init__(self, parts):
        self.parts = parts  # [(fmu, CaseList)]
        self.starts = list(accumulate((len(found) for _, found in parts), initial=0))

    def __len__(self):
        return self.starts[-1]

    def __getitem__(self, index):
        part = bisect_right(self.starts, index) - 1
        fmu, found = self.parts[part]
        return (fmu, *found.text(index - self.starts[part]))

    def __iter__(self):
        for fmu, found in self.parts:
            for i in range(len(found)):
                yield (fmu, *found.text(i))


class Todo:
    """The cases still to run, by their place in the plan: (i, fmu, folder, name)."""

    def __init__(self, work, indices):
        self.work, self.indices = work, indices

    def __len__(self):
        return len(self.indices)

    def __iter__(self):
        for i in self.indices:
            yield (i, *self.work[i])


def plan(fmus, paths):
    """A Plan of every FMU's cases under paths (InputError for an FMU
    without any)."""
    parts = []
    for fmu in fmus:
        found = find_cases(paths, fmu.model)
        if not found:
            raise InputError(f"no case of {fmu.label} (no {fmu.model}_ref.csv) under {', '.join(map(str, paths))}")
        parts.append((fmu, found))
    return Plan(parts)


def compare(fmus, cases, report=None, tolerance=None, rel_tol=0.0, abs_tol=0.0, tube_time=None, tube_value=None,
            junit=None, jobs=None, scheduler=None, shared_files=False, plots=None, timeout=None, progress=None,
            resume=False, case_timeout=None):
    """Replay every case through every FMU and compare with its reference.

    fmus        an FMU path, or a list of them (FMI 2 or 3 co-simulation)
    cases       a case folder or a folder of them (searched recursively),
                or a list; a case belongs to the FMU whose model name its
                files carry (<Model>_ref.csv)
    report      folder for index.html, summary.md, results.json, the
                results and plots (None: no files)
    tolerance   a Tolerance, or rel_tol/abs_tol, or tube_time/tube_value;
                none of them: exact, bit for bit
    junit       file for JUnit XML
    jobs        1: in this process; N: a local Dask cluster of N processes;
                None: one per core for 20 cases or more, else 1
    scheduler   address of a Dask scheduler (instead of a local cluster)
    shared_files  the scheduler's workers see the case folders at the same
                paths (they read the files; else they are sent the texts)
    plots       which cases get a plot and a result CSV in the report:
                'all', 'failed' or 'none'; None: all for up to 500 cases,
                else the failed ones
    timeout     seconds to wait for a cluster's results (None: no bound)
    case_timeout  seconds a case may run (None: no bound): a case over it
                is stopped and reported (cases then run in child processes)
    resume      take the cases the report's journal (results.jsonl) holds
                from it, run the others (after a campaign was stopped)

    Returns a CampaignResult (.passed, .cases, .summary(), .exit_code).
    Raises InputError for a bad FMU, folder or option; a case whose files
    are bad is reported as 'invalid' (exit code 2) and the others run.
    """
    try:
        tolerance = tolerance or Tolerance(rel_tol, abs_tol, tube_time, tube_value)
    except ValueError as error:
        raise InputError(str(error)) from None
    if plots not in (None, "all", "failed", "none"):
        raise InputError(f"plots must be all, failed or none, not {plots!r}")
    fmu_paths = [fmus] if isinstance(fmus, (str, Path)) else list(fmus)
    case_paths = [cases] if isinstance(cases, (str, Path)) else list(cases)
    if not fmu_paths or not case_paths:
        raise InputError("give at least one FMU and one case folder")
    loaded = [Fmu(path) for path in fmu_paths]
    work = plan(loaded, case_paths)
    if plots is None:
        plots = "all" if len(work) <= 500 else "failed"
    plots = plots if report else "none"
    if jobs is None:  # a local cluster takes seconds to start: worth it for many cases only
        jobs = os.cpu_count() if len(work) >= 20 else 1
    folders = _report_folders(loaded)
    labels = {f.path: {"fmu": f.label, "fmu_file": str(f.path), "fmu_folder": folders[f.path]} for f in loaded}
    fmu_bytes = {f.path: f.path.read_bytes() for f in loaded}

    started = time.perf_counter()
    # with a report, the outcomes live in its journal and this process keeps their offsets there
    outcomes = array("q", bytes(8 * len(work))) if report else [None] * len(work)
    counts = dict.fromkeys(STATUSES, 0)
    lock = journal = None
    if report:
        lock = ReportLock(report)
    try:
        if report:
            journal = Journal(report, campaign_key(fmu_bytes, tolerance, plots), resume)
        if journal and journal.done:
            indices = array("q")
            for i, (fmu, folder, name) in enumerate(work):
                offset = journal.done.get(case_key(fmu.path, folder))
                if offset is not None:  # finished by the campaign resumed
                    outcomes[i] = offset
                    counts[journal.entry(offset)["status"]] += 1
                else:
                    indices.append(i)
            journal.done = None  # read: not needed any more
        else:
            indices = range(len(work))
        todo = Todo(work, indices)
        bar = Progress(len(work), progress)

        def finished(i, outcome):
            counts[outcome.status] += 1
            if report:
                write_case_files(outcome, report)
                fmu, folder, _ = work[i]
                outcomes[i] = journal.record(case_key(fmu.path, folder), case_json(outcome))
            else:
                outcomes[i] = outcome
            bar.update(sum(counts.values()), sum(counts.values()) - counts["pass"])

        try:
            if not len(todo):
                where = "the journal"
            elif scheduler is None and jobs <= 1 and case_timeout is not None:
                for fmu in loaded:  # in child processes: a case over the timeout is stopped by killing its process
                    mine = [(i, folder, name) for i, f, folder, name in todo if f is fmu]
                    arrived = iter(mine)
                    run_isolated([(str(folder), name, None) for _, folder, name in mine], fmu_bytes[fmu.path],
                                 str(fmu.path), labels[fmu.path], tolerance, plots, case_timeout, CaseOutcome,
                                 on_outcome=lambda outcome: finished(next(arrived)[0], outcome))
                where = "1 process at a time (isolated)"
            elif scheduler is None and jobs <= 1:
                runners = {}
                try:
                    for i, fmu, folder, name in todo:
                        if fmu.path not in runners:
                            runners[fmu.path] = Runner(fmu_bytes[fmu.path])
                        finished(i, run_one(folder, name, None, runners[fmu.path], fmu, labels[fmu.path],
                                            tolerance, plots))
                finally:
                    for runner in runners.values():
                        runner.close()
                where = "1 process"
            else:
                where = _on_dask(todo, fmu_bytes, labels, tolerance, plots, jobs, scheduler, shared_files, timeout,
                                 case_timeout, finished)
        finally:
            bar.close()
    finally:
        if journal:
            journal.close()
        if lock:
            lock.release()
    resumed = len(work) - len(todo)
    if resumed and len(todo):
        where += f" ({resumed} cases from the journal)"
    cases = JournaledCases(report, journal.path, outcomes, {str(f.path): folders[f.path] for f in loaded}) if report \
        else outcomes
    result = CampaignResult(cases, tolerance, where, time.perf_counter() - started, Path(report) if report else None,
                            counts)
    if report:
        write_report(result, report)
    if junit:
        write_junit(result, junit)
    return result


def _batches(todo, size, ship_texts):
    """Consecutive runs of one FMU's cases, [(fmu, [(i, folder, name, texts)])]:
    at most size cases, and with their files' texts (ship_texts) at most
    BATCH_TEXT_BYTES of them, so that a worker's queue stays small."""
    batch, current, volume = [], None, 0
    for i, fmu, folder, name in todo:
        texts = case_texts(folder, fmu.model) if ship_texts else None
        if batch and (fmu is not current or len(batch) == size or volume >= BATCH_TEXT_BYTES):
            yield current, batch
            batch, volume = [], 0
        current = fmu
        volume += sum(map(len, texts.values())) if texts else 0
        batch.append((i, str(folder), name, texts))
    if batch:
        yield current, batch


def _on_dask(todo, fmu_bytes, labels, tolerance, plots, jobs, scheduler, shared_files, timeout, case_timeout,
             finished):
    """The cases in batches on Dask workers, at most a few batches per
    worker in flight (the client's memory stays flat). Workers of a local
    cluster, or of a remote one that sees the same files (shared_files),
    read the cases themselves; others get the files' texts."""
    import dask
    from dask.distributed import Client, LocalCluster, as_completed

    cluster = None
    with dask.config.set(SHORT_LOGS):
        if scheduler:
            client = Client(scheduler, timeout=timeout or 60)
        else:
            # a task whose worker dies is not tried on others: the batch is run isolated instead (below)
            with dask.config.set(LOCAL_CLUSTER):
                cluster = LocalCluster(n_workers=jobs, threads_per_worker=1, processes=True, dashboard_address=None,
                                       silence_logs=logging.CRITICAL)  # a worker's death is reported by the campaign
            client = Client(cluster)
    try:
        client.upload_file(str(package_zip()))  # fmutrace to every worker: nothing to install there but packages
        workers = len(client.scheduler_info()["workers"])
        shared = {path: client.scatter(data, broadcast=True) for path, data in fmu_bytes.items()}
        # about 8 batches per worker; at most BATCH_CASES cases each (a task's cost is a few milliseconds)
        size = max(1, min(BATCH_CASES, -(-len(todo) // (8 * workers))))
        batches = _batches(todo, size, ship_texts=bool(scheduler) and not shared_files)
        in_flight = as_completed()
        submitted = {}  # future -> (fmu, batch, isolated, attempt)

        def submit(fmu, batch, isolated, attempt):
            items = [(folder, name, texts) for _, folder, name, texts in batch]
            future = client.submit(run_batch, items, shared[fmu.path], str(fmu.path), labels[fmu.path], tolerance,
                                   plots, isolated, case_timeout, pure=False)
            submitted[future] = fmu, batch, isolated, attempt
            in_flight.add(future)

        def submit_next():
            for fmu, batch in batches:  # with a per-case timeout every batch runs isolated: a hang needs a process
                submit(fmu, batch, case_timeout is not None, 1)  # to kill
                return

        for _ in range(3 * workers):
            submit_next()
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
                    shared[fmu.path] = client.scatter(fmu_bytes[fmu.path], broadcast=True)
                    submit(fmu, batch, True, attempt + 1)  # isolated: a crashing case fails alone
                    continue
                outcomes = [CaseOutcome(name, **labels[fmu.path], status="error",
                                        messages=[f"lost with its Dask worker {attempt} times: {type(error).__name__}: "
                                                  f"{error}"]) for _, _, name, _ in batch]
            for (i, _, _, _), outcome in zip(batch, outcomes):
                finished(i, outcome)
            del outcomes
            submit_next()
        return f"Dask, {workers} workers" + (f" at {scheduler}" if scheduler else " (local processes)")
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def _next_within(in_flight, seconds, timeout):
    """The next finished future, or TimeoutError once the campaign's bound is up."""
    deadline = time.monotonic() + seconds
    while not in_flight.has_ready():
        if time.monotonic() > deadline:
            raise TimeoutError(f"the cluster did not finish the campaign within {timeout} s")
        time.sleep(0.01)
    return next(in_flight)
