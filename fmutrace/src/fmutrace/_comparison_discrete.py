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
        first = int(cycle[0])
        if not _same(x[first], expected[0]):
            ok[0] = False
            note = f"starts at {shown(x[first])}, expected {shown(expected[0])} at t={float(rt[first])!r}"
            return self._failed(deviation, ok, note, 1, (rt, x, cycle, expected)), ok
        seen = x[cycle]
        # the reference's changes, each somewhere in the cycles after its row's predecessor up to its row; the
        # result's that its samples at the reference's rows show (between two rows the reference says nothing),
        # each at the last cycle it changed in that interval
        wanted = [
            Change(int(cycle[row - 1]) + 1, int(cycle[row]), row, float(expected[row - 1]), float(expected[row]))
            for row in _changed(expected)
        ]
        made = []
        for row in _changed(seen):
            j = self._last_change(x, int(cycle[row - 1]), int(cycle[row]))
            made.append(Change(j, j, row, float(seen[row - 1]), float(seen[row])))
        pairs = pair_changes(wanted, made, self.cycles)
        problems = unpaired(wanted, made, pairs, self.cycles, rt)
        if problems:
            for _, row, _ in problems:
                ok[row] = False
            return self._failed(deviation, ok, explain(problems), len(problems), (rt, x, cycle, expected)), ok
        shifts = [(wanted[m].shift(made[n].first), made[n].first) for m, n in pairs.items()]
        if self.cycles and shifts:
            most, at = max(shifts, key=lambda s: s[0])  # (the first of the largest)
            where = f" at t={float(rt[at])!r}" if most else ""
            deviation.allowance = f"time allowance used: {most} of {cycles_text(self.cycles)}{where}"
        return deviation, ok

    @staticmethod
    def _failed(deviation, ok, note, failed, traces):
        """deviation failed at the first reference sample not ok, with note."""
        rt, x, cycle, expected = traces
        bad = int(np.argmin(ok))
        deviation.passed, deviation.failed, deviation.note = False, failed, note
        deviation.time, deviation.value = float(rt[cycle[bad]]), float(x[cycle[bad]])
        deviation.lower = deviation.upper = float(expected[bad])
        return deviation


@dataclass(frozen=True)
class Change:
    """A change of a discrete signal from before to after, made in one of
    the cycles first to last (a reference row says only that it happened
    since the row before); row: the reference row that shows it."""

    first: int
    last: int
    row: int
    before: float
    after: float

    def same_as(self, other: "Change") -> bool:
        """The same change (from the same value to the same value; NaN is NaN)."""
        return bool(_same(np.float64(self.before), other.before) and _same(np.float64(self.after), other.after))

    def shift(self, at: int) -> int:
        """How many cycles a change made at cycle at lies outside this one's cycles."""
        return max(self.first - at, at - self.last, 0)


def pair_changes(wanted, made, cycles) -> dict:
    """{index in wanted: index in made}: each of the reference's changes
    paired with the result's nearest change of the same values within
    cycles, as an engineer pairs them (the closest pairs first, a change in
    one pair only); a missing or added change leaves the others' pairs as
    they are."""
    starts = np.array([c.first for c in made], dtype=np.int64)
    candidates = []
    for m, change in enumerate(wanted):
        lo = int(np.searchsorted(starts, change.first - cycles, "left"))
        hi = int(np.searchsorted(starts, change.last + cycles, "right"))
        for n in range(lo, hi):
            if change.same_as(made[n]):
                candidates.append((change.shift(made[n].first), abs(made[n].first - change.last), m, n))
    pairs: dict = {}
    taken = set()
    for _, _, m, n in sorted(candidates):
        if m not in pairs and n not in taken:
            pairs[m] = n
            taken.add(n)
    return pairs


def unpaired(wanted, made, pairs, cycles, rt) -> list:
    """The changes left unpaired, in time order, as (cycle, reference row,
    words; rt: the result's times, the cycles' in the words): a change of the reference with the
    result's same change next to it in time (no other change between) comes
    too late or too early; a change to another value next to it is one;
    two changes of one trace there and back are a pulse; the rest are
    missing from the result or added to it."""

    def when(cycle):
        return repr(float(rt[cycle]))

    taken = set(pairs.values())
    lost = [m for m in range(len(wanted)) if m not in pairs]
    added = [n for n in range(len(made)) if n not in taken]
    unpaired_at = {(0, m) for m in lost} | {(1, n) for n in added}
    order = sorted([(c.last, 0, m) for m, c in enumerate(wanted)] + [(c.first, 1, n) for n, c in enumerate(made)])
    place = {(side, i): k for k, (_, side, i) in enumerate(order)}
    problems, done = [], set()
    for m in lost:
        change = wanted[m]
        for k in (place[0, m] - 1, place[0, m] + 1):  # the changes of either trace just before and after it
            if (
                not 0 <= k < len(order)
                or order[k][1] != 1
                or (1, order[k][2]) not in unpaired_at
                or (1, order[k][2]) in done
            ):
                continue
            n = order[k][2]
            other = made[n]
            if change.same_as(other):
                late = "late" if other.first > change.last else "early"
                words = (
                    f"the reference's change to {shown(change.after)} at t={when(change.last)} comes "
                    f"{cycles_text(change.shift(other.first))} {late} (t={when(other.first)}), "
                    f"more than the {cycles} allowed"
                )
            else:
                words = (
                    f"changes to {shown(other.after)} at t={when(other.first)} where the reference's next change is "
                    f"to {shown(change.after)} at t={when(change.last)}"
                )
            problems.append((min(change.last, other.first), change.row, words))
            done |= {(0, m), (1, n)}
            break
    for side, changes, left in ((0, wanted, lost), (1, made, added)):
        for i in left:
            if (side, i) in done:
                continue
            change, back = changes[i], changes[i + 1] if i + 1 < len(changes) else None
            pulse = (
                back is not None
                and (side, i + 1) in unpaired_at
                and (side, i + 1) not in done
                and back.same_as(_reversed(change))
            )
            at = change.last if side == 0 else change.first
            if pulse:
                assert back is not None
                until = back.last if side == 0 else back.first
                done.add((side, i + 1))
                words = (
                    f"the reference's pulse to {shown(change.after)} at t={when(at)} ({cycles_text(until - at)}) "
                    "is missing from the result"
                    if side == 0
                    else f"changes to {shown(change.after)} at t={when(at)} and back at t={when(until)}, "
                    "a pulse the reference lacks"
                )
            elif side == 0:
                words = f"the reference's change to {shown(change.after)} at t={when(at)} is missing from the result"
            else:
                words = f"changes to {shown(change.after)} at t={when(at)}, a change the reference lacks"
            problems.append((at, change.row, words))
            done.add((side, i))
    return sorted(problems, key=lambda p: p[0])


def _reversed(change: Change) -> Change:
    return Change(change.first, change.last, change.row, change.after, change.before)


def explain(problems) -> str:
    """The first of the unpaired changes in words, and how many there are in all."""
    first = problems[0][2]
    return first if len(problems) == 1 else f"{first}; {len(problems)} changes or pulses unpaired in all"
