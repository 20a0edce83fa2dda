"""Long runs through the FMU: 48 h of 10 ms cycles in large communication
steps end with the exact cycle count and the closed-form ramp value, and a
259,200 s duration jumps at exactly its cycle (no drift)."""

import pytest

from support.fmu_driver import Instance

STEP = 100.0  # 10,000 cycles of 10 ms per communication step
PER_CYCLE = 2.0**-7  # binary-exact, so the closed form is exact too


@pytest.mark.parametrize("version", [2, 3])
def test_48_hours_of_10ms_cycles(version):
    fmu = Instance("RateLimiter", version)
    fmu.start(cycleTime=0.01, ratePeriod=0.0, rateUpPar=PER_CYCLE)
    fmu.set(u=1e9)
    steps = int(48 * 3600 / STEP)
    for n in range(steps):
        fmu.fmu.doStep(currentCommunicationPoint=n * STEP, communicationStepSize=STEP)
    cycles = 48 * 3600 * 100
    assert cycles == 17_280_000
    assert fmu.get("y") == cycles * PER_CYCLE  # 135000, every cycle counted once
    assert fmu.get("runningTime") == 172800.0
    assert fmu.get("time") == 172800.0
    fmu.free()


@pytest.mark.parametrize("version", [2, 3])
def test_duration_of_48_hours_jumps_at_its_cycle(version):
    fmu = Instance("RateLimiter", version)
    fmu.start(cycleTime=0.01, ratePeriod=0.0, rateUpPar=PER_CYCLE, durationPar=259200.0)
    fmu.set(u=1e9)
    steps = int(259200 / STEP)
    for n in range(steps - 1):
        fmu.fmu.doStep(currentCommunicationPoint=n * STEP, communicationStepSize=STEP)
    assert fmu.get("y") == (steps - 1) * 10_000 * PER_CYCLE  # still ramping one step before
    fmu.fmu.doStep(currentCommunicationPoint=(steps - 1) * STEP, communicationStepSize=STEP)
    assert fmu.get("y") == 1e9  # cycle 25,920,000 ends at 259200 s
    assert fmu.get("runningTime") == 259200.0
    fmu.free()


@pytest.mark.parametrize("version", [2, 3])
def test_time_variable_follows_every_step(version):
    """time is published when read: after the common step (same h, only u
    changing) and after general ones (h changes, a parameter set), it is the
    end of the last step, t + h as the importer passed them."""
    fmu = Instance("RateLimiter", version)
    fmu.start(start_time=5.0, rateUpPar=1.0, rateDownPar=1.0)
    steps = [0.001] * 20 + [0.002] * 5 + [0.001] * 5
    for n, h in enumerate(steps):
        if n == 27:
            fmu.set(rateUpPar=2.0)  # a configuration change: a general step next
        fmu.set(u=float(n % 3))
        t = fmu.t
        fmu.step(h)
        assert fmu.get("time") == t + h, n
    assert fmu.get("time") == fmu.t
    fmu.free()
