"""Random scenarios of the acceleration limit through the FMU binaries
(support/fmu_driver.py's fast driver), cycle by cycle, for the property
checker (support/accel_properties.py).

A scenario is drawn as it runs (a target moved inside the braking distance
needs the output's position and speed): a `Chooser` (random.Random for the
campaign, hypothesis' data for the tests) picks its settings and, each
cycle, what changes. What was set is recorded (`Scenario`, plain JSON), so
that any run replays it exactly: through Model Exchange, another FMI
version, or as a reproducer printed by the campaign.
"""

import json
import math
import sys
from dataclasses import asdict, dataclass, field

from support.accel_properties import REAL, Cycle, Segment, check
from support.fmu_driver import Instance
from support.oracle import start_values

nan, inf = math.nan, math.inf
REAL_OUTPUTS = ("y", "dydt", "d2ydt2", "remainingTime", "runningTime")
INT_OUTPUTS = ("status", "subFunctionStatus")
# what a cycle may bring, by weight (most cycles bring nothing)
EVENTS = (
    ["none"] * 60
    + ["far"] * 4
    + ["inside"] * 4
    + ["behind"] * 2
    + ["moving"] * 2
    + ["limit"] * 3
    + ["release"]
    + ["rate"] * 2
    + ["accel"]
    + ["hold"]
    + ["bypass"]
    + ["nonfinite"]
    + ["reinit"]
    + ["period"]
)


@dataclass
class Scenario:
    model: str
    version: int
    arithmetic: int
    T: float
    cycle_time: float  # 0: one cycle a doStep of T (Co-Simulation only); T: cycles of the FMU
    start: dict  # the values set before initialisation
    cycles: list = field(default_factory=list)  # per cycle: the values set before it; "_reinit": a new start
    settle_from: int = -1  # the last stretch, from this cycle, was held until the output settled

    def dumps(self):
        return json.dumps(asdict(self))  # NaN and infinities as Python's json writes and reads them


def loads(text):
    return Scenario(**json.loads(text))


class RandomChooser:
    def __init__(self, rng):
        self.rng = rng

    def pick(self, options):
        return self.rng.choice(options)

    def uniform(self, low, high):
        return self.rng.uniform(low, high)

    def integer(self, low, high):
        return self.rng.randint(low, high)


class HypothesisChooser:
    def __init__(self, data):
        from hypothesis import strategies as st

        self.data, self.st = data, st

    def pick(self, options):
        return self.data.draw(self.st.sampled_from(options))

    def uniform(self, low, high):
        return self.data.draw(self.st.floats(low, high, allow_nan=False, allow_infinity=False))

    def integer(self, low, high):
        return self.data.draw(self.st.integers(low, high))


class Block:
    """One FMU instance driven a cycle at a time: Co-Simulation (a doStep of T) or Model Exchange (the time event
    at each cycle end)."""

    def __init__(self, model, version, model_exchange=False):
        self.fmu = Instance(model, version, name="accel", logging=False, model_exchange=model_exchange)
        self.me = model_exchange
        f = self.fmu.fmu
        self.real_names = [n for n in REAL_OUTPUTS if n in self.fmu.variables]
        self.real_vrs = [self.fmu.vr(n) for n in self.real_names]
        self.int_vrs = [self.fmu.vr(n) for n in INT_OUTPUTS]
        self.get_real = f.getReal if version == 2 else f.getFloat64
        self.get_int = f.getInteger if version == 2 else f.getInt32
        if model_exchange:
            self.update = f.newDiscreteStates if version == 2 else f.updateDiscreteStates
        self.next_event = None

    def start(self, t0, values):
        self.fmu.set(**values)
        self.fmu.enter_initialization(t0)
        self.fmu.fmu.exitInitializationMode()
        if self.me:
            self.event_update()
        return self.outputs()

    def event_update(self):
        result = self.update()
        self.next_event = result[5] if result[4] else None

    def cycle(self, T, changes, end=None):
        """One cycle of length T; with the FMU's cycleTime, the step ends at the cycle's end (t0 + n T, as the FMU
        counts them: a sum of steps drifts past the FMU's tolerance after some 10,000 cycles)."""
        self.fmu.set(**changes)
        if end is not None and not self.me:
            self.fmu.fmu.doStep(currentCommunicationPoint=self.fmu.t, communicationStepSize=end - self.fmu.t)
            self.fmu.t = end
            return self.outputs()
        if self.me:
            f = self.fmu.fmu
            f.enterContinuousTimeMode()
            f.setTime(self.next_event)
            f.enterEventMode()
            self.fmu.t = self.next_event
            self.event_update()
        else:
            self.fmu.step(T)
        return self.outputs()

    def outputs(self):
        out = dict(zip(self.real_names, self.get_real(self.real_vrs), strict=True))
        out.update(zip(INT_OUTPUTS, self.get_int(self.int_vrs), strict=True))
        return out

    def reset(self):
        self.fmu.fmu.reset()

    def free(self):
        self.fmu.free()


def settable(model, values):
    """The values a model has (RateLimiterStatic: no "or Par" inputs)."""
    names = start_values(model)
    return {k: v for k, v in values.items() if k in names}


class Run:
    """A scenario as it runs: the values in effect, the segments for the checker."""

    def __init__(self, scenario, model_exchange=False, block=None):
        self.sc = scenario
        self.block = (block or Block)(scenario.model, scenario.version, model_exchange)
        # a Python block (support/accel_model.py) takes every value; an FMU those its model has
        self.settable = settable if block is None else (lambda model, values: dict(values))
        self.segments = []
        self.t = 0.0
        self.n = 0  # cycles since the segment's start
        self.values = None
        self.y = self.v = 0.0

    def begin(self, start):
        self.values = dict(start_values(self.sc.model))
        self.values.update(start)
        self.values["cycleTime"] = self.sc.cycle_time
        self.values["arithmetic"] = self.sc.arithmetic
        t0 = self.t
        init_values = self.settable(
            self.sc.model, dict(start, cycleTime=self.sc.cycle_time, arithmetic=self.sc.arithmetic)
        )
        out = self.block.start(t0, init_values)
        self.segments.append(Segment(dict(self.values), t0, out))
        self.n = 0
        self.y, self.v = out["y"], 0.0
        return out

    def cycle(self, changes):
        if "_reinit" in changes:
            self.block.reset()
            return self.begin(changes["_reinit"])
        changes = self.settable(self.sc.model, changes)
        self.values.update(changes)
        seg = self.segments[-1]
        end = seg.start_time + (self.n + 1) * self.sc.T
        out = self.block.cycle(self.sc.T, changes, end if self.sc.cycle_time > 0 else None)
        self.n += 1
        self.t = end
        seg.cycles.append(Cycle(dict(self.values), end, out))
        self.v = out["y"] - self.y if math.isfinite(out["y"]) and math.isfinite(self.y) else 0.0
        self.y = out["y"]
        return out

    def free(self):
        self.block.free()


def replay(scenario, model_exchange=False):
    """Every cycle's outputs of a recorded scenario, and the segments for the checker."""
    run = Run(scenario, model_exchange)
    try:
        run.begin(scenario.start)
        for changes in scenario.cycles:
            run.cycle(changes)
        if scenario.settle_from >= 0:
            run.segments[-1].settle = True
        return run.segments
    finally:
        run.free()


def violations(scenario, segments):
    return check(segments, scenario.arithmetic, scenario.T)


# -- drawing a scenario ----------------------------------------------------------------------------------------


class Generator:
    """Draws a scenario's settings and, cycle by cycle, its changes, from a Chooser."""

    def __init__(self, chooser, model, version, arithmetic, model_exchange=False, cycles=(40, 200), accel_zero=False):
        c = self.c = chooser
        self.model, self.arithmetic, self.accel_zero = model, arithmetic, accel_zero
        self.T = c.pick([0.001, 0.01, 0.1, 0.25, 1.0, 0.3])
        cycle_time = self.T if model_exchange else c.pick([0.0, self.T])
        if arithmetic == REAL:
            self.scale = c.pick([1.0] * 6 + [1e-30, 1e-12, 1e-3, 1e3, 1e12, 1e27])
        else:
            self.scale = c.pick([1.0] * 6 + [1e-300, 1e-150, 1e-20, 1e20, 1e150, 1e290])
        self.offset = c.pick([0.0] * 6 + [1000.0 * self.scale, -30.0 * self.scale])
        self.length = c.integer(*cycles)
        self.scenario = Scenario(model, version, arithmetic, self.T, cycle_time, self.settings())
        self.pending = []  # changes due at later cycles: (cycle, changes)

    def far(self):
        return self.offset + self.scale * self.c.uniform(-400.0, 400.0)

    def settings(self):
        c, s, T = self.c, self.scale, self.T
        self.vmax = s * c.uniform(0.5, 20.0)  # per cycle
        self.a = self.vmax / c.uniform(1.0, 30.0)  # per cycle squared
        start = {
            "u": self.far(),
            "initMode": c.pick([2, 2, 2, 1, 3]),
            "initValue": self.far(),
            "initDelay": c.pick([0.0, 2 * T, 5 * T]),
            "zeroRate": c.pick([1, 1, 1, 2]),
        }
        start.update(self.rates(self.vmax))
        self.accel = 0.0 if self.accel_zero else self.a / T**2
        start["accelMax"] = self.accel
        start["decelMax"] = c.pick([0.0, 0.0, 0.25, 0.5, 2.0, 4.0]) * self.a / T**2
        if c.pick([False] * 4 + [True]):
            start.update(self.limit_values(c.pick(["yMax", "yMin"]), self.far(), par=True))
        if c.pick([False] * 8 + [True]):
            start["durationPar"] = c.pick([3, 10, 40]) * T
        self.base = {k: start[k] for k in ("rateUpPar", "rateDownPar", "ratePeriod", "rateUpNeg", "rateDownNeg")}
        return start

    def rates(self, vmax, rate_type="Par"):
        """Rates for a velocity limit vmax per cycle, in a ratePeriod drawn (0: per cycle)."""
        c, T = self.c, self.T
        period = c.pick([1.0, 1.0, 0.5, 2.0, 0.0])
        per_period = (lambda v: v) if period == 0 else (lambda v: v / T * period)
        up = c.pick([vmax, vmax, vmax * c.uniform(0.3, 3.0), inf])
        down = c.pick([up, up, vmax * c.uniform(0.3, 3.0), inf])
        values = {
            "ratePeriod": period,
            "rateUpPar": per_period(up) if up != inf else inf,
            "rateDownPar": per_period(down) if down != inf else inf,
            "rateUpNeg": nan,
            "rateDownNeg": nan,
        }
        if c.pick([False, False, False, True]):
            values["rateUpNeg"] = per_period(vmax * c.uniform(0.3, 3.0))
            values["rateDownNeg"] = c.pick([nan, per_period(vmax * c.uniform(0.3, 3.0))])
        return values

    def limit_values(self, name, value, par=None):
        par = self.model == "RateLimiterStatic" or (self.c.pick([True, False]) if par is None else par)
        if par:
            return {name + "Par": value}
        return {name: value}

    def braking(self, speed):
        """About the way braking needs from speed (per cycle)."""
        return speed * (speed / (2 * self.a)) + speed

    def changes(self, k, y, v, values):
        """What changes before cycle k, given the last output y, its step v and the values in effect."""
        out = {}
        for _, changes in [p for p in self.pending if p[0] == k]:
            out.update(changes)
        self.pending = [p for p in self.pending if p[0] != k]
        c, s = self.c, self.scale
        event = c.pick(EVENTS)
        direction = 1.0 if v > 0 else -1.0 if v < 0 else c.pick([1.0, -1.0])
        if not math.isfinite(y):
            y = self.offset
        if event == "far":
            out["u"] = self.far()
        elif event == "inside":  # the target moved inside the braking distance, in the direction of motion
            out["u"] = y + direction * c.uniform(0.0, 1.0) * self.braking(abs(v))
        elif event == "behind":
            out["u"] = y - direction * c.uniform(0.0, 2.0) * self.braking(abs(v))
        elif event == "moving":  # a target that moves every cycle for a while
            centre, amplitude = y, s * c.uniform(1.0, 100.0)
            period = c.integer(5, 60)
            for j in range(c.integer(5, 60)):
                self.pending.append((k + j, {"u": centre + amplitude * math.sin(2 * math.pi * j / period)}))
        elif event == "limit":  # ahead (inside or beyond the braking distance) or behind the output
            where = c.uniform(-1.0, 2.0) * self.braking(abs(v))
            name = "yMax" if direction > 0 else "yMin"
            out.update(self.limit_values(name, y + direction * where))
        elif event == "release":
            name = c.pick(["yMax", "yMin"])
            out[name + "Par"] = sys.float_info.max * (1 if name == "yMax" else -1)
            if self.model == "RateLimiter":
                out[name] = nan
        elif event == "rate":  # lowered (below the speed) or raised
            vmax = c.pick([abs(v) * c.uniform(0.1, 0.9), self.vmax * c.uniform(0.3, 3.0)]) or self.vmax
            period = values["ratePeriod"]
            per_period = (lambda x: x) if period == 0 else (lambda x: x / self.T * period)
            kind = c.pick(["Par", ""]) if self.model == "RateLimiter" else "Par"
            out["rateUp" + kind] = per_period(vmax)
            out["rateDown" + kind] = per_period(c.pick([vmax, vmax * c.uniform(0.3, 3.0)]))
        elif event == "accel" and not self.accel_zero:
            factor = c.uniform(0.2, 5.0)
            out["accelMax"] = self.accel * factor
            out["decelMax"] = c.pick([0.0, out["accelMax"] * c.uniform(0.25, 4.0)])
        elif event == "hold":
            out["hold"] = True
            self.pending.append((k + c.integer(1, 5), {"hold": False}))
        elif event == "bypass":
            out["bypass"] = True
            out[c.pick(["bypassValuePar"] + (["bypassValue"] if self.model == "RateLimiter" else []))] = c.pick(
                [nan, self.far()]
            )
            self.pending.append((k + c.integer(1, 3), {"bypass": False}))
        elif event == "nonfinite":
            out["u"] = c.pick([nan, inf, -inf])
            self.pending.append((k + 1, {"u": self.far()}))
        elif event == "reinit":
            self.pending = []
            return {"_reinit": self.reinit_values()}
        elif event == "period":
            out["zeroRate"] = c.pick([1, 2])
        # a value past the largest double is no scenario (a limit of +inf, a target of +inf by overflow)
        return {
            n: x
            for n, x in out.items()
            if not (
                isinstance(x, float)
                and math.isinf(x)
                and event != "nonfinite"
                and n not in ("rateUpPar", "rateDownPar", "rateUp", "rateDown")
            )
        }

    def reinit_values(self):
        return self.settings()

    def tail(self):
        """The changes that end a scenario: the base rates back, no hold or bypass, a last target."""
        out = dict(self.base)
        out.update({"hold": False, "bypass": False, "u": self.far(), "zeroRate": 1})
        if self.model == "RateLimiter":
            out.update({"rateUp": nan, "rateDown": nan})
        return out


def run_random(
    chooser,
    model,
    version,
    arithmetic,
    model_exchange=False,
    cycles=(40, 200),
    accel_zero=False,
    settle_cap=20000,
    block=None,
):
    """Draw and run one scenario in Co-Simulation (with the FMU's cycleTime for a later Model Exchange replay):
    (scenario, segments). The last stretch is held until the output has settled on its target for 3 cycles, or
    settle_cap cycles."""
    gen = Generator(chooser, model, version, arithmetic, model_exchange, cycles, accel_zero)
    sc = gen.scenario
    run = Run(sc, block=block)
    try:
        run.begin(sc.start)
        for k in range(1, gen.length + 1):
            changes = gen.changes(k, run.y, run.v, run.values)
            sc.cycles.append(changes)
            run.cycle(changes)
        tail = gen.tail()
        sc.settle_from = len(sc.cycles)
        sc.cycles.append(tail)
        out = run.cycle(tail)
        seg = run.segments[-1]
        first = len(seg.cycles) - 1
        # the block's own remaining time sets the length when it is longer (property 7 checks that time)
        if math.isfinite(out["remainingTime"]):
            settle_cap = max(settle_cap, min(int(3 * out["remainingTime"] / sc.T) + 100, 300_000))
        for _ in range(settle_cap):
            if len(seg.cycles) - first >= 4 and len({c.out["y"] for c in seg.cycles[-4:]}) == 1:
                break  # still for 3 cycles of the tail
            sc.cycles.append({})
            run.cycle({})
        seg.settle = True
        return sc, run.segments
    finally:
        run.free()
