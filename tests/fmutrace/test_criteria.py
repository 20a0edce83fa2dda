"""The comparison that knows PLC signals (issue 44): band edges that a
sample exactly at the allowed time or value lies inside, discrete signals
judged per change within whole cycles, per-signal criteria, units in the
last place. Expected verdicts are worked by hand from the criteria's
definitions (docs/fmutrace.md, Comparison), never taken from fmutrace's
output."""

import numpy as np
import pytest

import fmutrace
from fmutrace import Tube, write_trace
from fmutrace._comparison import compare_traces
from fmutrace._pipeline import CaseFiles, Streaming, run_folder_case
from fmutrace._worker import CaseSettings, Target, worker_fmu
from support.fmu_driver import BUILD_DIR
from support.scenarios import fmu_path


def trace(times, **signals):
    table = np.zeros(len(times), dtype=[("time", np.float64)] + [(s, np.float64) for s in signals])
    table["time"] = times
    for s, v in signals.items():
        table[s] = v
    return table


STEPS = np.arange(31)
DECIMAL_TIMES = np.array([float(f"{k / 10:.1f}") for k in STEPS])  # as a recorder prints them
SUMMED_TIMES = np.cumsum(np.r_[0.0, np.full(30, 0.1)])  # as a loop adds its steps


# ---- 1. band edges inclusive --------------------------------------------------


@pytest.mark.parametrize("result_times", [DECIMAL_TIMES, SUMMED_TIMES, STEPS * 0.1], ids=["decimal", "summed", "k*h"])
def test_a_boolean_exactly_one_cycle_late_lies_in_a_one_cycle_tube(result_times):
    """With tube time h and value 0, a step one cycle late has, at each of
    its samples, the reference's value one cycle away: inside, whatever
    t - h rounds to (the issue: refused 'off by 8.88178e-15')."""
    for k in range(1, 29):
        reference = trace(DECIMAL_TIMES, rampActive=STEPS >= k)
        result = trace(result_times, rampActive=STEPS >= k + 1)
        comparison = compare_traces(result, reference, Tube(0.1, 0.0))
        assert comparison.passed, (k, comparison.messages())
        two_late = trace(result_times, rampActive=STEPS >= k + 2)
        assert not compare_traces(two_late, reference, Tube(0.1, 0.0)).passed, k


def test_a_value_exactly_at_the_band_edge_lies_inside():
    """The value edge is one rounded sum: no double lies between it and
    the exact edge, so a value on the exact edge passes and the next one
    out fails (0.5 + 0.25 and 1 + 2^-52 are exact)."""
    reference = trace([0.0, 1.0], x=[0.5, 0.5])
    for mode in (Tube(0.0, 0.25), Tube(0.5, 0.25), fmutrace.Tolerance(abs_tol=0.25)):
        for edge, beyond in [(0.75, np.nextafter(0.75, 1.0)), (0.25, np.nextafter(0.25, 0.0))]:
            assert compare_traces(trace([0.0, 1.0], x=[edge, edge]), reference, mode).passed, mode
            assert not compare_traces(trace([0.0, 1.0], x=[beyond, beyond]), reference, mode).passed, mode


def fmu_target(model="RateLimiter", version=3):
    path = fmu_path(BUILD_DIR, model, version)
    runner, fmu = worker_fmu(path.read_bytes(), str(path))
    return Target(runner, fmu, {"fmu": fmu.label, "fmu_file": str(path), "fmu_folder": "f"})


def own_output_case(tmp_path, name="ramp", step=0.1):
    """A case whose reference is RateLimiter's own output (u 0 -> 10 at
    t = 1, 2 per s, cycles of step), its times printed as a recorder
    prints them (rounded to 10 decimals), as in the issue's measurement.
    Gives (folder, reference)."""
    folder = tmp_path / "RateLimiter" / name
    folder.mkdir(parents=True)
    (folder / "RateLimiter_in.csv").write_text("time,u\n0,0\n1,10\n")
    (folder / "RateLimiter_start.csv").write_text("rateUpPar,2.0\n")
    (folder / "RateLimiter_ref.opt").write_text(f"StartTime,0.0\nStopTime,8.0\nStepSize,{step}\nRelTol,1e-9\n")
    result = fmutrace.simulate(
        fmu_path(BUILD_DIR, "RateLimiter", 3),
        input=folder / "RateLimiter_in.csv",
        start_values={"rateUpPar": 2.0},
        step_size=step,
        stop_time=8.0,
        outputs=["y", "rampActive", "status"],
    )
    reference = trace(np.round(result["time"], 10), **{s: result[s] for s in ("y", "rampActive", "status")})
    write_trace(folder / "RateLimiter_ref.csv", reference)
    return folder, reference


def changed(folder, reference, **signals):
    """The case's reference with signals replaced."""
    for s, values in signals.items():
        reference[s] = values
    write_trace(folder / "RateLimiter_ref.csv", reference)
    return folder


def late(values, cycles):
    moved = values.copy()
    moved[cycles:] = values[:-cycles]
    return moved


@pytest.mark.parametrize("chunks", [(False, 1, 8), (False, 100_000, 1 << 22)], ids=["chunks of one step", "one chunk"])
def test_ramp_active_one_cycle_late_passes_a_one_cycle_tube_of_value_0(tmp_path, chunks):
    folder, reference = own_output_case(tmp_path)
    assert reference["rampActive"].any() and not reference["rampActive"].all()
    changed(folder, reference, rampActive=late(reference["rampActive"], 1))
    target, settings = fmu_target(), CaseSettings(Tube(0.1, 0.0), "none")
    outcome = run_folder_case(CaseFiles(folder, folder.name), target, settings, Streaming(*chunks))
    assert outcome.status == "pass", outcome.messages
    changed(folder, reference, rampActive=late(reference["rampActive"], 2))
    outcome = run_folder_case(CaseFiles(folder, folder.name), target, settings, Streaming(*chunks))
    assert outcome.status == "fail" and outcome.messages[0].startswith("rampActive leaves the band"), outcome.messages
