"""A result against its reference, signal by signal, in a comparison mode:

exact      every value bit for bit (any NaN matches any NaN)
tolerance  |result - reference| <= abs_tol + rel_tol * |reference|
tube       the reference drawn as a polyline (a repeated time is a
           vertical jump), widened by tube_time in time and tube_value in
           value, as the Modelica Association's csv-compare draws it: a
           result sample passes when some point of the reference lies
           within tube_time of its time and tube_value of its value (the
           samples inside the reference's time range are checked). For
           traces sampled at other instants than the FMU's steps.

A mode is an object (Exact, Tolerance, Tube) that gives each signal's
Band: the samples compared and the bounds each must lie in. The verdict,
the report's plot and its wording ask the mode; a new mode is a new class
here.

In the exact and tolerance modes each reference sample is compared with
the result's sample at the same time: times match within 1e-9 s, or
within 1e-9 of |t| beyond |t| = 1 s (they are communication points, sums
of steps); at a repeated time the reference's last row, the value from
that instant on, is the one compared. A reference sample without a
result sample at its time fails.
"""

import math
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from ._errors import InputError
from ._names import Names, name_of

TIME_MATCH = 1e-9  # seconds below |t| = 1 s, relative above


@dataclass(frozen=True)
class Band:
    """One signal's compared samples and the band each must lie in."""

    times: np.ndarray
    values: np.ndarray  # the result's, as float64
    lower: np.ndarray
    upper: np.ndarray
    ok: np.ndarray  # the sample passes
    deviation: np.ndarray  # what the report plots under the signals


@dataclass
class Deviation:
    """A signal's verdict; for a failing signal where it first leaves the
    band (time, result, the band's bounds, by how much) and the largest
    excess."""

    name: str
    passed: bool
    compared: int = 0
    failed: int = 0
    time: float | None = None
    value: float | None = None
    lower: float | None = None
    upper: float | None = None
    excess: float | None = None
    largest_excess: float | None = None
    largest_at: float | None = None
    note: str = ""

    NUMBERS: ClassVar[tuple] = ("time", "value", "lower", "upper", "excess", "largest_excess", "largest_at")

    def describe(self) -> str:
        if self.passed:
            return f"{self.name}: {self.compared} samples within the band"
        if self.note:
            return f"{self.name}: {self.note}"
        band = f"{self.lower!r}" if self.lower == self.upper else f"[{self.lower!r}, {self.upper!r}]"
        return (
            f"{self.name} leaves the band first at t={self.time!r}: {self.value!r}, expected {band}, "
            f"off by {self.excess:.6g}; {self.failed} of {self.compared} samples outside, "
            f"the most by {self.largest_excess:.6g} at t={self.largest_at!r}"
        )

    def to_json(self) -> dict:
        """The fields that have a value; NaN and infinities as "nan", "inf", "-inf" (JSON has none)."""
        return {
            k: repr(v) if isinstance(v, float) and not math.isfinite(v) else v
            for k, v in vars(self).items()
            if v is not None and v != ""
        }

    @classmethod
    def from_json(cls, entry: dict) -> "Deviation":
        fields: dict[str, Any] = {
            k: float(v) if k in cls.NUMBERS and isinstance(v, str) else v for k, v in entry.items()
        }
        return cls(**fields)


@dataclass
class Comparison:
    deviations: list = field(default_factory=list)  # of Deviation, one per signal
    problem: str = ""  # the whole result failed (no samples, simulation error)
    bands: dict = field(default_factory=dict, repr=False)  # name -> Band, for a plot

    @property
    def passed(self) -> bool:
        return not self.problem and all(d.passed for d in self.deviations)

    def messages(self) -> list:
        if self.problem:
            return [self.problem]
        return [d.describe() for d in self.deviations if not d.passed]


class Mode:
    """How a result is judged against a reference (a frozen dataclass of
    its settings)."""

    name: ClassVar[str]  # in results.json
    fills_band: ClassVar[bool]  # the plot draws the band (else the reference is it)
    reference_line: ClassVar[dict]  # how the plot draws the reference (matplotlib)
    deviation_label: ClassVar[str]  # what the plot's last axis shows

    def settings(self) -> dict:
        """The arguments of comparison_mode that make this mode."""
        return dict(vars(self))

    def describe(self) -> str:
        raise NotImplementedError

    def bands(self, result, reference, names) -> tuple:
        """({name: Band}, problem): problem names what the result lacks ("" if nothing)."""
        raise NotImplementedError


class Pointwise(Mode):
    """Each reference sample against the result's at its time."""

    fills_band = False
    reference_line = {"drawstyle": "steps-post", "color": "0.6", "linewidth": 4}
    deviation_label = "result - ref"

    def bounds(self, values, expected):
        """(lower, upper, ok) of the result's values against the expected ones."""
        raise NotImplementedError

    def bands(self, result, reference, names):
        index = aligned(result["time"], reference["time"])
        use = index >= 0
        times = reference["time"][use]
        bands = {}
        for name in names:
            expected = reference[name][use].astype(np.float64)
            values = result[name][index[use]].astype(np.float64)
            lower, upper, ok = self.bounds(values, expected)
            with np.errstate(invalid="ignore", over="ignore"):
                bands[name] = Band(times, values, lower, upper, ok, values - expected)
        absent = np.flatnonzero(index == -1)
        if not len(absent):
            return bands, ""
        return bands, (
            f"the result has no sample at t={float(reference['time'][absent[0]])!r} "
            f"({len(absent)} reference times without one)"
        )


@dataclass(frozen=True)
class Exact(Pointwise):
    name: ClassVar[str] = "exact"

    def describe(self):
        return "exact (bit for bit)"

    def bounds(self, values, expected):
        both_nan = np.isnan(values) & np.isnan(expected)
        return expected, expected, (values.view(np.uint64) == expected.view(np.uint64)) | both_nan


@dataclass(frozen=True)
class Tolerance(Pointwise):
    rel_tol: float = 0.0
    abs_tol: float = 0.0

    name: ClassVar[str] = "tolerance"

    def __post_init__(self):
        _check_widths({"rel_tol": self.rel_tol, "abs_tol": self.abs_tol})

    def describe(self):
        return f"relative tolerance {self.rel_tol:g}, absolute tolerance {self.abs_tol:g}"

    def bounds(self, values, expected):
        with np.errstate(invalid="ignore"):
            allowed = self.abs_tol + self.rel_tol * np.abs(expected)
            lower, upper = expected - allowed, expected + allowed
            ok = (
                ((values >= lower) & (values <= upper)) | (np.isnan(values) & np.isnan(expected)) | (values == expected)
            )  # an infinity equal to its reference (its band is NaN)
        return lower, upper, ok


@dataclass(frozen=True)
class Tube(Mode):
    time: float
    value: float

    name: ClassVar[str] = "tube"
    fills_band = True
    reference_line = {"color": "0.5", "linewidth": 1}
    deviation_label = "outside the tube"

    def __post_init__(self):
        _check_widths({"tube_time": self.time, "tube_value": self.value})

    def settings(self):
        return {"tube_time": self.time, "tube_value": self.value}

    def describe(self):
        return f"tube of {self.time:g} s and {self.value:g}"

    def bands(self, result, reference, names):
        return {name: self.band(result, reference, name) for name in names}, ""

    def band(self, result, reference, name, span=None):
        """The Band of the result's samples of signal name in the tube
        around the reference; span: the whole reference's (first, last)
        time where reference is a window of it (None: its own)."""
        lower, upper = tube_bounds(
            reference["time"], reference[name].astype(np.float64), result["time"], (self.time, self.value), span
        )
        inside = ~np.isnan(lower)  # the samples inside the reference's time range
        values, lower, upper = result[name].astype(np.float64)[inside], lower[inside], upper[inside]
        with np.errstate(invalid="ignore"):
            ok = (values >= lower) & (values <= upper)
            outside = np.where(values > upper, values - upper, np.where(values < lower, values - lower, 0.0))
        return Band(result["time"][inside], values, lower, upper, ok, outside)


def _check_widths(widths, names: Names = ()):
    """Every width a finite number >= 0; widths: setting -> value; names:
    the caller's words for the settings."""
    for setting, value in widths.items():
        if not (value >= 0 and math.isfinite(value)):
            raise InputError(f"{name_of(names, setting)} must be a finite number >= 0, not {value!r}")


EXACT = Exact()


def comparison_mode(
    rel_tol: float = 0.0,
    abs_tol: float = 0.0,
    tube_time: float | None = None,
    tube_value: float | None = None,
    *,
    names: Names = (),
) -> Mode:
    """The mode the command's options (and compare's arguments of the same
    names) choose: a tube, a tolerance, else exact. InputError if they do
    not make one, naming the settings in names (the caller's words, as
    RecordingOptions.names; default the API's)."""
    if (tube_time is None) != (tube_value is None):
        raise InputError(
            "a tube needs both its time and its value tolerance "
            f"({name_of(names, 'tube_time')} and {name_of(names, 'tube_value')})"
        )
    if tube_time is not None and tube_value is not None:
        if rel_tol or abs_tol:
            raise InputError("choose a tube or a relative/absolute tolerance, not both")
        _check_widths({"tube_time": tube_time, "tube_value": tube_value}, names)
        return Tube(tube_time, tube_value)
    _check_widths({"rel_tol": rel_tol, "abs_tol": abs_tol}, names)
    return Tolerance(rel_tol, abs_tol) if (rel_tol or abs_tol) else EXACT


def time_slack(t):
    """How far apart two times may be and still be the same instant (the
    rule aligned uses): communication points are sums of steps."""
    return TIME_MATCH * np.maximum(1.0, np.abs(t))


def aligned(result_time, reference_time):
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
        close = np.abs(result_time[candidate] - reference_time) <= time_slack(reference_time)
        best = np.where((best < 0) & close, candidate, best)
    return np.where(last, best, -2)


class Verdict:
    """A signal's Deviation from its bands given one after the other (a
    long case's chunks, in time order): the same as from the whole band at
    once (the first failing sample, the first of the largest excesses)."""

    def __init__(self, name):
        self.deviation = Deviation(name, True)

    def add(self, band):
        ok, d = band.ok, self.deviation
        failed = int((~ok).sum())
        d.compared += len(ok)
        if not failed:
            return
        d.passed, d.failed = False, d.failed + failed
        times, values, lower, upper = band.times, band.values, band.lower, band.upper
        with np.errstate(invalid="ignore"):
            excess = np.where(values > upper, values - upper, lower - values)
        excess = np.where(np.isnan(excess), np.inf, excess)
        excess = np.where(ok, -np.inf, excess)
        if d.time is None:
            first = int(np.argmin(ok))
            d.time, d.value = float(times[first]), float(values[first])
            d.lower, d.upper, d.excess = float(lower[first]), float(upper[first]), float(excess[first])
        worst = int(np.argmax(excess))
        if d.largest_excess is None or excess[worst] > d.largest_excess:
            d.largest_excess, d.largest_at = float(excess[worst]), float(times[worst])


def _verdict(name, band):
    verdict = Verdict(name)
    verdict.add(band)
    return verdict.deviation


def _polyline_at(times, values, at):
    """The reference polyline at time at (inside its time range)."""
    k = int(np.searchsorted(times, at, side="right")) - 1
    if k >= len(times) - 1:
        return float(values[-1])
    t0, t1 = times[k], times[k + 1]
    if t1 == t0:
        return float(values[k + 1])
    with np.errstate(invalid="ignore"):  # a NaN sample gives NaN, which the window's nanmin and nanmax leave out
        return float(values[k] + (values[k + 1] - values[k]) * (at - t0) / (t1 - t0))


def tube_bounds(reference_time, reference_values, times, widths, span=None):
    """The tube's lower and upper bound at each of times (NaN outside the
    reference's time range: there the reference says nothing); widths:
    (time, value); a reference sample at the window's edge counts (up to
    the rounding of its time). span: the whole reference's (first, last) time where
    reference_time is a window of it that holds every sample within the
    tube's time of each of times and one more on either side (None: its
    own)."""
    tube_time, tube_value = widths
    lower = np.full(len(times), np.nan)
    upper = np.full(len(times), np.nan)
    t_first, t_last = span if span is not None else (reference_time[0], reference_time[-1])
    for i, t in enumerate(times):
        if not t_first <= t <= t_last:
            continue
        start, end = max(t - tube_time, t_first), min(t + tube_time, t_last)
        slack = time_slack(t)  # a sample exactly at the allowed time counts, however t - tube_time rounds
        inside = reference_values[
            np.searchsorted(reference_time, start - slack, "left") : np.searchsorted(
                reference_time, end + slack, "right"
            )
        ]
        edges = [
            _polyline_at(reference_time, reference_values, start),
            _polyline_at(reference_time, reference_values, end),
        ]
        window = np.concatenate([inside, edges])
        if np.isnan(window).all():
            continue
        lower[i] = np.nanmin(window) - tube_value
        upper[i] = np.nanmax(window) + tube_value
    return lower, upper


def compare_traces(result, reference, mode: Mode = EXACT) -> Comparison:
    """The Comparison of a result (structured array with 'time') with a
    reference, for every signal of the reference."""
    names = [n for n in reference.dtype.names if n != "time"]
    missing = [n for n in names if n not in result.dtype.names]
    if missing:
        return Comparison(problem=f"the result has no signal {', '.join(missing)}")
    if len(result) == 0:
        return Comparison(problem="the result has no samples")
    bands, problem = mode.bands(result, reference, names)
    return Comparison([_verdict(name, band) for name, band in bands.items()], problem, bands)
