"""A result against its reference, signal by signal, in a comparison mode
(exact, tolerance, ulps: _comparison_modes; tube: _comparison_tube;
discrete: _comparison_discrete; per-signal criteria and the modes' words:
_comparison_criteria; the verdicts and their messages:
_comparison_verdicts). The rest of fmutrace imports the comparison from
here."""

from ._comparison_criteria import (
    MODE_WORDS,
    Criteria,
    comparison_mode,
    criteria_for,
    parse_mode,
    signal_criteria,
)
from ._comparison_discrete import Discrete
from ._comparison_modes import EXACT, Exact, Mode, Pointwise, Tolerance, Ulps, aligned, time_slack
from ._comparison_tube import Tube
from ._comparison_verdicts import Band, Comparison, Deviation, Verdict, verdict_of

__all__ = [
    "MODE_WORDS",
    "Band",
    "Comparison",
    "Criteria",
    "Deviation",
    "Discrete",
    "Exact",
    "Mode",
    "Pointwise",
    "Tolerance",
    "Tube",
    "Ulps",
    "Verdict",
    "aligned",
    "compare_traces",
    "comparison_mode",
    "criteria_for",
    "parse_mode",
    "signal_criteria",
    "time_slack",
    "verdict_of",
]


def compare_traces(result, reference, mode: Mode = EXACT) -> Comparison:
    """The Comparison of a result (structured array with 'time') with a
    reference, for every signal of the reference."""
    names = [n for n in reference.dtype.names if n != "time"]
    missing = [n for n in names if n not in result.dtype.names]
    if missing:
        return Comparison(problem=f"the result has no signal {', '.join(missing)}")
    if len(result) == 0:
        return Comparison(problem="the result has no samples")
    deviations, bands, problem = mode.judge(result, reference, names)
    return Comparison(list(deviations.values()), problem, bands)
