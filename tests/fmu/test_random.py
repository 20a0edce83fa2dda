"""Random scenarios (parameters, input changes, NaN and inf, step sizes,
tunable changes mid-run) through the FMU and the oracle: every output must
agree bit for bit after every step the importer reads it (outputs are
published when read, so reading after some steps only must not change
them). Ramp and RateLimit compute in REAL, RateLimiter in either
arithmetic (rules.md, Arithmetic): the values include some that binary32 cannot
hold (beyond its largest value, below its smallest) and times between
milliseconds. The same runs as Model Exchange (cycleTime > 0: the cycle
ends are time events) agree with the same oracle at every communication
point (fmi.md, Model Exchange)."""

import math
import sys

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from support.fmu_driver import MODELS, Instance
from support.oracle import LREAL, REAL, oracle_for, output_names

nan, inf = math.nan, math.inf
# 3.5e38 is an infinity in binary32, 1e-46 a zero, 16777217 an even neighbour's
SPECIAL = [0.0, -0.0, 1.0, -1.0, 0.5, 2.0, 10.0, nan, inf, -inf, 3.5e38, -3.5e38, 1e-46, 16777217.0]
reals = st.one_of(st.sampled_from(SPECIAL), st.floats(-100, 100, allow_nan=False))
# 1e-50 is a rate of 0 in binary32, -1e-50 a -0 (not negative there)
rates = st.one_of(st.sampled_from([0.0, 0.5, 1.0, 2.0, 10.0, inf, nan, -1.0, 1e-50, -1e-50, 3.5e38]), st.floats(0, 50))
durations = st.sampled_from([0.0, 0.25, 0.5, 1.0, 3.0, inf, nan, -1.0])

PARAMETERS = {
    "rateUpPar": rates,
    "rateDownPar": rates,
    "bypassValuePar": st.one_of(st.just(nan), reals),
    "durationPar": durations,
    "ratePeriod": st.sampled_from([1.0, 0.0, 0.5, 2.0, -1.0, inf]),
    "zeroRate": st.sampled_from([1, 2]),
    "cycleTime": st.sampled_from([0.0, 0.0, 0.1, 0.25, 0.05, 1.0, -1.0]),
    "initMode": st.sampled_from([1, 2, 3]),
    "initValue": reals,
    "initDelay": st.sampled_from([0.0, 0.3, 1.0, 2.0]),
    "u": reals,
    # output limits (rules.md, rule 0; none by default, NaN none too), here and in the changes
    "yMaxPar": st.sampled_from([inf, nan, 5.0, 1.0, 0.0, -2.0, sys.float_info.max]),
    "yMinPar": st.sampled_from([-inf, nan, -5.0, -1.0, 0.0, 2.0, -sys.float_info.max]),
}
parameters = st.fixed_dictionaries(PARAMETERS)
limits = st.one_of(
    st.just(nan),
    st.sampled_from([inf, -inf, 0.0, 3.0, -3.0, sys.float_info.max, -sys.float_info.max]),
    st.floats(-20, 20),
)

changes = st.fixed_dictionaries(
    {},
    optional={
        "u": reals,
        "rateUp": st.one_of(st.just(nan), rates),
        "rateDown": st.one_of(st.just(nan), rates),
        "bypass": st.booleans(),
        "bypassValue": st.one_of(st.just(nan), reals),
        "duration": st.one_of(st.just(nan), durations),
        "rateUpPar": rates,
        "ratePeriod": st.sampled_from([1.0, 0.0, 0.5, -1.0]),
        "zeroRate": st.sampled_from([1, 2]),
        "rateUpNeg": st.one_of(st.just(nan), rates),
        "rateDownNeg": st.one_of(st.just(nan), rates),
        "yMax": limits,
        "yMin": limits,
        "hold": st.booleans(),
        "yMaxPar": st.sampled_from([inf, nan, 4.0]),
    },
)
# the cycles end at startTime + n * cycleTime: off the grid of 0 too
start_times = st.sampled_from([0.0, 0.0, 1.0, -0.3, 12.5])
steps = st.lists(st.tuples(st.sampled_from([0.05, 0.1, 0.25, 0.3, 0.5, 1.0]), changes), min_size=1, max_size=40)

cycle_times = st.sampled_from([0.0, 0.0, 0.1, 0.25, 0.05, -1.0])
# TIME pins hold whole milliseconds: 2.5 ms is 2, 0.4 ms is T#0s
times = st.sampled_from([0.0, 0.3, 1.0, 2.0, 10.0, 0.0025, 0.0004, 0.3005, 1.0015])
# RateLimiterStatic: RateLimiter's parameters in either arithmetic, and its inputs u, bypass, hold
static_parameters = {
    "rateUpNeg": st.one_of(st.just(nan), rates),
    "rateDownNeg": st.one_of(st.just(nan), rates),
    "bypass": st.booleans(),
    "hold": st.booleans(),
    "arithmetic": st.sampled_from([LREAL, REAL]),
}
VENDOR_STRATEGIES = {
    "RateLimiterStatic": (
        st.fixed_dictionaries({**PARAMETERS, **static_parameters}),
        st.fixed_dictionaries(
            {},
            optional={
                "u": reals,
                "bypass": st.booleans(),
                "hold": st.booleans(),
                "rateUpPar": rates,
                "rateDownPar": rates,
                "bypassValuePar": st.one_of(st.just(nan), reals),
                "durationPar": durations,
                "ratePeriod": st.sampled_from([1.0, 0.0, 0.5, -1.0]),
                "zeroRate": st.sampled_from([1, 2]),
                "rateUpNeg": st.one_of(st.just(nan), rates),
                "rateDownNeg": st.one_of(st.just(nan), rates),
                "yMaxPar": limits,
                "yMinPar": limits,
            },
        ),
    ),
    "LGF_LimRateOfChangeAdvancedCI": (
        st.fixed_dictionaries(
            {
                "autoValue": reals,
                "manualValue": reals,
                "setPosUpRateLim": rates,
                "setPosDownRateLim": rates,
                "setNegUpRateLim": rates,
                "setNegDownRateLim": rates,
                "setHighLim": limits,
                "setLowLim": limits,
                "defaultOutValue": reals,
                "enDefaultOutValue": st.booleans(),
                "track": st.booleans(),
                "manOp": st.booleans(),
                "reset": st.booleans(),
                "callOB": st.sampled_from([30, 35, 38, 123, 200, 1, 29, 39, 122, -5]),
                "cycleTime": cycle_times,
            }
        ),
        st.fixed_dictionaries(
            {},
            optional={
                "autoValue": reals,
                "manualValue": reals,
                "setPosUpRateLim": rates,
                "setPosDownRateLim": rates,
                "setNegUpRateLim": rates,
                "setNegDownRateLim": rates,
                "setHighLim": limits,
                "setLowLim": limits,
                "defaultOutValue": reals,
                "enDefaultOutValue": st.booleans(),
                "track": st.booleans(),
                "manOp": st.booleans(),
                "reset": st.booleans(),
            },
        ),
    ),
    "LGF_LimRateOfChangeCI": (
        st.fixed_dictionaries(
            {
                "value": reals,
                "setChangeRate": rates,
                "defaultOutValue": reals,
                "enDefaultOutValue": st.booleans(),
                "callOB": st.sampled_from([30, 35, 38, 123, 200, 1, 29, 39, 122, -5]),
                "cycleTime": cycle_times,
            }
        ),
        st.fixed_dictionaries(
            {},
            optional={
                "value": reals,
                "setChangeRate": rates,
                "defaultOutValue": reals,
                "enDefaultOutValue": st.booleans(),
            },
        ),
    ),
    "RateLimit": (
        st.fixed_dictionaries(
            {
                "In": reals,
                "UpRatePar": rates,
                "DownRatePar": rates,
                "DurationPar": st.sampled_from([0.0, 0.5, 1.0, 3.0, 259200.0]),
                "BypassValuePar": st.one_of(st.just(nan), reals),
                "OutSave": st.booleans(),
                "SavedOut": st.one_of(st.just(nan), reals),
                "cycleTime": cycle_times,
            }
        ),
        st.fixed_dictionaries(
            {},
            optional={
                "In": reals,
                "UpRate": st.one_of(st.just(nan), rates),
                "DownRate": st.one_of(st.just(nan), rates),
                "EnableBypass": st.booleans(),
                "BypassValue": st.one_of(st.just(nan), reals),
                "Duration": st.sampled_from([nan, 0.0, 0.5, 2.0, 300000.0, -1.0, inf]),
                "UpRatePar": rates,
            },
        ),
    ),
    "Ramp": (
        st.fixed_dictionaries(
            {
                "rIn": reals,
                "rVariation": st.sampled_from([0.0, 0.5, 1.0, 100.0]) | st.floats(0, 100),
                "tTime": times,
                "rInitValue": reals,
                "eInitial": st.sampled_from([1, 2, 3]),
                "tInitDelay": times,
                "cycleTime": cycle_times,
            }
        ),
        st.fixed_dictionaries({}, optional={"rIn": reals, "rVariation": st.floats(0, 100), "tTime": times}),
    ),
}


def agree(fmu_value, oracle_value):
    a, b = float(fmu_value), float(oracle_value)
    return (math.isnan(a) and math.isnan(b)) or a == b


class ModelExchangeSteps:
    """An importer's Model Exchange loop with fmpy's calls: at each
    communication point t the FMU is in Event Mode (the inputs of t are set
    there); a step to t + h runs every time event before it (Continuous-Time
    Mode, the time, Event Mode, the update) and then the event at t + h."""

    def __init__(self, fmu):
        self.fmu, self.f = fmu, fmu.fmu
        self.update = self.f.newDiscreteStates if fmu.version == 2 else self.f.updateDiscreteStates
        self.next = None

    def event_update(self):
        result = self.update()
        assert result[:4] == (False, False, False, False), result
        self.next = result[5] if result[4] else None

    def step(self, h):
        end = self.fmu.t + h
        while True:
            at_end = self.next is None or not self.next < end
            self.f.enterContinuousTimeMode()
            self.f.setTime(end if at_end else self.next)
            self.f.enterEventMode()
            self.event_update()
            if at_end:
                break
        self.fmu.t = end


def run_against_oracle(model, version, start, run, skipped=(), start_time=0.0, model_exchange=False):
    """skipped: the steps after which the outputs are not read (the last one always is)."""
    fmu = Instance(model, version, model_exchange=model_exchange)
    steps = ModelExchangeSteps(fmu) if model_exchange else None
    try:
        vr = {name: fmu.vr(name) for name in fmu.variables}
        fmu.start(start_time=start_time, **start)
        if steps:
            steps.event_update()
        oracle = oracle_for(model, vr, start, start_time)
        names = output_names(model)
        expected = oracle.outputs()
        for name in names:
            assert agree(fmu.get(name), expected[name]), ("init", name, fmu.get(name), expected[name])
        for k, (h, inputs) in enumerate(run):
            t = fmu.t
            fmu.set(**inputs)
            steps.step(h) if steps else fmu.step(h)
            expected = oracle.do_step(t, h, inputs)
            if k in skipped and k < len(run) - 1:
                continue
            assert fmu.get("time") == fmu.t, (k, t, h)
            for name in names:
                assert agree(fmu.get(name), expected[name]), (k, t, h, name, fmu.get(name), expected[name])
    finally:
        fmu.free()


@pytest.mark.parametrize("version", [2, 3])
def test_outputs_in_initialization_mode_follow_what_is_set(version):
    """In Initialization Mode the outputs are the initial ones of the
    parameters and inputs set so far, read after each set."""
    fmu = Instance("RateLimiter", version)
    try:
        vr = {name: fmu.vr(name) for name in fmu.variables}
        start = {"initMode": 1, "initValue": 4.0}  # set before Initialization Mode
        fmu.set(**start)
        fmu.enter_initialization()
        for values in (
            {},
            {"u": 3.0},
            {"initValue": 7.0},
            {"yMaxPar": 5.0},
            {"rateUpPar": -1.0},
            {"initMode": 2, "u": -2.0},
        ):
            fmu.set(**values)
            start.update(values)
            expected = oracle_for("RateLimiter", vr, start).outputs()
            for name in output_names("RateLimiter"):
                assert agree(fmu.get(name), expected[name]), (start, name, fmu.get(name), expected[name])
    finally:
        fmu.free()


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize(
    "model,start,run,start_time",
    [
        # cycles of 1 s in steps of 0.5 s: a cycle ends every other step
        ("RateLimiter", {"cycleTime": 1.0, "u": 0.0}, [(0.5, {"u": 10.0})] * 6, 0.0),
        # the initial delay counts from the start time (one cycle per step)
        (
            "RateLimiter",
            {"initMode": 3, "initDelay": 1.0, "u": 0.0},
            [(0.5, {"u": 5.0}), (0.5, {"u": 2.0}), (0.5, {"u": 8.0}), (0.5, {"u": -1.0})],
            10.0,
        ),
        # track follows autoValue when autoValue (the cycle input) is all that changes
        (
            "LGF_LimRateOfChangeAdvancedCI",
            {"track": True},
            [(0.05, {}), (0.05, {"autoValue": 1.0}), (0.1, {"autoValue": -3.0}), (0.1, {"track": False})],
            0.0,
        ),
    ],
)
def test_directed_runs_agree_with_oracle(version, model, start, run, start_time):
    run_against_oracle(model, version, start, run, start_time=start_time)


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("skipped", [(), (0,)])
def test_steps_that_end_no_cycle_change_no_output(version, skipped):
    """fmi.md, Time: a step that ends no cycle changes nothing, also when a
    rate or a limit changed before it (remainingTime and the limit flags
    stay those of the last cycle's configuration), whether or not the
    outputs were read after that cycle."""
    run = [
        (0.5, {}),
        (0.1, {"rateUp": 2.0, "yMax": 0.2}),
        (0.1, {"rateUp": 4.0, "yMax": 0.1}),
        (0.1, {}),
        (0.2, {"rateUp": 0.5, "yMax": 0.7}),
    ]
    run_against_oracle(
        "RateLimiter",
        version,
        {"cycleTime": 0.5, "u": 0.0, "rateUpPar": 1.0},
        [(h, dict(inputs, u=10.0)) for h, inputs in run],
        skipped,
    )


# the fast lane draws on FMI 3 in LREAL and FMI 2 in REAL, the slow lane on the other two
@pytest.mark.parametrize(
    "version,arithmetic",
    [
        (3, LREAL),
        (2, REAL),
        pytest.param(2, LREAL, marks=pytest.mark.slow),
        pytest.param(3, REAL, marks=pytest.mark.slow),
    ],
)
@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(start=parameters, run=steps, skipped=st.sets(st.integers(0, 39)), start_time=start_times)
def test_rate_limiter_agrees_with_oracle(version, arithmetic, start, run, skipped, start_time):
    run_against_oracle("RateLimiter", version, dict(start, arithmetic=arithmetic), run, skipped, start_time)


# Model Exchange: a cycle only with cycleTime > 0 (0 and the invalid ones are no valid cycle there)
ME_CYCLE_TIMES = st.sampled_from([0.1, 0.25, 0.05, 1.0, 0.3])


@pytest.mark.parametrize("version", [2, 3])
@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    start=parameters,
    run=steps,
    skipped=st.sets(st.integers(0, 39)),
    start_time=start_times,
    cycle_time=ME_CYCLE_TIMES,
    arithmetic=st.sampled_from([LREAL, REAL]),
)
def test_rate_limiter_agrees_with_oracle_in_model_exchange(
    version, start, run, skipped, start_time, cycle_time, arithmetic
):
    run_against_oracle(
        "RateLimiter",
        version,
        dict(start, cycleTime=cycle_time, arithmetic=arithmetic),
        run,
        skipped,
        start_time,
        model_exchange=True,
    )


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("model", [m for m in MODELS if m != "RateLimiter"])
@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_vendor_model_agrees_with_oracle_in_model_exchange(model, version, data):
    run_vendor_model(model, version, data, model_exchange=True)


@pytest.mark.parametrize("version", [pytest.param(2, marks=pytest.mark.slow), 3])  # FMI 2: the slow lane
@pytest.mark.parametrize("model", [m for m in MODELS if m != "RateLimiter"])
@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_vendor_model_agrees_with_oracle(model, version, data):
    run_vendor_model(model, version, data)


def run_vendor_model(model, version, data, model_exchange=False):
    """A vendor model's random run (Model Exchange: with a cycleTime > 0)."""
    start_strategy, change_strategy = VENDOR_STRATEGIES[model]
    start = data.draw(start_strategy, label="start")
    if model_exchange:
        start["cycleTime"] = data.draw(ME_CYCLE_TIMES, label="cycleTime")
    run = data.draw(
        st.lists(
            st.tuples(st.sampled_from([0.05, 0.1, 0.25, 0.3, 0.5, 1.0]), change_strategy), min_size=1, max_size=40
        ),
        label="run",
    )
    run_against_oracle(
        model,
        version,
        start,
        run,
        data.draw(st.sets(st.integers(0, 39)), label="skipped"),
        data.draw(start_times, label="start_time"),
        model_exchange=model_exchange,
    )
