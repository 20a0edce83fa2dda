"""A closed loop in real co-simulations: the FirstOrderLag fixture (plant
and proportional controller, built by CMake) and RateLimiter, coupled in
ecospy (FMI 2 and 3), libcosimpy (FMI 2) and a scripted fmpy loop (FMI 2
and 3), each in its own process. All must agree with an oracle: the
contract's rate limiter (tests/oracle.py) and the plant's exact step
response, coupled the same way (at each communication point the outputs
go to the inputs, then both step)."""
import math
import sys

import numpy as np
import pytest
from fmpy import read_model_description
from fmpy.util import read_csv

from support.closed_loop import H, LIMITER, N, PLANT
from support.fmu_driver import BUILD_DIR, TESTS, fmu_file
from support.process import run as run_bounded
from support.oracle import oracle_for

RUNS = [("fmpy", 2), ("fmpy", 3), ("ecospy", 2), ("ecospy", 3), ("libcosimpy", 2)]


def oracle_loop():
    vr = {v.name: v.valueReference for v in read_model_description(str(fmu_file("RateLimiter", 2))).modelVariables}
    limiter = oracle_for("RateLimiter", vr, dict(LIMITER))
    y = limiter.outputs()["y"]
    x = PLANT["x0"]
    rows = []
    for k in range(N):
        t = k * H
        demand = PLANT["Kp"] * (PLANT["setpoint"] - x)
        command = y
        y = limiter.do_step(t, H, {"u": demand})["y"]
        x = command + (x - command) * math.exp(-H / PLANT["tau"])
        rows.append(((k + 1) * H, y, x))
    return rows


@pytest.mark.parametrize("importer,version", RUNS, ids=[f"{i}-fmi{v}" for i, v in RUNS])
def test_closed_loop_agrees_with_the_oracle(importer, version, tmp_path):
    out = tmp_path / "loop.csv"
    process = run_bounded([sys.executable, "-m", "support.closed_loop", importer, str(version), str(BUILD_DIR),
                           str(out)], timeout=300, what=f"the closed loop in {importer} (FMI {version})", cwd=TESTS)
    assert process.returncode == 0, (process.stdout + process.stderr)[-3000:]
    result = np.atleast_1d(read_csv(str(out)))
    expected = oracle_loop()
    assert len(result) == len(expected) == N
    for row, (t, y, x) in zip(result, expected):
        assert row["time"] == pytest.approx(t, rel=1e-12)
        assert row["y"] == pytest.approx(y, rel=1e-12, abs=1e-12), (t, row["y"], y)
        assert row["x"] == pytest.approx(x, rel=1e-12, abs=1e-12), (t, row["x"], x)
    # the loop settles where the controller's demand equals the plant output
    settle = PLANT["Kp"] * PLANT["setpoint"] / (1 + PLANT["Kp"])
    assert abs(result["x"][-1] - settle) < 0.05
