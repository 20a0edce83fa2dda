"""fmutrace: replay CSV traces through FMI 2 and FMI 3 co-simulation FMUs
with fmpy and report where they differ from references.

    import fmutrace
    result = fmutrace.simulate("RateLimiter.fmu", input="u.csv", start_values={"rateUpPar": 2})
    campaign = fmutrace.compare("RateLimiter.fmu", "my_traces/", report="report/")
    assert campaign.passed, campaign.summary()
"""
__version__ = "0.2.0"

from .campaign import CampaignResult, CaseOutcome, compare
from .cases import Case, find_cases, load_case
from .comparison import Comparison, Deviation, Tolerance
from .fmu import Fmu
from .simulation import SimulationError, simulate
from .traces import InputError, TraceError, read_trace, write_trace

__all__ = ["CampaignResult", "Case", "CaseOutcome", "Comparison", "Deviation", "Fmu", "InputError",
           "SimulationError", "Tolerance", "TraceError", "compare", "find_cases", "load_case", "read_trace",
           "simulate", "write_trace"]
