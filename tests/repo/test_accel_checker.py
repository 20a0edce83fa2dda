"""The property checker of the acceleration limit (support/accel_properties.py)
on hand-made traces: each breaks one property and must be flagged for it,
and clean ones (worked by hand from the properties) must pass. No FMU."""

import math
import random

import pytest

from support.accel_model import ModelBlock
from support.accel_properties import LREAL, REAL, Cycle, Segment, check, f32
from support.accel_scenarios import RandomChooser, run_random, violations

BASE = {"rateUpPar": 100.0, "rateDownPar": 100.0, "ratePeriod": 1.0, "accelMax": 1.0, "decelMax": 0.0}


def trace(ys, values, T=1.0, y0=0.0, per_cycle=None, outputs=None, settle=False, arithmetic=LREAL):
    """A segment whose outputs are ys (one a cycle), the derived outputs as the interface defines them: dydt,
    d2ydt2 and remainingTime (the time to the first later cycle on u, at constant inputs)."""
    real = f32 if arithmetic == REAL else float
    per_cycle = per_cycle or [{}] * len(ys)
    all_values = [dict(values, **extra) for extra in per_cycle]
    dydt_before, cycles = 0.0, []
    for k, y in enumerate(ys):
        yp = ys[k - 1] if k else y0
        dydt = real(real(y - yp) / real(T))
        ramps = not (all_values[k].get("hold") or all_values[k].get("bypass"))
        d2 = real(real(dydt - dydt_before) / real(T)) if ramps else 0.0  # rule 6: after any cycle
        here = all_values[k]
        uc = min(max(here["u"], here.get("yMinPar", -math.inf)), here.get("yMaxPar", math.inf))
        later = next((j for j in range(k + 1, len(ys)) if ys[j] == uc and all_values[j] == all_values[k]), None)
        remaining = 0.0 if y == uc else (later - k) * T if later is not None else math.inf
        out = {"y": y, "dydt": dydt, "d2ydt2": d2, "remainingTime": remaining, "runningTime": 0.0, "status": 0}
        out.update((outputs or {}).get(k + 1, {}))
        cycles.append(Cycle(all_values[k], (k + 1) * T, out))
        dydt_before = dydt
    init = {"y": y0, "dydt": 0.0, "d2ydt2": 0.0, "remainingTime": 0.0, "runningTime": 0.0, "status": 0}
    return Segment(dict(values), 0.0, init, cycles, settle)


def props(seg, arithmetic=LREAL, T=1.0):
    return sorted({v.prop for v in check([seg], arithmetic, T)})


# -- clean traces, worked by hand ---------------------------------------------

# a short step (triangular): A = 1, V = 100, T = 1, 0 -> 4: steps 1, 2, 1, then rest
TRIANGLE = [1.0, 3.0, 4.0, 4.0, 4.0]
# a long one (trapezoid): V = 2: 0 -> 8: steps 1, 2, 2, 2, 1
TRAPEZOID = [1.0, 3.0, 5.0, 7.0, 8.0, 8.0, 8.0]


@pytest.mark.parametrize(
    "ys,values",
    [
        (TRIANGLE, dict(BASE, u=4.0)),
        (TRAPEZOID, dict(BASE, u=8.0, rateUpPar=2.0, rateDownPar=2.0)),
        # braking at decelMax = 2 (steps 2 -> 0 in one cycle is allowed: b = 2)
        ([1.0, 3.0, 4.0, 4.0], dict(BASE, u=4.0, decelMax=2.0)),
    ],
)
def test_clean_steps_pass(ys, values):
    assert check([trace(ys, values, settle=True)], LREAL, 1.0) == []


def test_a_reversal_within_the_bounds_passes():
    """Moving up at 2 per cycle, the target moves behind (to 0): brake 2 -> 1 -> 0, then down 1, 2, ... a
    reversal within one cycle from 1 to -... is not needed; the output ends on 0 at rest."""
    up = [1.0, 3.0]  # u = 10
    down = [4.0, 4.0, 3.0, 1.0, 0.0, 0.0]  # steps 1, 0, -1, -2, -1, 0
    values = dict(BASE, u=10.0)
    seg = trace(up + down, values, per_cycle=[{}] * 2 + [{"u": 0.0}] * 6, settle=True)
    assert check([seg], LREAL, 1.0) == []


def test_a_reversal_within_a_cycle_is_judged_by_both_bounds():
    """p = 1 up, then s = -1 down within one cycle: |p|/b + |s|/a = 2 > 1 with a = b = 1 (flagged), 1/2 + 1/2
    with a = b = 2 (passes)."""
    per_cycle = [{}] + [{"u": -5.0}] * 6
    ys = [1.0, 0.0, -2.0, -4.0, -5.0, -5.0, -5.0]
    assert "2" in props(trace(ys, dict(BASE, u=10.0), per_cycle=per_cycle))
    assert check([trace(ys, dict(BASE, u=10.0, accelMax=2.0), per_cycle=per_cycle, settle=True)], LREAL, 1.0) == []


def test_hold_bypass_and_a_new_ramp_from_rest_pass():
    values = dict(BASE, u=4.0)
    per_cycle = [{}, {"hold": True}, {"hold": True}, {}, {"bypass": True, "bypassValuePar": 10.0}, {}, {}, {}, {}, {}]
    # 1 (a), hold, hold, from rest 1 step of 1 (2), bypass jumps to 10, from rest: 9, 7, 5, 4, 4
    ys = [1.0, 1.0, 1.0, 2.0, 10.0, 9.0, 7.0, 5.0, 4.0, 4.0]
    assert check([trace(ys, values, per_cycle=per_cycle, settle=True)], LREAL, 1.0) == []


def test_an_output_limit_approached_by_braking_passes():
    values = dict(BASE, u=10.0, yMaxPar=4.0)
    assert check([trace(TRIANGLE, values, settle=True)], LREAL, 1.0) == []


@pytest.mark.parametrize("scale", [2.0**900, 2.0**-1000, 3.0, 1e-7])
def test_huge_and_tiny_scales_pass(scale):
    """The trapezoid scaled: exactly by powers of 2 (down into the subnormals), rounded by 3 and 1e-7."""
    values = dict(BASE, u=8.0 * scale, rateUpPar=2.0 * scale, rateDownPar=2.0 * scale, accelMax=scale)
    ys = [y * scale for y in TRAPEZOID]
    assert check([trace(ys, values, settle=True)], LREAL, 1.0) == []


def test_real_arithmetic_with_rounded_values_passes():
    """REAL: 0.1 per second squared and 0.1 s cycles are binary32 values; steps of a = A T^2 rounded."""
    T = 0.1
    A = f32(0.1)
    a = f32(f32(A * f32(T)) * f32(T))
    ys, y, v = [], 0.0, 0.0
    for _ in range(3):
        v = f32(v + a)
        y = f32(y + v)
        ys.append(y)
    target = ys[-1]
    for _ in range(2):  # brake: v - a, then land
        v = f32(v - a)
        y = f32(y + v)
        ys.append(y)
    target = ys[-1]
    ys += [target, target]
    values = dict(BASE, u=target, accelMax=0.1)
    seg = trace(ys, values, T=T, settle=True, arithmetic=REAL)
    assert check([seg], REAL, T) == []


# -- each property broken ------------------------------------------------------


def test_1_velocity_beyond_the_limit():
    values = dict(BASE, u=20.0, rateUpPar=2.0, rateDownPar=2.0, accelMax=10.0)
    assert props(trace([2.0, 4.0, 7.0], values)) == ["1"]


def test_1_velocity_beyond_the_neg_rate_below_zero():
    values = dict(BASE, u=20.0, rateUpNeg=1.0, accelMax=10.0)
    assert props(trace([-8.0, -6.0], values, y0=-10.0)) == ["1"]  # below 0: rateUpNeg = 1, steps of 2


def test_1_a_rate_lowered_below_the_speed_may_be_braked_down_to():
    """Speed 4 per cycle, rateUp lowered to 1: braking at decelMax (1) 3, 2, 1 is allowed; speeding up is not."""
    values = dict(BASE, u=100.0, rateUpPar=4.0, rateDownPar=4.0)
    per_cycle = [{}] * 4 + [{"rateUpPar": 1.0}] * 4
    ys = [1.0, 3.0, 6.0, 10.0, 13.0, 15.0, 16.0, 17.0]
    assert check([trace(ys, values, per_cycle=per_cycle)], LREAL, 1.0) == []
    ys = [1.0, 3.0, 6.0, 10.0, 13.0, 15.0, 17.0, 19.0]  # 2 per cycle held above the new limit of 1
    assert props(trace(ys, values, per_cycle=per_cycle)) == ["1"]


# from -30 at rest towards 100, accelMax 1: steps 1 .. 6, the rates below 0 unlimited, rateUp 0.5 above
ZONES = dict(BASE, u=100.0, rateUpPar=0.5, rateUpNeg=100.0, rateDownNeg=100.0)
ACCELERATING = [-29.0, -27.0, -24.0, -20.0, -15.0, -9.0]


def test_1_braking_into_the_other_zone_after_the_target_moved_inside_the_braking_distance():
    """u moved behind the output at cycle 7, with 0 inside its braking distance: the output brakes at
    decelMax (steps 5, 4, 3, 2, 1, 0) across 0 into rateUp's 0.5 a cycle: the documented exception."""
    ys = ACCELERATING + [-4.0, 0.0, 3.0, 5.0, 6.0, 6.0]
    per_cycle = [{}] * 6 + [{"u": -100.0}] * 6
    assert "1" not in props(trace(ys, ZONES, y0=-30.0, per_cycle=per_cycle))


def test_1_a_target_moved_far_from_0_leaves_no_excuse_for_crossing_it_too_fast():
    """The target moved at cycle 2, 29 before 0 at a speed of 1: room enough to slow to 0.5 before 0."""
    ys = ACCELERATING + [-4.0, 0.0, 3.0, 5.0, 6.0, 6.0]
    per_cycle = [{}] + [{"u": -100.0}] * 11
    assert "1" in props(trace(ys, ZONES, y0=-30.0, per_cycle=per_cycle))


def test_1_crossing_into_the_other_zone_too_fast_for_a_constant_target():
    """The same course towards a target that never moved: the output had to slow to 0.5 a cycle before 0."""
    ys = ACCELERATING + [-4.0, 0.0, 3.0, 5.0, 6.0, 6.0]
    assert "1" in props(trace(ys, dict(ZONES, u=6.0), y0=-30.0))


def test_2_acceleration_beyond_accel_max():
    assert props(trace([1.0, 4.0], dict(BASE, u=20.0))) == ["2"]


def test_2_braking_beyond_decel_max():
    ys = [1.0, 3.0, 6.0, 7.0]  # steps 1, 2, 3, 1: shrinks by 2 > b = 1
    assert props(trace(ys, dict(BASE, u=7.0))) == ["2"]


def test_2_the_first_step_from_rest_is_bounded_too():
    assert props(trace([1.5, 3.0], dict(BASE, u=20.0))) == ["2"]


def test_3_no_arrival_in_a_settled_tail():
    ys = [1.0, 3.0, 4.0, 4.0, 4.0]
    assert props(
        trace(ys, dict(BASE, u=4.5), outputs={k: {"remainingTime": math.inf} for k in range(1, 6)}, settle=True)
    ) == ["3"]


def test_3_a_tail_too_short_for_the_velocity_limit_is_not_judged():
    """A hold that ends more than two cycles at the fastest velocity limit
    (V = 100 here) before the target cannot have settled: not flagged; one
    that ends within them, short of the target, is."""
    ys = [1.0, 3.0, 6.0, 10.0, 15.0]  # accelerating at A = 1, far from 1000
    assert props(trace(ys, dict(BASE, u=1000.0), settle=True)) == []
    ys = [1.0, 3.0, 4.0, 4.0, 4.0]  # stopped 150 short: within two cycles at V = 100
    assert props(trace(ys, dict(BASE, u=154.0), settle=True)) == ["3"]


def test_3_leaving_the_target_reached_at_rest():
    ys = [1.0, 3.0, 4.0, 4.0, 4.0, 4.0 + 2.0**-30, 4.0]
    found = props(trace(ys, dict(BASE, u=4.0)))
    assert "3" in found


def test_3_a_velocity_output_at_rest():
    seg = trace(TRIANGLE, dict(BASE, u=4.0), outputs={5: {"d2ydt2": 0.5}})
    assert "3" in props(seg)


def test_4_passing_a_target_the_output_could_stop_before():
    """From 1 at speed 1 per cycle (b = 1) the target 3 is 2 away: stopping needs 0 more; 4 is past it."""
    ys = [1.0, 3.0, 4.0, 4.0, 3.0, 3.0]
    assert props(trace(ys, dict(BASE, u=3.0))) == ["4"]


def test_4_passing_the_target_twice():
    """The target moved inside the braking distance may be passed once, then approached without passing again:
    here the output comes back below it."""
    values = dict(BASE, u=100.0, accelMax=1.0)
    per_cycle = [{}] * 3 + [{"u": 6.5}] * 8
    # steps 1, 2, 3 up to 6, target 6.5 then: 3 -> 2 (8), 1 (9), 0, -1 (8), -2 (6), -1 (5), 0, +1 (6)... passes
    ys = [1.0, 3.0, 6.0, 8.0, 9.0, 9.0, 8.0, 6.0, 5.0, 5.0, 6.0]
    found = check([trace(ys, values, per_cycle=per_cycle)], LREAL, 1.0)
    assert {v.prop for v in found} == {"4"} and any("changed sign 2 times" in v.text for v in found)


def test_4_a_target_moved_inside_the_braking_distance_may_be_passed_once():
    values = dict(BASE, u=100.0)
    per_cycle = [{}] * 3 + [{"u": 6.5}] * 8
    ys = [1.0, 3.0, 6.0, 8.0, 9.0, 9.0, 8.0, 7.0, 6.5, 6.5]  # steps ..., 0, -1, -1, -0.5, 0
    assert check([trace(ys, values, per_cycle=per_cycle[:10], settle=True)], LREAL, 1.0) == []


def test_5_slower_than_time_optimal():
    """V = 1, A = 1, D = 10: t_opt = 11 s; 20 cycles of 0.5 break the bound of 13."""
    ys = [0.5 * k for k in range(1, 21)] + [10.0]
    values = dict(BASE, u=10.0, rateUpPar=1.0, rateDownPar=1.0)
    assert props(trace(ys, values)) == ["5"]


def test_5_two_cycles_late_is_allowed():
    """V = 1, A = 1, D = 6: t_opt = 6/1 + 1/1 = 7 s; arriving at cycle 7 is within t_opt + 2T."""
    ys = [1.0, 2.0, 3.0, 4.0, 5.0, 5.5, 6.0, 6.0]
    values = dict(BASE, u=6.0, rateUpPar=1.0, rateDownPar=1.0)
    assert check([trace(ys, values, settle=True)], LREAL, 1.0) == []


def test_6_crossing_a_limit_it_could_stop_before():
    """At 3, moving up at 1 per cycle towards yMax = 5, the target moves behind (0): the output may go on but not
    past 5."""
    values = dict(BASE, u=10.0, yMaxPar=5.0)
    per_cycle = [{}] * 3 + [{"u": 0.0}] * 3
    ys = [1.0, 2.0, 3.0, 4.0, 5.5, 6.0]
    assert props(trace(ys, values, per_cycle=per_cycle)) == ["6"]


def test_6_a_limit_tightened_under_way_may_be_crossed_back_into_the_band():
    values = dict(BASE, u=10.0)
    per_cycle = [{}] * 3 + [{"yMaxPar": 3.5}] * 8
    # at 6 moving up at 3 per cycle, yMax drops to 3.5: brake, turn, come back down and land on it
    ys = [1.0, 3.0, 6.0, 8.0, 9.0, 9.0, 8.0, 6.0, 4.5, 3.5, 3.5]
    assert check([trace(ys, values, per_cycle=per_cycle, settle=True)], LREAL, 1.0) == []


def test_7_a_wrong_remaining_time():
    seg = trace(TRAPEZOID, dict(BASE, u=8.0, rateUpPar=2.0, rateDownPar=2.0), outputs={2: {"remainingTime": 2.5}})
    assert props(seg) == ["7"]


def test_7_remaining_time_zero_before_arrival():
    seg = trace(TRAPEZOID, dict(BASE, u=8.0, rateUpPar=2.0, rateDownPar=2.0), outputs={5: {"remainingTime": 1.0}})
    assert props(seg) == ["7"]


def test_rules_hold_moves_the_output():
    per_cycle = [{}, {"hold": True}, {}]
    assert "rules" in props(trace([1.0, 2.0, 3.0], dict(BASE, u=10.0), per_cycle=per_cycle))


def test_status_of_a_negative_accel_max():
    values = dict(BASE, u=10.0, accelMax=-1.0)
    found = check([trace([0.0, 0.0], values)], LREAL, 1.0)
    assert {v.prop for v in found} == {"status"}
    assert "0x8205" in found[0].text


def test_interface_d2ydt2_after_a_hold():
    per_cycle = [{}, {"hold": True}, {}]
    assert "interface" in props(
        trace([1.0, 1.0, 2.0], dict(BASE, u=10.0), per_cycle=per_cycle, outputs={2: {"d2ydt2": -1.0}})
    )


@pytest.mark.parametrize("seed", range(4))
def test_a_second_order_limiter_that_keeps_the_properties_passes_random_scenarios(seed):
    """support/accel_model.py (a plain time-optimal limiter, exact, that brakes a few ulp harder to absorb the
    rounding of its outputs) through the random scenarios the FMU gets: no violation, so that one found in the
    FMU is the FMU's and not the checker's."""
    scenario, segments = run_random(
        RandomChooser(random.Random(seed)), "RateLimiter", 2, LREAL, cycles=(20, 60), block=ModelBlock
    )
    assert sum(len(s.cycles) for s in segments) > 20
    assert violations(scenario, segments) == [], scenario.dumps()


class FirstOrder(ModelBlock):
    """The block of section 3 and 6: the acceleration parameters not passed on."""

    def start(self, t0, values):
        return super().start(t0, {k: v for k, v in values.items() if k not in ("accelMax", "decelMax")})

    def cycle(self, T, changes, end=None):
        return super().cycle(T, {k: v for k, v in changes.items() if k not in ("accelMax", "decelMax")}, end)


@pytest.mark.parametrize("seed", range(4))
def test_the_block_without_the_acceleration_limit_fails_the_same_scenarios(seed):
    """The control of the test above: the first-order block jumps to its velocity limit from rest."""
    scenario, segments = run_random(
        RandomChooser(random.Random(seed)), "RateLimiter", 2, LREAL, cycles=(20, 60), block=FirstOrder
    )
    assert "2" in {v.prop for v in violations(scenario, segments)}


def test_1_braking_to_a_lowered_limit_ends_when_the_limit_is_raised_again():
    """Speed 4, rateUp lowered to 1: braking 3; the rate raised to 10 again: accelerating to 4 is allowed."""
    values = dict(BASE, u=100.0, rateUpPar=4.0, rateDownPar=4.0)
    per_cycle = [{}] * 4 + [{"rateUpPar": 1.0}] + [{"rateUpPar": 10.0}] * 2
    ys = [1.0, 3.0, 6.0, 10.0, 13.0, 17.0, 22.0]
    assert check([trace(ys, values, per_cycle=per_cycle)], LREAL, 1.0) == []


def test_1_crossing_0_into_a_lower_limit_too_fast_is_flagged():
    """Below 0 rateDownNeg = 2 per cycle: the output crosses 0 at a speed of 3 and goes on at 2.5."""
    values = dict(BASE, u=-10.0, rateDownNeg=2.0, decelMax=1.0)
    ys = [4.0, 2.0, -1.0, -3.5, -5.5]
    found = check([trace(ys, values, y0=5.0)], LREAL, 1.0)
    assert {v.prop for v in found} == {"1"} and "sign of y changed at 0" in found[0].text


def test_1_crossing_0_after_decel_max_was_lowered_may_brake_down_to_the_limit():
    """The same crossing right after decelMax was lowered to 0.5: no way left to slow down to 2 in time; braking
    at the new decelMax down to the limit is allowed."""
    values = dict(BASE, u=-10.0, rateDownNeg=2.0, decelMax=1.0)
    per_cycle = [{}, {}, {"decelMax": 0.5}, {"decelMax": 0.5}, {"decelMax": 0.5}]
    ys = [4.0, 2.0, -1.0, -3.5, -5.5]
    assert check([trace(ys, values, y0=5.0, per_cycle=per_cycle)], LREAL, 1.0) == []


def test_1_the_braking_to_a_lowered_limit_is_judged_without_a_far_targets_allowance():
    """A rate lowered to 1000 per cycle at a speed of 1500 while the target is 2^60 away (8 ulp of it: 2048, more
    than the excess): braking at decelMax (200) down to the limit is allowed, also after the target came near."""
    values = dict(BASE, u=2.0**60, rateUpPar=10000.0, rateDownPar=10000.0, accelMax=1000.0, decelMax=200.0)
    per_cycle = [{}, {}, {"rateUpPar": 1000.0}] + [{"rateUpPar": 1000.0, "u": 10000.0}] * 3
    ys = [1000.0, 2500.0, 3800.0, 4900.0, 5900.0, 6900.0]
    assert check([trace(ys, values, per_cycle=per_cycle)], LREAL, 1.0) == []


def test_5_the_bound_at_huge_values_does_not_overflow():
    """D = 8 * 2^1000, V = 2 * 2^1000 per s, A = 2^1000 per s^2: V^2 overflows, D >= V^2 / A all the same (the
    trapezoid: t_opt = 4 + 2 = 6 s); arriving at cycle 5 is within it, where the triangle's 2 sqrt(D/A) = 5.7 s
    would wrongly allow it too but a slower arrival at cycle 8 must not be flagged."""
    scale = 2.0**1000
    values = dict(BASE, u=8.0 * scale, rateUpPar=2.0 * scale, rateDownPar=2.0 * scale, accelMax=scale)
    ys = [y * scale for y in [1.0, 2.5, 4.0, 5.5, 6.5, 7.25, 7.75, 8.0, 8.0, 8.0]]
    assert "5" not in props(trace(ys, values, settle=True))
