"""The oracle's binary32 arithmetic (rules.md, Arithmetic) checked on its own:
f32 rounds as IEEE binary32 does, one operation of binary32 values in
binary64 rounded by f32 is the operation in binary32 (numpy's float32
scalars, which compute each operation in single precision, agree bit for
bit), a division by a zero is IEEE's, and TIME values round to whole
milliseconds, ties to even."""

import math
import random
import struct

import numpy as np
import pytest

from support.fmu_driver import Instance
from support.oracle import REAL, RateLimiterOracle, divide, f32, time_ms

FLT_MAX = struct.unpack("<f", bytes.fromhex("ffff7f7f"))[0]
FLT_TRUE_MIN = struct.unpack("<f", bytes.fromhex("01000000"))[0]


def bits(x):
    return struct.pack("<f", x).hex() if math.isfinite(x) else repr(x)


def numpy_f32(x):
    with np.errstate(over="ignore"):
        return float(np.float32(x))


def binary32_values(count, seed):
    """Random binary32 values of every magnitude, and the edges."""
    rng = random.Random(seed)
    edges = [
        0.0,
        -0.0,
        1.0,
        -1.0,
        0.01,
        1e-5,
        262144.0,
        262000.0,
        20.0,
        30.0,
        FLT_MAX,
        -FLT_MAX,
        FLT_TRUE_MIN,
        -FLT_TRUE_MIN,
        2.0**-126,
        math.inf,
        -math.inf,
    ]
    drawn = [struct.unpack("<f", struct.pack("<I", rng.getrandbits(32)))[0] for _ in range(count)]
    close = [f32(rng.uniform(-300.0, 300.0)) for _ in range(count)]
    return [f32(x) for x in edges] + [x for x in drawn if not math.isnan(x)] + close


def test_f32_rounds_to_nearest_ties_to_even():
    one_ulp = 2.0**-23
    assert f32(1.0 + one_ulp / 2) == 1.0  # a tie: to the even neighbour
    assert f32(1.0 + 3 * one_ulp / 2) == 1.0 + 2 * one_ulp
    assert f32(1.0 + one_ulp / 2 + 2.0**-40) == 1.0 + one_ulp
    assert f32(0.01) == 0.009999999776482582
    assert f32(1e-5) == 9.999999747378752e-06
    assert f32(FLT_MAX) == FLT_MAX
    halfway = FLT_MAX + 2.0**103  # between FLT_MAX and 2^128: FLT_MAX is odd
    assert f32(halfway) == math.inf and f32(-halfway) == -math.inf
    assert f32(math.nextafter(halfway, 0)) == FLT_MAX
    assert f32(1e300) == math.inf and f32(-1e300) == -math.inf
    assert math.copysign(1.0, f32(-1e-50)) == -1.0 and f32(-1e-50) == 0.0
    assert math.isnan(f32(math.nan))


def test_f32_agrees_with_numpy_conversion():
    rng = random.Random(1)
    doubles = [rng.uniform(-1e6, 1e6) for _ in range(2000)] + [
        math.ldexp(rng.random(), rng.randint(-160, 140)) * rng.choice((1, -1)) for _ in range(2000)
    ]
    for x in doubles:
        assert bits(f32(x)) == bits(numpy_f32(x)), x


@pytest.mark.parametrize("operation", ["+", "-", "*", "/"])
def test_one_operation_rounded_by_f32_is_numpys_float32_operation(operation):
    """numpy float32 scalars compute in single precision, each operation
    rounded (SSE on x86_64, no wider intermediate); f32 of the binary64
    result is the same bits, which is what the oracle relies on."""
    values = binary32_values(3000, seed=hash(operation) & 0xFFFF)
    rng = random.Random(2)
    ops = {"+": lambda a, b: a + b, "-": lambda a, b: a - b, "*": lambda a, b: a * b, "/": lambda a, b: a / b}
    with np.errstate(all="ignore"):
        for _ in range(20000):
            a, b = rng.choice(values), rng.choice(values)
            if operation == "/" and b == 0:
                continue  # Python refuses; no cycle divides by a zero T or ratePeriod
            exact = ops[operation](a, b)
            in_numpy = float(ops[operation](np.float32(a), np.float32(b)))
            if math.isnan(in_numpy):
                assert math.isnan(f32(exact)), (a, operation, b)
            else:
                assert bits(f32(exact)) == bits(in_numpy), (a, operation, b)


def test_time_rounds_to_whole_milliseconds_ties_to_even():
    assert time_ms(0.0025) == 0.002  # 2.5 ms: to the even 2 ms, not up to 3 ms (C's round would)
    assert time_ms(0.0035) == 0.004
    assert time_ms(0.0015) == 0.002
    assert time_ms(0.0024999) == 0.002
    assert time_ms(0.0004) == 0.0  # below half a millisecond: T#0s, per task cycle
    assert time_ms(10.0) == 10.0
    assert time_ms(0.3) == 0.3  # 300 ms, as the decimal 0.3 reads
    assert time_ms(4294967.295) == 4294967.295


def test_division_by_a_zero_is_ieee():
    assert divide(1.0, 0.0) == math.inf and divide(-1.0, 0.0) == -math.inf
    assert divide(1.0, -0.0) == -math.inf and divide(-1.0, -0.0) == math.inf
    assert math.isnan(divide(0.0, 0.0)) and math.isnan(divide(-0.0, 0.0)) and math.isnan(divide(math.nan, 0.0))
    assert divide(3.0, 2.0) == 1.5 and math.isnan(divide(1.0, math.nan))


@pytest.mark.parametrize(
    "rate_period, u, y, dydt",
    [
        (0.0, 10.0, 1.0, math.inf),  # ratePeriod 0: rateUp 1 per cycle; (1 - 0) / +0
        (0.0, -10.0, -1.0, -math.inf),  # (-1 - 0) / +0
        (1.0, 10.0, 0.0, math.nan),  # 1 * T / 1 = 0 per cycle: y stays; (0 - 0) / +0
    ],
)
def test_real_step_of_the_smallest_subnormal_divides_by_zero(rate_period, u, y, dydt):
    """REAL (rules.md, Arithmetic): T = 5e-324 enters as +0 (below binary32's
    smallest subnormal), so dydt = (y - yp) / T is a binary32 division by +0,
    IEEE's: an infinity of the step's sign, or NaN where y did not move."""
    start = {"arithmetic": REAL, "ratePeriod": rate_period, "rateUpPar": 1.0, "rateDownPar": 1.0}
    oracle = RateLimiterOracle({}, start).do_step(0.0, 5e-324, {"u": u})
    results = [oracle]
    for version in (2, 3):  # the FMUs give the same
        fmu = Instance("RateLimiter", version)
        fmu.start(u=0.0, **start)
        fmu.set(u=u)
        fmu.step(5e-324)
        results.append(fmu.outputs(["y", "dydt"]))
        fmu.free()
    for out in results:
        assert out["y"] == y
        assert math.isnan(out["dydt"]) if math.isnan(dydt) else out["dydt"] == dydt
