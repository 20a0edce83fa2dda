"""Time as recorders stamp it, made seconds from the recording's first
sample, and matched to the cycles of the FMU's step.

Units: s, ms, us, ns (a number per sample), FILETIME (100 ns ticks since
1601, TwinCAT's full time stamps), OLE days (WinCC's Time_ms: days since
30 Dec 1899 times 1e6), date strings (ISO 8601, 24.03.2014 10:42:55.123,
22-Sep-26 09:00:01.250 AM UTC, ...), and cycle counts (times the step).
Integer stamps are subtracted as integers first, so FILETIME's 1.3e17
ticks lose no resolution.

Each stamp belongs to its nearest cycle on the grid its channels fit
(_clock: jitter, a recorder's own clock); one further than OFF_CYCLE of
a cycle from it is reported.
"""

import re
from datetime import datetime, timedelta, timezone

import numpy as np

from .._traces import MAX_STEPS
from .._errors import InputError, TraceError
from .._names import Names, name_of, shortest
from fractions import Fraction

from ._model import TIME_DIVISORS, TIME_FACTORS

OFF_CYCLE = 0.1  # a stamp more than this fraction of a cycle from a cycle end is reported
MAX_SPARSE = 100  # and so are samples this many steps apart on average (unless the caller gave the unit)
MAX_SPAN = 366 * 86400.0  # and so is a recording over a year long
FINEST = "the finest interval between its time stamps"  # a step's source: the channels' median intervals
SNAP = 1e-3  # an interval between stamps this close to a shorter decimal is that decimal
UNIT_WORDS = {
    "s": "s",
    "sec": "s",
    "seconds": "s",
    "ms": "ms",
    "msec": "ms",
    "us": "us",
    "µs": "us",
    "μs": "us",
    "usec": "us",
    "ns": "ns",
    "cycle": "cycles",
    "cycles": "cycles",
}
UNIT_NAMES = {
    "s": "seconds",
    "ms": "milliseconds",
    "us": "microseconds",
    "ns": "nanoseconds",
    "cycles": "cycle counts",
    "FILETIME": "FILETIME (100 ns ticks since 1601)",
    "OLE days": "OLE days (days since 30 Dec 1899, times 1e6)",
    "date": "dates and times",
}
_UNIT_IN_NAME = re.compile(r"(?:[\[(]\s*([^\])]+?)\s*[\])]|[_/ ](ms|us|µs|ns|s)\s*$)", re.IGNORECASE)


def unit_in_name(name):
    """The time unit a column's name states ('Time [ms]', 'Zeit (ms)',
    'Time_ms', 'time/s'), or None."""
    match = _UNIT_IN_NAME.search(name)
    if not match:
        return None
    word = (match.group(1) or match.group(2)).strip()
    return UNIT_WORDS.get(word) or UNIT_WORDS.get(word.lower())


# stamps of a time column that names no unit, by their size: FILETIME of the years 1981 to 2108 (100 ns ticks
# since 1601, as TwinCAT and Windows stamp), Unix time in ms of 2001 to 2096; anything else is seconds
FILETIME_SIZED = (1.2e17, 1.6e17)
UNIX_MS_SIZED = (1e12, 4e12)


def unnamed_unit(stamps, name):
    """(unit, why) of a time column that names no unit."""
    first = stamps[0]
    if stamps.dtype.kind == "i" and FILETIME_SIZED[0] <= first <= FILETIME_SIZED[1]:
        return "FILETIME", f"column {name!r} names no unit; its stamps are FILETIME-sized"
    if UNIX_MS_SIZED[0] <= first <= UNIX_MS_SIZED[1]:
        return "ms", f"column {name!r} names no unit; its stamps are Unix time in ms"
    return "s", f"assumed: column {name!r} names no unit"


# -- date strings ---------------------------------------------------------------
_MONTHS = {
    m: i + 1 for i, m in enumerate(("jan", "feb", "mar", "apr", "may", "jun", "jul", "aug", "sep", "oct", "nov", "dec"))
}
_MONTHS.update({"mär": 3, "mrz": 3, "mai": 5, "okt": 10, "dez": 12})
_DATE_FORMS = [
    # 2026-11-20T14:03:11.125+01:00, 2026-11-20 14:03:11,125
    re.compile(
        r"^(?P<Y>\d{4})-(?P<m>\d{1,2})-(?P<d>\d{1,2})[T ](?P<H>\d{1,2}):(?P<M>\d{2}):(?P<S>\d{2})"
        r"(?:[.,](?P<f>\d+))?\s*(?P<z>Z|[+-]\d{2}:?\d{2})?(?:\s*(?P<zn>[A-Za-z]{1,5}))?$"
    ),
    # 24.03.2014 10:42:55.123 (WinCC), 20/11/2026 14:03:11
    re.compile(
        r"^(?P<d>\d{1,2})[./](?P<m>\d{1,2})[./](?P<Y>\d{2,4})\s+(?P<H>\d{1,2}):(?P<M>\d{2}):(?P<S>\d{2})"
        r"(?:[.,](?P<f>\d+))?(?:\s*(?P<ap>[AaPp][Mm]))?(?:\s*(?P<zn>[A-Za-z]{1,5}))?$"
    ),
    # 22-Sep-26 09:00:01.250 AM UTC (Niagara)
    re.compile(
        r"^(?P<d>\d{1,2})-(?P<b>[A-Za-zä]{3})-(?P<Y>\d{2,4})\s+(?P<H>\d{1,2}):(?P<M>\d{2}):(?P<S>\d{2})"
        r"(?:[.,](?P<f>\d+))?(?:\s*(?P<ap>[AaPp][Mm]))?(?:\s*(?P<z>[+-]\d{2}:?\d{2}))?"
        r"(?:\s*(?P<zn>[A-Za-z]{1,5}))?$"
    ),
]


def looks_like_date(text):
    return any(form.match(text.strip()) for form in _DATE_FORMS)


def parse_date(text):
    """A date string as integer nanoseconds since 1970 (local times and
    named zones other than UTC/GMT/Z taken as they read: only differences
    matter here); None if it is no date form known."""
    text = text.strip()
    for form in _DATE_FORMS:
        match = form.match(text)
        if match:
            break
    else:
        return None
    g = match.groupdict()
    year = int(g["Y"])
    if year < 100:
        year += 2000
    month = _MONTHS.get(g["b"].lower()) if g.get("b") else int(g["m"])
    if month is None:
        return None
    hour = int(g["H"])
    if g.get("ap"):
        hour = hour % 12 + (12 if g["ap"].lower() == "pm" else 0)
    try:
        moment = datetime(year, month, int(g["d"]), hour, int(g["M"]), int(g["S"]), tzinfo=timezone.utc)
    except ValueError:
        return None
    zone = g.get("z")
    if zone and zone != "Z":
        sign = -1 if zone[0] == "-" else 1
        digits = zone[1:].replace(":", "")
        moment -= sign * timedelta(hours=int(digits[:2]), minutes=int(digits[2:]))
    fraction = g.get("f") or ""
    nanoseconds = int((fraction + "000000000")[:9]) if fraction else 0
    return int((moment - datetime(1970, 1, 1, tzinfo=timezone.utc)).total_seconds()) * 1_000_000_000 + nanoseconds


def dates(cells, text, line_of, column, name):
    """A column of date strings as int64 nanoseconds; the first that is no
    date is a TraceError at its place."""
    out = np.empty(len(cells), dtype=np.int64)
    for i, cell in enumerate(cells):
        value = parse_date(cell)
        if value is None:
            raise text.error(
                line_of(i),
                column,
                f"{cell.strip()!r} in column {name!r} is not a date and time "
                "(e.g. 2026-11-20 14:03:11.125 or 20.11.2026 14:03:11.125)",
            )
        out[i] = value
    return out


# -- seconds from the first sample -------------------------------------------------
def normalise(recording, time_unit=None, step_size=None, default_step=None, names: Names = (), using=None):
    """Set every channel's times (seconds from the first sample of the
    channels using names, by default all of them) and the recording's
    step_size: step_size if given, else the sample time the file declares
    for those channels, else the finest interval between their time
    stamps (the recorder sampled every cycle), else default_step (the
    FMU's) for cycle counts. using: the channels compared or driven (the
    others never change the time base: a CAN log's unmapped 100 Hz
    messages, an XCP calibration channel at t = 0). time_unit overrides
    the recording's. Refuses a recording whose length in steps is absurd,
    naming the unit it assumed. names: the caller's words for the settings
    (RecordingOptions.names)."""
    if time_unit:
        if recording.time_unit in ("date", "OLE days") and time_unit != recording.time_unit:
            raise InputError(
                f"{recording.label}: its time stamps are {UNIT_NAMES[recording.time_unit]}: "
                f"{name_of(names, time_unit=time_unit)} does not apply"
            )
        recording.time_unit, recording.time_source = time_unit, name_of(names, "time_unit")
        recording.unit_given = True
    unit = recording.time_unit
    channels = [c for c in (recording.channels if using is None else using) if len(c.stamps)]
    if not channels and using:
        named = ", ".join(repr(c.name) for c in using)
        raise TraceError(recording.label, 0, 0, f"no samples: the channels compared or driven ({named}) hold none")
    if not channels:
        raise TraceError(recording.label, 0, 0, "no samples: the recording holds no channel with values")
    declared = [c.sample_time for c in channels if c.sample_time]
    sample_time = min(declared) if declared else recording.sample_time
    if unit == "cycles":
        step = step_size or sample_time or default_step
        if not step:
            raise InputError(
                f"{recording.label}: its time is a cycle count: give the cycle time with {name_of(names, 'step_size')}"
            )
        recording.step_size = step
        recording.step_source = (
            name_of(names, "step_size")
            if step_size
            else "the recording's sample time"
            if sample_time
            else "the FMU's default step size"
        )
    origin = min(c.stamps[0] for c in channels)
    recording.origin = origin
    for channel in recording.channels:
        channel.times = seconds(_minus(channel.stamps, origin), unit, recording.step_size)
    span = max(float(c.times[-1]) for c in channels)
    assumed = f"{UNIT_NAMES[unit]} ({recording.time_source})" if unit != "date" else UNIT_NAMES[unit]
    if too_long(span):
        advice = (
            f"more than a year: compare a part of it ({name_of(names, 'time_unit')} does not apply to "
            f"{UNIT_NAMES[unit]})"
            if unit in ("date", "OLE days")
            else f"if that is not its unit, give {name_of(names, 'time_unit')} (s, ms, us, ns, cycles, filetime)"
        )
        raise InputError(
            f"{recording.label}: with its time read as {assumed}, the recording would span "
            f"{span:.4g} s ({span / 86400:.4g} days): {advice}"
        )
    if unit != "cycles":
        if step_size:
            recording.step_size, recording.step_source = step_size, name_of(names, "step_size")
        elif sample_time:
            recording.step_size, recording.step_source = sample_time, "the recording's sample time"
        else:
            step = finest_interval(channels)
            if step is None:
                if not default_step:
                    raise InputError(
                        f"{recording.label}: one sample per channel tells no cycle time: give "
                        f"{name_of(names, 'step_size')}"
                    )
                step, source = default_step, "the FMU's default step size"
            else:
                source = FINEST
            recording.step_size, recording.step_source = step, source
    steps = span / recording.step_size
    samples = max(len(c.times) for c in channels)
    certain = recording.unit_given or unit in ("date", "OLE days")  # no unit can be misread
    if too_many_steps(steps, samples, recording.unit_given or (certain and bool(step_size))):
        step = name_of(names, "step_size")
        cycle = "a coarser cycle" if step_size else "the recorder's cycle"
        advice = (
            f"give {cycle} with {step}"
            if certain
            else f"if that is not its unit, give {name_of(names, 'time_unit')} (s, ms, us, ns, cycles, filetime)"
            + ("" if step_size else f", or the recorder's cycle with {step}")
        )
        raise InputError(
            f"{recording.label}: with its time read as {assumed} and a step of "
            f"{shortest(recording.step_size)} s ({recording.step_source}) the recording would take "
            f"{steps:.3g} steps for {samples} samples: {advice}"
        )
    return recording


def _minus(stamps, origin):
    """stamps - origin as float64, exactly for integer stamps."""
    if stamps.dtype.kind in "iu":
        return (stamps - np.int64(origin)).astype(np.float64)
    if stamps.dtype.kind == "M":
        return (stamps - origin).astype("timedelta64[ns]").astype(np.int64).astype(np.float64)
    return stamps.astype(np.float64) - float(origin)


def seconds(elapsed, unit, step=None):
    """Stamps minus the origin (float64, in unit) as seconds, each rounded once: divided by a unit's
    whole fraction of a second, cycle counts by cycle_times."""
    if unit == "cycles":
        whole = np.rint(elapsed)
        if np.array_equal(whole, elapsed):
            return cycle_times(whole.astype(np.int64), step)
        return elapsed * step
    if unit in TIME_DIVISORS:
        return elapsed / TIME_DIVISORS[unit]
    return elapsed * TIME_FACTORS[unit]


WHOLE = 1e-3  # of a tick: a stamp this close to a whole number of ticks is one (its decimals read back)


def decimal_resolution(values):
    """The fewest decimals (0 to 9) of their unit that make every value
    whole: a recorder's resolution, read back from the stamps it wrote
    (a TIME in ms: 0); None where none does."""
    for digits in range(10):
        scaled = values * 10.0**digits
        if not len(values) or (np.abs(scaled).max() < 2**53 and np.all(np.abs(scaled - np.rint(scaled)) <= WHOLE)):
            return digits
    return None


def cycle_times(index, step):
    """The times index * step of whole cycles, each the double nearest the exact decimal product when
    the step is a short decimal (p / q): (index * p) / q, one rounding, so cycle 42 of 0.0001 s is
    0.0042, not 0.004200000000000001; index * step where that cannot be exact."""
    index = np.asarray(index)
    numerator, denominator = Fraction(repr(float(step))).as_integer_ratio()
    largest = int(np.abs(index).max()) if len(index) else 0
    if denominator > 1 << 53 or largest * abs(numerator) > 1 << 53:
        return index * step
    return (index * numerator).astype(np.float64) / float(denominator)


def nominal(time, cycle, step):
    """A sample's time (seconds) as a message shows it: its cycle's time from the whole cycle when it
    is on that cycle (the arithmetic of reading it adds no noise then: 0.0042, not
    0.004200000000000001), else as read (as_read)."""
    exact = float(cycle_times(np.array([cycle]), step)[0])
    return exact if abs(time - exact) <= OFF_CYCLE * step else as_read(time)


def as_read(time):
    """A time read from a stamp (seconds) without the few ulps its conversion added (10.0004 ms is
    0.010000400000000001 s divided, 0.0100004 s as written): 15 significant digits, which every
    decimal of 15 digits survives."""
    return float(f"{float(time):.15g}")


def too_long(span):
    """Whether a recording span seconds long is a misread unit."""
    return span > MAX_SPAN


def too_many_steps(steps, samples, unit_given):
    """Whether so many steps for so many samples is a misread unit (or
    step); sparse samples are not, when the caller gave the unit."""
    return steps > MAX_STEPS or (steps > MAX_SPARSE * samples and not unit_given)


class Intervals:
    """The positive intervals between consecutive times of a time column,
    given whole or block by block, counted by value (a recorder's are a
    handful of values): their exact median without keeping them all."""

    def __init__(self, times=None):
        self.values, self.counts, self.last = np.empty(0), np.empty(0, dtype=np.int64), None
        if times is not None:
            self.add(times)

    def add(self, times):
        if not len(times):
            return
        joined = times if self.last is None else np.concatenate([[self.last], times])
        self.last = times[-1]
        steps = np.diff(joined)
        values, counts = np.unique(steps[steps > 0], return_counts=True)
        self.values, at = np.unique(np.concatenate([self.values, values]), return_inverse=True)
        merged = np.zeros(len(self.values), dtype=np.int64)
        np.add.at(merged, at, np.concatenate([self.counts, counts]))
        self.counts = merged

    def median(self):
        """np.median of all the intervals (None if there are none)."""
        total = int(self.counts.sum())
        if not total:
            return None
        middle = np.searchsorted(np.cumsum(self.counts), [(total - 1) // 2, total // 2], side="right")
        return float(np.median(self.values[middle]))  # one value twice, or the two middle ones: their mean


def finest_interval(channels):
    """The smallest of the channels' typical (median) positive intervals
    between samples, in seconds; None if no channel has two samples."""
    medians = [m for m in (Intervals(channel.times).median() for channel in channels) if m is not None]
    return snapped_interval(min(medians)) if medians else None


def snapped_interval(best):
    """A typical interval between stamps as the recorder's cycle."""
    # clocks and printed stamps are not exact: a median of 0.2499985 s is a 250 ms cycle (the shortest
    # decimal within SNAP of it)
    for digits in range(1, 16):
        rounded = float(f"{best:.{digits}g}")
        if abs(rounded - best) <= SNAP * best:
            return rounded
    return best
