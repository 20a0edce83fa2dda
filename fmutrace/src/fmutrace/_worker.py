"""One case on one FMU, where the work happens (this process, a child
process or a Dask worker): read and checked, simulated, compared, plotted
if asked."""
import hashlib
import os
import tempfile
import time

from ._cases import load_case
from ._comparison import Comparison, Mode
from ._errors import InputError, SimulationError
from ._fmu import Fmu
from ._longcase import is_long, run_long_case
from ._longrecording import is_long_recording, run_long_recording
from ._outcome import CaseOutcome, Status
from ._plot import load_plotting, plot_case
from ._recorded import recorded_case
from .recordings import is_recording
from .recordings.options import RecordingOptions
from ._runner import Runner

PLOTS = ("all", "failed", "none")  # which cases get a plot and a result CSV
PLOT_ALL_UP_TO = 500               # the default: all for campaigns up to so many cases, else the failed ones


def default_plots(cases: int) -> str:
    return "all" if cases <= PLOT_ALL_UP_TO else "failed"


def run_case(folder, name, texts, runner: Runner, fmu: Fmu, labels: dict, mode: Mode, plots: str,
             recording: RecordingOptions = None) -> CaseOutcome:
    """The case in folder (its files' texts given, or None: read them), or
    the recording there (read with recording's options); labels: the
    CaseOutcome fields that name the FMU."""
    started = time.perf_counter()
    recorded = texts is None and is_recording(folder)  # (texts come with a case folder only)
    streamed = is_long_recording(folder) if recorded else is_long(folder, fmu.model, texts)
    if streamed:
        result_file = _result_file() if plots != "none" else None
        long = run_long_recording(folder, name, runner, fmu, labels, mode, plots, recording or RecordingOptions(),
                                  result_file=result_file) if recorded else \
            run_long_case(folder, name, runner, fmu, labels, mode, plots, result_file=result_file)
        if result_file and (long is None or not long.png):  # a result file only with the case's plot
            os.unlink(result_file)
        elif long is not None:
            long.result_path = result_file
        if long is not None:
            return long
    outcome = CaseOutcome(name, **labels)
    try:
        if recorded:
            case = recorded_case(str(folder), fmu, name, recording or RecordingOptions())
        else:
            case = load_case(folder, fmu, name, texts)
    except InputError as error:
        outcome.status, outcome.messages = Status.INVALID, [str(error)]
        outcome.seconds = time.perf_counter() - started
        return outcome
    try:
        o = case.options
        result = runner.run(o["StartTime"], o["StopTime"], o["StepSize"], case.inputs, case.start_values,
                            case.outputs, o["RelTol"])
        comparison = case.comparison(result, mode)
        outcome.status = Status.PASS if comparison.passed else Status.FAIL
    except SimulationError as error:
        result, outcome.status = None, Status.ERROR
        comparison = Comparison(problem=str(error))
    outcome.deviations = [d for d in comparison.deviations if not d.passed]  # a passing signal says nothing more
    outcome.messages = comparison.messages()
    if recorded:  # what was read, matched and assumed, pass or fail
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


_fmus = {}  # the FMU's content hash -> (Runner, Fmu), kept from task to task in a worker process


def worker_fmu(fmu_bytes: bytes, path: str) -> tuple:
    """The Runner (one instance, reused) and the Fmu of these bytes in this
    process."""
    key = hashlib.sha256(fmu_bytes).hexdigest()
    if key not in _fmus:
        runner = Runner(fmu_bytes)
        _fmus[key] = runner, Fmu(path, runner.md)
    return _fmus[key]


def run_cases(items, fmu_bytes: bytes, path: str, labels: dict, mode: Mode, plots: str,
              recording: RecordingOptions = None, on_start=None):
    """The outcomes of the cases [(folder, name, texts or None)] of one FMU
    in this process, as they finish; on_start() before each case starts."""
    runner, fmu = worker_fmu(fmu_bytes, path)
    if plots != "none":
        load_plotting()  # start-up, not the first case's time: a case's timeout counts from on_start
    for folder, name, texts in items:
        if on_start:
            on_start()
        yield run_case(folder, name, texts, runner, fmu, labels, mode, plots, recording)
