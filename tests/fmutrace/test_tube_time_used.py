"""A tube's time allowance used (Tube.time_used, the per-signal criteria's
"time allowance used" figure), taken for all samples at once, against a
plain oracle written here from the tube's definition: for each result
sample inside the reference's time range, the nearest time at which the
reference's polyline (a repeated time a vertical jump, a NaN a break)
lies within the tube's value of the sample, segment by segment; the
sample named is the first that needs the most (of those beyond the tube's
time by no more than the times' rounding, the last)."""

import math

import numpy as np
import pytest

from fmutrace import Tube
from fmutrace._comparison_modes import time_slack


def _distance(times, values, t, v, width, reach):
    best = math.inf
    lo = int(np.searchsorted(times, t - reach, "left"))
    hi = int(np.searchsorted(times, t + reach, "right"))
    for k in range(max(lo - 1, 0), min(hi + 1, len(times))):
        t0, p0 = float(times[k]), float(values[k])
        if abs(p0 - v) <= width:
            best = min(best, abs(t0 - t))
        if k + 1 >= len(times):
            continue
        t1, p1 = float(times[k + 1]), float(values[k + 1])
        if t1 == t0:
            if min(p0, p1) - width <= v <= max(p0, p1) + width:
                best = min(best, abs(t0 - t))
            continue
        if math.isnan(p0) or math.isnan(p1) or math.isnan(v):
            continue
        if p1 == p0:
            if abs(p0 - v) > width:
                continue
            a, b = 0.0, 1.0
        else:
            a, b = sorted(((v - width - p0) / (p1 - p0), (v + width - p0) / (p1 - p0)))
            a, b = max(a, 0.0), min(b, 1.0)
        if a > b:
            continue
        start, end = t0 + a * (t1 - t0), t0 + b * (t1 - t0)
        best = min(best, 0.0 if start <= t <= end else min(abs(start - t), abs(end - t)))
    return best


def _time_used(tube, result, reference, name):
    times, values = reference["time"], reference[name].astype(np.float64)
    most, at = 0.0, None
    for t, v in zip(result["time"].tolist(), result[name].astype(np.float64).tolist(), strict=True):
        if not times[0] <= t <= times[-1]:
            continue
        slack = float(time_slack(t))
        need = _distance(times, values, t, v, tube.value, tube.time + slack)
        need = 0.0 if need <= slack else need
        if need <= tube.time + slack and (at is None or need > most):
            most, at = min(need, tube.time), t
    return most, at


def _trace(times, values):
    trace = np.empty(len(times), dtype=[("time", np.float64), ("y", np.float64)])
    trace["time"], trace["y"] = times, values
    return trace


@pytest.mark.parametrize("seed", range(40))
def test_the_time_allowance_used_is_the_oracles(seed):
    """Random references of 60 samples (steps of 10 ms, some repeated times, a few NaN, flat stretches),
    results of 70 samples shifted and disturbed, tubes of 0 to 5 steps and values of 0 to 1."""
    rng = np.random.default_rng(seed)
    steps = rng.choice([0.0, 0.01, 0.01, 0.01, 0.02], 59)
    times = np.concatenate([[0.0], np.cumsum(steps)])
    values = np.round(rng.normal(0, 1, 60), 1)
    values[rng.random(60) < 0.2] = 0.0
    values[rng.integers(0, 60, 2)] = np.nan if seed % 3 == 0 else 0.5
    result_times = np.sort(rng.uniform(-0.05, times[-1] + 0.05, 70))
    result_values = np.interp(result_times + rng.normal(0, 0.01, 70), times, np.nan_to_num(values))
    result_values += rng.normal(0, 0.2, 70) * (rng.random(70) < 0.3)
    result_values[rng.integers(0, 70, 1)] = np.nan if seed % 4 == 0 else 0.0
    tube = Tube(float(rng.choice([0.0, 0.005, 0.01, 0.03, 0.05])), float(rng.choice([0.0, 0.1, 0.5, 1.0])))
    reference, result = _trace(times, values), _trace(result_times, result_values)
    assert tube.time_used(result, reference, "y") == _time_used(tube, result, reference, "y")


def test_samples_beyond_the_tube_time_by_the_rounding_name_the_last():
    """Reference 0 until t = 1, then 1 (a jump); result samples of 0 at t = 0.5 (needing nothing), 1.2
    (0.2 s) and two just after 1.3 s, beyond a 0.3 s tube by less than the times' rounding: the allowance
    used is the tube's time, at the last of the two."""
    reference = _trace(np.array([0.0, 1.0, 1.0, 2.0]), np.array([0.0, 0.0, 1.0, 1.0]))
    result = _trace(np.array([0.5, 1.2, 1.3 + 1e-12, 1.3 + 2e-12]), np.array([0.0, 0.0, 0.0, 0.0]))
    tube = Tube(0.3, 0.0)
    used, at = tube.time_used(result, reference, "y")
    assert (used, at) == _time_used(tube, result, reference, "y") == (0.3, 1.3 + 2e-12)
