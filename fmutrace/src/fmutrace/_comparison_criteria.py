"""The criteria a case is judged by: the mode the command's options
choose, a mode read from its words (--signal NAME=MODE, criteria files),
and per-signal criteria (Criteria: each signal its own mode)."""

import fnmatch
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import ClassVar

from ._comparison_discrete import Discrete
from ._comparison_modes import ARITHMETIC_TYPES, EXACT, TIME_MATCH, Exact, Mode, Tolerance, Ulps, check_widths
from ._comparison_tube import Tube
from ._errors import InputError
from ._names import Names, name_of
from ._traces import plain_float


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


MODE_WORDS = "exact, tol:abs=A,rel=R, tube:time=S,value=V[,sides=1], discrete[:cycles=K], ulps:N[,binary32|binary64]"


def parse_mode(text: str) -> Mode:
    """A mode from its words (Mode.spec's): exact, tol:abs=1e-6,rel=0,
    tube:time=0.01,value=0 (sides=1: one-sided), discrete:cycles=1,
    ulps:4,binary32.
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
        given = numbers(("time", "value", "sides"), whole=("sides",))
        if "time" not in given or "value" not in given:
            raise InputError(f"mode {text!r}: a tube needs both time= and value=")
        if given.get("sides", 2) not in (1, 2):
            raise InputError(f"mode {text!r}: a tube's sides are 1 or 2")
        return Tube(given["time"], given["value"], given.get("sides", 2))
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


def comparison_mode(
    rel_tol: float = 0.0,
    abs_tol: float = 0.0,
    tube_time: float | None = None,
    tube_value: float | None = None,
    *,
    tube_sides: int = 2,
    names: Names = (),
) -> Mode:
    """The mode the command's options (and compare's arguments of the same
    names) choose: a tube (tube_sides: 2, both ways; 1, the result's samples
    only), a tolerance, else exact. InputError if they do
    not make one, naming the settings in names (the caller's words, as
    RecordingOptions.names; default the API's)."""
    if (tube_time is None) != (tube_value is None):
        raise InputError(
            "a tube needs both its time and its value tolerance "
            f"({name_of(names, 'tube_time')} and {name_of(names, 'tube_value')})"
        )
    if tube_sides != 2 and tube_time is None:
        raise InputError(f"{name_of(names, 'tube_sides')} is a tube's: give the tube too")
    if tube_time is not None and tube_value is not None:
        if rel_tol or abs_tol:
            raise InputError("choose a tube or a relative/absolute tolerance, not both")
        check_widths({"tube_time": tube_time, "tube_value": tube_value}, names)
        return Tube(tube_time, tube_value, tube_sides)
    check_widths({"rel_tol": rel_tol, "abs_tol": abs_tol}, names)
    return Tolerance(rel_tol, abs_tol) if (rel_tol or abs_tol) else EXACT
