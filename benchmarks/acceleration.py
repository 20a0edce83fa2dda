#!/usr/bin/env python3
"""The acceleration limit against the field: LinuxCNC's limit3.

LinuxCNC tests its second-order limiter `limit3` by switching its input
among the waveforms of its signal generator (sine, cosine, square,
sawtooth, triangle: 2 Hz, amplitude 100) and a loopback of its own output,
with position limits +-101, maxv 1500 per s, maxa 15800 per s^2 (a hair
above what the sine needs) in a 1 ms thread, and fails on any position,
velocity or acceleration limit broken or any sample that accelerates or
moves more sluggishly than it could. The same inputs, rebuilt from that
description, go here through

- RateLimiter (the FMU, FMI 2, through the tests' fast driver) with
  rateUpPar = rateDownPar = maxv, accelMax = maxa, yMaxPar / yMinPar = +-101,
  1 ms cycles, and
- limit3's published algorithm, written again here in Python (from its
  description and its component's documented steps: the reachable
  velocities of the next period, the distance to stop and to match the
  input's velocity, the choice between the input and a position limit, full
  acceleration towards it unless that would overshoot, a smoothed landing
  in the last periods), with the same maxv, maxa and cycle,

each input from rest at 0 for 2 s (the loopback: 0.5 s of the sine, then
0.5 s with the input = the block's own previous output). Counted per input,
with the property checker of the tests (tests/support/accel_properties.py,
the allowance of the acceleration limit in docs/rules.md): velocity and acceleration limit
violations, position limit violations, avoidable overshoots (the output
passes a target it could have stopped before: a target not moved inside the
braking distance), the largest overshoot past the target, the time to the
target after each jump (mean, ms, of the jumps it reached before the next;
the square's continuous time-optimal profile takes 228 ms), and the median
distance to the input in the last second (the lag).

    acceleration.py --build-dir build [--smoke]
"""

import argparse
import math
import os
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
T = 0.001
FREQUENCY, AMPLITUDE = 2.0, 100.0
LOW, HIGH, MAXV, MAXA = -101.0, 101.0, 1500.0, 15800.0


# -- the inputs, from the signal generator's description ---------------------------------------------------------
def phase(k):
    """The generator's phase after k periods of its thread (it advances before it writes)."""
    return math.fmod(k * FREQUENCY * T, 1.0)


def sine(k):
    return AMPLITUDE * math.sin(2 * math.pi * phase(k))


def cosine(k):
    return AMPLITUDE * math.cos(2 * math.pi * phase(k))


def square(k):
    """Positive while the cosine rises (the second half of the phase)."""
    return AMPLITUDE if phase(k) > 0.5 else -AMPLITUDE


def sawtooth(k):
    """-A to +A over a period, then drops."""
    return AMPLITUDE * (2 * phase(k) - 1)


def triangle(k):
    """Peaks with the cosine: +A at phase 0, -A at 0.5."""
    p = phase(k)
    return AMPLITUDE * (1 - 4 * p if p <= 0.5 else 4 * p - 3)


INPUTS = {"sine": sine, "cosine": cosine, "square": square, "sawtooth": sawtooth, "triangle": triangle}


# -- limit3's published algorithm ---------------------------------------------------------------------------------
class Limit3:
    """LinuxCNC limit3 as its component describes its steps, in double precision (its pins' type). State: the
    output of this and the last period and the last input, all 0 at the start (HAL's pins)."""

    EPSILON = 1e-9

    def __init__(self, low, high, maxv, maxa, period, smooth_steps=2):
        self.low, self.high, self.maxv, self.maxa, self.T, self.smooth = low, high, maxv, maxa, period, smooth_steps
        self.out = self.out_old = self.in_old = 0.0

    def step(self, target):
        T, a, eps = self.T, self.maxa, self.EPSILON
        out = self.out
        v_out = (out - self.out_old) / T
        v_in = (target - self.in_old) / T
        # 1. what one period can reach, the way to stop, the way to match the input's velocity
        v_lo, v_hi = max(v_out - a * T, -self.maxv), min(v_out + a * T, self.maxv)
        p_lo, p_hi = out + v_lo * T, out + v_hi * T
        stop_lo = out + v_lo / 2 * (abs(v_lo) / a + T)
        stop_hi = out + v_hi / 2 * (abs(v_hi) / a + T)
        match_t_lo, match_t_hi = abs(v_in - v_lo) / a - T, abs(v_in - v_hi) / a - T
        out_at_match_lo = p_lo + (v_lo + v_in) / 2 * match_t_lo
        out_at_match_hi = p_hi + (v_hi + v_in) / 2 * match_t_hi
        in_at_match_lo, in_at_match_hi = target + v_in * match_t_lo, target + v_in * match_t_hi

        def reachable(x):
            return p_lo <= x <= p_hi

        # 2. the goal: a position limit the output is heading into (or the input is beyond), else the input
        limit = None
        if stop_hi > self.high + eps and not reachable(self.high):
            limit = self.high
        elif stop_lo < self.low - eps and not reachable(self.low):
            limit = self.low
        elif target >= self.high and in_at_match_hi > out_at_match_hi:
            limit = self.high
        elif target <= self.low and in_at_match_lo < out_at_match_lo:
            limit = self.low
        if limit is not None:
            goal_lo = goal_hi = goal_now = goal_before = limit
            dv, reach_lo, reach_hi = -v_out, stop_lo, stop_hi
        else:
            goal_lo, goal_hi, goal_now, goal_before = in_at_match_lo, in_at_match_hi, target, self.in_old
            dv, reach_lo, reach_hi = v_out - v_in, out_at_match_lo, out_at_match_hi
        # 3. the acceleration
        t = 0.0 if abs(dv) < eps else (out - goal_before) / (dv / 2)
        if reachable(goal_now) and abs(t) <= T:
            return self.move(goal_now, target)
        if reach_hi < goal_hi + eps:
            return self.move(p_hi, target)
        if reach_lo > goal_lo - eps:
            return self.move(p_lo, target)
        if abs(t) < T * self.smooth:
            sign = 1 if t >= 0 else -1
            whole = math.trunc((t - eps * sign) / T + sign) * T  # the time rounded up to whole periods
            v = v_out + dv / whole * T
            return self.move(min(p_hi, max(p_lo, out + v * T)), target)
        if goal_hi + eps < reach_hi and goal_before > out:
            return self.move(p_lo, target)
        if goal_lo - eps > reach_lo and goal_before < out:
            return self.move(p_hi, target)
        return self.move((p_lo + p_hi) / 2, target)

    def move(self, y, target):
        self.out_old, self.out, self.in_old = self.out, y, target
        return y


class RateLimiterBlock:
    """RateLimiter's FMU (FMI 2), a doStep of 1 ms a cycle."""

    def __init__(self):
        from support.accel_scenarios import Block

        self.block = Block("RateLimiter", 2)
        self.block.start(
            0.0,
            {
                "initMode": 1,
                "initValue": 0.0,
                "u": 0.0,
                "rateUpPar": MAXV,
                "rateDownPar": MAXV,
                "accelMax": MAXA,
                "yMaxPar": HIGH,
                "yMinPar": LOW,
            },
        )

    def step(self, target):
        return self.block.cycle(T, {"u": target})["y"]

    def free(self):
        self.block.free()


# -- a run and its figures ---------------------------------------------------------------------------------------
def run(block, name, cycles):
    """The inputs and outputs of one input's run: [(u_k, y_k)], k = 1.."""
    wave = INPUTS.get(name, sine)
    rows, y = [], 0.0
    for k in range(1, cycles + 1):
        u = y if name == "loopback" and k > cycles // 2 else wave(k)
        y = block.step(u)
        rows.append((u, y))
    return rows


def figures(rows):
    from support.accel_properties import Cycle, Segment, check

    values = {
        "rateUpPar": MAXV,
        "rateDownPar": MAXV,
        "ratePeriod": 1.0,
        "accelMax": MAXA,
        "decelMax": 0.0,
        "yMaxPar": HIGH,
        "yMinPar": LOW,
    }
    segment = Segment(
        values,
        0.0,
        {"y": 0.0},
        [Cycle(dict(values, u=u), (k + 1) * T, {"y": y, "runningTime": 0.0}) for k, (u, y) in enumerate(rows)],
    )
    found = check([segment], 1, T)
    count = {p: sum(1 for v in found if v.prop == p) for p in ("1", "2", "4", "6")}
    positions = sum(1 for _, y in rows if y > HIGH or y < LOW)
    # the largest overshoot past the target: beyond this cycle's target, seen from where the output was
    largest, before = 0.0, 0.0
    for u, y in rows:
        uc = min(max(u, LOW), HIGH)
        d = 1 if uc > before else -1 if uc < before else 0
        largest = max(largest, d * (y - uc)) if d else largest
        before = y
    # the time to the target after each jump of the input (by more than a cycle's velocity limit)
    times, k = [], 1
    while k < len(rows):
        if abs(rows[k][0] - rows[k - 1][0]) > 10 * MAXV * T:
            j = k
            while j < len(rows) and abs(rows[j][1] - rows[j][0]) > 1e-6 * AMPLITUDE:
                if j > k and abs(rows[j][0] - rows[j - 1][0]) > 10 * MAXV * T:
                    break  # the next jump came first
                j += 1
            times.append(
                (j - k + 1) * T * 1000 if j < len(rows) and abs(rows[j][1] - rows[j][0]) <= 1e-6 * AMPLITUDE else None
            )
            k = j - 1
        k += 1
    tail = sorted(abs(y - u) for u, y in rows[-min(len(rows), 1000) :])
    lag = tail[len(tail) // 2]  # the median distance to the input in the last second
    return count, positions, largest, times, lag


def settle(rows, cycles):
    """The loopback: cycles from the switch until the output stands still for good, and its direction changes."""
    start = cycles // 2
    ys = [y for _, y in rows[start - 1 :]]
    steps = [b - a for a, b in zip(ys, ys[1:], strict=False)]
    still = next((i for i in range(len(steps)) if all(s == 0 for s in steps[i:])), None)
    signs = [s > 0 for s in steps if s != 0]
    turns = sum(1 for a, b in zip(signs, signs[1:], strict=False) if a != b)
    return still, turns


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build-dir", default=str(REPO / "build"))
    parser.add_argument("--smoke", action="store_true", help="0.2 s per input: keeps the script working")
    args = parser.parse_args(argv)
    os.environ.setdefault("RL_BUILD_DIR", str(Path(args.build_dir).resolve()))
    sys.path.insert(0, str(REPO / "tests"))
    cycles = 200 if args.smoke else 2000
    print(
        f"limit3's inputs (2 Hz, amplitude 100), maxv {MAXV:g}/s, maxa {MAXA:g}/s^2, limits +-{HIGH:g}, "
        f"{T * 1000:g} ms cycles, {cycles} cycles an input\n"
    )
    print(
        "| input | block | velocity violations | acceleration violations | position violations | avoidable "
        "overshoots | largest overshoot past the target | time to target after a jump (ms, mean) | "
        "median distance to the input, last second | loopback: still after (ms), direction changes |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|")
    total_rl = 0
    for name in list(INPUTS) + ["loopback"]:
        for label in ("RateLimiter", "limit3 (Python)"):
            block = RateLimiterBlock() if label == "RateLimiter" else Limit3(LOW, HIGH, MAXV, MAXA, T)
            try:
                rows = run(block, name, cycles)
            finally:
                if label == "RateLimiter":
                    block.free()
            count, positions, largest, times, lag = figures(rows)
            if label == "RateLimiter":
                total_rl += count["1"] + count["2"] + count["4"] + count["6"] + positions
            reached = [t for t in times if t is not None]
            arrival = "-"
            if times and name != "loopback":
                arrival = f"{sum(reached) / len(reached):.0f}" if reached else "never"
                arrival += f" ({len(reached)} of {len(times)} jumps)"
            loop = "-"
            if name == "loopback":
                still, turns = settle(rows, cycles)
                loop = f"{'never' if still is None else f'{still * T * 1000:.0f}'}, {turns}"
            smooth = f"{lag:.3g}" if name != "loopback" else "-"
            print(
                f"| {name} | {label} | {count['1']} | {count['2']} | {positions} | {count['4'] + count['6']} | "
                f"{largest:.3g} | {arrival} | {smooth} | {loop} |"
            )
    print(f"\nRateLimiter: {total_rl} violations and avoidable overshoots in all")
    return 0  # a benchmark: the figures are reported, not asserted (the tests assert the properties)


if __name__ == "__main__":
    sys.exit(main())
