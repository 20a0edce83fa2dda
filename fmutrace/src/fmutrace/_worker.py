"""One case on one FMU, where the work happens (this process, a child
process or a Dask worker): read and checked, simulated, compared, plotted
if asked."""

import hashlib
import os
import tempfile
import time
from dataclasses import dataclass, field

from ._cases import Case
from ._comparison import Comparison, Mode
from ._errors import InputError, SimulationError
from ._fmpy import Experiment, Signals
from ._fmu import Fmu
from ._pipeline import CaseFiles, Streaming, run_folder_case
from ._longrecording import is_long_recording, run_long_recording
from ._outcome import CaseOutcome, Status
from ._plot import load_plotting, plot_case
from ._recorded import RecordedCase, recorded_case
from .recordings import is_recording
from .recordings._options import RecordingOptions
from ._runner import Runner

PLOTS = ("all", "failed", "none")  # which cases get a plot and a result CSV
PLOT_ALL_UP_TO = 500  # the default: all for campaigns up to so many cases, else the failed ones


def default_plots(cases: int) -> str:
    return "all" if cases <= PLOT_ALL_UP_TO else "failed"


@dataclass(frozen=True)
class CaseSettings:
    """What every case of a campaign is run, compared and reported with."""

    mode: Mode
    plots: str = "none"  # which cases get a plot and a result CSV: PLOTS
    recording: RecordingOptions = field(default_factory=RecordingOptions)  # how recordings are read
    case_timeout: float | None = None  # seconds a case may run in a child process (None: no bound)


@dataclass(frozen=True)
class FmuFile:
    """An FMU as a campaign names it where its cases run (its bytes travel beside it)."""

    path: str
    labels: dict  # the CaseOutcome fields that name the FMU


@dataclass(frozen=True)
class Target:
    """The FMU a case runs on in this process: its Runner (one instance, reused), its Fmu and labels."""

    runner: Runner
    fmu: Fmu
    labels: dict


def run_case(folder, name, texts, target: Target, settings: CaseSettings) -> CaseOutcome:
    """The case in folder (its files' texts given, or None: read them), or
    the recording there (read with settings.recording), on target."""
    plots = settings.plots
    recorded = texts is None and is_recording(folder)  # (texts come with a case folder only)
    if recorded and not is_long_recording(folder):
        return _run_recording_in_memory(folder, name, target, settings)
    result_file = _result_file() if plots != "none" else None
    streaming = Streaming(result_file=result_file)
    outcome = (
        run_long_recording(folder, name, target, settings, streaming)
        if recorded
        else run_folder_case(CaseFiles(folder, name, texts), target, settings, streaming)
    )
    if recorded and outcome is None:
        outcome = _run_recording_in_memory(folder, name, target, settings)
    if result_file and (outcome is None or not outcome.png):  # a result file only with a plot
        os.unlink(result_file)
    elif outcome is not None:
        outcome.result_path = result_file
    return outcome


def _run_recording_in_memory(folder, name, target: Target, settings: CaseSettings) -> CaseOutcome:
    started = time.perf_counter()
    runner, fmu, labels, mode, plots = target.runner, target.fmu, target.labels, settings.mode, settings.plots
    outcome = CaseOutcome(name, **labels)
    case: Case
    try:
        case = recorded_case(str(folder), fmu, name, settings.recording)
    except InputError as error:
        outcome.status, outcome.messages = Status.INVALID, [str(error)]
        outcome.seconds = time.perf_counter() - started
        return outcome
    try:
        o = case.options
        result = runner.run(
            Experiment(o["StartTime"], o["StopTime"], o["StepSize"], o["RelTol"]),
            Signals(case.inputs, case.start_values, case.outputs),
        )
        comparison = case.comparison(result, mode)
        outcome.status = Status.PASS if comparison.passed else Status.FAIL
    except SimulationError as error:
        result, outcome.status = None, Status.ERROR
        comparison = Comparison(problem=str(error))
    outcome.deviations = [d for d in comparison.deviations if not d.passed]  # a passing signal says nothing more
    outcome.messages = comparison.messages()
    if isinstance(case, RecordedCase):  # what was read, matched and assumed, pass or fail
        outcome.messages += [case.description] + (case.explain(comparison) if not comparison.passed else case.notes)
    if result is not None and (plots == "all" or (plots == "failed" and not outcome.passed)):
        outcome.result = result
        outcome.png = plot_case(case, result, comparison, mode, labels["fmu"])
    outcome.seconds = time.perf_counter() - started
    return outcome


def _result_file():
    """A new file for a long case's result, written as it is made (the report takes it)."""
    handle, path = tempfile.mkstemp(prefix="fmutrace-", suffix="_out.csv")
    os.close(handle)
    os.chmod(path, 0o644)  # as the report's other files (mkstemp makes it private)
    return path


# the FMU's content hash -> (Runner, Fmu), kept from task to task in a worker process
_fmus: dict[str, tuple[Runner, Fmu]] = {}


def worker_fmu(fmu_bytes: bytes, path: str) -> tuple[Runner, Fmu]:
    """The Runner (one instance, reused) and the Fmu of these bytes in this
    process."""
    key = hashlib.sha256(fmu_bytes).hexdigest()
    if key not in _fmus:
        runner = Runner(fmu_bytes)
        _fmus[key] = runner, Fmu(path, runner.md)
    return _fmus[key]


def run_cases(items, fmu_bytes: bytes, fmu: FmuFile, settings: CaseSettings, on_start=None):
    """The outcomes of the cases [(folder, name, texts or None)] of one FMU
    in this process, as they finish; on_start() before each case starts."""
    target = Target(*worker_fmu(fmu_bytes, fmu.path), fmu.labels)
    if settings.plots != "none":
        load_plotting()  # start-up, not the first case's time: a case's timeout counts from on_start
    for folder, name, texts in items:
        if on_start:
            on_start()
        yield run_case(folder, name, texts, target, settings)
