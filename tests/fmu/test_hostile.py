"""Hostile values in every input and parameter: NaN, +-inf, -0.0,
subnormals, 1e308, huge and tiny rates, cycleTime of 1e-9 and 1e9. Never a
crash or an endless step; where the status table (rules.md, Status words) applies the FMU
agrees with the oracle bit for bit; a value outside a declared range is
refused with an error and the last good value kept."""

import math
import sys

import pytest

from support.fmu_driver import MODELS, Instance, call_status
from support.oracle import kept, oracle_for, output_names
from test_random import agree

HOSTILE = [math.nan, math.inf, -math.inf, -0.0, 5e-324, 2.2250738585072014e-308, 1e-300, 1e308, -1e308, 1e300]


def settable(model, version):
    fmu = Instance(model, version)
    try:
        return [v for v in fmu.md.modelVariables if v.causality in ("input", "parameter")]
    finally:
        fmu.free()


def in_declared_range(variable, value):
    low = float(variable.min) if variable.min is not None else -math.inf
    high = float(variable.max) if variable.max is not None else math.inf
    if variable.type == "Enumeration" and variable.min is None:  # the items' range
        items = [int(item.value) for item in variable.declaredType.items]
        low, high = min(items), max(items)
    if variable.type == "Boolean":
        return True
    return (low == -math.inf and high == math.inf) or low <= value <= high


def coerce(variable, value):
    """What an importer can send for this type: integers and booleans from
    a hostile float (NaN and inf have no integer; they are skipped)."""
    if variable.type in ("Integer", "Int32", "Enumeration"):
        return None if not math.isfinite(value) else max(min(int(value), 2**31 - 1), -(2**31))
    if variable.type == "Boolean":
        return bool(value == value and value != 0)
    return value


CASES = [(model, version, value_index) for model in MODELS for version in (2, 3) for value_index in range(len(HOSTILE))]


@pytest.mark.parametrize("model,version,value_index", CASES)
def test_hostile_value_in_every_variable(model, version, value_index):
    """Each input and parameter in turn gets the hostile value (integers:
    the nearest int32, booleans: true unless 0 or NaN), at the start
    and again mid-run; the FMU runs 6 steps and agrees with the oracle, or
    refuses a value outside a declared range and keeps the last good one."""
    hostile = HOSTILE[value_index]
    for variable in settable(model, version):
        value = coerce(variable, hostile)
        if value is None:
            continue
        fmu = Instance(model, version)
        try:
            vr = {name: fmu.vr(name) for name in fmu.variables}
            names = output_names(model)
            if not in_declared_range(variable, value):
                assert call_status(fmu.set, **{variable.name: value}) == 3
                assert fmu.errors() and variable.name in fmu.errors()[-1][2], fmu.messages
                if version == 2:  # FMI 2 reads values in its Error state: the start value is kept
                    assert agree(fmu.get(variable.name), float(variable.start))
                fmu.fmu.reset()
                fmu.start()
                fmu.step(0.1)
                continue
            start = {variable.name: value}
            fmu.start(**start)
            oracle = oracle_for(model, vr, start)
            steps = [(0.1, {}), (0.25, {}), (1.0, {}), (0.1, {}), (0.5, {}), (2.0, {})]
            if variable.variability != "fixed":  # again mid-run, after a good value
                good = coerce(variable, 1.0)
                steps[1] = (0.25, {variable.name: good})
                steps[3] = (0.1, {variable.name: value})
            for k, (h, inputs) in enumerate(steps):
                t = fmu.t
                fmu.set(**inputs)
                if variable.name == "cycleTime" and 0 < value and (t + h) / value > 1e8:
                    # more than FMU_MAX_CYCLES_PER_STEP cycles: refused, not run for ages
                    assert fmu.raw_step(h) == 3
                    assert "at most" in fmu.errors()[-1][2], fmu.messages
                    break
                fmu.step(h)
                expected = oracle.do_step(t, h, inputs)
                for name in names:
                    assert agree(fmu.get(name), expected[name]), (
                        variable.name,
                        value,
                        k,
                        name,
                        fmu.get(name),
                        expected[name],
                    )
        finally:
            fmu.free()


@kept
def tiny_cycle_oracle(vr_items, start_items):
    """The oracle's 1,000,000 cycles (about 20 s of Python), worked once for both FMI versions."""
    oracle = oracle_for("RateLimiter", dict(vr_items), dict(start_items))
    return oracle.do_step(0.0, 1e-3, {"u": 1.0})


@pytest.mark.slow
@pytest.mark.parametrize("version", [2, 3])
def test_tiny_cycle_time_runs_or_is_refused(version):
    """cycleTime 1e-9: a 1 ms step runs its 1,000,000 cycles, bit for bit as
    the oracle; a 1 s step would run 1e9 > 1e8 cycles and is refused with an
    error, not a hang, and the outputs keep their last good values."""
    fmu = Instance("RateLimiter", version)
    try:
        vr = {name: fmu.vr(name) for name in fmu.variables}
        start = {"cycleTime": 1e-9, "u": 0.0}
        fmu.start(**start)
        fmu.set(u=1.0)
        fmu.step(1e-3)
        expected = tiny_cycle_oracle(tuple(sorted(vr.items())), tuple(sorted(start.items())))
        assert fmu.get("y") == expected["y"] and 0.99e-3 < fmu.get("y") < 1.01e-3
        assert fmu.get("runningTime") == expected["runningTime"]
        y = fmu.get("y")
        assert fmu.raw_step(1.0) == 3
        assert fmu.errors()[-1][2] == (
            f"fmi{version}DoStep: a step of 1 s would run 1e+09 cycles of 1e-09 s; at most 1e+08 per step"
        ), fmu.messages
        if version == 2:  # FMI 2 reads values in its Error state
            assert fmu.get("y") == y
    finally:
        fmu.free()


@pytest.mark.parametrize("version", [2, 3])
def test_a_step_of_exactly_the_most_cycles_runs(version):
    """At most 1e8 cycles per step (docs/fmi.md): a step of exactly 1e8
    cycles of 2^-20 s (both exact in binary) runs them; y ramps at 1 per s,
    2^-20 per cycle, and reaches u = 1 exactly after 2^20 cycles."""
    fmu = Instance("RateLimiter", version)
    try:
        fmu.start(cycleTime=2.0**-20)
        fmu.set(u=1.0)
        assert fmu.raw_step(1e8 * 2.0**-20) == 0, fmu.messages
        assert fmu.get("y") == 1.0 and fmu.get("time") == 1e8 * 2.0**-20
        assert not fmu.errors()
    finally:
        fmu.free()


@pytest.mark.parametrize("version", [2, 3])
def test_the_largest_finite_step_is_taken(version):
    """communicationStepSize must be finite and > 0, and the largest double
    is: one cycle of that length, at 1 per s, takes y to u."""
    fmu = Instance("RateLimiter", version)
    try:
        fmu.start()
        fmu.set(u=5.0)
        assert fmu.raw_step(sys.float_info.max) == 0, fmu.messages
        assert fmu.get("y") == 5.0 and fmu.get("time") == sys.float_info.max
    finally:
        fmu.free()


@pytest.mark.parametrize("version", [2, 3])
def test_a_step_ending_past_the_largest_time_is_refused_and_named(version):
    """From half the largest double, a step of the largest double would end
    past it: refused, the message naming the step size and where it starts."""
    fmu = Instance("RateLimiter", version)
    try:
        fmu.start()
        half = sys.float_info.max / 2
        assert fmu.raw_step(half) == 0, fmu.messages
        assert fmu.raw_step(sys.float_info.max) == 3
        expected = f"a step of {sys.float_info.max:g} s from {half:g} would end past the largest time"
        assert any(expected in m[2] for m in fmu.errors()), fmu.messages
    finally:
        fmu.free()


@pytest.mark.parametrize("version", [2, 3])
def test_huge_cycle_time_holds(version):
    """cycleTime 1e9: no cycle ends within 10 s, so the output holds at its
    initial value (fmi.md, Time: a step that ends no cycle changes nothing)."""
    fmu = Instance("RateLimiter", version)
    try:
        fmu.start(cycleTime=1e9, u=3.0)
        fmu.set(u=-7.0)
        for _ in range(10):
            fmu.step(1.0)
        assert fmu.get("y") == 3.0
        assert fmu.get("runningTime") == 0.0
    finally:
        fmu.free()
