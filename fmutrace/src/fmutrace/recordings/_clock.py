"""The PLC's cycles in a recorder's time stamps: the samples of the
channels compared or driven fitted to one grid of cycles (a period and a
phase in the recorder's own clock), so that stamps that jitter, a clock
that drifts against the PLC's, a recorder that samples every k-th cycle
and cycles the OB skipped each put every sample on the cycle it was taken
in.

The model: a sample of cycle n is stamped phase + n * period + e, where e
is the jitter (the OB's start, the recorder's transport and clock) and
|e| < period / 2. The fit numbers the first samples by a search of the period
whose circle holds them in the narrowest arc (no guess of a phase, so
jitter of up to nearly half a cycle numbers them right), then fits the
line of period and phase by least squares over windows that grow from
there, each numbered by the line of the one before (so a drift of the
recorder's clock never puts a sample a cycle off); each sample's cycle is
then its nearest one on the last line. A window holds at
most FIT_SAMPLES samples, spread evenly over it, but the last, which
holds every sample (the line a recording read in blocks gets, clock.Line),
so a 48-hour recording costs a few passes over its stamps.
"""

from dataclasses import dataclass

import numpy as np

from ._timebase import snapped_interval

# samples on no grid: a typical distance over NO_GRID and more than FAR_SHARE of them FAR of a cycle off
# (stamps at random: 25 % and 10 %; jitter of up to 45 %: 22.5 % and none; Gaussian jitter of 15 %: 10 %
# and 0.3 %; a sender whose phase slips now and then: a few % typical)
NO_GRID, FAR, FAR_SHARE = 0.2, 0.45, 0.05
FIT_SAMPLES = 1 << 16  # samples a window's fit takes at most, spread evenly over it
SEARCH_WINDOW = 1024  # the first samples, numbered by the search of the period
NEAR = 2e-3  # the search's range around the period given: a snapped interval (0.1 %), clocks' drift
NO_ARC = 0.95  # of a cycle: an arc this wide near the period given means it is not the samples' period
PERIOD_RANGE = 0.15  # the wide search's range: a median interval that jitter and skipped cycles pulled a step off
ARC_STEP = 0.01  # of a cycle: the search's resolution at the last sample of its window
MAX_CANDIDATES = 4001  # periods the search tries at most in a window
RESTEP = 0.02  # a fitted cycle this far from the step that came from the median interval replaces it
GROWTH = 1.5  # each window this many times the one before
HISTOGRAM_BINS = 10_000  # of distances from 0 to half a cycle: the typical distance to 0.005 % of a cycle


@dataclass(frozen=True)
class Grid:
    """Cycle n of a recording is stamped phase + n * period (seconds from its first sample)."""

    period: float
    phase: float

    def index(self, times):
        """Each time's nearest cycle (int64)."""
        return np.rint((np.asarray(times, dtype=np.float64) - self.phase) / self.period).astype(np.int64)

    def distance(self, times, index):
        """How far each time is from its cycle, in cycles (negative: early)."""
        return (np.asarray(times, dtype=np.float64) - self.phase) / self.period - index


def fit(times, period):
    """The Grid of sorted times (seconds) near period: the first samples'
    by a search of the period whose circle holds them in the narrowest
    arc, near period (NEAR) or, where that leaves the samples on no grid
    (fits), in a wider range too (PERIOD_RANGE; the nearer of the two by
    the samples' typical distance); then the line of growing windows. One time: on
    the grid of period through it."""
    times = np.asarray(times, dtype=np.float64)
    if len(times) == 0:
        return Grid(period, 0.0)
    first = times[:SEARCH_WINDOW]
    near = _fit(times, _search(first, period, NEAR)[0])
    if fits(near.distance(times, near.index(times))):
        return near
    coarse = _search(first, period, PERIOD_RANGE)[0]  # (its steps may be coarser than ARC_STEP: refined)
    wide = _fit(times, _search(first, coarse.period, 4 * PERIOD_RANGE / MAX_CANDIDATES)[0])
    return min((near, wide), key=lambda g: _typical(times, g))


def _fit(times, grid):
    """The line of growing windows from the grid of the first samples."""
    size = min(len(times), SEARCH_WINDOW)
    while True:
        # each window numbered by the line of the one before (the first by the search), which the samples it
        # shares set: a window's line never numbers its own samples, which a narrow strip could tilt
        if size == len(times):  # the last line through every sample: the one a recording read in blocks gets
            grid = _line(times, grid)
            break
        grid = _line(times[: size : max(1, size // FIT_SAMPLES)], grid)
        size = min(len(times), int(size * GROWTH) + 1)
    first = int(grid.index(times[:1])[0])  # cycle 0 is the first sample's
    return Grid(grid.period, grid.phase + first * grid.period)


def fits(distance):
    """Whether samples so far from their cycles (in cycles) sit on a grid at all."""
    distance = np.abs(distance)
    return not (np.median(distance) > NO_GRID and np.mean(distance > FAR) > FAR_SHARE)


def _typical(times, grid):
    """The median distance of (FIT_SAMPLES of) times from their cycles on grid."""
    spread = times[:: max(1, len(times) // FIT_SAMPLES)]
    return float(np.median(np.abs(grid.distance(spread, grid.index(spread)))))


def _search(times, period, reach):
    """(Grid, its arc in cycles) of the first samples: of the periods within
    reach (relative) of period, in steps that move the last sample by
    ARC_STEP of a cycle, the one whose circle holds the samples in the
    narrowest arc (the numbering that best explains them, whatever their
    jitter), its phase the arc's middle."""
    cycles = max((times[-1] - times[0]) / period, 1.0)
    count = int(min(MAX_CANDIDATES, 2 * reach * cycles / ARC_STEP)) | 1
    candidates = period * (1 + np.linspace(-reach, reach, count))
    arcs = [_arc(times, p) for p in candidates]
    best = min(range(count), key=lambda i: (arcs[i][0], abs(i - count // 2)))  # ties: the period given
    return Grid(float(candidates[best]), arcs[best][1]), arcs[best][0]


def restep(grid, step):
    """The step a recording whose step came from its median interval takes
    once its samples are fitted: the fitted cycle (as snapped_interval
    gives an interval) where it is more than RESTEP from step, else step."""
    return step if abs(grid.period / step - 1) <= RESTEP else snapped_interval(grid.period)


def _arc(times, period):
    """(length in cycles, middle as a phase) of the narrowest arc of a
    circle of period that holds every time: the circle less the widest gap
    between neighbours."""
    offsets = np.sort(np.mod(times - times[0], period))
    gaps = np.diff(np.concatenate([offsets, [offsets[0] + period]]))
    widest = int(np.argmax(gaps))
    arc_start = offsets[(widest + 1) % len(offsets)]
    return 1 - gaps[widest] / period, float(times[0] + arc_start + (period - gaps[widest]) / 2)


def _line(times, grid):
    """The least-squares Grid of times numbered by grid."""
    return line(grid.index(times), times, grid)


def line(index, times, grid):
    """The least-squares Grid of times on their cycles index (centred sums:
    exact enough for 2^31 cycles); grid's period where they span no cycle."""
    index = np.asarray(index, dtype=np.float64)
    if len(times) < 2 or index.min() == index.max():
        return Grid(grid.period, float(np.mean(times - index * grid.period)))
    index_mean, time_mean = index.mean(), times.mean()
    centred = index - index_mean
    period = float(_dot(centred, times - time_mean) / _dot(centred, centred))
    return Grid(period, float(time_mean - period * index_mean)) if period > 0 else grid


class Jitter:
    """How far samples are from their cycles on a Grid: the largest
    distance, exactly, and the typical one (the median, from a histogram
    of HISTOGRAM_BINS bins: the same figure whether the samples come whole
    or block by block), in fractions of a cycle."""

    def __init__(self):
        self.largest = 0.0
        self.samples = 0
        self.counts = np.zeros(HISTOGRAM_BINS + 1, dtype=np.int64)

    def add(self, distance):
        self.add_far(np.abs(np.asarray(distance, dtype=np.float64)))

    def add_far(self, far, largest=None):
        """add() of distances already made positive (and their largest, if known); one over half a cycle
        (a sample put apart from its nearest cycle) counts in the last bin."""
        if not len(far):
            return
        self.largest = max(self.largest, float(far.max()) if largest is None else largest)
        self.samples += len(far)
        bins = np.minimum(far * (2 * HISTOGRAM_BINS), HISTOGRAM_BINS).astype(np.int64)
        self.counts += np.bincount(bins, minlength=HISTOGRAM_BINS + 1)

    @property
    def typical(self):
        """The median distance (the middle of its bin)."""
        if not self.samples:
            return 0.0
        middle = int(np.searchsorted(np.cumsum(self.counts), (self.samples + 1) // 2))
        return min((middle + 0.5) / (2 * HISTOGRAM_BINS), self.largest)

    def describe(self):
        """'up to 12.3 % of a cycle (typical 4.5 %)', or 'none' where every stamp is on its cycle."""
        if self.largest < 5e-4:
            return "none (every stamp within 0.05 % of a cycle of its cycle)"
        return f"up to {100 * self.largest:.1f} % of a cycle (typical {100 * self.typical:.1f} %)"

    def fits(self):
        """fits() of the distances added (from their histogram)."""
        if not self.samples:
            return True
        far = self.counts[int(FAR * 2 * HISTOGRAM_BINS) + 1 :].sum() / self.samples
        return not (self.typical > NO_GRID and far > FAR_SHARE)

    def settings(self):
        """Its figures for results.json, in % of a cycle."""
        return {"largest_percent": round(100 * self.largest, 3), "typical_percent": round(100 * self.typical, 3)}


def missing(index, most=10):
    """(count, the first `most` of them) of the cycles between index's
    first and last that no sample has: index is the sorted, unique cycles
    of a recording that samples every cycle."""
    if len(index) < 2:
        return 0, []
    gaps = np.flatnonzero(np.diff(index) > 1)
    count = int((np.diff(index)[gaps] - 1).sum())
    first: list[int] = []
    for at in gaps:
        first.extend(range(int(index[at]) + 1, min(int(index[at + 1]), int(index[at]) + 1 + most)))
        if len(first) >= most:
            break
    return count, first[:most]


def _dot(a, b):
    """The dot product of two float64 vectors without BLAS, whose threads cost more than the product on a
    busy machine (np.dot of 140,000 values: 8 ms under load, this 0.1 ms)."""
    return float(np.einsum("i,i", a, b))


class Line:
    """The least-squares Grid of (cycle, time) pairs of consecutive cycles given block by block
    (centred sums merged as Chan, Golub and LeVeque merge variances: exact
    enough for 2^31 cycles), for a recording read in blocks."""

    def __init__(self):
        self.count, self.mean_index, self.mean_time, self.index_squares, self.products = 0, 0.0, 0.0, 0.0, 0.0

    def add(self, index, times):
        """The pairs (index[k], times[k]): their cycles, and their stamps (each block's centred sums in two
        passes)."""
        n = len(times)
        if not n:
            return
        index = np.asarray(index, dtype=np.float64)
        mean_index, mean_time = float(index.mean()), float(times.mean())
        centred = index - mean_index
        squares = _dot(centred, centred)
        products = _dot(centred, times)  # (the centred index sums to 0)
        total = self.count + n
        d_index, d_time = mean_index - self.mean_index, mean_time - self.mean_time
        weight = self.count * n / total
        self.index_squares += squares + d_index * d_index * weight
        self.products += products + d_index * d_time * weight
        self.mean_index += d_index * n / total
        self.mean_time += d_time * n / total
        self.count = total

    def grid(self, period):
        """The Grid of the pairs so far (period and a phase through them until two cycles are in)."""
        if self.index_squares > 0 and self.products > 0:
            period = self.products / self.index_squares
        return Grid(period, self.mean_time - period * self.mean_index)
