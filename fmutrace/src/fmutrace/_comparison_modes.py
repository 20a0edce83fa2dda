"""How a result is judged against a reference: a mode is an object that
gives each signal's Band (the samples compared and the bounds each must
lie in); the verdict, the report's plot and its wording ask the mode; a
new mode is a new class (here, or in a module of its own as Tube and
Discrete).

exact      every value bit for bit (any NaN matches any NaN)
tolerance  |result - reference| <= abs_tol + rel_tol * |reference|
ulps       within n units in the last place of binary32 or binary64

These pointwise modes compare each reference sample with the result's
sample at the same time: times match within 1e-9 s, or within 1e-9 of
|t| beyond |t| = 1 s (they are communication points, sums of steps); at
a repeated time the reference's last row, the value from that instant
on, is the one compared. A reference sample without a result sample at
its time fails.
"""

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from ._errors import InputError
from ._names import Names, name_of
from ._comparison_verdicts import Band, verdict_of

TIME_MATCH = 1e-9  # seconds below |t| = 1 s, relative above


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

    def spec(self) -> str:
        """The mode in the words of --signal NAME=MODE and criteria files (parse_mode reads it back)."""
        raise NotImplementedError

    def judge(self, result, reference, names) -> tuple:
        """({name: Deviation}, {name: Band}, problem): the verdict of every signal."""
        bands, problem = self.bands(result, reference, names)
        return {name: verdict_of(name, band) for name, band in bands.items()}, bands, problem


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

    def spec(self):
        return "exact"

    def bounds(self, values, expected):
        both_nan = np.isnan(values) & np.isnan(expected)
        return expected, expected, (values.view(np.uint64) == expected.view(np.uint64)) | both_nan


@dataclass(frozen=True)
class Tolerance(Pointwise):
    rel_tol: float = 0.0
    abs_tol: float = 0.0

    name: ClassVar[str] = "tolerance"

    def __post_init__(self):
        check_widths({"rel_tol": self.rel_tol, "abs_tol": self.abs_tol})

    def describe(self):
        return f"relative tolerance {self.rel_tol:g}, absolute tolerance {self.abs_tol:g}"

    def spec(self):
        return f"tol:abs={self.abs_tol!r},rel={self.rel_tol!r}"

    def bounds(self, values, expected):
        with np.errstate(invalid="ignore"):
            allowed = self.abs_tol + self.rel_tol * np.abs(expected)
            lower, upper = expected - allowed, expected + allowed
            ok = (
                ((values >= lower) & (values <= upper)) | (np.isnan(values) & np.isnan(expected)) | (values == expected)
            )  # an infinity equal to its reference (its band is NaN)
        return lower, upper, ok


ARITHMETIC_TYPES = {
    "binary32": (np.float32, np.int32, 0x7FFFFFFF),
    "binary64": (np.float64, np.int64, 0x7FFFFFFFFFFFFFFF),
}


FINITE_MAX = {"binary32": float(np.finfo(np.float32).max), "binary64": float(np.finfo(np.float64).max)}


def _ordinal(values, arithmetic):
    """Each value rounded to the arithmetic, as its place on the line of
    that arithmetic's numbers (adjacent numbers 1 apart, +0 and -0 both 0)."""
    float_type, int_type, magnitude = ARITHMETIC_TYPES[arithmetic]
    with np.errstate(over="ignore"):
        bits = values.astype(float_type).view(int_type).astype(np.int64)
    return np.where(bits < 0, -(bits & magnitude), bits)


def _from_ordinal(ordinal, arithmetic):
    float_type, int_type, magnitude = ARITHMETIC_TYPES[arithmetic]
    sign = np.int64(magnitude) + 1 if arithmetic == "binary32" else np.iinfo(np.int64).min
    bits = np.where(ordinal < 0, (-ordinal) | sign, ordinal)
    return bits.astype(int_type).view(float_type).astype(np.float64)


@dataclass(frozen=True)
class Ulps(Pointwise):
    """Within n units in the last place of a named arithmetic: result and
    reference rounded to it (binary32: a REAL controller's numbers), then
    their distance counted in its numbers (across zero too; NaN matches
    NaN, an infinity only itself)."""

    n: int = 1
    arithmetic: str = "binary64"

    name: ClassVar[str] = "ulps"

    def __post_init__(self):
        if not (isinstance(self.n, int) and self.n >= 0):
            raise InputError(f"Ulps.n must be a whole number >= 0, not {self.n!r}")
        if self.arithmetic not in ARITHMETIC_TYPES:
            raise InputError(f"Ulps.arithmetic must be one of {', '.join(ARITHMETIC_TYPES)}, not {self.arithmetic!r}")

    def describe(self):
        return f"within {self.n} ulp{'s' if self.n != 1 else ''} of {self.arithmetic}"

    def spec(self):
        return f"ulps:{self.n},{self.arithmetic}"

    def distance(self, values, expected):
        """Each pair's distance in the arithmetic's numbers (capped above n)."""
        a, b = _ordinal(values, self.arithmetic), _ordinal(expected, self.arithmetic)
        cap = self.n + 1
        across = (a > 0) & (b < 0) | (a < 0) & (b > 0)
        with np.errstate(over="ignore"):
            near = np.abs(a - b)
        return np.where(across, np.minimum(np.abs(a), cap) + np.minimum(np.abs(b), cap), np.minimum(near, cap))

    def bounds(self, values, expected):
        nan_a, nan_b = np.isnan(values), np.isnan(expected)
        with np.errstate(over="ignore"):  # (beyond the arithmetic's range: its infinity)
            rounded_a, rounded_b = (v.astype(ARITHMETIC_TYPES[self.arithmetic][0]) for v in (values, expected))
        infinite_b = np.isinf(rounded_b)
        with np.errstate(invalid="ignore"):
            ok = np.where(
                nan_a | nan_b | np.isinf(rounded_a) | infinite_b,
                (nan_a & nan_b) | (rounded_a == rounded_b),
                self.distance(values, expected) <= self.n,
            )
        base = _ordinal(np.where(nan_b | infinite_b, 0.0, expected), self.arithmetic)
        finite_max = _ordinal(np.array([FINITE_MAX[self.arithmetic]]), self.arithmetic)[0]
        lower = _from_ordinal(np.maximum(base - self.n, -finite_max), self.arithmetic)
        upper = _from_ordinal(np.minimum(base + self.n, finite_max), self.arithmetic)
        special = nan_b | infinite_b
        return np.where(special, expected, lower), np.where(special, expected, upper), ok


def check_widths(widths, names: Names = ()):
    """Every width a finite number >= 0; widths: setting -> value; names:
    the caller's words for the settings."""
    for setting, value in widths.items():
        if not (value >= 0 and math.isfinite(value)):
            raise InputError(f"{name_of(names, setting)} must be a finite number >= 0, not {value!r}")


EXACT = Exact()


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
