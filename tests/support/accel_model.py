"""A plain second-order limiter in Python, for checking the property
checker (support/accel_properties.py) on many random runs: a block that
keeps the properties must pass, so that a violation the checker finds in
the FMU is the FMU's. It is not the FMU's algorithm and no test compares
the FMU with it.

The oracle (support/oracle.py) decides each cycle by rules 1 to 6 as
before; a ramping cycle with accelMax > 0 then steps as fast as it can
while it can still stop at the target: the largest speed w per cycle within
[|v| - b, |v| + a] and the velocity limit with w + B(w) <= E (E the distance
to uc, B(w) the way braking at b needs from w); moving away from uc it
brakes (and, once it can stop within the cycle, turns towards uc with what
is left of a). Exact arithmetic, the output rounded once to the block's
arithmetic (LREAL or REAL).
"""

import collections
import math
from fractions import Fraction

from support.accel_properties import ulp
from support.oracle import RateLimiterOracle, finite


def stopping(w, b):
    n = w // b
    return n * w - b * n * (n + 1) / 2


def fastest(E, low, high, b):
    """The largest w in [low, high] with w + B(w) <= E, or low when none (exact: Fractions)."""
    if low + stopping(low, b) > E:
        return low
    if high is None or E / b > 10**30:
        if high is None or high + stopping(high, b) <= E:  # braking is no bound at this scale
            return high if high is not None else E
    ratio = float(E / b) if E / b < 10**300 else 1e300
    n = max(0, math.floor((math.sqrt(1 + 8 * ratio) - 1) / 2) - 1)
    while b * (n + 1) * (n + 2) / 2 <= E:  # the largest n with b n (n + 1) / 2 <= E
        n += 1
    w = min((E + b * n * (n + 1) / 2) / (n + 1), (n + 1) * b)
    return max(low, min(high, w)) if high is not None else max(low, w)


class AccelModel(RateLimiterOracle):
    def __init__(self, vr, start=None, start_time=0.0):
        super().__init__(vr, start, start_time)
        self.v = Fraction(0)
        self.dydt_before = 0.0
        self.ramped = False
        self.last = self.evaluate_outputs()

    def accel(self):
        accel, decel = self.real(self.values.get("accelMax", 0.0)), self.real(self.values.get("decelMax", 0.0))
        return accel, decel if decel > 0 else accel

    def evaluate_status(self):
        status, culprit = super().evaluate_status()
        if status in (0, 0x8601):
            for name in ("accelMax", "decelMax"):
                value = self.values.get(name, 0.0)
                if not finite(value) or value < 0:
                    return 0x8205, name
        return status, culprit

    def limit(self, rising, y, T):
        """The velocity limit per cycle, exact (None: no limit)."""
        up, down, up_neg, down_neg = self.rates()
        rate = (up_neg if rising else down_neg) if y < 0 else (up if rising else down)
        limit = self.per_cycle_limit(rate.value, T)
        if math.isinf(limit):
            return None
        period = self.rate_period()
        if limit == 0:
            return Fraction(0)
        T = self.real(T)
        return Fraction(rate.value) * Fraction(T) / Fraction(period) if period > 0 else Fraction(rate.value)

    def step(self, yp, v, uc, T):
        """The next output from yp after a step v (exact arithmetic, the output rounded once)."""
        accel, decel = self.accel()
        Th = Fraction(self.real(T))
        a, b = Fraction(accel) * Th**2, Fraction(decel) * Th**2
        out = self.round
        Y, U = Fraction(yp), Fraction(uc)
        d = 1 if U > Y else -1 if U < Y else 0
        s, E = abs(v), abs(U - Y)
        if d == 0 and s == 0:
            return yp
        if d == 0 or d * v < 0:  # at uc while moving, or moving away from it: brake
            if s > b:
                return out(Y + (s - b) * (1 if v > 0 else -1))
            if d == 0:
                return yp
            limit = self.limit(d > 0, yp, T)
            low, high = Fraction(0), a * (1 - s / b) if limit is None else min(a * (1 - s / b), limit)
        else:
            low = max(Fraction(0), s - b)
            limit = self.limit(d > 0, yp, T)
            high = s + a if limit is None else min(s + a, limit)
            high = max(low, high)  # a lowered limit: brake at b
        if low + stopping(low, b) > E:
            # short of the braking curve by the rounding of the outputs: brake up to 4 ulp harder (within the
            # allowance) to keep to it; else it cannot stop before uc: pass it
            slack = 4 * ulp(max(abs(yp), abs(uc)), self.values["arithmetic"])
            harder = max(Fraction(0), low - slack)
            if harder + stopping(harder, b) > E:
                return out(Y + d * low)
            low = harder
        w = fastest(E, low, high, b)
        return uc if w >= E else out(Y + d * w)

    def round(self, x):
        """An exact value as the arithmetic holds the output (REAL: binary32, overflow to an infinity)."""
        try:
            return self.real(float(x))
        except OverflowError:
            return math.copysign(math.inf, x)

    def cycle(self, T, elapsed):
        yp = self.y
        super().cycle(T, elapsed)
        accel, _ = self.accel()
        ramping = self.decided_by == "6" and not self.jumped
        if ramping and accel > 0 and finite(self.y):
            self.y = self.step(yp, self.v, self.target(self.u_prev), T)
        self.v = Fraction(self.y) - Fraction(yp) if ramping and finite(self.y) and finite(yp) else Fraction(0)
        self.ramped_before, self.ramped = self.ramped, ramping

    def plan(self, y, v, uc, T):
        """Seconds to uc at constant inputs (inf: beyond 100,000 cycles)."""
        for n in range(1, 100_000):
            following = self.step(y, v, uc, T)
            v, y = Fraction(following) - Fraction(y), following
            if y == uc:
                return n * T
        return math.inf

    def evaluate_outputs(self):
        out = super().evaluate_outputs()
        if not hasattr(self, "v"):
            return out
        real = self.real
        y, yp = self.y, self.yp
        dydt = real(real(y - yp) / real(self.T)) if self.decided_by and finite(y) and finite(yp) else 0.0
        out["dydt"] = dydt
        ramped_before = getattr(self, "ramped_before", False)
        out["d2ydt2"] = real(real(dydt - self.dydt_before) / real(self.T)) if self.ramped and ramped_before else 0.0
        self.dydt_before = dydt
        accel, _ = self.accel()
        uc = self.target(self.u_prev)
        if accel > 0 and self.decided_by in ("6", "5b") and self.y != uc and finite(uc) and finite(self.y):
            remaining = self.plan(self.y, self.v if self.decided_by == "6" else Fraction(0), uc, self.T)
            duration = self.resolve_time("duration").value
            if duration > 0:
                remaining = min(remaining, max(0.0, duration - self.running_time))
            out["remainingTime"] = remaining
        return out


class ModelBlock:
    """AccelModel behind the interface of support.accel_scenarios.Block."""

    def __init__(self, model, version, model_exchange=False):
        self.model = None

    def start(self, t0, values):
        self.model = AccelModel(collections.defaultdict(int), dict(values), t0)
        self.t = t0
        return self.outputs()

    def cycle(self, T, changes, end=None):
        h = T if end is None else end - self.t  # cycleTime 0: the step is the cycle, T exactly
        out = self.model.do_step(self.t, h, changes)
        self.t = self.t + T if end is None else end
        return self.pick(out)

    def outputs(self):
        return self.pick(self.model.outputs())

    @staticmethod
    def pick(out):
        return {k: out.get(k, 0.0) for k in ("y", "dydt", "d2ydt2", "remainingTime", "runningTime", "status")}

    def reset(self):
        pass

    def free(self):
        pass
