"""What a comparison says: each signal's Band (the samples compared and
the bounds each must lie in), its Deviation (the verdict and, for a
failing signal, where and by how much), a result's Comparison, and the
Verdict that gathers a Deviation from Bands given one after the other.
The words every mode's messages share live here too."""

import math
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np


@dataclass(frozen=True)
class Band:
    """One signal's compared samples and the band each must lie in."""

    times: np.ndarray
    values: np.ndarray  # the result's, as float64
    lower: np.ndarray
    upper: np.ndarray
    ok: np.ndarray  # the sample passes
    deviation: np.ndarray  # what the report plots under the signals
    back: "Band | None" = None  # a two-sided tube's second side: the reference's samples in the tube around the result


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
    direction: str = ""  # a tube's failing side: "result" (in the tube around the reference) or "reference"
    also: str = ""  # a two-sided tube's other side where it fails too

    NUMBERS: ClassVar[tuple] = ("time", "value", "lower", "upper", "excess", "largest_excess", "largest_at")

    def describe(self) -> str:
        who = f"{self.name} ({self.criterion})" if self.criterion else self.name
        used = f"; {self.allowance}" if self.allowance else ""
        if self.passed:
            return f"{who}: {self.compared} samples pass{used}"
        if self.note:
            return f"{who}: {self.note}{used}"
        band = f"{self.lower!r}" if self.lower == self.upper else f"[{self.lower!r}, {self.upper!r}]"
        if self.direction:
            also = f"; {self.also}" if self.also else ""
            return (
                f"{who}: {self.side()} first at t={self.time!r}: {self.value!r}, the tube there {band}, "
                f"off by {self.excess:.6g}; {self.failed} of {self.compared} of its samples outside, "
                f"the most by {self.largest_excess:.6g} at t={self.largest_at!r}{also}{used}"
            )
        if self.lower == self.upper:  # (exact: no band but the expected value)
            return (
                f"{who} differs first at t={self.time!r}: {self.value!r}, expected {band}, "
                f"off by {self.excess:.6g}; {self.failed} of {self.compared} samples differ, "
                f"the most by {self.largest_excess:.6g} at t={self.largest_at!r}{used}"
            )
        return (
            f"{who} leaves the band first at t={self.time!r}: {self.value!r}, expected {band}, "
            f"off by {self.excess:.6g}; {self.failed} of {self.compared} samples outside, "
            f"the most by {self.largest_excess:.6g} at t={self.largest_at!r}{used}"
        )

    def side(self) -> str:
        """Which trace leaves the tube around which (direction's words)."""
        inner, outer = ("result", "reference") if self.direction == "result" else ("reference", "result")
        return f"the {inner} leaves the tube around the {outer}"

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


def verdict_of(name, band):
    verdict = Verdict(name)
    verdict.add(band)
    return verdict.deviation


def shown(value):
    """A discrete signal's value as its reader writes it: whole numbers without a fraction."""
    number = float(value)
    return repr(int(number)) if number.is_integer() and abs(number) < 2**53 else repr(number)


def cycles_text(n):
    return f"{n} cycle{'' if n == 1 else 's'}"
