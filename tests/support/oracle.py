"""An independent model of the rate limiter, written from SPEC sections 2
and 3 (not from the C code), to check the FMUs against.

The oracle speaks the unified block's variable names. It follows the
project's documented conventions where the contract leaves room:
runningTime is counted in whole cycles (cycles * T, with the sum started
afresh when T changes), and time comparisons use a relative 1e-9.
"""
import math
from dataclasses import dataclass

TOL = 1e-9

PARAMETER_DEFAULTS = {
    "rateUpPar": 1.0, "rateDownPar": 1.0, "bypassValuePar": math.nan, "durationPar": 0.0,
    "ratePeriod": 1.0, "zeroRate": 1, "cycleTime": 0.0, "initMode": 2, "initValue": 0.0, "initDelay": 0.0,
}
INPUT_DEFAULTS = {
    "u": 0.0, "rateUp": math.nan, "rateDown": math.nan, "bypass": False, "bypassValue": math.nan,
    "duration": math.nan,
}
OUTPUTS = ("y", "rampActive", "runningTime", "error", "status", "subFunctionStatus")


def finite(x):
    return not (math.isnan(x) or math.isinf(x))


@dataclass
class Resolved:
    value: float
    name: str  # the variable the value came from


class RateLimiterOracle:
    """One instance of the unified block; `vr` maps names to value references
    (for subFunctionStatus). `compare_only=True` is the Siemens reading of a
    non-finite input: no rule 1, u is only compared with the output."""

    def __init__(self, vr, start=None, start_time=0.0, compare_only=False):
        self.vr = vr
        self.values = dict(PARAMETER_DEFAULTS)
        self.values.update(INPUT_DEFAULTS)
        self.values.update(start or {})
        self.compare_only = compare_only
        self.t0 = start_time
        self.time = start_time
        self.cycles_done = 0
        u = self.values["u"]
        self.y = self.values["initValue"] if self.values["initMode"] == 1 else u
        self.u_prev = u
        self.ramp_active = False
        self.run_cycles, self.run_T, self.run_base = 0, 0.0, 0.0
        self.status, self.culprit = self.evaluate_status()

    # -- rule 0 and the status table -------------------------------------
    def resolve(self, name):
        value = self.values[name]
        if math.isnan(value):
            return Resolved(self.values[name + "Par"], name + "Par")
        return Resolved(value, name)

    def evaluate_status(self):
        up, down = self.resolve("rateUp"), self.resolve("rateDown")
        period = self.values["ratePeriod"]
        duration = self.resolve("duration")
        cycle = self.values["cycleTime"]
        for rate in (up, down):
            if rate.value < 0:
                return 0x8200, rate.name
        for rate in (up, down):
            if math.isnan(rate.value):
                return 0x8201, rate.name
        if not finite(period) or period < 0:
            return 0x8202, "ratePeriod"
        if math.isnan(duration.value) or duration.value < 0:
            return 0x8203, duration.name
        if not finite(cycle) or cycle < 0:
            return 0x8601, "cycleTime"
        return 0, None

    def per_cycle_limit(self, rate, T):
        if rate == 0:
            return math.inf if self.values["zeroRate"] == 2 else 0.0
        period = self.values["ratePeriod"]
        return rate * T / period if period > 0 else rate

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

    # -- one cycle (rules 1 to 6) ------------------------------------------
    def cycle(self, T, elapsed):
        v = self.values
        u = v["u"]
        yp = self.y
        self.status, self.culprit = self.evaluate_status()
        by_rule_6 = False
        if not self.compare_only and not finite(u):                      # rule 1
            y = u
            self.running_reset()
        elif v["bypass"]:                                                # rule 2
            bypass_value = self.resolve("bypassValue").value
            y = bypass_value if finite(bypass_value) else u
            self.running_reset()
        elif v["initMode"] == 3 and elapsed <= v["initDelay"] + TOL * T:  # rule 3
            y = u
            self.running_reset()
        elif not finite(yp) and finite(u):                               # rule 4
            y = u
            self.running_reset()
        elif self.status >= 0x8000:                                      # rule 5
            y = yp
        else:                                                            # rule 6
            by_rule_6 = True
            if u != self.u_prev:
                self.running_reset()
            if yp != u:
                self.running_add(T)
            duration = self.resolve("duration").value
            if duration > 0 and self.running_time >= duration * (1 - TOL):
                y = u
            elif u > yp:
                y = min(u, yp + self.per_cycle_limit(self.resolve("rateUp").value, T))
            elif u < yp:
                y = max(u, yp - self.per_cycle_limit(self.resolve("rateDown").value, T))
            else:
                y = yp
        self.ramp_active = by_rule_6 and y != u
        self.y = y
        self.u_prev = u

    # -- SPEC section 2: a communication step --------------------------------
    def do_step(self, t, h, inputs=None):
        """Set the inputs (held for the whole step), then run every cycle
        whose end lies in (t, t+h]."""
        self.values.update(inputs or {})
        end = t + h
        c = self.values["cycleTime"]
        if finite(c) and c > 0:
            last = math.floor((end - self.t0) / c + TOL)
            for n in range(self.cycles_done + 1, last + 1):
                self.cycle(c, n * c)
            self.cycles_done = max(self.cycles_done, last)
        else:
            self.cycle(h, end - self.t0)
        self.time = end
        return self.outputs()

    def outputs(self):
        error = self.status >= 0x8000
        return {
            "y": self.y,
            "rampActive": self.ramp_active,
            "runningTime": self.running_time,
            "error": error,
            "status": self.status,
            "subFunctionStatus": self.vr[self.culprit] if error else 0,
        }


# -- SPEC section 4: the vendor blocks, each read as the unified block -------
nan = math.nan


def siemens(v):
    ob = v["callOB"]
    ob_valid = 30 <= ob <= 38 or ob >= 123
    unified = {
        "u": v["value"], "rateUp": v["setChangeRate"], "rateDown": v["setChangeRate"],
        "rateUpPar": nan, "rateDownPar": nan, "ratePeriod": 1.0, "zeroRate": 1,
        "bypass": v["enDefaultOutValue"], "bypassValue": v["defaultOutValue"], "bypassValuePar": nan,
        "duration": 0.0, "durationPar": 0.0, "cycleTime": v["cycleTime"] if ob_valid else nan,
        "initMode": 1, "initValue": 0.0, "initDelay": 0.0,
    }
    culprits = {"rateUp": "setChangeRate", "rateDown": "setChangeRate", "rateUpPar": "setChangeRate",
                "rateDownPar": "setChangeRate", "cycleTime": "cycleTime" if ob_valid else "callOB"}
    return unified, culprits


def irmn4(v):
    restart = bool(v["OutSave"]) and finite(v["SavedOut"])
    duration = v["Duration"]
    duration_par = v["DurationPar"]
    unified = {
        "u": v["In"], "rateUp": v["UpRate"], "rateDown": v["DownRate"], "rateUpPar": v["UpRatePar"],
        "rateDownPar": v["DownRatePar"], "ratePeriod": 1.0, "zeroRate": 2,
        "bypass": v["EnableBypass"], "bypassValue": v["BypassValue"], "bypassValuePar": v["BypassValuePar"],
        # the block's range: a longer Duration is 259200 s
        "duration": min(duration, 259200.0) if not math.isnan(duration) else nan,
        "durationPar": min(duration_par, 259200.0), "cycleTime": v["cycleTime"],
        "initMode": 1 if restart else 2, "initValue": v["SavedOut"], "initDelay": 0.0,
    }
    culprits = {"rateUp": "UpRate", "rateDown": "DownRate", "rateUpPar": "UpRatePar",
                "rateDownPar": "DownRatePar", "duration": "Duration", "durationPar": "DurationPar",
                "cycleTime": "cycleTime"}
    return unified, culprits


def codesys(v):
    unified = {
        "u": v["rIn"], "rateUp": v["rVariation"], "rateDown": v["rVariation"], "rateUpPar": nan,
        "rateDownPar": nan, "ratePeriod": v["tTime"], "zeroRate": 1, "bypass": False, "bypassValue": nan,
        "bypassValuePar": nan, "duration": 0.0, "durationPar": 0.0, "cycleTime": v["cycleTime"],
        "initMode": v["eInitial"], "initValue": v["rInitValue"], "initDelay": v["tInitDelay"],
    }
    culprits = {"rateUp": "rVariation", "rateDown": "rVariation", "ratePeriod": "tTime", "cycleTime": "cycleTime"}
    return unified, culprits


VENDORS = {
    "LGF_LimRateOfChangeCI": {
        "translate": siemens, "compare_only": True,
        "defaults": {"value": 0.0, "setChangeRate": 0.0, "defaultOutValue": 0.0, "enDefaultOutValue": False,
                     "callOB": 30, "cycleTime": 0.0},
        "outputs": {"delayedValue": "y", "error": "error", "status": "status", "subFunctionStatus": "subFunctionStatus"},
    },
    "RateLimit": {
        "translate": irmn4, "compare_only": False,
        "defaults": {"EnableBypass": False, "In": 0.0, "Duration": nan, "BypassValue": nan, "UpRate": nan,
                     "DownRate": nan, "DurationPar": 0.0, "BypassValuePar": nan, "UpRatePar": 0.0,
                     "DownRatePar": 0.0, "OutSave": False, "SavedOut": nan, "cycleTime": 0.0},
        "outputs": {"Out": "y", "RunningTime": "runningTime"},
    },
    "Ramp": {
        "translate": codesys, "compare_only": False,
        "defaults": {"rIn": 0.0, "rVariation": 100.0, "tTime": 10.0, "rInitValue": 0.0, "eInitial": 2,
                     "tInitDelay": 5.0, "cycleTime": 0.0},
        "outputs": {"rOut": "y", "xRampActive": "rampActive"},
    },
}


class VendorOracle:
    """A vendor block: its own variables, translated onto the unified oracle
    before every step, as SPEC section 4 describes it."""

    def __init__(self, model, vr, start=None, start_time=0.0):
        self.spec = VENDORS[model]
        self.vendor_vr = vr
        self.values = dict(self.spec["defaults"])
        self.values.update(start or {})
        unified, culprits = self.spec["translate"](self.values)
        self.unified = RateLimiterOracle(self.culprit_vrs(culprits), unified, start_time,
                                         compare_only=self.spec["compare_only"])

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
        return {vendor: out[name] for vendor, name in self.spec["outputs"].items()}


def oracle_for(model, vr, start=None, start_time=0.0):
    if model == "RateLimiter":
        return RateLimiterOracle(vr, start, start_time)
    return VendorOracle(model, vr, start, start_time)


def output_names(model):
    return list(OUTPUTS) if model == "RateLimiter" else list(VENDORS[model]["outputs"])
