"""The tube: a trace drawn as a polyline (a repeated time is a vertical
jump), widened by tube_time in time and tube_value in value, as the
Modelica Association's csv-compare draws it: a sample passes when some
point of the polyline lies within tube_time of its time and tube_value of
its value (the samples inside the polyline's time range are checked).
For traces sampled at other instants than the FMU's steps.

A tube is checked both ways: the result's samples within the tube around
the reference, and the reference's within the tube around the result. A
one-cycle spike in the reference only widens the tube around it, so
csv-compare's one-sided check (sides=1, kept for comparisons with it)
passes it; the other way round the spike lies outside the tube around
the result, which no shift in time explains.
"""

import math
from dataclasses import dataclass, replace
from typing import ClassVar

import numpy as np

from ._comparison_modes import Mode, check_widths, time_slack
from ._errors import InputError
from ._comparison_verdicts import Band, Deviation, verdict_of


@dataclass(frozen=True)
class Tube(Mode):
    """A tube of time seconds and value around each trace; sides: 2 (the
    result within the tube around the reference and the reference within
    the tube around the result), 1 (the result's samples only, as
    csv-compare)."""

    time: float
    value: float
    sides: int = 2

    name: ClassVar[str] = "tube"
    fills_band = True
    reference_line = {"color": "0.5", "linewidth": 1}
    deviation_label = "outside the tube"

    def __post_init__(self):
        check_widths({"tube_time": self.time, "tube_value": self.value})
        if self.sides not in (1, 2):
            raise InputError(f"Tube.sides must be 1 or 2, not {self.sides!r}")

    def settings(self):
        return {"tube_time": self.time, "tube_value": self.value, "tube_sides": self.sides}

    def describe(self):
        one = ", one-sided" if self.sides == 1 else ""
        return f"tube of {self.time:g} s and {self.value:g}{one}"

    def spec(self):
        one = ",sides=1" if self.sides == 1 else ""
        return f"tube:time={self.time!r},value={self.value!r}{one}"

    def time_used(self, result, reference, name):
        """(seconds, at): the largest time, over the result's samples inside
        the tube, to the nearest point of the reference's polyline within
        the tube's value of the sample, and that sample's time: how much of
        the tube's time a sample needed (a time allowance that hides a value
        error uses all of it). (0, None) if none is inside. The sample named
        is the first that needs the most, or, of those needing more than the
        tube's time by no more than the times' rounding, the last."""
        times, values = reference["time"], reference[name].astype(np.float64)
        t, v = result["time"].astype(np.float64), result[name].astype(np.float64)
        inside = (times[0] <= t) & (t <= times[-1])
        t, v = t[inside], v[inside]
        slack = time_slack(t)
        need = _distances_to_polyline(times, values, t, v, self.value, self.time + slack)
        need = np.where(need <= slack, 0.0, need)  # (the same instant, up to the times' rounding)
        within = need <= self.time + slack
        t, need = t[within], need[within]
        if not len(need):
            return 0.0, None
        over = np.flatnonzero(need > self.time)
        if len(over):
            return self.time, float(t[over[-1]])
        at = int(np.argmax(need))
        return float(need[at]), float(t[at])

    def bands(self, result, reference, names):
        return {name: self.band(result, reference, name) for name in names}, ""

    def judge(self, result, reference, names):
        bands = {name: self.band(result, reference, name) for name in names}
        if self.sides == 2:  # (the second side's band rides on the first's: the report plots both)
            bands = {name: replace(band, back=self.back_band(reference, result, name)) for name, band in bands.items()}
        deviations = {
            name: self.verdict(verdict_of(name, band), verdict_of(name, band.back) if band.back else None)
            for name, band in bands.items()
        }
        return deviations, bands, ""

    def verdict(self, forth: Deviation, back: Deviation | None) -> Deviation:
        """A signal's verdict from the result's samples in the tube around
        the reference (forth) and, on a two-sided tube, the reference's in
        the tube around the result (back): the side that fails first in
        time, the other named if it fails too (a pass counts the result's
        samples, as a one-sided tube's)."""
        if back is None or (forth.passed and back.passed):
            forth.direction = "" if forth.passed else "result"
            return forth
        forth.direction, back.direction = "result", "reference"
        failing = [d for d in (forth, back) if not d.passed]
        first = min(failing, key=lambda d: d.time if d.time is not None else math.inf)
        other = back if first is forth else forth
        if not other.passed:
            first.also = f"{other.side()} too, first at t={other.time!r}"
        return first

    def band(self, inner, outer, name, span=None):
        """The Band of inner's samples of signal name in the tube around
        outer (Tube.band(result, reference, ...): the result's samples in
        the tube around the reference; the other way round for the second
        side); span: the whole outer trace's (first, last) time where outer
        is a window of it (None: its own)."""
        lower, upper = tube_bounds(
            outer["time"], outer[name].astype(np.float64), inner["time"], (self.time, self.value), span
        )
        inside = ~np.isnan(lower)  # the samples inside outer's time range
        values, lower, upper = inner[name].astype(np.float64)[inside], lower[inside], upper[inside]
        with np.errstate(invalid="ignore"):
            ok = (values >= lower) & (values <= upper)
            outside = np.where(values > upper, values - upper, np.where(values < lower, values - lower, 0.0))
        return Band(inner["time"][inside], values, lower, upper, ok, outside)

    def back_band(self, reference, result, name, span=None, following=math.nan):
        """The second side's Band: the reference's samples in the tube
        around the result, those whose whole window of the tube's time lies
        in the result's time range (span: its (first, last), None: its own).
        Nearer the run's ends the first side alone judges: beyond them the
        result says nothing, and a result one cycle late is not a spike. At
        a repeated time the last row, the value from that instant on, is
        the sample (as the pointwise modes compare it; the rows before it
        are the value up to the instant, which a result sampled at
        communication points does not hold); following: the time of the
        row after reference's last (NaN: none)."""
        first, last = span if span is not None else (result["time"][0], result["time"][-1])
        t = reference["time"]
        last_row = np.append(t[1:] != t[:-1], t[-1:] != following)
        with np.errstate(invalid="ignore"):  # (last: inf while the run goes on)
            whole = (t - self.time >= first - time_slack(t)) & (t + self.time <= last + time_slack(t))
        return self.band(reference[whole & last_row], result, name, span)


def _distances_to_polyline(times, values, t, v, width, reach):
    """For each sample (t, v): the smallest |tau - t| (at most its reach;
    inf if none) at which the polyline (times, values) lies within width of
    v; a repeated time is a vertical jump, a NaN breaks the line (its
    neighbours are reached at their times). Each segment near a sample is
    taken in one pass over all the samples: as many passes as a reach
    spans segments."""
    n = len(times)
    first = np.maximum(np.searchsorted(times, t - reach, "left") - 1, 0)
    end = np.minimum(np.searchsorted(times, t + reach, "right") + 1, n)
    best = np.full(len(t), np.inf)
    with np.errstate(invalid="ignore", divide="ignore"):
        for offset in range(int((end - first).max(initial=0))):
            k = first + offset
            active = k < end
            k = np.minimum(k, n - 1)
            t0, p0 = times[k], values[k]
            _nearer(best, active & (np.abs(p0 - v) <= width), np.abs(t0 - t))
            following = active & (k + 1 < n)
            t1, p1 = times[np.minimum(k + 1, n - 1)], values[np.minimum(k + 1, n - 1)]
            jump = t1 == t0
            low, high = np.where(p1 < p0, p1, p0), np.where(p1 > p0, p1, p0)
            _nearer(best, following & jump & (low - width <= v) & (v <= high + width), np.abs(t0 - t))
            line = following & ~jump & ~np.isnan(p0) & ~np.isnan(p1)
            flat = p1 == p0
            near = np.abs(p0 - v) <= width
            x, y = (v - width - p0) / (p1 - p0), (v + width - p0) / (p1 - p0)
            a = np.where(flat, np.where(near, 0.0, 1.0), np.where(y < x, y, x))
            b = np.where(flat, np.where(near, 1.0, 0.0), np.where(y < x, x, y))
            a, b = np.where(a < 0.0, 0.0, a), np.where(b > 1.0, 1.0, b)
            start, stop = t0 + a * (t1 - t0), t0 + b * (t1 - t0)
            distance = np.where((start <= t) & (t <= stop), 0.0, np.minimum(np.abs(start - t), np.abs(stop - t)))
            _nearer(best, line & ~(a > b), distance)
    return best


def _nearer(best, where, distance):
    """best lowered to distance where that is nearer (a NaN distance is none)."""
    np.copyto(best, distance, where=where & (distance < best))


def _polyline_at(times, values, at):
    """The reference polyline at each time of at (inside its time range)."""
    k = np.searchsorted(times, at, side="right") - 1
    last = k >= len(times) - 1
    k = np.minimum(k, len(times) - 2)
    t0, t1, v0, v1 = times[k], times[k + 1], values[k], values[k + 1]
    with np.errstate(invalid="ignore", divide="ignore"):  # a NaN sample gives NaN, which the window's fmin leaves out
        between = v0 + (v1 - v0) * (at - t0) / (t1 - t0)
    return np.where(last, values[-1], np.where(t1 == t0, v1, between))


QUERIES = 4096  # tube windows whose extremes one sparse table answers (its memory: their span of samples, log2 deep)


def _window_extremes(values, lo, hi):
    """(smallest, largest) of values[lo[i]:hi[i]] for each i, NaN left out
    (NaN where a window is empty or all NaN); lo and hi ascending: a
    sparse table of the span of each QUERIES windows answers them."""
    smallest, largest = np.full(len(lo), np.nan), np.full(len(lo), np.nan)
    for first in range(0, len(lo), QUERIES):
        part = slice(first, first + QUERIES)
        a, b = lo[part], hi[part]
        filled = b > a
        if not filled.any():
            continue
        base = int(a[filled].min())
        a, b = a[filled] - base, b[filled] - base
        size = b - a
        depth = int(size.max()).bit_length() - 1  # the largest power of 2 at most the widest window: 2^depth
        level = np.floor(np.log2(size)).astype(np.int64)
        low = high = values[base : base + int(b.max())]
        got_low, got_high = np.full(len(a), np.nan), np.full(len(a), np.nan)
        for j in range(depth + 1):
            if j:
                half = 1 << (j - 1)
                low, high = np.fmin(low[:-half], low[half:]), np.fmax(high[:-half], high[half:])
            at = level == j
            if at.any():
                reach = b[at] - (1 << j)
                got_low[at] = np.fmin(low[a[at]], low[reach])
                got_high[at] = np.fmax(high[a[at]], high[reach])
        smallest[np.flatnonzero(filled) + first] = got_low
        largest[np.flatnonzero(filled) + first] = got_high
    return smallest, largest


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
    inside = np.flatnonzero((times >= t_first) & (times <= t_last))
    if not len(inside):
        return lower, upper
    t = times[inside]
    start, end = np.maximum(t - tube_time, t_first), np.minimum(t + tube_time, t_last)
    slack = time_slack(t)  # a sample exactly at the allowed time counts, however t - tube_time rounds
    smallest, largest = _window_extremes(
        reference_values,
        np.searchsorted(reference_time, start - slack, "left"),
        np.searchsorted(reference_time, end + slack, "right"),
    )
    edges = (_polyline_at(reference_time, reference_values, start), _polyline_at(reference_time, reference_values, end))
    smallest, largest = np.fmin(smallest, np.fmin(*edges)), np.fmax(largest, np.fmax(*edges))
    lower[inside], upper[inside] = smallest - tube_value, largest + tube_value  # (NaN where the window is all NaN)
    return lower, upper
