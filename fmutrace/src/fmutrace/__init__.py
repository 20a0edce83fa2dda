"""fmutrace: replay CSV traces through FMI 2 and FMI 3 co-simulation FMUs
with fmpy and report where they differ from references.

    import fmutrace
    result = fmutrace.simulate("RateLimiter.fmu", input="u.csv", start_values={"rateUpPar": 2})
    campaign = fmutrace.compare("RateLimiter.fmu", "my_traces/", report="report/",
                                run=fmutrace.RunOptions(jobs=4))
    assert campaign.passed, campaign.summary()
"""

__version__ = "0.2.0"  # the package's version (pyproject.toml reads it from here)

from ._campaign import compare
from ._cases import Case, find_cases, load_case
from ._check import check
from ._comparison import (
    Comparison,
    Criteria,
    Deviation,
    Discrete,
    Exact,
    Mode,
    Tolerance,
    Tube,
    Ulps,
    compare_traces,
    comparison_mode,
    parse_mode,
)
from ._errors import ExitStatus, InputError, SimulationError, TraceError
from ._executors import RunOptions
from ._fmu import Fmu
from ._outcome import CampaignResult, CaseOutcome, Status
from ._simulation import simulate
from ._traces import read_trace, write_trace
from .recordings._options import RecordingOptions

__all__ = [
    "CampaignResult",
    "Case",
    "CaseOutcome",
    "Comparison",
    "Criteria",
    "Deviation",
    "Discrete",
    "Exact",
    "ExitStatus",
    "Fmu",
    "InputError",
    "Mode",
    "RecordingOptions",
    "RunOptions",
    "SimulationError",
    "Status",
    "Tolerance",
    "TraceError",
    "Tube",
    "Ulps",
    "check",
    "compare",
    "compare_traces",
    "comparison_mode",
    "find_cases",
    "load_case",
    "parse_mode",
    "read_trace",
    "simulate",
    "write_trace",
]
