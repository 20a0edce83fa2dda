"""One case on one FMU, where the work happens (this process, a child
process or a Dask worker): read and checked, simulated, compared, plotted
if asked."""

import hashlib
from dataclasses import dataclass, field

from ._comparison import Mode
from ._fmu import Fmu
from ._pipeline import CaseFiles, Streaming, run_folder_case
from ._reading import campaign_read_limit
from ._recording import run_recording
from ._outcome import CaseOutcome
from ._plot import load_plotting
from .recordings import is_recording
from .recordings._options import RecordingOptions
from ._runner import Runner

PLOTS = ("all", "failed", "none", "png")  # which cases get a plot and a result CSV; png: as the default, and
# a static PNG figure beside each interactive plot
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
    png: bool = False  # a plotted case gets a static PNG figure too (matplotlib), beside its interactive plot
    read_limit: int | None = None  # the client's read bound, where the cases run (None: the worker's own)


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
    the recording there (read with settings.recording), on target: read,
    run and compared by the pipeline, plotted if asked."""
    streaming = Streaming(keep_result=settings.plots != "none")
    with campaign_read_limit(settings.read_limit):
        if texts is None and is_recording(folder):  # (texts come with a case folder only)
            return run_recording(folder, name, target, settings, streaming)
        return run_folder_case(CaseFiles(folder, name, texts), target, settings, streaming)


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


def plotting_first(settings: CaseSettings) -> bool:
    """Load the plotting packages before the first case: every case is
    drawn, or a case's timeout counts from its start and must not pay for
    the import (else the first figure loads them, if any is drawn)."""
    return settings.png and (
        settings.plots == "all" or (settings.plots == "failed" and settings.case_timeout is not None)
    )


def run_cases(items, fmu_bytes: bytes, fmu: FmuFile, settings: CaseSettings, on_start=None):
    """The outcomes of the cases [(folder, name, texts or None)] of one FMU
    in this process, as they finish; on_start() before each case starts."""
    target = Target(*worker_fmu(fmu_bytes, fmu.path), fmu.labels)
    if plotting_first(settings):
        load_plotting()
    for folder, name, texts in items:
        if on_start:
            on_start()
        yield run_case(folder, name, texts, target, settings)
