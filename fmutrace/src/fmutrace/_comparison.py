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

import fnmatch
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from ._errors import InputError
from ._names import Names, name_of
from ._traces import plain_float

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
    criterion: str = ""  # the signal's own criterion (per-signal criteria only)
    allowance: str = ""  # how much of a time allowance was used, where it came closest to failing

    NUMBERS: ClassVar[tuple] = ("time", "value", "lower", "upper", "excess", "largest_excess", "largest_at")

    def describe(self) -> str:
        who = f"{self.name} ({self.criterion})" if self.criterion else self.name
        used = f"; {self.allowance}" if self.allowance else ""
        if self.passed:
            return f"{who}: {self.compared} samples within the band{used}"
        if self.note:
            return f"{who}: {self.note}{used}"
        band = f"{self.lower!r}" if self.lower == self.upper else f"[{self.lower!r}, {self.upper!r}]"
        return (
            f"{who} leaves the band first at t={self.time!r}: {self.value!r}, expected {band}, "
            f"off by {self.excess:.6g}; {self.failed} of {self.compared} samples outside, "
            f"the most by {self.largest_excess:.6g} at t={self.largest_at!r}{used}"
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
        failing = [d.describe() for d in self.deviations if not d.passed]
        return failing + [d.describe() for d in self.deviations if d.passed and d.allowance]  # (time allowances)


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
        return {name: _verdict(name, band) for name, band in bands.items()}, bands, problem


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
        _check_widths({"rel_tol": self.rel_tol, "abs_tol": self.abs_tol})

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

    def spec(self):
        return f"tube:time={self.time!r},value={self.value!r}"

    def time_used(self, result, reference, name):
        """(seconds, at): the largest time, over the result's samples inside
        the tube, to the nearest point of the reference's polyline within
        the tube's value of the sample, and that sample's time: how much of
        the tube's time a sample needed (a time allowance that hides a value
        error uses all of it). (0, None) if none is inside."""
        times, values = reference["time"], reference[name].astype(np.float64)
        most, at = 0.0, None
        for t, v in zip(result["time"], result[name].astype(np.float64), strict=True):
            if not times[0] <= t <= times[-1]:
                continue
            need = _distance_to_polyline(times, values, float(t), float(v), self.value, self.time + time_slack(t))
            need = 0.0 if need <= time_slack(t) else need  # (the same instant, up to the times' rounding)
            if need <= self.time + time_slack(t) and (at is None or need > most):
                most, at = min(need, self.time), float(t)
        return most, at

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


def _shown(value):
    """A discrete signal's value as its reader writes it: whole numbers without a fraction."""
    number = float(value)
    return repr(int(number)) if number.is_integer() and abs(number) < 2**53 else repr(number)


def _changed(values):
    """The indexes where values change (NaN equal to NaN)."""
    return np.flatnonzero(~_same(values[1:], values[:-1])) + 1


def _cycles(n):
    return f"{n} cycle{'' if n == 1 else 's'}"


def _same(a, b):
    """Equal values, NaN equal to NaN."""
    return (a == b) | (np.isnan(a) & np.isnan(b))


@dataclass(frozen=True)
class Discrete(Mode):
    """Exact in value, never interpolated, each change of the reference
    found in the result within cycles result samples (communication
    points: PLC cycles) early or late, and no change of the result that the
    reference lacks. A reference sample holds the result's value of the
    last communication point at or before its time (sample and hold); a
    reference sparser than the result sees the result's changes at its own
    samples only."""

    cycles: int = 0

    name: ClassVar[str] = "discrete"
    fills_band = False
    reference_line = {"drawstyle": "steps-post", "color": "0.6", "linewidth": 4}
    deviation_label = "result - ref"

    def __post_init__(self):
        if not (isinstance(self.cycles, int) and self.cycles >= 0):
            raise InputError(f"Discrete.cycles must be a whole number >= 0, not {self.cycles!r}")

    def describe(self):
        if not self.cycles:
            return "exact"
        return f"exact, up to {_cycles(self.cycles)} early or late"

    def spec(self):
        return f"discrete:cycles={self.cycles}"

    def bands(self, result, reference, names):
        deviations, bands, problem = self.judge(result, reference, names)
        return bands, problem

    def judge(self, result, reference, names):
        rt = result["time"]
        ref_t = reference["time"]
        last_row = np.ones(len(ref_t), dtype=bool)
        last_row[:-1] = ref_t[1:] != ref_t[:-1]  # (at a repeated time: the value from that instant on)
        held = np.searchsorted(rt, ref_t + time_slack(ref_t), "right") - 1
        use = last_row & (held >= 0)
        cycle, times = held[use], ref_t[use]
        deviations, bands = {}, {}
        for name in names:
            expected = reference[name][use].astype(np.float64)
            result_values = result[name].astype(np.float64)
            values = result_values[cycle]
            deviation, ok = self._changes(name, rt, result_values, cycle, expected)
            deviation.compared = len(times)
            deviations[name] = deviation
            with np.errstate(invalid="ignore", over="ignore"):
                bands[name] = Band(times, values, expected, expected, ok, values - expected)
        return deviations, bands, ""

    @staticmethod
    def _last_change(x, after, until):
        """The last result sample in (after, until] where x changes."""
        return after + int(_changed(x[after : until + 1])[-1])

    def _changes(self, name, rt, x, cycle, expected):
        """(Deviation, ok per reference sample) of result x against the
        expected values at the result samples cycle."""
        ok = np.ones(len(cycle), dtype=bool)
        deviation = Deviation(name, True)
        if not len(cycle):
            return deviation, ok
        k = self.cycles
        ref_at = _changed(expected)  # reference rows that change
        # the result's changes that its samples at the reference's rows show (between two rows the reference
        # says nothing), each at the last cycle it changed in that interval
        first = int(cycle[0])
        res_at = [self._last_change(x, int(cycle[s - 1]), int(cycle[s])) for s in _changed(x[cycle])]
        problem, shift_most, shift_at = "", 0, None
        if not _same(x[first], expected[0]):
            problem = f"starts at {_shown(x[first])}, expected {_shown(expected[0])} at t={float(rt[first])!r}"
            ok[0] = False
        for m in range(max(len(ref_at), len(res_at))):
            if problem:
                break
            if m >= len(ref_at):
                j = int(res_at[m])
                problem = f"changes to {_shown(x[j])} at t={float(rt[j])!r}, a change the reference lacks"
                ok[min(int(np.searchsorted(cycle, j)), len(ok) - 1)] = False
                break
            row = int(ref_at[m])
            earliest, latest = int(cycle[row - 1]) + 1, int(cycle[row])
            if m >= len(res_at):
                problem = (
                    f"the reference's change to {_shown(expected[row])} at t={float(rt[latest])!r} "
                    "is missing from the result"
                )
                ok[row] = False
                break
            j = int(res_at[m])
            shift = max(earliest - j, j - latest, 0)
            if not _same(x[j], expected[row]):
                problem = (
                    f"changes to {_shown(x[j])} at t={float(rt[j])!r} where the reference's next change is "
                    f"to {_shown(expected[row])} at t={float(rt[latest])!r}"
                )
            elif shift > k:
                when = "late" if j > latest else "early"
                problem = (
                    f"the reference's change to {_shown(expected[row])} at t={float(rt[latest])!r} comes "
                    f"{_cycles(shift)} {when} (t={float(rt[j])!r}), more than the {k} allowed"
                )
            if problem:
                ok[row] = False
                break
            if shift_at is None or shift > shift_most:
                shift_most, shift_at = shift, float(rt[j])
        if problem:
            bad = int(np.argmin(ok))
            deviation.passed, deviation.failed, deviation.note = False, 1, problem
            deviation.time, deviation.value = float(rt[cycle[bad]]), float(x[cycle[bad]])
            deviation.lower = deviation.upper = float(expected[bad])
        elif k and shift_at is not None:
            where = f" at t={shift_at!r}" if shift_most else ""
            deviation.allowance = f"time allowance used: {shift_most} of {_cycles(k)}{where}"
        return deviation, ok


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


@dataclass(frozen=True)
class Criteria(Mode):
    """Each signal its own mode: the first of signals (name or fnmatch
    pattern -> mode; "*" is the default) that matches its name, else
    default. A discrete signal (discrete: the names of the FMU's variables
    of a discrete type, Fmu.discrete_names, given by whoever knows the FMU)
    is never interpolated or judged by its magnitude: under a tube it is
    judged Discrete with the tube's time in whole cycles, under a
    tolerance or ulps exactly."""

    signals: tuple = ()  # ((pattern, Mode), ...); a mapping is turned into one
    default: Mode = field(default_factory=Exact)
    discrete: frozenset = frozenset()

    name: ClassVar[str] = "criteria"
    fills_band = True
    reference_line = {"color": "0.5", "linewidth": 1}
    deviation_label = "result - ref, or outside the tube"

    def __post_init__(self):
        signals = self.signals.items() if isinstance(self.signals, Mapping) else self.signals
        pairs = []
        for pattern, mode in signals:
            if not isinstance(mode, Mode) or isinstance(mode, Criteria):
                raise InputError(f"Criteria: the mode of {pattern!r} must be a mode object, not {mode!r}")
            if pattern == "*":
                object.__setattr__(self, "default", mode)
            else:
                pairs.append((str(pattern), mode))
        object.__setattr__(self, "signals", tuple(pairs))
        object.__setattr__(self, "discrete", frozenset(self.discrete))
        if not isinstance(self.default, Mode) or isinstance(self.default, Criteria):
            raise InputError(f"Criteria: the default must be a mode object, not {self.default!r}")

    def settings(self):
        return {"signals": [[p, m.spec()] for p, m in self.signals], "default": self.default.spec()}

    def describe(self):
        named = "; ".join(f"{p}: {m.describe()}" for p, m in self.signals)
        return f"per signal: {named + '; ' if named else ''}the rest: {self.default.describe()}"

    def spec(self):
        raise InputError("per-signal criteria cannot be one signal's mode")

    def given(self, name) -> Mode:
        """The mode given for signal name (first matching pattern, else the default)."""
        for pattern, mode in self.signals:
            if pattern == name or fnmatch.fnmatchcase(name, pattern):
                return mode
        return self.default

    def mode_of(self, name, step) -> Mode:
        """The mode signal name is judged by; step: the result's communication step."""
        mode = self.given(name)
        if name not in self.discrete or isinstance(mode, (Exact, Discrete)):
            return mode
        if isinstance(mode, Tube):
            return Discrete(int(math.floor(mode.time / step + TIME_MATCH))) if step > 0 else Discrete(0)
        return Discrete(0)

    def bands(self, result, reference, names):
        deviations, bands, problem = self.judge(result, reference, names)
        return bands, problem

    def judge(self, result, reference, names):
        step = float(result["time"][1] - result["time"][0]) if len(result) > 1 else 0.0
        deviations, bands, problems = {}, {}, []
        for name in names:
            mode = self.mode_of(name, step)
            judged, banded, problem = mode.judge(result, reference, [name])
            if problem and problem not in problems:
                problems.append(problem)
            if name not in judged:
                continue
            deviation = judged[name]
            deviation.criterion = mode.describe()
            if isinstance(mode, Tube) and mode.time > 0:
                used, at = mode.time_used(result, reference, name)
                if at is not None:
                    where = f" at t={at!r}" if used else ""
                    deviation.allowance = (
                        f"time allowance used: {used:.6g} of {mode.time:g} s ({used / mode.time:.0%}){where}"
                    )
            deviations[name], bands[name] = deviation, banded[name]
        return deviations, bands, "; ".join(problems)


def criteria_for(mode: Mode, pairs=(), discrete=frozenset()) -> Mode:
    """The mode a case is judged by: mode with a case's own criteria
    (pairs: (pattern, Mode), "*" the default) before the campaign's, the
    FMU's discrete signals named; mode itself when neither is per-signal
    (a Discrete mode for every signal is a Criteria of that default)."""
    if not pairs and not isinstance(mode, (Criteria, Discrete)):  # (Discrete judges the whole trace, as Criteria)
        return mode
    given = Criteria(pairs)
    if isinstance(mode, Criteria):
        named = dict(pairs)
        default = named.get("*", mode.default)
        return Criteria(given.signals + mode.signals, default, frozenset(discrete))
    return Criteria(given.signals, dict(pairs).get("*", mode), frozenset(discrete))


def signal_criteria(assignments, default: Mode, names: Names = ()) -> Mode:
    """The mode of the command's --signal NAME=MODE assignments (pairs of
    texts; '*' the default) over default (the other options' mode); default
    itself without any. InputError for a mode that is not one, naming the
    setting in names (the caller's words)."""
    if not assignments:
        return default
    pairs = []
    for pattern, words in assignments:
        try:
            pairs.append((pattern, parse_mode(words)))
        except InputError as error:
            raise InputError(f"{name_of(names, signals=(pattern, words))}: {error}") from None
    if any(p == "*" for p, _ in pairs) and default != EXACT:
        raise InputError(f"give the rest's mode once: {name_of(names, signals=('*', '...'))} or a tolerance or tube")
    return Criteria(tuple(pairs), default)


MODE_WORDS = "exact, tol:abs=A,rel=R, tube:time=S,value=V, discrete[:cycles=K], ulps:N[,binary32|binary64]"


def parse_mode(text: str) -> Mode:
    """A mode from its words (Mode.spec's): exact, tol:abs=1e-6,rel=0,
    tube:time=0.01,value=0, discrete:cycles=1, ulps:4,binary32.
    InputError if text is none of them."""
    kind, _, rest = text.strip().partition(":")
    kind = kind.strip().lower()
    items = [item.strip() for item in rest.split(",")] if rest.strip() else []

    def numbers(allowed, whole=()):
        given = {}
        for item in items:
            key, sep, value = item.partition("=")
            key = key.strip().lower()
            if not sep or key not in allowed or key in given:
                raise InputError(f"mode {text!r}: expected {kind}:{','.join(k + '=...' for k in allowed)}")
            try:
                given[key] = int(value) if key in whole else plain_float(value.strip())
            except ValueError:
                raise InputError(f"mode {text!r}: {key} {value.strip()!r} is not a number") from None
            if not (given[key] >= 0 and math.isfinite(given[key])):
                raise InputError(f"mode {text!r}: {key} must be a finite number >= 0, not {value.strip()}")
        return given

    if kind == "exact" and not items:
        return EXACT
    if kind in ("tol", "tolerance"):
        given = numbers(("abs", "rel"))
        return Tolerance(given.get("rel", 0.0), given.get("abs", 0.0))
    if kind == "tube":
        given = numbers(("time", "value"))
        if len(given) != 2:
            raise InputError(f"mode {text!r}: a tube needs both time= and value=")
        return Tube(given["time"], given["value"])
    if kind == "discrete":
        return Discrete(numbers(("cycles",), whole=("cycles",)).get("cycles", 0))
    if kind == "ulps" and 1 <= len(items) <= 2:
        arithmetic = items[1].lower() if len(items) == 2 else "binary64"
        if not items[0].isdigit():
            raise InputError(f"mode {text!r}: the number of ulps {items[0]!r} is not a whole number >= 0")
        if arithmetic not in ARITHMETIC_TYPES:
            raise InputError(f"mode {text!r}: the arithmetic is one of {', '.join(ARITHMETIC_TYPES)}")
        return Ulps(int(items[0]), arithmetic)
    raise InputError(f"mode {text!r} is none of: {MODE_WORDS}")


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
        with np.errstate(invalid="ignore", over="ignore"):
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


def _distance_to_polyline(times, values, t, v, width, reach):
    """The smallest |tau - t| (at most reach; inf if none) at which the
    polyline (times, values) lies within width of v."""
    lo = int(np.searchsorted(times, t - reach, "left"))
    hi = int(np.searchsorted(times, t + reach, "right"))
    best = math.inf
    for k in range(max(lo - 1, 0), min(hi + 1, len(times))):
        t0, p0 = times[k], values[k]
        if abs(p0 - v) <= width:
            best = min(best, abs(t0 - t))
        if k + 1 >= len(times):
            continue
        t1, p1 = times[k + 1], values[k + 1]
        if math.isnan(p0) or math.isnan(p1) or t1 == t0:  # (a jump is reached at its time)
            if t1 == t0 and min(p0, p1) - width <= v <= max(p0, p1) + width:
                best = min(best, abs(t0 - t))
            continue
        if p1 == p0:
            a, b = (0.0, 1.0) if abs(p0 - v) <= width else (1.0, 0.0)
        else:
            a, b = sorted(((v - width - p0) / (p1 - p0), (v + width - p0) / (p1 - p0)))
        a, b = max(a, 0.0), min(b, 1.0)
        if a > b:
            continue
        start, end = t0 + a * (t1 - t0), t0 + b * (t1 - t0)
        best = min(best, 0.0 if start <= t <= end else min(abs(start - t), abs(end - t)))
    return best


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
    deviations, bands, problem = mode.judge(result, reference, names)
    return Comparison(list(deviations.values()), problem, bands)
