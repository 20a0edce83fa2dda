"""An independent model of the rate limiter, written from the cycle rules
(docs/rules.md), the time model (docs/fmi.md), the vendor readings
(docs/models.md) and the arithmetic of rules.md, Arithmetic, not from the C code,
to check the FMUs against.

The oracle speaks the unified block's variable names. It follows the
project's documented conventions where the rules leave room:
runningTime is counted in whole cycles (cycles * T, with the sum started
afresh when T changes), and time comparisons use a relative 1e-9.

Arithmetic (rules.md, Arithmetic): LREAL computes in Python floats (binary64).
REAL rounds every value that enters a cycle and the result of every
operation of the signal path to binary32 with f32, in the order the
rules write it. f32 of one +, -, * or / of two binary32 values computed
in binary64 is that operation correctly rounded in binary32: binary64 has
more than twice binary32's precision plus two bits, so the double rounding
is innocuous (test_oracle.py checks it against numpy's float32 scalars).
"""

import copy
import functools
import hashlib
import json
import math
import os
import struct
import sys
import tomllib
from dataclasses import dataclass
from pathlib import Path

import numpy

TOL = 1e-9

LREAL, REAL = 1, 2  # the values of RateLimiter's `arithmetic`
_BINARY32 = struct.Struct("<f")


def f32(x):
    """x rounded to binary32 (to nearest, ties to even), as a Python float;
    beyond the largest binary32 it is an infinity, NaN stays NaN."""
    try:
        return _BINARY32.unpack(_BINARY32.pack(x))[0]
    except OverflowError:  # struct refuses what rounds to an infinity
        return math.copysign(math.inf, x)


def f64(x):
    return x


def divide(a, b):
    """a / b as IEEE has it (Python refuses a zero divisor): by a zero, NaN
    for 0 / 0 and NaN, else the infinity of the signs, the zero's included.
    A REAL T that is a binary64 subnormal enters as a zero (rules.md,
    Arithmetic), so that dydt divides by it."""
    if b != 0 or math.isnan(b):
        return a / b
    if a == 0 or math.isnan(a):
        return math.nan
    return math.inf if math.copysign(1.0, a) == math.copysign(1.0, b) else -math.inf


def time_ms(seconds):
    """A TIME pin set in seconds: whole milliseconds, seconds * 1000 in
    binary64 rounded to nearest, ties to even (Python's round of a float is
    exact and ties to even, as C's nearbyint), used as ms / 1000."""
    return round(seconds * 1000.0) / 1000.0


PARAMETER_DEFAULTS = {
    "rateUpPar": 1.0,
    "rateDownPar": 1.0,
    "bypassValuePar": math.nan,
    "durationPar": 0.0,
    "ratePeriod": 1.0,
    "zeroRate": 1,
    "cycleTime": 0.0,
    "initMode": 2,
    "initValue": 0.0,
    "initDelay": 0.0,
    "yMaxPar": sys.float_info.max,
    "yMinPar": -sys.float_info.max,
    "arithmetic": LREAL,
    "accelMax": 0.0,
    "decelMax": 0.0,
}
INPUT_DEFAULTS = {
    "u": 0.0,
    "rateUp": math.nan,
    "rateDown": math.nan,
    "bypass": False,
    "bypassValue": math.nan,
    "duration": math.nan,
    "rateUpNeg": math.nan,
    "rateDownNeg": math.nan,
    "yMax": math.nan,
    "yMin": math.nan,
    "hold": False,
}
OUTPUTS = (
    "y",
    "rampActive",
    "runningTime",
    "error",
    "status",
    "subFunctionStatus",
    "dydt",
    "limitingUp",
    "limitingDown",
    "highLimit",
    "lowLimit",
    "remainingTime",
    "d2ydt2",
)


def finite(x):
    return not (math.isnan(x) or math.isinf(x))


@dataclass
class Resolved:
    value: float
    name: str  # the variable the value came from


class RateLimiterOracle:
    """One instance of the unified block; `vr` maps names to value references
    (for subFunctionStatus). `compare_only=True` is the Siemens reading of a
    non-finite input: no rule 1, u is only compared with the output.
    `neg_fallback=False`: a NaN Neg rate is not replaced by the other rate
    (LGF_LimRateOfChangeAdvancedCI: a NaN rate is 16#8201).
    `limit_initial=False`: the initial output is not limited (ibid.).
    The arithmetic is the value `arithmetic` (LREAL or REAL, fixed)."""

    def __init__(self, vr, start=None, start_time=0.0, compare_only=False, neg_fallback=True, limit_initial=True):
        self.vr = vr
        self.values = dict(PARAMETER_DEFAULTS)
        self.values.update(INPUT_DEFAULTS)
        self.values.update(start or {})
        self.compare_only = compare_only
        self.neg_fallback = neg_fallback
        # every value entering the signal path, and every operation of it, goes through real
        self.real = f32 if self.values["arithmetic"] == REAL else f64
        self.resolved = {}  # of the values as they are: emptied whenever they change
        self.t0 = start_time
        self.time = start_time
        self.cycles_done = 0
        u = self.real(self.values["u"])
        y = self.real(self.values["initValue"]) if self.values["initMode"] == 1 else u
        # rules.md, Initialisation: limited if y is finite and yMin <= yMax (a NaN limit: none)
        low, high = self.limits()
        if limit_initial and finite(y) and low <= high:
            y = min(max(y, low), high)
        self.y = y
        self.yp = y
        self.u_prev = u
        self.decided_by = None  # rule that decided the last cycle: "1-5", "5b", "6"
        self.jumped = False
        self.T = math.nan
        self.rates_used = (math.nan, math.nan)
        self.run_cycles, self.run_T, self.run_base = 0, 0.0, 0.0
        self.ypp, self.T_before = y, 0.0  # the cycle before the last: its yp and T
        self.status, self.culprit = self.evaluate_status()
        self.last = self.evaluate_outputs()

    # -- rule 0 and the status table -------------------------------------
    def resolve(self, name):
        """The input, or its parameter when it is NaN, as it enters the
        signal path (rates, limits, bypass value)."""
        known = self.resolved.get(name)
        if known is None:
            value = self.values[name]
            if math.isnan(value):
                known = Resolved(self.real(self.values[name + "Par"]), name + "Par")
            else:
                known = Resolved(self.real(value), name)
            self.resolved[name] = known
        return known

    def resolve_time(self, name):
        """duration: time bookkeeping, binary64 in either arithmetic."""
        value = self.values[name]
        if math.isnan(value):
            return Resolved(self.values[name + "Par"], name + "Par")
        return Resolved(value, name)

    def rate_period(self):
        return self.real(self.values["ratePeriod"])

    def resolve_neg(self, name):
        """rateUpNeg / rateDownNeg: NaN falls back to the resolved rateUp /
        rateDown (rules.md, rule 0)."""
        value = self.values[name]
        if math.isnan(value) and self.neg_fallback:
            return self.resolve(name[:-3])
        return Resolved(self.real(value), name)

    def rates(self):
        return (
            self.resolve("rateUp"),
            self.resolve("rateDown"),
            self.resolve_neg("rateUpNeg"),
            self.resolve_neg("rateDownNeg"),
        )

    def limits(self):
        """yMin and yMax after fallback; NaN, an infinity or the largest
        finite double (its negative for yMin) means no limit (rules.md, rule 0)."""
        low, high = self.resolve("yMin").value, self.resolve("yMax").value
        return (
            -math.inf if math.isnan(low) or low <= -sys.float_info.max else low,
            math.inf if math.isnan(high) or high >= sys.float_info.max else high,
        )

    def evaluate_status(self):
        rates = self.rates()
        period = self.rate_period()
        duration = self.resolve_time("duration")
        cycle = self.values["cycleTime"]
        for rate in rates:  # rateUp, rateDown, rateUpNeg, rateDownNeg
            if rate.value < 0:
                return 0x8200, rate.name
        for rate in rates:
            if math.isnan(rate.value):
                return 0x8201, rate.name
        if not finite(period) or period < 0:
            return 0x8202, "ratePeriod"
        if math.isnan(duration.value) or duration.value < 0:
            return 0x8203, duration.name
        low, high = self.limits()
        if low > high:
            return 0x8204, self.resolve("yMin").name
        for name in ("accelMax", "decelMax"):
            value = self.real(self.values[name])
            if not (finite(value) and value >= 0):
                return 0x8205, name
        if not finite(cycle) or cycle < 0 or not self.values.get("cycleValid", True):
            return 0x8601, "cycleTime"
        return 0, None

    def per_cycle_limit(self, rate, T):
        if rate == 0:
            return math.inf if self.values["zeroRate"] == 2 else 0.0
        period = self.rate_period()
        real = self.real
        return real(real(rate * real(T)) / period) if period > 0 else rate

    @property
    def running_time(self):
        return self.run_base + self.run_cycles * self.run_T

    def running_reset(self):
        self.run_cycles, self.run_base = 0, 0.0

    def running_add(self, T):
        if T != self.run_T:
            self.run_base += self.run_cycles * self.run_T
            self.run_cycles, self.run_T = 0, T
        self.run_cycles += 1

    def target(self, u):
        """uc = min(max(u, yMin), yMax); a NaN u stays NaN."""
        low, high = self.limits()
        return low if u < low else high if u > high else u

    # -- one cycle (rules 1 to 6) ------------------------------------------
    # -- rules.md, Acceleration limit ------------------------------------------
    def accelerating(self):
        return self.status < 0x8000 and self.real(self.values["accelMax"]) > 0

    def cycle_steps(self, T):
        """a = accelMax * T * T, b = decelMax (or accelMax) * T * T"""
        real = self.real
        accel = real(self.values["accelMax"])
        decel = real(self.values["decelMax"])
        decel = decel if decel > 0 else accel
        A = Arithmetic(real)
        return A.mul(A.mul(accel, real(T)), real(T)), A.mul(A.mul(decel, real(T)), real(T))

    def previous_step(self, T):
        """the last cycle's step at this cycle's length; 0 after a cycle rule 6
        did not decide, or at or past the duration's jump"""
        duration = self.resolve_time("duration").value
        if self.decided_by != "6" or (duration > 0 and self.running_time >= duration * (1 - TOL)):
            return 0.0
        if not (finite(self.y) and finite(self.yp)):
            return 0.0
        A = Arithmetic(self.real)
        step = directed_sum(A, self.y, -self.yp, False)
        T_last = self.T
        if T_last == T or not T_last > 0:
            return step
        return A.mul(step, A.div(self.real(T), self.real(T_last)))

    def cycle(self, T, elapsed):
        v = self.values
        real = self.real
        u = real(v["u"])
        yp = self.y
        previous = self.previous_step(T) if self.accelerating() else 0.0
        self.ypp, self.T_before = self.yp, self.T if finite(self.T) else 0.0
        self.yp, self.T = yp, T
        self.jumped = False
        decided_by = "1-5"
        if not self.compare_only and not finite(u):  # rule 1
            y = u
            self.running_reset()
        elif v["bypass"]:  # rule 2
            bypass_value = self.resolve("bypassValue").value
            y = bypass_value if finite(bypass_value) else u
            self.running_reset()
        elif v["initMode"] == 3 and elapsed <= v["initDelay"] + TOL * T:  # rule 3
            y = u
            self.running_reset()
        elif not finite(yp) and finite(u):  # rule 4
            y = u
            self.running_reset()
        elif self.status >= 0x8000:  # rule 5
            y = yp
        elif v["hold"]:  # rule 5b
            y = yp
            decided_by = "5b"
        else:  # rule 6
            decided_by = "6"
            uc = self.target(u)
            up, down, up_neg, down_neg = self.rates()
            # the rates by the sign of yp (a non-finite yp: the others)
            rate_up, rate_down = (up_neg, down_neg) if yp < 0 else (up, down)
            max_up = self.per_cycle_limit(rate_up.value, T)
            max_down = self.per_cycle_limit(rate_down.value, T)
            self.rates_used = (max_up, max_down)
            if u != self.u_prev:
                self.running_reset()
            if yp != uc:
                self.running_add(T)
            duration = self.resolve_time("duration").value
            if duration > 0 and self.running_time >= duration * (1 - TOL):
                y = uc
                self.jumped = True
            elif self.accelerating():
                limits = (max_up, max_down) + tuple(
                    self.per_cycle_limit(rate.value, T) for rate in ((up_neg, down_neg) if yp >= 0 else (up, down))
                )
                if yp < 0:  # (maxUp, maxDown) of yp >= 0, then those of yp < 0
                    limits = (limits[2], limits[3], limits[0], limits[1])
                a, b = self.cycle_steps(T)
                y = accel_step(Arithmetic(real), yp, uc, previous, a, b, limits)
            elif uc > yp:
                y = min(uc, real(yp + max_up))
            elif uc < yp:
                y = max(uc, real(yp - max_down))
            else:
                y = yp
        self.decided_by = decided_by
        self.y = y
        self.u_prev = u

    # -- a communication step (fmi.md, Time: the communication step is the PLC cycle)
    def do_step(self, t, h, inputs=None):
        """Set the inputs (held for the whole step), then run every cycle
        whose end lies in (t, t+h]."""
        self.values.update(inputs or {})
        self.resolved = {}
        # evaluated every cycle from the values, which a step holds
        self.status, self.culprit = self.evaluate_status()
        end = t + h
        c = self.values["cycleTime"]
        if finite(c) and c > 0:
            last = math.floor((end - self.t0) / c + TOL)
            for n in range(self.cycles_done + 1, last + 1):
                self.cycle(c, n * c)
            if last > self.cycles_done:
                self.last = self.evaluate_outputs()  # the outputs are those of the last cycle run (fmi.md, Time)
            self.cycles_done = max(self.cycles_done, last)
        else:
            self.cycle(h, end - self.t0)
            self.last = self.evaluate_outputs()
        self.time = end
        return self.outputs()

    # -- rules.md, Outputs derived from the last cycle ---------------------------
    def remaining_time(self, y, uc):
        """The way from y to uc in legs: below 0 at the Neg rate, the rest at
        the other; each leg's length / rate per second."""
        up, down, up_neg, down_neg = self.rates()
        if uc > y:
            legs = [
                (min(uc, 0.0) - y, up_neg.value) if y < 0 else (0.0, up_neg.value),
                (uc - max(y, 0.0), up.value) if uc > 0 else (0.0, up.value),
            ]
        else:
            legs = [
                (min(y, 0.0) - uc, down_neg.value) if uc < 0 else (0.0, down_neg.value),
                (y - max(uc, 0.0), down.value) if y > 0 else (0.0, down.value),
            ]
        period = self.rate_period()
        total = 0.0
        for length, rate in legs:
            if length <= 0:
                continue  # not part of the way
            if rate == 0:
                total += math.inf if self.values["zeroRate"] == 1 else 0.0
                continue
            per_second = rate / period if period > 0 else rate / self.T
            # IEEE division, as the PLC's: a rate per second that underflows to 0 never arrives
            total += length / per_second if per_second != 0 else math.inf
        duration = self.resolve_time("duration").value
        if duration > 0:
            total = min(total, max(0.0, duration - self.running_time))
        return total

    def d2ydt2(self, dydt):
        """(dydt - the dydt of the cycle before) / T; 0 where the dydt before, the change or the quotient is not
        finite (rules.md: a quotient of finite values overflows after a jump of about the largest value times T^2)"""
        real = self.real
        moved = real(self.yp - self.ypp)
        before = 0.0 if moved == 0 else real(divide(moved, real(self.T_before)))
        if not finite(before):
            return 0.0
        change = real(dydt - before)
        d2ydt2 = real(divide(change, real(self.T))) if finite(change) else 0.0
        return d2ydt2 if finite(d2ydt2) else 0.0

    def planned_time(self, uc):
        """The block's own plan: rule 6's cycles ahead on a copy at the same
        inputs until y == uc, n * T; +inf when the output cannot move from
        rest, or after 2^26 cycles."""
        ahead = copy.deepcopy(self)
        if ahead.decided_by == "5b":
            ahead.decided_by = "1-5"  # hold stops the output
        ahead.values["hold"] = False
        ahead.values["bypass"] = False
        cycles = 0
        T = self.T
        while ahead.y != uc and cycles < 2**26:
            before = ahead.y
            at_rest = ahead.decided_by != "6" or ahead.y == ahead.yp
            ahead.cycle(T, math.inf)
            cycles += 1
            if at_rest and ahead.y == before:
                return math.inf
        return cycles * T if ahead.y == uc else math.inf

    def outputs(self):
        return dict(self.last)

    def evaluate_outputs(self):
        error = self.status >= 0x8000
        y, yp = self.y, self.yp
        uc = self.target(self.u_prev)
        low, high = self.limits()
        by_rule_6 = self.decided_by == "6"
        ramped = by_rule_6 and not self.jumped
        max_up, max_down = self.rates_used
        real = self.real
        remaining = 0.0
        if self.decided_by in ("6", "5b") and y != uc and finite(y) and finite(uc):
            remaining = self.planned_time(uc) if self.accelerating() else self.remaining_time(y, uc)
        dydt = real(divide(real(y - yp), real(self.T))) if self.decided_by and finite(y) and finite(yp) else 0.0
        if self.accelerating():
            limiting_up = ramped and y < uc and real(yp + max_up) <= y
            limiting_down = ramped and y > uc and real(yp - max_down) >= y
        else:
            limiting_up = ramped and real(yp + max_up) < uc
            limiting_down = ramped and real(yp - max_down) > uc
        return {
            "y": y,
            "rampActive": by_rule_6 and y != uc,
            "runningTime": self.running_time,
            "error": error,
            "status": self.status,
            "subFunctionStatus": self.vr[self.culprit] if error else 0,
            "dydt": dydt,
            "limitingUp": limiting_up,
            "limitingDown": limiting_down,
            "highLimit": finite(y) and y >= high,
            "lowLimit": finite(y) and y <= low,
            "remainingTime": remaining,
            "d2ydt2": self.d2ydt2(dydt) if by_rule_6 and finite(dydt) else 0.0,
            # what a vendor mapping needs of the same cycle
            "_yp": yp,
            "_mode": self.values.get("mode"),
        }


# -- the vendor blocks, each read as the unified block (models.md) ---------
nan = math.nan


def siemens(v):
    ob = v["callOB"]
    ob_valid = 30 <= ob <= 38 or ob >= 123
    unified = {
        "u": v["value"],
        "rateUp": v["setChangeRate"],
        "rateDown": v["setChangeRate"],
        "rateUpPar": nan,
        "rateDownPar": nan,
        "ratePeriod": 1.0,
        "zeroRate": 1,
        "bypass": v["enDefaultOutValue"],
        "bypassValue": v["defaultOutValue"],
        "bypassValuePar": nan,
        # an invalid callOB is reported by the status; the cycles are still cycleTime's
        "duration": 0.0,
        "durationPar": 0.0,
        "cycleTime": v["cycleTime"],
        "cycleValid": ob_valid,
        "initMode": 1,
        "initValue": 0.0,
        "initDelay": 0.0,
    }
    culprits = {
        "rateUp": "setChangeRate",
        "rateDown": "setChangeRate",
        "rateUpPar": "setChangeRate",
        "rateDownPar": "setChangeRate",
        "cycleTime": "cycleTime" if ob_valid else "callOB",
    }
    return unified, culprits


def irmn4(v):
    restart = bool(v["OutSave"]) and finite(v["SavedOut"])
    duration = v["Duration"]
    duration_par = v["DurationPar"]
    unified = {
        "u": v["In"],
        "rateUp": v["UpRate"],
        "rateDown": v["DownRate"],
        "rateUpPar": v["UpRatePar"],
        "rateDownPar": v["DownRatePar"],
        "ratePeriod": 1.0,
        "zeroRate": 2,
        "bypass": v["EnableBypass"],
        "bypassValue": v["BypassValue"],
        "bypassValuePar": v["BypassValuePar"],
        # the block's range: a longer Duration is 259200 s
        "duration": min(duration, 259200.0) if not math.isnan(duration) else nan,
        "durationPar": min(duration_par, 259200.0),
        "cycleTime": v["cycleTime"],
        "initMode": 1 if restart else 2,
        "initValue": v["SavedOut"],
        "initDelay": 0.0,
        "arithmetic": REAL,  # the IRMN4 family's analog pins are 32-bit floats
    }
    culprits = {
        "rateUp": "UpRate",
        "rateDown": "DownRate",
        "rateUpPar": "UpRatePar",
        "rateDownPar": "DownRatePar",
        "duration": "Duration",
        "durationPar": "DurationPar",
        "cycleTime": "cycleTime",
    }
    return unified, culprits


def codesys(v):
    unified = {
        "u": v["rIn"],
        "rateUp": v["rVariation"],
        "rateDown": v["rVariation"],
        "rateUpPar": nan,
        "rateDownPar": nan,
        "ratePeriod": time_ms(v["tTime"]),
        "zeroRate": 1,
        "bypass": False,
        "bypassValue": nan,
        "bypassValuePar": nan,
        "duration": 0.0,
        "durationPar": 0.0,
        "cycleTime": v["cycleTime"],
        "initMode": v["eInitial"],
        "initValue": v["rInitValue"],
        "initDelay": time_ms(v["tInitDelay"]),
        "arithmetic": REAL,  # REAL pins, TIME in milliseconds
    }
    culprits = {"rateUp": "rVariation", "rateDown": "rVariation", "ratePeriod": "tTime", "cycleTime": "cycleTime"}
    return unified, culprits


def siemens_advanced(v):
    """models.md, LGF_LimRateOfChangeAdvancedCI: modes (first match wins) reset, manOp,
    enDefaultOutValue, track set the output as a bypass does; else a ramp
    towards autoValue within [setLowLim, setHighLim]."""
    ob = v["callOB"]
    ob_valid = 30 <= ob <= 38 or ob >= 123
    if v["reset"]:
        mode, value = "reset", v["defaultOutValue"] if v["enDefaultOutValue"] else 0.0
    elif v["manOp"]:
        mode, value = "manOp", v["manualValue"]
    elif v["enDefaultOutValue"]:
        mode, value = "enDefaultOutValue", v["defaultOutValue"]
    elif v["track"]:
        mode, value = "track", v["autoValue"]
    else:
        mode, value = "ramp", nan
    unified = {
        "u": v["autoValue"],
        "rateUp": v["setPosUpRateLim"],
        "rateDown": v["setPosDownRateLim"],
        # quadrants by the output's magnitude: negUp falls below 0, negDown rises
        "rateDownNeg": v["setNegUpRateLim"],
        "rateUpNeg": v["setNegDownRateLim"],
        "rateUpPar": nan,
        "rateDownPar": nan,
        "ratePeriod": 1.0,
        "zeroRate": 1,
        "yMax": v["setHighLim"],
        "yMin": v["setLowLim"],
        "yMaxPar": nan,
        "yMinPar": nan,
        "hold": False,
        "bypass": mode != "ramp",
        "bypassValue": value,
        "bypassValuePar": nan,
        "duration": 0.0,
        "durationPar": 0.0,
        "cycleTime": v["cycleTime"],
        "cycleValid": ob_valid,
        "initMode": 1,
        "initValue": 0.0,
        "initDelay": 0.0,
        "mode": mode,
    }
    culprits = {
        "rateUp": "setPosUpRateLim",
        "rateDown": "setPosDownRateLim",
        "rateUpNeg": "setNegDownRateLim",
        "rateDownNeg": "setNegUpRateLim",
        "rateUpPar": "setPosUpRateLim",
        "rateDownPar": "setPosDownRateLim",
        "yMin": "setLowLim",
        "yMinPar": "setLowLim",
        "cycleTime": "cycleTime" if ob_valid else "callOB",
    }
    return unified, culprits


def unified_static(v):
    """RateLimiterStatic (rules.md): RateLimiter with every "or Par" input
    unconnected (NaN), its parameters under the same names; rateUpNeg and
    rateDownNeg, parameters here, fall back to the resolved rates."""
    unified = {name: v[name] for name in v if name in PARAMETER_DEFAULTS or name in INPUT_DEFAULTS}
    unified.update({"rateUp": nan, "rateDown": nan, "bypassValue": nan, "duration": nan, "yMax": nan, "yMin": nan})
    return unified, {name: name for name in v}


def siemens_advanced_outputs(out, unified):
    negative = out["_yp"] < 0  # the quadrant the rate was picked by
    reset = out["_mode"] == "reset"
    return {
        "outputValue": out["y"],
        "posUpRateLim": out["limitingUp"] and not negative,
        "posDownRateLim": out["limitingDown"] and not negative,
        "negUpRateLim": out["limitingDown"] and negative,
        "negDownRateLim": out["limitingUp"] and negative,
        "highLim": out["highLimit"] and not reset,
        "lowLim": out["lowLimit"] and not reset,
        "error": out["error"],
        "status": out["status"],
        "subfunctionStatus": out["subFunctionStatus"],
    }


VENDORS = {
    "RateLimiterStatic": {
        "translate": unified_static,
        "compare_only": False,
        "outputs": {name: name for name in OUTPUTS},
    },
    "LGF_LimRateOfChangeCI": {
        "translate": siemens,
        "compare_only": True,
        "outputs": {
            "delayedValue": "y",
            "error": "error",
            "status": "status",
            "subFunctionStatus": "subFunctionStatus",
        },
    },
    "RateLimit": {
        "translate": irmn4,
        "compare_only": False,
        "outputs": {"Out": "y", "RunningTime": "runningTime"},
    },
    "LGF_LimRateOfChangeAdvancedCI": {
        "translate": siemens_advanced,
        "compare_only": True,
        "neg_fallback": False,
        "limit_initial": False,
        "outputs": siemens_advanced_outputs,
        "output_names": [
            "outputValue",
            "posUpRateLim",
            "posDownRateLim",
            "negUpRateLim",
            "negDownRateLim",
            "highLim",
            "lowLim",
            "error",
            "status",
            "subfunctionStatus",
        ],
    },
    "Ramp": {
        "translate": codesys,
        "compare_only": False,
        "outputs": {"rOut": "y", "xRampActive": "rampActive"},
    },
}


MODEL_DESCRIPTIONS = Path(__file__).resolve().parents[2] / "modelDescription"


@functools.cache
def start_values(model):
    """The start values of a model's inputs and parameters, from its TOML
    file (the single source of every variable)."""
    with open(MODEL_DESCRIPTIONS / f"{model}.toml", "rb") as f:
        variables = tomllib.load(f)["variable"]
    return {
        v["name"]: bool(v.get("start", False)) if v["type"] == "Boolean" else v.get("start", 0.0)
        for v in variables
        if v["causality"] in ("input", "parameter")
    }


class VendorOracle:
    """A vendor block: its own variables, translated onto the unified oracle
    before every step, as models.md describes it."""

    def __init__(self, model, vr, start=None, start_time=0.0):
        self.spec = VENDORS[model]
        self.vendor_vr = vr
        self.values = dict(start_values(model))
        self.values.update(start or {})
        unified, culprits = self.spec["translate"](self.values)
        self.unified = RateLimiterOracle(
            self.culprit_vrs(culprits),
            unified,
            start_time,
            compare_only=self.spec["compare_only"],
            neg_fallback=self.spec.get("neg_fallback", True),
            limit_initial=self.spec.get("limit_initial", True),
        )

    def culprit_vrs(self, culprits):
        return {name: self.vendor_vr[vendor] for name, vendor in culprits.items()}

    def do_step(self, t, h, inputs=None):
        self.values.update(inputs or {})
        unified, culprits = self.spec["translate"](self.values)
        self.unified.values.update(unified)
        self.unified.vr = self.culprit_vrs(culprits)
        self.unified.do_step(t, h)
        return self.outputs()

    def outputs(self):
        out = self.unified.outputs()
        if callable(self.spec["outputs"]):
            return self.spec["outputs"](out, self.unified)
        return {vendor: out[name] for vendor, name in self.spec["outputs"].items()}


def oracle_for(model, vr, start=None, start_time=0.0):
    if model == "RateLimiter":
        return RateLimiterOracle(vr, start, start_time)
    return VendorOracle(model, vr, start, start_time)


def output_names(model):
    if model == "RateLimiter":
        return list(OUTPUTS)
    return list(VENDORS[model].get("output_names") or VENDORS[model]["outputs"])


def kept(function):
    """function's results kept for its arguments; with RL_ORACLE_CACHE (a folder; the mutation runner
    sets it) also on disk between processes, under the hash of this file, the name and the arguments,
    so that a slow oracle run is worked once for many runs of the same tests."""

    @functools.lru_cache(maxsize=None)
    def wrapper(*args):
        folder = os.environ.get("RL_ORACLE_CACHE")
        if not folder:
            return function(*args)
        key = hashlib.sha256(Path(__file__).read_bytes() + f"{function.__qualname__}{args!r}".encode()).hexdigest()
        path = Path(folder) / f"{key}.json"
        if path.exists():
            return json.loads(path.read_text())  # floats, NaN and inf come back bit for bit
        result = function(*args)
        path.parent.mkdir(parents=True, exist_ok=True)
        partial = path.with_suffix(f".{os.getpid()}")
        partial.write_text(json.dumps(result))
        os.replace(partial, path)  # a reader sees the whole result or none
        return result

    return wrapper


# -- rules.md, Acceleration limit ----------------------------------------------
# Written from that section: the steps per cycle in the arithmetic (`real`
# rounds every operation), the feasibility of a step decided in exact
# rational arithmetic (Fraction) where the rules say exactly.

from fractions import Fraction  # noqa: E402


class Arithmetic:
    """The operations of one arithmetic: LREAL (binary64) or REAL (binary32)."""

    def __init__(self, real):
        self.real = real
        self.binary32 = real is f32
        self.mant_dig, self.min_exp = (24, -125) if self.binary32 else (53, -1021)
        self.largest = f32(3.4028234663852886e38) if self.binary32 else sys.float_info.max
        self.roundoff = 2.0**-self.mant_dig
        self.counted = 2.0 ** (self.mant_dig // 2)  # below this many cycles of braking, counts are exact

    def ulp(self, x):
        e = math.frexp(x)[1] if x != 0 else self.min_exp
        return 2.0 ** (max(e, self.min_exp) - self.mant_dig)

    def towards(self, x, y):
        """the neighbour of x towards y in the arithmetic"""
        if not self.binary32:
            return math.nextafter(x, y)
        return float(numpy.nextafter(numpy.float32(x), numpy.float32(y)))

    def add(self, a, b):
        r = self.real
        try:
            return r(a + b)
        except OverflowError:
            return math.copysign(math.inf, a)

    def mul(self, a, b):
        try:
            return self.real(a * b)
        except OverflowError:
            return math.copysign(math.inf, a) * math.copysign(1.0, b)

    def div(self, a, b):
        return self.real(divide(a, b))


def braking_distance(A, s, b):
    """B(s) = n * (s - b * (n + 1) / 2), n = floor(s / b); 0 for s <= b"""
    if not s > b:
        return 0.0
    if math.isinf(s):
        return s
    n = A.real(math.floor(A.div(s, b)))
    return A.mul(n, A.add(s, -(A.mul(b, A.real(n + 1)) / 2)))


def stops_within(A, s, b, e):
    """s + B(s) <= e: exactly in the rules' range, else as written"""
    if not s > b or math.isinf(b):
        return s <= e
    if s < 1e300 and e < 1e300 and b > 1e-290 and A.div(s, b) < 2.0**26:
        S, B, E = Fraction(s), Fraction(b), Fraction(e)
        n = math.floor(S / B)
        return (n + 1) * S - B * (n * (n + 1) // 2) - E <= 0
    return A.add(s, braking_distance(A, s, b)) <= e


def triangle(A, b, n):
    return A.mul(A.mul(b, n), A.real(n + 1)) / 2


def stoppable_step(A, e, b):
    """S(E): the largest step from which braking stops within e"""
    if math.isinf(b):
        return e
    q = A.div(e, b)
    if not q < A.counted * A.counted:
        root = A.mul(A.real(math.sqrt(2.0 * b)), A.real(math.sqrt(e)))
        s = A.add(root, -b)
        return s if s > 0 else 0.0
    n = A.real(math.floor((math.sqrt(8 * q + 1) - 1) / 2))
    if triangle(A, b, n) > e:
        n = A.real(n - 1)
    elif triangle(A, b, A.real(n + 1)) <= e:
        n = A.real(n + 1)
    return A.add(A.real(e / A.real(n + 1)), A.mul(A.real(b / 2), n))


def zone_step(A, z, v, b):
    """Z(z, L0): the largest step after which braking at b reaches L0 within z"""
    if math.isinf(b) or math.isinf(v):
        return math.inf
    q, w = A.div(z, b), A.div(v, b)
    if not (q < A.counted * A.counted) or not (w < A.counted):
        s2 = v * v + 2.0 * b * z  # binary64, an overflow an infinity
        s = A.add(A.real(math.sqrt(s2)), -b)
        return s if s > v else v

    def reach(k):  # (K - 1) * L0 + b * (K - 1) * K / 2
        return A.add(A.mul(A.real(k - 1), v), triangle(A, b, A.real(k - 1)))

    k = A.real(math.floor(((1 - 2 * w) + math.sqrt((2 * w - 1) * (2 * w - 1) + 8 * (w + q))) / 2))
    k = max(k, 1.0)
    if k > 1 and reach(k) > z:
        k = A.real(k - 1)
    elif reach(A.real(k + 1)) <= z:
        k = A.real(k + 1)
    if k <= 1:
        return A.add(v, b)
    return min(A.add(v, A.mul(k, b)), A.add(A.real(z / A.real(k - 1)), A.mul(A.real(b / 2), A.real(k - 2))))


def advance(A, y, delta):
    """y + delta rounded to nearest, then towards y if that went past the exact sum"""
    if not (abs(y) < 1e300 and abs(delta) < 1e300):
        return A.add(y, delta)
    nearest = A.add(y, delta)
    beyond = Fraction(nearest) - (Fraction(y) + Fraction(delta))
    if (delta > 0 and beyond > 0) or (delta <= 0 and beyond < 0):
        return A.towards(nearest, y)
    return nearest


def directed_sum(A, a, b, towards_zero):
    """a + b rounded to nearest, then towards 0 (or away from it) if that went
    beyond (or fell short of) the exact sum"""
    nearest = A.add(a, b)
    if not (abs(a) < 1e300 and abs(b) < 1e300):
        return nearest
    beyond = Fraction(nearest) - (Fraction(a) + Fraction(b))
    away = (nearest > 0 and beyond > 0) or (nearest < 0 and beyond < 0)
    short = (nearest > 0 and beyond < 0) or (nearest < 0 and beyond > 0)
    if towards_zero and away:
        return A.towards(nearest, 0.0)
    if not towards_zero and short:
        return A.towards(nearest, math.copysign(math.inf, nearest))
    return nearest


def accel_step(A, yp, uc, v, a, b, limits):
    """One cycle of rules.md, Acceleration limit, steps 1 to 6. limits:
    (maxUp, maxDown, maxUpNeg, maxDownNeg) per cycle."""
    max_up, max_down, max_up_neg, max_down_neg = limits
    e = directed_sum(A, uc, -yp, True)
    up = e > 0 or (e == 0 and v > 0)  # 1
    distance = e if up else -e
    if math.isinf(distance):
        distance = A.largest
    moving = v if up else -v
    negative = yp < 0
    limit = (max_up_neg if negative else max_up) if up else (max_down_neg if negative else max_down)
    if moving < 0 and -moving > b:  # 2
        step = A.add(moving, b)
    else:
        if moving >= 0:  # 3
            fastest = A.add(moving, a)
        else:
            fastest = a if math.isinf(b) else A.mul(a, A.div(A.add(b, moving), b))
        fastest = min(fastest, limit)
        zone_ahead = (negative and not uc < 0) if up else (not negative and uc < 0)  # 4
        if zone_ahead:
            zone_limit = max_up if up else max_down_neg
            z = -yp if negative else yp
            z = A.add(z, -A.add(A.mul(z, 8 * A.roundoff), 2 * A.ulp(z) if up else 0.0))
            if zone_limit < fastest:
                fastest = zone_limit if z < 0 else min(fastest, zone_step(A, z, zone_limit, b))
        if not stops_within(A, fastest, b, distance):  # 5
            stoppable = stoppable_step(A, distance, b)
            for _ in range(8):
                if not (stoppable > 0 and not stops_within(A, stoppable, b, distance)):
                    break
                stoppable = A.towards(stoppable, 0.0)
            if not stops_within(A, stoppable, b, distance):  # still too far: braking's step alone
                stoppable = 0.0
            fastest = min(fastest, stoppable)
        if moving > b:
            braked = directed_sum(A, moving, -b, True)  # rounded down
            step = braked if fastest < braked else fastest
        else:
            step = fastest
    scale = uc if abs(uc) > abs(yp) else yp  # 6
    if abs(A.add(step, -distance)) <= 4 * A.ulp(scale):
        return uc
    if distance == 0 and 0 < step <= 4 * A.ulp(moving):  # at uc: the landing's rounding left this speed
        return uc
    following = advance(A, yp, step if up else -step)
    if following == yp and step > 0:  # below the output's resolution: one unit in the last place
        return A.towards(yp, uc)
    return following
