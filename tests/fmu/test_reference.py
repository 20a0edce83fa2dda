"""Every reference scenario through fmpy.simulate_fmu on both FMI versions,
and the oracle against the same hand-worked references (so that the oracle
the random tests rely on is itself checked), bit for bit: a reference holds
the doubles the PLC's LREAL arithmetic gives (three steps of 0.1 make
0.30000000000000004)."""

import math

import pytest

from support.fmu_driver import MODELS, fmu_file, unzipped
from fmpy import read_model_description
from support.oracle import oracle_for
from support.scenarios import compare, discover, same, simulate

SCENARIOS = discover()


# hand-worked scenarios per model, at least: 6, and more where there are by now
LEAST_SCENARIOS = {"RateLimiter": 28, "LGF_LimRateOfChangeCI": 8, "RateLimit": 8, "Ramp": 8}


@pytest.mark.parametrize("model", MODELS)
def test_enough_hand_worked_scenarios(model):
    least = LEAST_SCENARIOS.get(model, 6)
    scenarios = [s for s in SCENARIOS if s.model == model]
    assert len(scenarios) >= least
    for s in scenarios:
        assert s.description, f"{s.name} has no README.md"


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("scenario", SCENARIOS, ids=lambda s: s.name)
def test_fmu_matches_reference(scenario, version):
    result = simulate(scenario, fmu_file(scenario.model, version))
    problems = compare(scenario, result)
    assert not problems, "\n".join(problems)


def communication_points(scenario):
    """fmpy's CS loop: the output grid plus every input change between."""
    o = scenario.options
    t0, stop, h = o["StartTime"], o["StopTime"], o["StepSize"]
    points = [t0 + n * h for n in range(1, int(round((stop - t0) / h)) + 1)]
    if scenario.inputs is not None:
        points += [float(t) for t in scenario.inputs["time"] if t0 < t < stop]
    merged = []
    for p in sorted(points):
        if not merged or not math.isclose(p, merged[-1]):
            merged.append(p)
    return merged


def inputs_at(scenario, t, booleans):
    if scenario.inputs is None:
        return {}
    rows = [r for r in scenario.inputs if r["time"] < t or math.isclose(r["time"], t)]
    row = rows[-1] if rows else scenario.inputs[0]
    return {
        name: (bool(row[name]) if name in booleans else float(row[name])) for name in scenario.inputs.dtype.names[1:]
    }


@pytest.mark.slow
@pytest.mark.parametrize("scenario", SCENARIOS, ids=lambda s: s.name)
def test_oracle_matches_reference(scenario):
    md = read_model_description(unzipped(scenario.model, 2))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    booleans = {v.name for v in md.modelVariables if v.type == "Boolean"}
    t0 = scenario.options["StartTime"]
    start = dict(scenario.start_values)
    start.update(inputs_at(scenario, t0, booleans))
    oracle = oracle_for(scenario.model, vr, start, t0)
    trace = {t0: oracle.outputs()}
    t = t0
    for point in communication_points(scenario):
        trace[point] = oracle.do_step(t, point - t, inputs_at(scenario, t, booleans))
        t = point
    for row in scenario.reference:
        at = min(trace, key=lambda p: abs(p - row["time"]))
        for name in scenario.outputs:
            assert same(float(trace[at][name]), row[name]), (row["time"], name, trace[at][name], row[name])
