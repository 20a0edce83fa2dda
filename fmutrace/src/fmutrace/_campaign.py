"""Campaigns: every case of every FMU run, compared with its reference
and reported (`compare`, the API of the `fmutrace compare` command).

The cases are indexed here (every FMU's cases, found under the folders
given), run by an executor (executors.py), recorded as they finish (in
memory, or in the report's journal) and reported at the end.
"""
import time
from array import array
from bisect import bisect_right
from collections.abc import Iterable, Sequence
from itertools import accumulate
from os import PathLike
from pathlib import Path
from typing import TextIO

from ._cases import find_cases
from ._comparison import Mode, comparison_mode
from ._errors import InputError
from ._executors import Work, executor_for
from ._fmu import Fmu
from ._journal import Journal, JournaledOutcomes, ReportLock, campaign_key, case_key
from ._outcome import CampaignResult, KeptOutcomes, Status
from ._progress import Progress
from .recordings import is_recording, recording_paths
from .recordings.options import RecordingOptions
from ._report import write_case_files, write_junit, write_report
from ._worker import PLOTS, default_plots

Paths = str | PathLike | Iterable[str | PathLike]  # one path, or several


def compare(fmus: Paths, cases: Paths, report: str | PathLike | None = None,
            mode: Mode | None = None, rel_tol: float = 0.0, abs_tol: float = 0.0, tube_time: float | None = None,
            tube_value: float | None = None, junit: str | PathLike | None = None, jobs: int | None = None,
            scheduler: str | None = None, shared_files: bool = False, plots: str | None = None,
            case_timeout: float | None = None, cluster_timeout: float | None = None, resume: bool = False,
            progress: TextIO | None = None, step_size: float | None = None, maps: Iterable = (),
            start_values: dict | None = None, time_unit: str | None = None,
            timing: str = "cycle") -> CampaignResult:
    """Replay every case through every FMU and compare with its reference.

    fmus        an FMU path, or a list of them (FMI 2 or 3 co-simulation)
    cases       a case folder or a folder of them (searched recursively),
                or a list; a case belongs to the FMU whose model name its
                files carry (<Model>_ref.csv). A file (or a folder without
                cases) is a recording as a recorder exports it
                (docs/recordings.md): it is run on every FMU
    report      folder for index.html, summary.md, results.json, the
                results and plots (None: no files)
    mode        a comparison mode (fmutrace.Exact(), Tolerance(rel_tol,
                abs_tol), Tube(time, value)), or rel_tol/abs_tol, or
                tube_time/tube_value; none of them: exact, bit for bit
    junit       file for JUnit XML
    jobs        1: in this process; N: a local Dask cluster of N processes;
                None: one per core for 20 cases or more, else 1
    scheduler   address of a Dask scheduler (instead of a local cluster)
    shared_files  the scheduler's workers see the case folders at the same
                paths (they read the files; else they are sent the texts)
    plots       which cases get a plot and a result CSV in the report:
                'all', 'failed' or 'none'; None: all for up to 500 cases,
                else the failed ones
    case_timeout  seconds a case may run (None: no bound): a case over it
                is stopped and reported (cases then run in child processes)
    cluster_timeout  seconds to wait for a cluster's results (None: no bound)
    resume      take the cases the report's journal (results.jsonl) holds
                from it, run the others (after a campaign was stopped)
    progress    the stream of the progress bar (default: standard error;
                drawn on a terminal only)
    step_size   recordings: the PLC's cycle (default: the recording's
                sample time, else its finest interval between samples)
    maps        recordings: (VARIABLE, CHANNEL) pairs, or {VARIABLE: CHANNEL}
    start_values  recordings: {name: value} of the FMU's start values
    time_unit   recordings: s, ms, us, ns, cycles or filetime, instead of
                the recording's own
    timing      recordings: 'cycle' (a row is one cycle's input and
                output, as recorders write it) or 'fmi' (a row's output is
                the output at its time, as fmpy writes it)

    Returns a CampaignResult (.passed, .cases, .summary(), .exit_code).
    Raises InputError for a bad FMU, folder or option; a case whose files
    are bad is reported as 'invalid' (exit code 2) and the others run.
    """
    mode = mode or comparison_mode(rel_tol, abs_tol, tube_time, tube_value)
    if plots not in (None, *PLOTS):
        raise InputError(f"plots must be {', '.join(PLOTS[:-1])} or {PLOTS[-1]}, not {plots!r}")
    fmu_paths = [fmus] if isinstance(fmus, (str, PathLike)) else list(fmus)
    case_paths = [cases] if isinstance(cases, (str, PathLike)) else list(cases)
    if not fmu_paths or not case_paths:
        raise InputError("give at least one FMU and one case folder")
    loaded = [Fmu(path) for path in fmu_paths]
    recording = RecordingOptions(step_size, time_unit, timing, tuple(dict(maps).items()),
                                 tuple((start_values or {}).items()))
    work = index_cases(loaded, case_paths)
    plots = (plots or default_plots(len(work))) if report else "none"
    folders = _report_folders(loaded)
    job = Work(fmu_bytes={f.path: f.path.read_bytes() for f in loaded},
               labels={f.path: {"fmu": f.label, "fmu_file": str(f.path), "fmu_folder": folders[f.path]}
                       for f in loaded},
               mode=mode, plots=plots, case_timeout=case_timeout, recording=recording)
    executor = executor_for(len(work), jobs, scheduler, shared_files, case_timeout, cluster_timeout)

    started = time.perf_counter()
    # with a report, the outcomes live in its journal and this process keeps their offsets there
    outcomes = array("q", bytes(8 * len(work))) if report else [None] * len(work)
    counts = dict.fromkeys(Status, 0)
    lock = journal = None
    if report:
        lock = ReportLock(report)
    try:
        if report:
            journal = Journal(report, campaign_key(job.fmu_bytes, mode, plots, recording.settings()
                                                   if any(is_recording(p) for p in case_paths) else None), resume)
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
                outcomes[i] = journal.record(case_key(fmu.path, folder), outcome.to_json())
            else:
                outcomes[i] = outcome
            bar.update(sum(counts.values()), sum(counts.values()) - counts[Status.PASS])

        try:
            if len(todo):
                executor.run(todo, job, finished)
        finally:
            bar.close()
    finally:
        if journal:
            journal.close()
        if lock:
            lock.release()
    where = executor.where if len(todo) else "the journal"
    resumed = len(work) - len(todo)
    if resumed and len(todo):
        where += f" ({resumed} cases from the journal)"
    kept = JournaledOutcomes(report, journal.path, outcomes, {str(f.path): folders[f.path] for f in loaded}) \
        if report else KeptOutcomes(outcomes)
    result = CampaignResult(kept, mode, where, time.perf_counter() - started, Path(report) if report else None,
                            counts)
    if report:
        write_report(result, report)
    if junit:
        write_junit(result, junit)
    return result


def _report_folders(fmus):
    """Each FMU's folder in the report: <model>-fmi<version>, numbered if two are alike."""
    folders = {}
    for fmu in fmus:
        folder = f"{fmu.model}-fmi{fmu.fmi_version}"
        n = 2
        while folder in folders.values():
            folder, n = f"{fmu.model}-fmi{fmu.fmi_version}-{n}", n + 1
        folders[fmu.path] = folder
    return folders


class CaseIndex(Sequence):
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
    """The cases still to run, by their place in the CaseIndex: (i, fmu, folder, name)."""

    def __init__(self, work, indices):
        self.work, self.indices = work, indices

    def __len__(self):
        return len(self.indices)

    def __iter__(self):
        for i in self.indices:
            yield (i, *self.work[i])


def index_cases(fmus, paths):
    """A CaseIndex of every FMU's cases under the case folders among paths,
    and of the recordings among them (every FMU's too); InputError for an
    FMU with neither."""
    folders = [p for p in paths if not is_recording(p)]
    recordings = RecordingList(recording_paths([p for p in paths if is_recording(p)]))
    parts = []
    for fmu in fmus:
        found = find_cases(folders, fmu.model)
        if not found and not recordings:
            raise InputError(f"no case of {fmu.label} (no {fmu.model}_ref.csv) under {', '.join(map(str, paths))}")
        parts += [(fmu, found)] * bool(found) + [(fmu, recordings)] * bool(recordings)
    return CaseIndex(parts)


class RecordingList(Sequence):
    """(path, name) of each recording, as a CaseList gives its cases."""

    def __init__(self, items):
        self.items = items

    def __len__(self):
        return len(self.items)

    def __getitem__(self, index):
        return self.items[index]

    def text(self, index):
        return self.items[index]
