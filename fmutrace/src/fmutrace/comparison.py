"""A result against its reference, signal by signal, in one of three modes:

exact      every value bit for bit (any NaN matches any NaN)
tolerance  |result - reference| <= abs_tol + rel_tol * |reference|
tube       the reference drawn as a polyline (a repeated time is a
           vertical jump), widened by tube_time in time and tube_value in
           value, as the Modelica Association's csv-compare draws it: a
           result sample passes when some point of the reference lies
           within tube_time of its time and tube_value of its value (the
           samples inside the reference's time range are checked). For
           traces sampled at other instants than the FMU's steps.

In the exact and tolerance modes each reference sample is compared with
the result's sample at the same time (times within a relative 1e-9, they
are communication points); at a repeated time the reference's last row,
the value from that instant on, is the one compared. A reference sample
without a result sample at its time fails.
"""
import math
from dataclasses import dataclass, field

import numpy as np

TIME_MATCH = 1e-9


@dataclass(frozen=True)
class Tolerance:
    rel_tol: float = 0.0
    abs_tol: float = 0.0
    tube_time: float = None
    tube_value: float = None

    def __post_init__(self):
        for name in ("rel_tol", "abs_tol", "tube_time", "tube_value"):
            value = getattr(self, name)
            if value is not None and not (value >= 0 and math.isfinite(value)):
                raise ValueError(f"{name.replace('_', '-')} must be a finite number >= 0, not {value!r}")
        if (self.tube_time is None) != (self.tube_value is None):
            raise ValueError("a tube needs both its time and its value tolerance (--tube-time and --tube-value)")
        if self.tube_time is not None and (self.rel_tol or self.abs_tol):
            raise ValueError("choose a tube or a relative/absolute tolerance, not both")

    @property
    def mode(self):
        if self.tube_time is not None:
            return "tube"
        return "tolerance" if (self.rel_tol or self.abs_tol) else "exact"

    def describe(self):
        if self.mode == "tube":
            return f"tube of {self.tube_time:g} s and {self.tube_value:g}"
        if self.mode == "tolerance":
            return f"relative tolerance {self.rel_tol:g}, absolute tolerance {self.abs_tol:g}"
        return "exact (bit for bit)"


@dataclass
class Deviation:
    """A signal's verdict; for a failing signal where it first leaves the
    band (time, result, the band's bounds, by how much) and the largest
    excess."""
    name: str
    passed: bool
    compared: int = 0
    failed: int = 0
    time: float = None
    value: float = None
    lower: float = None
    upper: float = None
    excess: float = None
    largest_excess: float = None
    largest_at: float = None
    note: str = ""

    def describe(self):
        if self.passed:
            return f"{self.name}: {self.compared} samples within the band"
        if self.note:
            return f"{self.name}: {self.note}"
        band = f"{self.lower!r}" if self.lower == self.upper else f"[{self.lower!r}, {self.upper!r}]"
        return (f"{self.name} leaves the band first at t={self.time!r}: {self.value!r}, expected {band}, "
                f"off by {self.excess:.6g}; {self.failed} of {self.compared} samples outside, "
                f"the most by {self.largest_excess:.6g} at t={self.largest_at!r}")

    def as_dict(self):
        """For JSON: the fields that have a value."""
        return {k: _json_number(v) for k, v in vars(self).items() if v is not None and v != ""}


def _json_number(value):
    if isinstance(value, float) and not math.isfinite(value):
        return repr(value)  # JSON has no NaN or infinity: "nan", "inf", "-inf"
    return value


@dataclass
class Comparison:
    deviations: list = field(default_factory=list)
    problem: str = ""  # the whole result failed (no samples, simulation error)

    @property
    def passed(self):
        return not self.problem and all(d.passed for d in self.deviations)

    def messages(self):
        if self.problem:
            return [self.problem]
        return [d.describe() for d in self.deviations if not d.passed]


def _same_bits(a, b):
    both_nan = np.isnan(a) & np.isnan(b)
    return (a.view(np.uint64) == b.view(np.uint64)) | both_nan


def _aligned(result_time, reference_time):
    """For each reference time, the index of the result sample at that
    time (-1 if none); at a repeated reference time only the last row is
    compared (the others get -2)."""
    last = np.ones(len(reference_time), dtype=bool)
    last[:-1] = reference_time[1:] != reference_time[:-1]
    index = np.searchsorted(result_time, reference_time)
    index = np.clip(index, 0, len(result_time) - 1)
    best = np.full(len(reference_time), -1)
    for candidate in (index - 1, index):
        candidate = np.clip(candidate, 0, len(result_time) - 1)
        close = np.abs(result_time[candidate] - reference_time) <= TIME_MATCH * np.maximum(1.0, np.abs(reference_time))
        best = np.where((best < 0) & close, candidate, best)
    return np.where(last, best, -2)


def _verdict(name, times, values, lower, upper, ok):
    deviation = Deviation(name, bool(ok.all()), compared=len(ok), failed=int((~ok).sum()))
    if not deviation.passed:
        with np.errstate(invalid="ignore"):
            excess = np.where(values > upper, values - upper, lower - values)
        excess = np.where(np.isnan(excess), np.inf, excess)
        excess = np.where(ok, -np.inf, excess)
        first = int(np.argmin(ok))
        worst = int(np.argmax(excess))
        deviation.time, deviation.value = float(times[first]), float(values[first])
        deviation.lower, deviation.upper = float(lower[first]), float(upper[first])
        deviation.excess = float(excess[first])
        deviation.largest_excess, deviation.largest_at = float(excess[worst]), float(times[worst])
    return deviation


def _pointwise(name, result, reference, tolerance, index):
    use = index >= 0
    times = reference["time"][use]
    expected = reference[name][use].astype(np.float64)
    values = result[name][index[use]].astype(np.float64)
    if tolerance.mode == "exact":
        ok = _same_bits(values, expected)
        lower = upper = expected
    else:
        with np.errstate(invalid="ignore"):
            allowed = tolerance.abs_tol + tolerance.rel_tol * np.abs(expected)
            lower, upper = expected - allowed, expected + allowed
            ok = ((values >= lower) & (values <= upper)) | (np.isnan(values) & np.isnan(expected)) | (values == expected)
    return _verdict(name, times, values, lower, upper, ok)


def _polyline_at(times, values, at):
    """The reference polyline at time at (inside its time range)."""
    k = int(np.searchsorted(times, at, side="right")) - 1
    if k >= len(times) - 1:
        return float(values[-1])
    t0, t1 = times[k], times[k + 1]
    if t1 == t0:
        return float(values[k + 1])
    return float(values[k] + (values[k + 1] - values[k]) * (at - t0) / (t1 - t0))


def tube_bounds(reference_time, reference_values, times, tube_time, tube_value):
    """The tube's lower and upper bound at each of times (NaN outside the
    reference's time range: there the reference says nothing)."""
    lower = np.full(len(times), np.nan)
    upper = np.full(len(times), np.nan)
    t_first, t_last = reference_time[0], reference_time[-1]
    for i, t in enumerate(times):
        if not t_first <= t <= t_last:
            continue
        start, end = max(t - tube_time, t_first), min(t + tube_time, t_last)
        inside = reference_values[np.searchsorted(reference_time, start, "left"):
                                  np.searchsorted(reference_time, end, "right")]
        edges = [_polyline_at(reference_time, reference_values, start),
                 _polyline_at(reference_time, reference_values, end)]
        window = np.concatenate([inside, edges])
        if np.isnan(window).all():
            continue
        lower[i] = np.nanmin(window) - tube_value
        upper[i] = np.nanmax(window) + tube_value
    return lower, upper


def _tube(name, result, reference, tolerance):
    reference_values = reference[name].astype(np.float64)
    times = result["time"]
    values = result[name].astype(np.float64)
    lower, upper = tube_bounds(reference["time"], reference_values, times, tolerance.tube_time, tolerance.tube_value)
    inside = ~np.isnan(lower)
    with np.errstate(invalid="ignore"):
        ok = (values[inside] >= lower[inside]) & (values[inside] <= upper[inside])
    return _verdict(name, times[inside], values[inside], lower[inside], upper[inside], ok)


def compare(result, reference, tolerance=Tolerance()):
    """The Comparison of a result (structured array with 'time') with a
    reference, for every signal of the reference."""
    names = [n for n in reference.dtype.names if n != "time"]
    missing = [n for n in names if n not in result.dtype.names]
    if missing:
        return Comparison(problem=f"the result has no signal {', '.join(missing)}")
    if len(result) == 0:
        return Comparison(problem="the result has no samples")
    if tolerance.mode == "tube":
        return Comparison([_tube(name, result, reference, tolerance) for name in names])
    index = _aligned(result["time"], reference["time"])
    deviations = [_pointwise(name, result, reference, tolerance, index) for name in names]
    absent = np.flatnonzero(index == -1)
    if len(absent):
        t = float(reference["time"][absent[0]])
        return Comparison(deviations, problem=f"the result has no sample at t={t!r} "
                                              f"({len(absent)} reference times without one)")
    return Comparison(deviations)
