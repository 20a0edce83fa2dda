"""The discrete mode: a signal of a discrete type (a Boolean, an integer,
a status) judged exactly in value, never interpolated, its changes found
in the result within a number of cycles early or late."""

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from ._comparison_modes import Mode, time_slack
from ._comparison_verdicts import Band, Deviation, cycles_text, shown
from ._errors import InputError


def _changed(values):
    """The indexes where values change (NaN equal to NaN)."""
    return np.flatnonzero(~_same(values[1:], values[:-1])) + 1


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
        return f"exact, up to {cycles_text(self.cycles)} early or late"

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
            problem = f"starts at {shown(x[first])}, expected {shown(expected[0])} at t={float(rt[first])!r}"
            ok[0] = False
        for m in range(max(len(ref_at), len(res_at))):
            if problem:
                break
            if m >= len(ref_at):
                j = int(res_at[m])
                problem = f"changes to {shown(x[j])} at t={float(rt[j])!r}, a change the reference lacks"
                ok[min(int(np.searchsorted(cycle, j)), len(ok) - 1)] = False
                break
            row = int(ref_at[m])
            earliest, latest = int(cycle[row - 1]) + 1, int(cycle[row])
            if m >= len(res_at):
                problem = (
                    f"the reference's change to {shown(expected[row])} at t={float(rt[latest])!r} "
                    "is missing from the result"
                )
                ok[row] = False
                break
            j = int(res_at[m])
            shift = max(earliest - j, j - latest, 0)
            if not _same(x[j], expected[row]):
                problem = (
                    f"changes to {shown(x[j])} at t={float(rt[j])!r} where the reference's next change is "
                    f"to {shown(expected[row])} at t={float(rt[latest])!r}"
                )
            elif shift > k:
                when = "late" if j > latest else "early"
                problem = (
                    f"the reference's change to {shown(expected[row])} at t={float(rt[latest])!r} comes "
                    f"{cycles_text(shift)} {when} (t={float(rt[j])!r}), more than the {k} allowed"
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
            deviation.allowance = f"time allowance used: {shift_most} of {cycles_text(k)}{where}"
        return deviation, ok
