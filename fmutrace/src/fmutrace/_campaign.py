"""Campaigns: every case of every FMU run, compared with its reference
and reported (`compare`, the API of the `fmutrace compare` command).

The cases are indexed here (every FMU's cases, found under the folders
given), run by an executor (executors.py), recorded as they finish (in
memory, or in the report's journal) and reported at the end.
"""

import os
import time
from array import array
from bisect import bisect_right
from collections.abc import Iterable, MutableSequence, Sequence
from itertools import accumulate
from os import PathLike
from pathlib import Path
from typing import TextIO

from ._cases import find_cases
from ._comparison import Mode, comparison_mode
from ._errors import InputError, require_extra
from ._executors import RunOptions, Work, executor_for
from ._fmu import Fmu
from ._journal import JOURNAL, Journal, JournaledOutcomes, ReportLock, campaign_key, case_key, fmu_digest
from ._outcome import CampaignResult, KeptOutcomes, Status
from ._progress import Progress
from ._reading import read_bytes, read_limit
from .recordings import is_recording, recording_paths
from .recordings._options import RecordingOptions
from ._report import file_name, output_problem, write_case_files, write_junit, write_report
from ._worker import PLOTS, CaseSettings, FmuFile, default_plots

Paths = str | PathLike | Iterable[str | PathLike]  # one path, or several


def compare(
    fmus: Paths,
    cases: Paths,
    *,
    mode: Mode | None = None,
    rel_tol: float | None = None,
    abs_tol: float | None = None,
    tube_time: float | None = None,
    tube_value: float | None = None,
    report: str | PathLike | None = None,
    junit: str | PathLike | None = None,
    plots: str | None = None,
    resume: bool = False,
    progress: TextIO | None = None,
    run: RunOptions = RunOptions(),
    recording: RecordingOptions = RecordingOptions(),
) -> CampaignResult:
    """Replay every case through every FMU and compare with its reference.

    fmus        an FMU path, or a list of them (FMI 2 or 3 co-simulation)
    cases       a case folder or a folder of them (searched recursively),
                or a list; a case belongs to the FMU whose model name its
                files carry (<Model>_ref.csv). A file (or a folder without
                cases) is a recording as a recorder exports it
                (docs/recordings.md): it is run on every FMU
    mode        a comparison mode: fmutrace.Exact() (bit for bit),
                Tolerance(rel_tol, abs_tol), Tube(time, value[, sides]); or, instead
                of mode, rel_tol/abs_tol or tube_time/tube_value; none of
                them: exact
    report      folder for index.html, summary.md, results.json, the
                results and plots (None: no files)
    junit       file for JUnit XML
    plots       which cases get a plot and a result CSV in the report:
                'all', 'failed' or 'none'; None: all for up to 500 cases,
                else the failed ones; 'png': as None, each plot with a
                static PNG figure too
    resume      take the cases the report's journal (results.jsonl) holds
                from it, run the others (after a campaign was stopped)
    progress    the stream of the progress bar (default: standard error;
                drawn on a terminal only)
    run         where and how long the cases run: RunOptions(jobs=None,
                scheduler=None, shared_files=False, case_timeout=None,
                cluster_timeout=None); by default in local worker
                processes, as many as the work pays for
    recording   how recordings are read: RecordingOptions(step_size,
                time_unit, timing, maps, start_values); case folders carry
                their own settings, so recording options are refused for
                them alone

    Returns a CampaignResult (.passed, .cases, .summary(), .exit_code).
    Raises InputError for a bad FMU, folder or option, or settings that
    contradict each other; a case whose files are bad is reported as
    'invalid' (exit code 2) and the others run.
    """
    widths = {"rel_tol": rel_tol, "abs_tol": abs_tol, "tube_time": tube_time, "tube_value": tube_value}
    given = [name for name, value in widths.items() if value is not None]
    if mode is not None and given:
        raise InputError(f"give mode or {', '.join(given)}, not both")
    if mode is None:
        mode = comparison_mode(rel_tol or 0.0, abs_tol or 0.0, tube_time, tube_value)
    if plots not in (None, *PLOTS):
        raise InputError(f"plots must be {', '.join(PLOTS[:-1])} or {PLOTS[-1]}, not {plots!r}")
    if resume and not report:
        raise InputError("resume continues the campaign of a report folder: give the report folder")
    fmu_paths = [fmus] if isinstance(fmus, (str, PathLike)) else list(fmus)
    fmu_paths = list({os.path.realpath(p): p for p in reversed(fmu_paths)}.values())[::-1]  # one FMU given twice: once
    case_paths = [cases] if isinstance(cases, (str, PathLike)) else list(cases)
    if not fmu_paths or not case_paths:
        raise InputError("give at least one FMU and one case folder")
    has_recordings = any(is_recording(p) for p in case_paths)
    if recording != RecordingOptions() and not has_recordings:
        raise InputError(
            "recording options apply to recordings, and only case folders are given: a case folder "
            "carries its own settings (<Model>_ref.opt, <Model>_start.csv)"
        )
    if plots == "png":
        require_extra("matplotlib", "png", "drawing PNG figures")
    loaded = [Fmu(path) for path in fmu_paths]
    cases_of = index_cases(loaded, case_paths)
    png = plots == "png"  # (the default's cases, each with a PNG figure too)
    plots = ((None if png else plots) or default_plots(len(cases_of))) if report else "none"
    folders = _report_folders(loaded)
    work = Work(
        fmu_bytes={f.path: read_bytes(f.path) for f in loaded},
        fmus={
            f.path: FmuFile(str(f.path), {"fmu": f.label, "fmu_file": str(f.path), "fmu_folder": folders[f.path]})
            for f in loaded
        },
        settings=CaseSettings(mode, plots, recording, run.case_timeout, png, read_limit()),
    )
    executor = executor_for(run)
    key = campaign_key(work.fmu_bytes, mode, plots + " png" * png, recording.settings() if has_recordings else None)
    started = time.perf_counter()
    lock = ReportLock(report) if report else None
    try:  # the report folder stays locked until its last file is written
        if junit and output_problem(junit):  # (checked once the report folder is made: it may hold the file)
            raise InputError(output_problem(junit))
        outcomes, counts, where = _run(cases_of, work, executor, (report, key, resume), progress)
        kept = (
            JournaledOutcomes(
                report,
                Path(report) / JOURNAL,
                outcomes,
                {fmu_digest(work.fmu_bytes[path]): fmu.labels for path, fmu in work.fmus.items()},
            )
            if report
            else KeptOutcomes(outcomes)
        )
        result = CampaignResult(
            kept, mode, where, time.perf_counter() - started, Path(report) if report else None, counts
        )
        if report:
            write_report(result, report)
        if junit:
            write_junit(result, junit)
    finally:
        if lock:
            lock.release()
    return result


def _run(cases_of, work, executor, journal_of, progress):
    """(outcomes, counts by status, where they ran) of the campaign's cases;
    journal_of: (report folder or None, campaign key, resume). With a
    report the outcomes live in its journal and this process keeps their
    offsets there."""
    report, key, resume = journal_of
    outcomes: MutableSequence = array("q", bytes(8 * len(cases_of))) if report else [None] * len(cases_of)
    counts = dict.fromkeys(Status, 0)
    journal = Journal(report, key, resume, work.settings.recording.names) if report else None
    digests = {path: fmu_digest(data) for path, data in work.fmu_bytes.items()}  # a journal knows FMUs by content
    try:
        indices: Sequence[int]
        if journal and journal.done:
            indices = array("q")
            for i, (fmu, folder, _) in enumerate(cases_of):
                offset = journal.done.get(case_key(digests[fmu.path], folder))
                if offset is not None:  # finished by the campaign resumed
                    outcomes[i] = offset
                    counts[journal.entry(offset)["status"]] += 1
                else:
                    indices.append(i)
            journal.done = None  # read: not needed any more
        else:
            indices = range(len(cases_of))
        todo = Todo(cases_of, indices)
        run_again = [0]  # cases run a second time (their first run's process died)
        bar = Progress(len(cases_of), progress)

        def finished(i, outcome):
            counts[outcome.status] += 1
            run_again[0] += bool(outcome.retried)
            if journal:
                write_case_files(outcome, report)
                fmu, folder, _ = cases_of[i]
                outcomes[i] = journal.record(case_key(digests[fmu.path], folder), outcome.to_json())
            else:
                outcomes[i] = outcome
            bar.update(sum(counts.values()), sum(counts.values()) - counts[Status.PASS])

        try:
            if len(todo):
                executor.run(todo, work, finished)
        finally:
            bar.close()
    finally:
        if journal:
            journal.close()
    where = executor.where if len(todo) else "the journal"
    if run_again[0]:
        where += f", {run_again[0]} case{'s' if run_again[0] != 1 else ''} run again"
    resumed = len(cases_of) - len(todo)
    if resumed and len(todo):
        where += f" ({resumed} cases from the journal)"
    return outcomes, counts, where


def _report_folders(fmus):
    """Each FMU's folder in the report: <model>-fmi<version>, numbered if two are alike."""
    folders: dict[Path, str] = {}
    for fmu in fmus:
        folder = file_name(f"{fmu.model}-fmi{fmu.fmi_version}")
        n = 2
        while folder in folders.values():
            folder, n = file_name(f"{fmu.model}-fmi{fmu.fmi_version}-{n}"), n + 1
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
