"""The acceleration limit (docs/rules.md) through the FMU binaries.

- Properties: random scenarios (support/accel_scenarios.py: cycles, rates
  with the Neg rates, zeroRate and ratePeriod 0 or not, accelMax and
  decelMax, targets moved mid-ramp and inside the braking distance, output
  limits tightened under way, hold, bypass, non-finite inputs and
  re-initialisation between, huge and tiny values, LREAL and REAL)
  through RateLimiter and RateLimiterStatic, FMI 2 and 3, every cycle
  checked against the properties by support/accel_properties.py, which
  knows nothing of the block's algorithm. Model Exchange gives the
  Co-Simulation outputs at every cycle end, bit for bit.
- accelMax = 0 is the block without the acceleration limit: random
  scenarios agree with the tests' oracle (support/oracle.py, which has no
  acceleration) after every cycle, decelMax set or not.
- Status 16#8205 for a negative, NaN or infinite accelMax or decelMax,
  with its value reference as subFunctionStatus, the output held.

More scenarios than CI runs: `python -m support.accel_campaign` (from tests/).
A scenario one of them once failed on is kept in accel_regressions/ and
replayed on every run.
"""

import math
from pathlib import Path

import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

from support.accel_properties import LREAL, REAL
from support.accel_scenarios import HypothesisChooser, loads, replay, run_random, violations
from support.fmu_driver import Instance
from support.oracle import oracle_for, output_names

MODELS = ["RateLimiter", "RateLimiterStatic"]
CI_CYCLES = (20, 80)
# no shrinking: a failure prints its whole scenario (replayed by support.accel_campaign --replay), and shrinking
# scenarios that run the FMU takes minutes
NO_SHRINK = [Phase.explicit, Phase.reuse, Phase.generate]
HEALTH = [HealthCheck.too_slow, HealthCheck.data_too_large]


def agree(a, b):
    a, b = float(a), float(b)
    return (math.isnan(a) and math.isnan(b)) or a == b


def report(scenario, found):
    return "\n".join([str(v) for v in found[:10]] + ["scenario: " + scenario.dumps()])


# the random tests' models, FMI versions and arithmetic types: the fast lane draws on two, which between
# them take each model, each version and each arithmetic; the slow lane on the other six
FAST_DRAWS = {("RateLimiter", 3, LREAL), ("RateLimiterStatic", 2, REAL)}
DRAWS = [
    pytest.param(
        model,
        version,
        arithmetic,
        id=f"{model}-{version}-{'LREAL' if arithmetic == LREAL else 'REAL'}",
        marks=[] if (model, version, arithmetic) in FAST_DRAWS else [pytest.mark.slow],
    )
    for model in MODELS
    for version in (2, 3)
    for arithmetic in (LREAL, REAL)
]

# scenarios the random tests once failed on, as they printed them: every run replays them
REGRESSIONS = sorted((Path(__file__).parent / "accel_regressions").glob("*.json"))


@pytest.mark.parametrize("model_exchange", [False, True], ids=["CS", "ME"])
@pytest.mark.parametrize("path", REGRESSIONS, ids=[p.stem for p in REGRESSIONS])
def test_scenarios_once_failed_hold_every_property(path, model_exchange):
    scenario = loads(path.read_text())
    found = violations(scenario, replay(scenario, model_exchange=model_exchange))
    assert not found, report(scenario, found)


@pytest.mark.parametrize("model,version,arithmetic", DRAWS)
@settings(max_examples=40, deadline=None, suppress_health_check=HEALTH, phases=NO_SHRINK)
@given(data=st.data())
def test_every_property_holds_on_random_scenarios(model, version, arithmetic, data):
    scenario, segments = run_random(HypothesisChooser(data), model, version, arithmetic, cycles=CI_CYCLES)
    found = violations(scenario, segments)
    assert not found, report(scenario, found)


@pytest.mark.parametrize("model,version,arithmetic", DRAWS)
@settings(max_examples=20, deadline=None, suppress_health_check=HEALTH, phases=NO_SHRINK)
@given(data=st.data())
def test_model_exchange_gives_the_co_simulation_outputs_and_the_properties(model, version, arithmetic, data):
    """The scenario drawn in Co-Simulation with cycleTime = T, replayed as Model Exchange (a time event at
    each cycle end): the same bits after every cycle, and so the same properties."""
    scenario, segments = run_random(
        HypothesisChooser(data), model, version, arithmetic, model_exchange=True, cycles=CI_CYCLES
    )
    found = violations(scenario, segments)
    assert not found, report(scenario, found)
    me = replay(scenario, model_exchange=True)
    cs_cycles = [c for s in segments for c in s.cycles]
    me_cycles = [c for s in me for c in s.cycles]
    assert len(me_cycles) == len(cs_cycles)
    for n, (a, b) in enumerate(zip(cs_cycles, me_cycles, strict=True), start=1):
        for name in a.out:
            assert agree(a.out[name], b.out[name]), (n, name, a.out[name], b.out[name], scenario.dumps())


def run_against_oracle(scenario):
    """The scenario's cycles through the FMU and the oracle: every oracle output equal after every cycle."""
    model, T = scenario.model, scenario.T
    fmu = Instance(model, scenario.version, logging=False)
    try:
        vr = {name: fmu.vr(name) for name in fmu.variables}
        names = output_names(model)
        start = dict(scenario.start, cycleTime=scenario.cycle_time, arithmetic=scenario.arithmetic)

        def begin(values, t0):
            known = {k: v for k, v in values.items() if k in fmu.variables}
            fmu.start(start_time=t0, **known)
            return oracle_for(model, vr, known, t0)

        oracle = begin(start, 0.0)
        for k, changes in enumerate(scenario.cycles, start=1):
            if "_reinit" in changes:
                fmu.fmu.reset()
                oracle = begin(
                    dict(changes["_reinit"], cycleTime=scenario.cycle_time, arithmetic=scenario.arithmetic), fmu.t
                )
                expected, where = oracle.outputs(), "initialisation"
            else:
                changes = {n: v for n, v in changes.items() if n in fmu.variables}
                t = fmu.t
                fmu.set(**changes)
                fmu.step(T)
                expected, where = oracle.do_step(t, T, changes), f"cycle {k}"
            for name in names:
                assert agree(fmu.get(name), expected[name]), (
                    where,
                    name,
                    fmu.get(name),
                    expected[name],
                    scenario.dumps(),
                )
    finally:
        fmu.free()


@pytest.mark.parametrize("model,version,arithmetic", DRAWS)
@settings(max_examples=30, deadline=None, suppress_health_check=HEALTH, phases=NO_SHRINK)
@given(data=st.data())
def test_accel_max_zero_is_the_block_without_the_acceleration_limit(model, version, arithmetic, data):
    """accelMax = 0 (decelMax 0 or not: it brakes only where accelMax limits): the oracle (rules.md) which
    has no acceleration limit, bit for bit after every cycle, every output it has."""
    scenario, _ = run_random(
        HypothesisChooser(data), model, version, arithmetic, cycles=CI_CYCLES, accel_zero=True, settle_cap=50
    )
    assert scenario.start["accelMax"] == 0.0
    run_against_oracle(scenario)


# -- status 16#8205 --------------------------------------------------------------------------------------------

BAD = [-1.0, -1e300, math.nan, math.inf, -math.inf]


@pytest.mark.parametrize("arithmetic", [LREAL, REAL], ids=["LREAL", "REAL"])
@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("name", ["accelMax", "decelMax"])
def test_a_bad_acceleration_is_status_8205_naming_it_and_holds(model, version, arithmetic, name):
    """accelMax or decelMax negative or not finite is 16#8205 with its value reference;
    as every error status, the output holds (rule 5). Set at the start, and set mid-ramp (both tunable):
    the next cycle reports it and holds; a good value again and the ramp goes on."""
    for bad in BAD:
        fmu = Instance(model, version, logging=False)
        try:
            good = {"accelMax": 2.0, "decelMax": 0.0}
            fmu.start(u=0.0, arithmetic=arithmetic, rateUpPar=10.0, **dict(good, **{name: bad}))
            assert (fmu.get("status"), fmu.get("error"), fmu.get("subFunctionStatus")) == (
                0x8205,
                True,
                fmu.vr(name),
            ), bad
            fmu.set(u=100.0)
            for _ in range(3):
                fmu.step(0.5)
                assert fmu.get("y") == 0.0 and fmu.get("status") == 0x8205, bad
                assert fmu.get("d2ydt2") == 0.0 and fmu.get("dydt") == 0.0
            fmu.set(**good)
            fmu.step(0.5)
            assert fmu.get("status") == 0 and fmu.get("subFunctionStatus") == 0
            moving = fmu.get("y")
            assert 0.0 < moving < 100.0  # ramping again, from rest (at most accelMax T^2 in the first cycle)
            assert moving <= 2.0 * 0.5 * 0.5 * (1 + 1e-6)
            fmu.set(**{name: bad})
            fmu.step(0.5)
            assert (fmu.get("status"), fmu.get("subFunctionStatus"), fmu.get("y")) == (0x8205, fmu.vr(name), moving)
        finally:
            fmu.free()


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("model", MODELS)
def test_8205_comes_after_8204_and_before_8601(model, version):
    """The first-match order of the status table: yMin > yMax (16#8204) wins over a bad accelMax, which wins
    over an invalid cycleTime (16#8601)."""
    fmu = Instance(model, version, logging=False)
    try:
        fmu.start(accelMax=-1.0, yMinPar=2.0, yMaxPar=1.0)
        assert fmu.get("status") == 0x8204
    finally:
        fmu.free()
    fmu = Instance(model, version, logging=False)
    try:
        fmu.start(decelMax=math.nan, cycleTime=-1.0)
        assert (fmu.get("status"), fmu.get("subFunctionStatus")) == (0x8205, fmu.vr("decelMax"))
    finally:
        fmu.free()


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("model", MODELS)
def test_a_negative_acceleration_that_rounds_to_minus_zero_in_real_is_no_error(model, version):
    """rules.md, Arithmetic: in REAL the status words judge the binary32 values; -1e-50 is -0 there, not negative
    (and an acceleration of 0: no limit, the ramp of section 3: 10 per cycle at once)."""
    fmu = Instance(model, version, logging=False)
    try:
        fmu.start(u=0.0, arithmetic=REAL, rateUpPar=10.0, accelMax=-1e-50)
        assert fmu.get("status") == 0
        fmu.set(u=100.0)
        fmu.step(1.0)
        assert fmu.get("y") == 10.0
    finally:
        fmu.free()


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("model", MODELS)
def test_a_duration_jump_stops_the_output(model, version):
    """The duration jump sets the output (y = uc) and the velocity to 0: the next ramp starts from rest, its
    first step at most accelMax T^2 = 100 * 0.1^2 = 1."""
    fmu = Instance(model, version, logging=False)
    try:
        fmu.start(u=0.0, rateUpPar=100.0, rateDownPar=100.0, accelMax=100.0, durationPar=0.3)
        fmu.set(u=10.0)
        for _ in range(3):
            fmu.step(0.1)
        assert fmu.get("y") == 10.0 and fmu.get("runningTime") >= 0.3 * (1 - 1e-9)  # the jump, at 3 cycles
        fmu.set(u=0.0)
        fmu.step(0.1)
        assert 10.0 - 1.0 * (1 + 1e-12) <= fmu.get("y") < 10.0
    finally:
        fmu.free()
