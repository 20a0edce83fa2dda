"""The properties of the acceleration limit (docs/rules.md), checked on a
run's cycles, whatever algorithm produced them.

A run is a list of segments (an initialisation and the cycles after it,
until the next re-initialisation). Each cycle is a `Cycle`: the values of
every variable as they were set for it (inputs and parameters by name, as
the importer set them), the time at its end, and the outputs read after
it. `check(segments, arithmetic, T)` returns every `Violation` of:

1. velocity, 2. acceleration, 3. arrival and standstill, 4. no avoidable
overshoot, 5. time-optimal within two cycles, 6. output limits,
7. remainingTime, as the tests' brief states them (exact rationals of the
doubles, allowance x <= B (1 + 16 eps) + 8 ulp(m)); and, beside them, what
the interface fixes: the rules 1 to 5b and the duration jump decide a cycle
as before (`rules`), the status word (`status`), `dydt` and `d2ydt2`
(`interface`).

Nothing here knows how the block plans its motion: the checks read the
outputs only, against bounds worked from the settings.
"""

import math
import struct
import sys
from dataclasses import dataclass, field
from fractions import Fraction

LREAL, REAL = 1, 2
EPS = {LREAL: Fraction(1, 2**53), REAL: Fraction(1, 2**24)}
INF = math.inf
TIME_TOL = 1e-9
_F32 = struct.Struct("<f")

# the parameters' start values (modelDescription/RateLimiter.toml), for a variable a run leaves out
DEFAULTS = {
    "rateUpPar": 1.0,
    "rateDownPar": 1.0,
    "bypassValuePar": math.nan,
    "durationPar": 0.0,
    "yMaxPar": sys.float_info.max,
    "yMinPar": -sys.float_info.max,
}


def f32(x):
    try:
        return _F32.unpack(_F32.pack(x))[0]
    except OverflowError:
        return math.copysign(math.inf, x)


def finite(x):
    return not (math.isnan(x) or math.isinf(x))


def ulp(x, arithmetic):
    """The unit in the last place of |x| in the arithmetic, exact."""
    x = abs(x)
    if not finite(x):
        return Fraction(0)
    if arithmetic == LREAL:
        return Fraction(math.ulp(x))
    if x < 2.0**-126:
        return Fraction(1, 2**149)
    exponent = math.frexp(x)[1]  # x in [2^(e-1), 2^e)
    return Fraction(2) ** (exponent - 24)


@dataclass
class Cycle:
    values: dict  # every variable's value as set for this cycle
    end: float  # the time at the cycle's end
    out: dict  # the outputs after it (y, dydt, d2ydt2, remainingTime, runningTime, status)


@dataclass
class Segment:
    start_values: dict  # the values at initialisation
    start_time: float
    init_out: dict  # the outputs after initialisation
    cycles: list = field(default_factory=list)
    settle: bool = False  # the run's last stretch was held until the output settled (property 3's arrival)


@dataclass
class Violation:
    prop: str  # "1" ... "7", "rules", "status", "interface", "finite"
    segment: int
    cycle: int  # 1-based within the segment (0: initialisation)
    text: str

    def __str__(self):
        return f"property {self.prop}, segment {self.segment}, cycle {self.cycle}: {self.text}"


@dataclass
class Settings:
    """One cycle's resolved settings, as the block holds them."""

    u: float
    up: float
    down: float
    up_neg: float
    down_neg: float
    period: float
    zero_rate: int
    y_max: float
    y_min: float
    bypass: bool
    bypass_value: float
    hold: bool
    duration: float
    accel: float
    decel: float
    status: int
    T: float  # the cycle length as the signal path holds it

    def uc(self):
        return self.y_min if self.u < self.y_min else self.y_max if self.u > self.y_max else self.u

    def limit(self, rising, yp):
        """The velocity limit per cycle (exact; None: no limit) in a direction, picked by the sign of yp."""
        if yp < 0:
            rate = self.up_neg if rising else self.down_neg
        else:
            rate = self.up if rising else self.down
        if rate == 0:
            return None if self.zero_rate == 2 else Fraction(0)
        if math.isinf(rate):
            return None
        if self.period > 0:
            return Fraction(rate) * Fraction(self.T) / Fraction(self.period)
        return Fraction(rate)

    def per_second(self, rate, T):
        """A rate per second (None: no limit)."""
        if rate == 0:
            return None if self.zero_rate == 2 else 0.0
        if math.isinf(rate):
            return None
        return rate / self.period if self.period > 0 else rate / T

    def a(self):
        return Fraction(self.accel) * Fraction(self.T) ** 2

    def b(self):
        return Fraction(self.decel if self.decel > 0 else self.accel) * Fraction(self.T) ** 2

    def key(self):
        """What a stretch of constant settings keeps (the time aside)."""
        return tuple(
            float(v).hex() if isinstance(v, float) else v
            for v in (
                self.u,
                self.up,
                self.down,
                self.up_neg,
                self.down_neg,
                self.period,
                self.zero_rate,
                self.y_max,
                self.y_min,
                self.bypass,
                self.bypass_value,
                self.hold,
                self.duration,
                self.accel,
                self.decel,
                self.T,
            )
        )


def resolve(values, arithmetic, T):
    """Rule 0 and the status words (rules.md) with 16#8205, in the arithmetic."""
    real = f32 if arithmetic == REAL else float

    def or_par(name):
        value = values.get(name, math.nan)
        return value if not math.isnan(value) else values.get(name + "Par", DEFAULTS[name + "Par"])

    up, down = real(or_par("rateUp")), real(or_par("rateDown"))
    up_neg = real(values.get("rateUpNeg", math.nan))
    down_neg = real(values.get("rateDownNeg", math.nan))
    up_neg = up if math.isnan(up_neg) else up_neg
    down_neg = down if math.isnan(down_neg) else down_neg
    period = real(values.get("ratePeriod", 1.0))
    duration = or_par("duration")
    y_max, y_min = real(or_par("yMax")), real(or_par("yMin"))
    y_max = INF if math.isnan(y_max) or y_max >= sys.float_info.max else y_max
    y_min = -INF if math.isnan(y_min) or y_min <= -sys.float_info.max else y_min
    accel, decel = real(values.get("accelMax", 0.0)), real(values.get("decelMax", 0.0))
    cycle_time = values.get("cycleTime", 0.0)
    rates = (up, down, up_neg, down_neg)
    if any(r < 0 for r in rates):
        status = 0x8200
    elif any(math.isnan(r) for r in rates):
        status = 0x8201
    elif not finite(period) or period < 0:
        status = 0x8202
    elif math.isnan(duration) or duration < 0:
        status = 0x8203
    elif y_min > y_max:
        status = 0x8204
    elif not finite(accel) or accel < 0 or not finite(decel) or decel < 0:
        status = 0x8205
    elif not finite(cycle_time) or cycle_time < 0 or values.get("_me_cycle_zero", False):
        status = 0x8601
    else:
        status = 0
    return Settings(
        real(values["u"]),
        up,
        down,
        up_neg,
        down_neg,
        period,
        int(values.get("zeroRate", 1)),
        y_max,
        y_min,
        bool(values.get("bypass", False)),
        real(or_par("bypassValue")),
        bool(values.get("hold", False)),
        duration,
        accel,
        decel,
        status,
        real(T),
    )


def braking_distance(speed, b):
    """sum over j >= 1 of max(0, speed - j b): the way braking at b per cycle needs to stop from speed."""
    if speed <= 0:
        return Fraction(0)
    n = speed // b  # the braking cycles that still move
    return n * speed - b * n * (n + 1) / 2


def same(a, b):
    return (math.isnan(a) and math.isnan(b)) or (a == b and math.copysign(1, a) == math.copysign(1, b))


class Checker:
    def __init__(self, arithmetic, T):
        self.arithmetic = arithmetic
        self.T = T
        self.eps = EPS[arithmetic]
        self.real = f32 if arithmetic == REAL else float
        self.violations = []

    def holds(self, x, bound, *magnitudes):
        """x <= bound (1 + 16 eps) + 8 ulp(m): bound None is no bound."""
        if bound is None:
            return True
        m = max((abs(v) for v in magnitudes if finite(v)), default=0.0)
        slack = 8 * ulp(m, self.arithmetic)
        return x <= bound * (1 + 16 * self.eps) + slack

    def allowance(self, *magnitudes):
        m = max((abs(v) for v in magnitudes if finite(v)), default=0.0)
        return 8 * ulp(m, self.arithmetic)

    def flag(self, prop, segment, cycle, text):
        self.violations.append(Violation(prop, segment, cycle, text))

    # -- one segment ------------------------------------------------------
    def segment(self, index, seg):
        cycles = seg.cycles
        n = len(cycles)
        ys = [seg.init_out["y"]] + [c.out["y"] for c in cycles]
        settings = [resolve(c.values, self.arithmetic, self.T) for c in cycles]
        ramping = [False] * (n + 1)  # index by cycle number 1..n
        decided = [None] * (n + 1)
        t0 = seg.start_time
        for k, (c, s) in enumerate(zip(cycles, settings, strict=True), start=1):
            yp, y = ys[k - 1], ys[k]
            rule, expected = self.rule(c, s, yp, t0)
            decided[k] = rule
            if c.out.get("status", s.status) != s.status:
                self.flag("status", index, k, f"status {c.out['status']:#06x}, the settings give {s.status:#06x}")
            if rule == "6":
                ramping[k] = True
                if not finite(y):
                    self.flag("finite", index, k, f"a ramping cycle from y = {yp!r} towards {s.uc()!r} gave y = {y!r}")
            elif not same(y, expected):
                self.flag("rules", index, k, f"rule {rule} gives y = {expected!r}, the block gave {y!r}")
        steps = [None] + [
            Fraction(ys[k]) - Fraction(ys[k - 1]) if finite(ys[k]) and finite(ys[k - 1]) else None
            for k in range(1, n + 1)
        ]
        prev = [Fraction(0)] * (n + 1)
        for k in range(2, n + 1):
            if ramping[k - 1] and steps[k - 1] is not None:
                prev[k] = steps[k - 1]
        self.interface(index, seg, settings, ramping, decided)
        self.velocity_and_acceleration(index, cycles, settings, ys, steps, prev, ramping)
        self.stretches(index, seg, settings, ys, steps, prev, ramping)

    def rule(self, c, s, yp, t0):
        """The rule that decides the cycle and, where not rule 6, its output."""
        if not finite(s.u):
            return "1", s.u
        if s.bypass:
            return "2", s.bypass_value if finite(s.bypass_value) else s.u
        if c.values.get("initMode", 2) == 3 and c.end <= t0 + c.values.get("initDelay", 0.0) + TIME_TOL * self.T:
            return "3", s.u
        if not finite(yp):
            return "4", s.u
        if s.status >= 0x8000:
            return "5", yp
        if s.hold:
            return "5b", yp
        if s.duration > 0 and c.out["runningTime"] >= s.duration * (1 - TIME_TOL):
            return "jump", s.uc()
        return "6", None

    def interface(self, index, seg, settings, ramping, decided):
        """dydt = (y - yp) / T in the arithmetic; d2ydt2 = (dydt - dydt_previous) / T after a cycle that rule 6
        decided, the duration's jump included (rules.md, Outputs derived from the last cycle; in REAL binary32,
        or binary64 with T rounded or not), else 0."""
        real, cycles = self.real, seg.cycles
        for k, (c, s) in enumerate(zip(cycles, settings, strict=True), start=1):
            out, before = c.out, seg.init_out if k == 1 else cycles[k - 2].out
            y, yp = out["y"], before["y"]
            if "dydt" in out:
                expected = real(real(y - yp) / s.T) if finite(y) and finite(yp) else 0.0
                if out["dydt"] != expected and not (math.isnan(out["dydt"]) and math.isnan(expected)):
                    self.flag("interface", index, k, f"dydt = {out['dydt']!r}, (y - yp) / T = {expected!r}")
            if "d2ydt2" not in out:
                continue
            d2 = out["d2ydt2"]
            if decided[k] not in ("6", "jump"):
                if d2 != 0:
                    self.flag(
                        "interface", index, k, f"d2ydt2 = {d2!r} after a cycle decided by rule {decided[k]}, not 0"
                    )
                continue
            if not finite(d2):
                self.flag("interface", index, k, f"d2ydt2 = {d2!r} is not finite")
            if k == 1 or decided[k - 1] not in ("6", "jump"):
                continue  # after initialisation or another rule: the velocity before is 0 or the jump's, unchecked
            # rules.md: (dydt - dydt') / T, dydt' the dydt of the cycle before
            dydt, dydt_prev = out["dydt"], before.get("dydt", 0.0)
            if finite(dydt) and finite(dydt_prev):
                expected = {real(real(dydt - dydt_prev) / s.T), (dydt - dydt_prev) / s.T, (dydt - dydt_prev) / self.T}
                expected = {e if finite(e) else 0.0 for e in expected}
            else:
                expected = {0.0}
            if d2 not in expected:
                self.flag(
                    "interface",
                    index,
                    k,
                    f"d2ydt2 = {d2!r}, (dydt - dydt_previous) / T = "
                    f"({dydt!r} - {dydt_prev!r}) / T = {sorted(expected)!r}",
                )

    # -- properties 1 and 2, cycle by cycle --------------------------------
    def velocity_and_acceleration(self, index, cycles, settings, ys, steps, prev, ramping):
        braking_to = None  # property 1's exception: the limit a change lowered below the speed
        changed_at = 0  # the last cycle whose rates, ratePeriod, zeroRate, accelMax or decelMax changed
        moved_at = 0  # the last cycle whose target uc moved
        for k in range(1, len(cycles) + 1):
            s = settings[k - 1]
            if k >= 2 and settings[k - 2].key()[1:7] + settings[k - 2].key()[13:15] != s.key()[1:7] + s.key()[13:15]:
                changed_at = k
            if k >= 2 and settings[k - 2].uc() != s.uc():
                moved_at = k
            if not ramping[k] or steps[k] is None:
                braking_to = None
                continue
            if s.accel <= 0:
                braking_to = None
                continue
            step, p, yp = steps[k], prev[k], ys[k - 1]
            mags = (ys[k - 2] if k >= 2 else ys[k - 1], ys[k - 1], ys[k], s.uc())
            # 1. velocity
            if p != 0 and ramping[k - 1] and k >= 2:
                limit = s.limit(p > 0, yp)
                # the exception: an input or parameter change lowered the limit at this y below the speed; or
                # the output crossed 0 into the other rates' lower limit, and a change of the settings (a
                # lowered decelMax) or a target moved inside the braking distance, within the braking time
                # before, may have left no way to slow down to it in time (docs/rules.md)
                changed = settings[k - 2].limit(p > 0, yp) != limit
                crossed = k >= 3 and (ys[k - 2] < 0) != (yp < 0)
                recent = [at for at in (changed_at, moved_at) if at and k - at <= abs(p) / s.b() + 2]
                if moved_at in recent and changed_at not in recent and not self.unavoidable(s, ys, steps, moved_at):
                    recent = []
                if crossed and recent:
                    changed = True
                if limit is not None and changed and abs(p) > limit:
                    braking_to = (p > 0, limit)
            if braking_to is not None:
                rising = braking_to[0]
                limit = s.limit(rising, yp)  # the limit of this cycle: raised again, it ends the braking
                # it ends at the limit itself: the allowance (8 ulp of a far target in REAL) would end it early
                if limit is None or (step > 0) != rising or step == 0 or abs(step) <= limit:
                    braking_to = None
                elif not self.holds(abs(step), max(limit, abs(p) - s.b()), *mags):
                    self.flag(
                        "1",
                        index,
                        k,
                        f"speed {float(abs(p))!r} -> {float(abs(step))!r} per cycle above the "
                        f"lowered limit {float(limit)!r}: not braking at decelMax",
                    )
            if braking_to is None and step != 0:
                limit = s.limit(step > 0, yp)
                if not self.holds(abs(step), limit, *mags):
                    before = ys[k - 2] if k >= 2 else yp
                    where = " (the rates picked by the sign of y changed at 0)" if (before < 0) != (yp < 0) else ""
                    self.flag(
                        "1",
                        index,
                        k,
                        f"step {float(step)!r} from y = {yp!r} beyond the velocity limit "
                        f"{float(limit)!r} per cycle{where}",
                    )
            # 2. acceleration (not in the cycle after one without the limit: no velocity to keep)
            if k >= 2 and ramping[k - 1] and settings[k - 2].accel <= 0:
                continue
            a, b = s.a(), s.b()
            if step == 0 or p == 0 or (step > 0) == (p > 0):
                if abs(step) >= abs(p):
                    if not self.holds(abs(step) - abs(p), a, *mags):
                        self.flag(
                            "2",
                            index,
                            k,
                            f"speed per cycle {float(abs(p))!r} -> {float(abs(step))!r}: "
                            f"grows by more than accelMax T^2 = {float(a)!r}",
                        )
                elif not self.holds(abs(p) - abs(step), b, *mags):
                    self.flag(
                        "2",
                        index,
                        k,
                        f"speed per cycle {float(abs(p))!r} -> {float(abs(step))!r}: "
                        f"shrinks by more than decelMax T^2 = {float(b)!r}",
                    )
            elif not self.holds(abs(step) + abs(p) * a / b, a, *mags):
                self.flag(
                    "2",
                    index,
                    k,
                    f"reversal {float(p)!r} -> {float(step)!r} per cycle: |p|/b + |s|/a = "
                    f"{float(abs(p) / b + abs(step) / a)!r} > 1 (a = {float(a)!r}, b = {float(b)!r})",
                )

    # -- properties 3 to 7, over stretches ---------------------------------
    def stretches(self, index, seg, settings, ys, steps, prev, ramping):
        n = len(seg.cycles)
        k = 1
        while k <= n:
            if not ramping[k]:
                k += 1
                continue
            # a stretch of ramping cycles with the same settings
            key = settings[k - 1].key()
            end = k
            while end + 1 <= n and ramping[end + 1] and settings[end].key() == key:
                end += 1
            self.constant_stretch(index, seg, settings[k - 1], k, end, ys, steps, prev, end == n and seg.settle)
            k = end + 1
        # property 4 over stretches of constant uc (and braking), property 6 over constant limits
        self.overshoot_stretches(index, settings, ys, steps, prev, ramping, n)

    def constant_stretch(self, index, seg, s, first, last, ys, steps, prev, settle):
        uc = s.uc()
        arrival = next((j for j in range(first, last + 1) if ys[j] == uc), None)
        accel_limited = s.accel > 0
        # 3. once at rest on the target (two outputs equal to it), it stays there, dydt 0, then d2ydt2 0
        rest = next((j for j in range(first, last + 1) if ys[j] == uc and ys[j - 1] == uc), None)
        if accel_limited and rest is not None:
            for j in range(rest, last + 1):
                out = seg.cycles[j - 1].out
                if ys[j] != uc:
                    self.flag("3", index, j, f"left the target {uc!r} it had reached at rest (y = {ys[j]!r})")
                    break
                if out.get("dydt", 0.0) != 0:
                    self.flag("3", index, j, f"at rest on the target but dydt = {out['dydt']!r}")
                if j > rest and out.get("d2ydt2", 0.0) != 0:
                    self.flag("3", index, j, f"at rest on the target for a second cycle but d2ydt2 = {out['d2ydt2']!r}")
        if accel_limited and settle and not (ys[last] == uc and last >= 2 and ys[last - 1] == uc):
            if self.still_on_its_way(s, ys[last], uc):
                return  # the hold ended before even the velocity limit could have brought it there
            stall = ""
            if ys[last] == ys[last - 1] and s.a() < ulp(ys[last], self.arithmetic):
                stall = f"; a stall: accelMax T^2 = {float(s.a())!r} is below one ulp of y"
            self.flag(
                "3",
                index,
                last,
                f"held constant for {last - first + 1} cycles, the output did not settle "
                f"on the target {uc!r} (y = {ys[last]!r}, before it {ys[last - 1]!r}){stall}",
            )
        if accel_limited:
            self.time_optimal(index, seg, s, first, last, ys, prev, arrival)
            self.remaining_time(index, seg, s, first, last, ys)

    def unavoidable(self, s, ys, steps, moved_at):
        """Whether, when the target moved (cycle moved_at), 0 lay inside the distance the output needed to
        brake from its speed down to the other side's velocity limit (then crossing 0 faster is allowed)."""
        if not all(math.isfinite(x) for x in (ys[moved_at - 1], steps[moved_at - 1] or 0)):
            return False
        y, v = Fraction(ys[moved_at - 1]), abs(Fraction(steps[moved_at - 1] or 0))
        limit = s.limit((steps[moved_at - 1] or 0) > 0, -ys[moved_at - 1] or 0.0)  # the other side's
        low = Fraction(limit) if limit is not None else Fraction(0)
        b = Fraction(s.b())
        needed = (v * v - low * low) / (2 * b) + v + b if v > low else Fraction(0)
        return abs(y) < needed

    def still_on_its_way(self, s, y, uc):
        """Whether more than two cycles at the fastest velocity limit separate y from uc."""
        speeds = [s.per_second(rate, self.T) for rate in (s.up, s.down, s.up_neg, s.down_neg)]
        if any(v is None or not math.isfinite(v) for v in speeds):
            return False
        fastest = max(speeds) * self.T
        return abs(Fraction(uc) - Fraction(y)) > 2 * Fraction(fastest)

    def time_optimal(self, index, seg, s, first, last, ys, prev, arrival):
        """5: from rest, a step to u with V and A, no limits cutting, no duration."""
        if prev[first] != 0 or s.duration != 0 or s.uc() != s.u:
            return
        if first >= 2 and ys[first - 1] != ys[first - 2]:
            return
        y0, uc = ys[first - 1], s.uc()
        if not (s.y_min <= y0 <= s.y_max) or y0 == uc:
            return
        if s.decel not in (0.0, s.accel):
            return
        if min(y0, uc) >= 0:
            rates = {s.up, s.down}
        elif max(y0, uc) < 0:
            rates = {s.up_neg, s.down_neg}
        else:
            rates = {s.up, s.down, s.up_neg, s.down_neg}
        if len(rates) != 1:
            return
        V = s.per_second(rates.pop(), self.T)
        A = s.accel
        if V == 0:
            return
        D = abs(float(Fraction(uc) - Fraction(y0)))
        if V is None or D / V < V / A:  # D < V^2 / A, without V^2 overflowing at huge values
            t_opt = 2 * math.sqrt(D / A)
        else:
            t_opt = D / V + V / A
        bound = (t_opt + 2 * self.T) * (1 + 1e-9) + 1e-12 * self.T
        if arrival is not None:
            N = arrival - first + 1
            if N * self.T > bound:
                self.flag(
                    "5",
                    index,
                    arrival,
                    f"a step of {D!r} from rest (V = {V!r}, A = {A!r}) took {N} cycles "
                    f"of {self.T!r} s, the bound t_opt + 2T is {t_opt + 2 * self.T!r} s",
                )
        elif (last - first + 1) * self.T > bound:
            self.flag(
                "5",
                index,
                last,
                f"a step of {D!r} from rest (V = {V!r}, A = {A!r}) has not arrived after "
                f"{last - first + 1} cycles; the bound t_opt + 2T is {t_opt + 2 * self.T!r} s",
            )

    def remaining_time(self, index, seg, s, first, last, ys):
        """7: after cycle k, the first j > k with y_j == uc is (j - k) T ahead."""
        if s.duration > 0:
            return
        uc = s.uc()
        next_arrival = None
        for k in range(last, first - 1, -1):
            rt = seg.cycles[k - 1].out.get("remainingTime")
            if rt is None:
                continue
            if ys[k] == uc:
                if rt != 0:
                    self.flag("7", index, k, f"y == uc = {uc!r} but remainingTime = {rt!r}")
            elif next_arrival is not None:
                want = (next_arrival - k) * self.T
                if not abs(rt - want) <= TIME_TOL * want:
                    self.flag(
                        "7",
                        index,
                        k,
                        f"remainingTime = {rt!r}, the output arrived {next_arrival - k} cycles later ({want!r} s)",
                    )
            elif last > k:
                want = (last + 1 - k) * self.T
                if not rt >= want * (1 - TIME_TOL):
                    self.flag(
                        "7",
                        index,
                        k,
                        f"remainingTime = {rt!r}, the output had not arrived "
                        f"{last - k} cycles later ({want!r} s at the least)",
                    )
            if ys[k] == uc:
                next_arrival = k

    def overshoot_stretches(self, index, settings, ys, steps, prev, ramping, n):
        k = 1
        while k <= n:
            s = settings[k - 1]
            if not ramping[k] or s.accel <= 0:
                k += 1
                continue
            end = k
            while (
                end + 1 <= n
                and ramping[end + 1]
                and settings[end].accel == s.accel
                and settings[end].decel == s.decel
                and settings[end].T == s.T
            ):
                end += 1
            # within [k, end]: sub-stretches of constant uc (4) and of constant limits (6)
            self.no_passing(index, settings, ys, prev, k, end, lambda t: t.uc(), "4")
            for side in (0, 1):
                self.no_passing(
                    index,
                    settings,
                    ys,
                    prev,
                    k,
                    end,
                    lambda t, side=side: (t.y_min, t.y_max)[side],
                    "6",
                    limit_side=side,
                )
            k = end + 1

    def no_passing(self, index, settings, ys, prev, first, last, target_of, prop, limit_side=None):
        k = first
        while k <= last:
            target = target_of(settings[k - 1])
            end = k
            while end + 1 <= last and same(target_of(settings[end]), target):
                end += 1
            if finite(target):
                self.no_passing_stretch(index, settings[k - 1], ys, prev, k, end, target, prop, limit_side)
            k = end + 1

    def no_passing_stretch(self, index, s, ys, prev, first, last, target, prop, limit_side):
        """From a cycle k at whose start braking at b stops at or before target (d p >= 0), no later y of the
        stretch is past the target; for uc also: y - uc changes sign at most once."""
        b = s.b()
        tq = Fraction(target)
        # the farthest excursion of the later outputs either way, and their largest magnitude
        hi, lo, mag = [None] * (last + 2), [None] * (last + 2), [0.0] * (last + 2)
        for i in range(last, first - 1, -1):
            y = ys[i]
            hi[i] = y if hi[i + 1] is None else max(y, hi[i + 1])
            lo[i] = y if lo[i + 1] is None else min(y, lo[i + 1])
            mag[i] = max(abs(y) if finite(y) else 0.0, mag[i + 1])
        for k in range(first, last + 1):
            yp = ys[k - 1]
            if not finite(yp):
                continue
            if limit_side is not None:
                # 6: the limit, from inside the band, towards it
                d = 1 if limit_side == 1 else -1
                if d * (Fraction(yp) - tq) > self.allowance(yp, target):
                    continue  # outside: a tightened limit, brought back under 1 and 2
            else:
                d = 1 if yp < target else -1 if yp > target else 0
            p = prev[k]
            if d == 0:
                if p != 0:
                    continue
                past_hi, past_lo = Fraction(hi[k]) - tq, tq - Fraction(lo[k])
                if max(past_hi, past_lo) > self.allowance(mag[k], target):
                    self.flag(
                        prop,
                        index,
                        k,
                        f"at rest on {target!r}, the output left it in a stretch that kept it "
                        f"(to {hi[k]!r} / {lo[k]!r})",
                    )
                break
            if d * p < 0 and limit_side is None:
                continue  # moving away from uc: the target moved behind it, the sign rule below judges
            E = d * (tq - Fraction(yp))
            need = braking_distance(d * p, b)  # 0 when moving away from a limit
            if E < need * (1 + 16 * self.eps) + self.allowance(yp, target, mag[k]):
                continue  # the premise must hold with the allowance in the block's favour
            extreme = hi[k] if d > 0 else lo[k]
            past = d * (Fraction(extreme) - tq)
            if past > self.allowance(mag[k], target):
                what = "the target uc" if limit_side is None else ("yMax" if limit_side == 1 else "yMin")
                self.flag(
                    prop,
                    index,
                    k,
                    f"could stop before {what} = {target!r} (distance {float(E)!r}, braking "
                    f"needs {float(need)!r} at speed {float(d * p)!r} per cycle) but passed it to "
                    f"{extreme!r}",
                )
                break  # one report a stretch
        if limit_side is None:
            signs, allowance = [], self.allowance(mag[first], target, ys[first - 1])
            for i in range(first - 1, last + 1):
                gap = Fraction(ys[i]) - tq if finite(ys[i]) else None
                if gap is not None and abs(gap) > allowance:
                    sign = gap > 0
                    if not signs or signs[-1] != sign:
                        signs.append(sign)
            if len(signs) > 2:
                self.flag(
                    "4",
                    index,
                    last,
                    f"y - uc changed sign {len(signs) - 1} times in a stretch of constant "
                    f"uc = {target!r} (cycles {first} to {last})",
                )


def check(segments, arithmetic, T):
    """Every violation in a run: a list of Segment with one constant cycle length T."""
    checker = Checker(arithmetic, T)
    for index, seg in enumerate(segments):
        checker.segment(index, seg)
    return checker.violations
