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
from support.cli import fmutrace_in_process
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


def early(values, cycles):
    """The reference early: the result late."""
    moved = values.copy()
    moved[:-cycles] = values[cycles:]
    return moved


@pytest.mark.parametrize("shift", [early, late], ids=["result late", "result early"])
@pytest.mark.parametrize("chunks", [(False, 1, 8), (False, 100_000, 1 << 22)], ids=["chunks of one step", "one chunk"])
def test_ramp_active_one_cycle_late_passes_a_one_cycle_tube_of_value_0(tmp_path, chunks, shift):
    """The issue's measurement: the result's rampActive one cycle late was
    refused 'off by 8.88178e-15' at its fall (t=5.1)."""
    folder, reference = own_output_case(tmp_path)
    ramp = reference["rampActive"].copy()
    assert ramp.any() and not ramp.all()
    changed(folder, reference, rampActive=shift(ramp, 1))
    target, settings = fmu_target(), CaseSettings(Tube(0.1, 0.0), "none")
    outcome = run_folder_case(CaseFiles(folder, folder.name), target, settings, Streaming(*chunks))
    assert outcome.status == "pass", outcome.messages
    changed(folder, reference, rampActive=shift(ramp, 2))
    outcome = run_folder_case(CaseFiles(folder, folder.name), target, settings, Streaming(*chunks))
    assert outcome.status == "fail", outcome.messages
    # two cycles off: a trace's change lies outside the tube around the other (which first: late or early)
    first = outcome.messages[0]
    assert first.startswith("rampActive: the ") and " leaves the tube around the " in first, outcome.messages


# ---- 2. discrete signals: exact in value, changes within k cycles --------------

GRID = np.arange(20) * 0.1  # a result on its communication points


def discrete(reference_values, result_values, cycles):
    reference, result = trace(GRID, b=reference_values), trace(GRID, b=result_values)
    return compare_traces(result, reference, fmutrace.Discrete(cycles))


def step_at(k, low=0, high=1):
    return np.where(np.arange(20) >= k, high, low)


def test_a_boolean_late_by_two_cycles_fails_with_one_and_passes_with_two():
    for cycles, passes in [(0, False), (1, False), (2, True), (3, True)]:
        assert discrete(step_at(5), step_at(7), cycles).passed is passes, cycles
        assert discrete(step_at(7), step_at(5), cycles).passed is passes, cycles  # two early
    message = discrete(step_at(5), step_at(7), 1).messages()[0]
    assert "comes 2 cycles late" in message and "more than the 1 allowed" in message, message


def test_a_status_word_flipped_for_one_cycle_fails_whatever_the_time_allowance():
    status = np.full(20, 0x8200)
    flipped = status.copy()
    flipped[9] = 0x8201
    for cycles in (0, 1, 5):
        comparison = discrete(status, flipped, cycles)
        assert not comparison.passed, cycles
        assert comparison.messages()[0] == "b: changes to 33281 at t=0.9 and back at t=1.0, a pulse the reference lacks"
    # the reference's one-cycle flip missing from the result fails too: a pulse missing, at its time
    comparison = discrete(flipped, status, 3)
    assert not comparison.passed
    assert comparison.messages()[0] == "b: the reference's pulse to 33281 at t=0.9 (1 cycle) is missing from the result"


def test_a_pulse_missing_from_the_result_is_that_pulse_not_every_later_change_late():
    """The issue's case: the reference's one-cycle pulse at t = 0.5 that
    the result lacks, the signal's later changes (t = 1.0 and 1.5) in
    both: changes pair nearest first, so the pulse is missing at its time;
    paired in order, the change at 0.5 came 5 cycles late."""
    later = np.where((np.arange(20) >= 10) & (np.arange(20) < 15), 1, 0)
    spurious = later.copy()
    spurious[5] = 1
    for cycles in (1, 3, 4):
        comparison = discrete(spurious, later, cycles)
        assert comparison.messages() == [
            "b: the reference's pulse to 1 at t=0.5 (1 cycle) is missing from the result"
        ], cycles
    # within the cycles allowed of the later rise (5 cycles), the pulse's rise pairs with it: the rest is unpaired
    assert not discrete(spurious, later, 5).passed


def test_changes_pair_nearest_first_and_a_change_too_late_names_both_times():
    """A pulse 2 cycles late within 2 allowed pairs; a rise 4 cycles late,
    with nothing between it and the reference's rise, is that rise late,
    named with both times."""
    reference = np.zeros(20)
    reference[[3, 4, 5]] = 1  # a rise at 0.3, a fall at 0.6
    reference[12:] = 1  # a rise at 1.2
    result = np.zeros(20)
    result[[5, 6, 7]] = 1  # the first pulse 2 cycles late
    result[16:] = 1  # the rise at 1.2 four cycles late: unpaired with 2 allowed
    comparison = discrete(reference, result, 2)
    assert comparison.messages() == [
        f"b: the reference's change to 1 at t={float(GRID[12])!r} comes 4 cycles late (t={float(GRID[16])!r}), "
        "more than the 2 allowed"
    ]
    assert discrete(reference, result, 4).passed


def test_a_change_to_another_value_fails_where_a_tube_would_interpolate():
    """16#8200 -> 16#8201 is not 16#8200 -> 16#8202, however close the numbers."""
    comparison = discrete(step_at(5, 0x8200, 0x8201), step_at(5, 0x8200, 0x8202), 2)
    assert (
        not comparison.passed
        and "changes to 33282 at t=0.5 where the reference's next change is to 33281" in comparison.messages()[0]
    )


def test_the_time_allowance_used_is_stated():
    comparison = discrete(step_at(5), step_at(6), 2)
    assert comparison.passed
    assert comparison.deviations[0].allowance == "time allowance used: 1 of 2 cycles at t=0.6000000000000001"


def test_a_sparser_reference_holds_the_result_at_its_times():
    """A reference every 0.3 s: its change from 0 (t=0.3) to 1 (t=0.6) can
    be at any cycle of (0.3, 0.6] without using the allowance."""
    times = GRID[::3]
    reference = trace(times, b=(times >= 0.55).astype(float))
    for k in (4, 5, 6):
        assert compare_traces(trace(GRID, b=step_at(k)), reference, fmutrace.Discrete(0)).passed, k
    assert not compare_traces(trace(GRID, b=step_at(7)), reference, fmutrace.Discrete(0)).passed
    assert compare_traces(trace(GRID, b=step_at(7)), reference, fmutrace.Discrete(1)).passed


# ---- 4. units in the last place ----------------------------------------------


def ulps(reference_values, result_values, n, arithmetic):
    reference = trace(np.arange(len(reference_values)), x=reference_values)
    result = trace(np.arange(len(result_values)), x=result_values)
    return compare_traces(result, reference, fmutrace.Ulps(n, arithmetic))


F32 = np.float32


def up(x, k=1, t=F32):
    x = t(x)
    for _ in range(k):
        x = np.nextafter(x, t(np.inf))
    return float(x)


@pytest.mark.parametrize(
    "reference,result,distance",
    [
        (1.0, up(1.0), 1),
        (2.0**20, up(2.0**20, 3), 3),  # binary32's ulp there is 2^-3, binary64's 2^-32
        (0.0, up(0.0), 1),  # the smallest subnormal
        (-float(up(0.0)), up(0.0), 2),  # across zero: -s, (-0 = +0), +s
        (-0.0, 0.0, 0),
        (float(np.finfo(F32).tiny), up(np.finfo(F32).tiny, 2), 2),  # normal from the smallest normal
        (float(up(0.0, 5)), up(0.0, 7), 2),  # subnormals
        (-1.5, float(-np.nextafter(F32(1.5), F32(2))), 1),
    ],
)
def test_binary32_ulps_count_binary32_numbers(reference, result, distance):
    assert ulps([reference], [result], distance, "binary32").passed
    if distance:
        assert not ulps([reference], [result], distance - 1, "binary32").passed


def test_binary32_rounds_both_first_and_binary64_counts_doubles():
    """0.1 printed by a recorder and the REAL 0.1 (0.100000001490116...) are
    the same binary32 number, 2^29 - ... binary64 numbers apart."""
    real = float(F32(0.1))
    assert ulps([0.1], [real], 0, "binary32").passed
    assert not ulps([0.1], [real], 1000, "binary64").passed
    assert ulps([1.0], [up(1.0, 2, np.float64)], 2, "binary64").passed
    assert not ulps([1.0], [up(1.0, 2, np.float64)], 1, "binary64").passed


def test_ulps_nan_and_infinities():
    nan, inf = float("nan"), float("inf")
    assert ulps([nan, inf, -inf], [nan, inf, -inf], 0, "binary32").passed
    assert not ulps([nan], [1.0], 4, "binary32").passed
    assert not ulps([float(np.finfo(F32).max)], [inf], 4, "binary32").passed
    assert not ulps([inf], [-inf], 4, "binary64").passed
    # the largest binary64 numbers apart across zero: no overflow
    assert not ulps([-float(np.finfo(np.float64).max)], [float(np.finfo(np.float64).max)], 4, "binary64").passed


# ---- 3. per-signal criteria --------------------------------------------------


def run_case(folder, mode, chunks=(False, 1, 8)):
    return run_folder_case(CaseFiles(folder, folder.name), fmu_target(), CaseSettings(mode, "none"), Streaming(*chunks))


Y_STATUS_RAMP = {"y": fmutrace.Tolerance(abs_tol=1e-6), "status": fmutrace.Exact(), "rampActive": fmutrace.Discrete(1)}


@pytest.mark.parametrize("chunks", [(False, 1, 8), (False, 100_000, 1 << 22)], ids=["chunks", "one chunk"])
def test_y_within_1e_6_status_exact_ramp_active_up_to_one_cycle_late(tmp_path, chunks):
    folder, reference = own_output_case(tmp_path)
    y, ramp = reference["y"].copy(), reference["rampActive"].copy()
    criteria = fmutrace.Criteria(Y_STATUS_RAMP)
    changed(folder, reference, y=y + 0.5e-6, rampActive=late(ramp, 1))
    outcome = run_case(folder, criteria, chunks)
    assert outcome.status == "pass", outcome.messages
    changed(folder, reference, rampActive=late(ramp, 2))
    outcome = run_case(folder, criteria, chunks)
    assert outcome.status == "fail" and len(outcome.deviations) == 1
    assert outcome.messages[0].startswith("rampActive (exact, up to 1 cycle early or late): the reference's change")
    assert "comes 2 cycles early" in outcome.messages[0]  # (the reference is the late one)
    changed(folder, reference, y=y + 2e-6, rampActive=ramp)
    outcome = run_case(folder, criteria, chunks)
    assert outcome.status == "fail" and len(outcome.deviations) == 1
    assert outcome.messages[0].startswith("y (relative tolerance 0, absolute tolerance 1e-06) leaves the band")


def test_a_pattern_and_a_default_and_the_first_match_wins():
    criteria = fmutrace.Criteria({"ramp*": fmutrace.Discrete(2), "r*": fmutrace.Exact(), "*": Tube(0.1, 0.0)})
    assert criteria.given("rampActive") == fmutrace.Discrete(2)
    assert criteria.given("runningTime") == fmutrace.Exact()
    assert criteria.given("y") == Tube(0.1, 0.0)
    # a discrete signal under a tube: exact in value, the tube's time in whole cycles
    discrete = fmutrace.Criteria({"*": Tube(0.25, 1.0)}, discrete=frozenset({"status"}))
    assert discrete.mode_of("status", 0.1) == fmutrace.Discrete(2) and discrete.mode_of("y", 0.1) == Tube(0.25, 1.0)
    assert discrete.mode_of("status", 0.125) == fmutrace.Discrete(2)


def test_a_status_word_is_recognised_from_the_fmu_and_never_interpolated(tmp_path):
    """The issue: under a one-cycle tube a status word flipped to 16#8200
    for one cycle passed. Per-signal criteria know status is an Integer."""
    folder, reference = own_output_case(tmp_path)
    status = reference["status"].copy()
    status[40] = 0x8200
    changed(folder, reference, status=status)
    assert run_case(folder, Tube(0.1, 0.0, sides=1)).status == "pass"  # the old, one-sided judgement, unchanged
    # both ways, the flip in the reference lies outside the tube around the result (status is 0 there)
    flipped = run_case(folder, Tube(0.1, 0.0))
    assert flipped.status == "fail" and flipped.messages[0].startswith(
        "status: the reference leaves the tube around the result first at t=4.0: 33280.0, the tube there 0.0, off by"
    ), flipped.messages
    outcome = run_case(folder, fmutrace.Criteria({"*": Tube(0.1, 0.0)}))
    assert outcome.status == "fail", outcome.messages
    assert outcome.messages[0] == (
        "status (exact, up to 1 cycle early or late): "
        "the reference's pulse to 33280 at t=4.0 (1 cycle) is missing from the result"
    )


def test_a_time_tolerance_hiding_a_value_error_shows_its_use(tmp_path):
    """A +10 glitch of y at one sample of the reference passes a one-sided
    one-cycle tube (its neighbours are in the window); the verdict says the
    sample needed nearly the whole time: y rises 0.2 a cycle there, so the
    reference's polyline from the sample before (y - 0.2) to the glitch
    (y + 10.2) passes y at 10/10.2 of the cycle before. The tube both ways
    fails it: the glitch lies outside the tube around the result."""
    folder, reference = own_output_case(tmp_path)
    y = reference["y"].copy()
    y[20] += 10
    changed(folder, reference, y=y)
    outcome = run_case(folder, fmutrace.Criteria({"y": Tube(0.1, 0.0, sides=1)}))
    assert outcome.status == "pass"
    assert f"time allowance used: {0.1 * 10 / 10.2:.6g} of 0.1 s (98%) at t=2.0" in outcome.messages[0]
    assert outcome.messages[0].startswith("y (tube of 0.1 s and 0, one-sided): ")
    outcome = run_case(folder, fmutrace.Criteria({"y": Tube(0.1, 0.0)}))
    assert outcome.status == "fail"
    assert outcome.messages[0].startswith(
        "y (tube of 0.1 s and 0): the reference leaves the tube around the result first at t=2.0: "
    ), outcome.messages


def test_a_case_folder_carries_its_criteria(tmp_path):
    folder, reference = own_output_case(tmp_path)
    changed(folder, reference, y=reference["y"] + 0.5e-6, rampActive=late(reference["rampActive"], 1))
    assert run_case(folder, fmutrace.Exact()).status == "fail"
    (folder / "RateLimiter_criteria.csv").write_text(
        "# signal,mode\ny,tol:abs=1e-6,rel=0\nramp*,discrete:cycles=1\n*,exact\n"
    )
    outcome = run_case(folder, fmutrace.Exact())
    assert outcome.status == "pass", outcome.messages
    # the case's criteria before the campaign's: the command's y=exact does not override the file's
    assert run_case(folder, fmutrace.Criteria({"y": fmutrace.Exact()})).status == "pass"
    for text, where in [("nosuch,exact\n", "line 1, column 1"), ("y,tube:time=1\n", "line 1, column 2")]:
        (folder / "RateLimiter_criteria.csv").write_text(text)
        outcome = run_case(folder, fmutrace.Exact())
        assert outcome.status == "invalid" and where in outcome.messages[0], outcome.messages


def command(*args):
    done = fmutrace_in_process("compare", fmu_path(BUILD_DIR, "RateLimiter", 3), *args)
    return done.returncode, done.stdout, done.stderr


def test_the_command_checks_a_tube_both_ways_unless_told_one_side(tmp_path):
    """A +10 glitch of the reference's y: --tube-time 0.1 --tube-value 0
    fails it, naming the side; --tube-sides 1 passes it, as csv-compare;
    the sides without a tube are refused, naming the flag."""
    folder, reference = own_output_case(tmp_path)
    y = reference["y"].copy()
    y[20] += 10
    changed(folder, reference, y=y)
    tube = ("--tube-time", 0.1, "--tube-value", 0)
    status, out, _ = command(tmp_path, *tube)
    assert status == 1 and "y: the reference leaves the tube around the result first at t=2.0: " in out, out
    status, out, _ = command(tmp_path, *tube, "--tube-sides", 1)
    assert status == 0, out
    status, _, err = command(tmp_path, "--tube-sides", 1)
    assert status == 2 and "--tube-sides is a tube's: give the tube too" in err, err


def test_the_command_states_each_signals_criterion(tmp_path):
    folder, reference = own_output_case(tmp_path)
    changed(folder, reference, y=reference["y"] + 0.5e-6, rampActive=late(reference["rampActive"], 1))
    assert command(tmp_path)[0] == 1
    status, out, _ = command(tmp_path, "--signal", "y=tol:abs=1e-6,rel=0", "--signal", "ramp*=discrete:cycles=1")
    assert status == 0, out
    status, out, _ = command(tmp_path, "--signal", "y=tol:abs=1e-7", "--signal", "*=discrete:cycles=1")
    assert status == 1 and "y (relative tolerance 0, absolute tolerance 1e-07) leaves the band" in out, out
    # the rest by the other flags: a one-cycle tube, rampActive judged exactly, one cycle late allowed
    status, out, _ = command(tmp_path, "--signal", "y=tol:abs=1e-6", "--tube-time", 0.1, "--tube-value", 0)
    assert status == 0, out


@pytest.mark.parametrize(
    "mode,message",
    [
        ("tol:abs", "--signal y=tol:abs: mode 'tol:abs': expected tol:abs=...,rel=..."),
        ("tube:time=1", "a tube needs both time= and value="),
        ("ulps:1,binary16", "mode 'ulps:1,binary16': the arithmetic is one of binary32, binary64"),
        ("ulps:-1", "the number of ulps '-1' is not a whole number >= 0"),
        ("discrete:cycles=-1", "mode 'discrete:cycles=-1': cycles must be a finite number >= 0, not -1"),
        ("discrete:cycles=0.5", "cycles '0.5' is not a number"),
        ("tol:rel=nan", "rel must be a finite number >= 0, not nan"),
        ("tol:abs=-1", "--signal y=tol:abs=-1: mode 'tol:abs=-1': abs must be a finite number >= 0, not -1"),
        ("tube:time=inf,value=0", "time must be a finite number >= 0, not inf"),
        ("fuzzy", "mode 'fuzzy' is none of: exact, tol:abs=A,rel=R"),
    ],
)
def test_a_bad_mode_is_refused_with_its_flag(tmp_path, mode, message):
    own_output_case(tmp_path)
    status, _, err = command(tmp_path, "--signal", f"y={mode}")
    assert status == 2 and message in err and "Traceback" not in err, err


@pytest.mark.parametrize(
    "mode",
    [
        fmutrace.Exact(),
        fmutrace.Tolerance(1e-3, 1e-9),
        Tube(0.01, 0.0),
        fmutrace.Discrete(3),
        fmutrace.Ulps(4, "binary32"),
        fmutrace.Ulps(0, "binary64"),
    ],
)
def test_a_mode_reads_back_from_its_words(mode):
    assert fmutrace.parse_mode(mode.spec()) == mode


def test_ulps_beyond_binary32s_range_is_its_infinity():
    assert ulps([1e300], [float("inf")], 0, "binary32").passed
    assert not ulps([1e300], [float("inf")], 4, "binary64").passed


def test_per_signal_criteria_draw_their_plot_and_report(tmp_path):
    folder, reference = own_output_case(tmp_path)
    changed(folder, reference, rampActive=late(reference["rampActive"], 2))
    criteria = fmutrace.Criteria({"y": Tube(0.1, 0.0), "rampActive": fmutrace.Discrete(1)})
    outcome = run_folder_case(CaseFiles(folder, folder.name), fmu_target(), CaseSettings(criteria, "all", png=True))
    assert outcome.status == "fail" and outcome.png.startswith(b"\x89PNG")
    assert outcome.plot_js.startswith("window.fmutracePlot") and "tube of 0.1 s and 0" in outcome.plot_js
    campaign = fmutrace.compare(fmu_path(BUILD_DIR, "RateLimiter", 3), tmp_path, mode=criteria, report=tmp_path / "r")
    assert campaign.exit_code == 1
    summary = (tmp_path / "r" / "summary.md").read_text()
    assert (
        "per signal: y: tube of 0.1 s and 0; rampActive: exact, up to 1 cycle early or late; the rest: exact" in summary
    )
    assert r"rampActive \(exact, up to 1 cycle early or late\): the reference's change" in summary  # (Markdown)
    assert r"y \(tube of 0.1 s and 0\): 81 samples pass; time allowance used: 0 of 0.1 s \(0%\) |" in summary


def test_one_discrete_or_ulps_mode_for_every_signal(tmp_path):
    folder, reference = own_output_case(tmp_path / "late")
    ramp, y = reference["rampActive"].copy(), reference["y"].copy()
    changed(folder, reference, rampActive=late(ramp, 1))
    fmu = fmu_path(BUILD_DIR, "RateLimiter", 3)
    assert fmutrace.compare(fmu, tmp_path / "late", mode=fmutrace.Discrete(1)).passed
    assert not fmutrace.compare(fmu, tmp_path / "late", mode=fmutrace.Discrete(0)).passed
    moved = int(np.flatnonzero(y != 0)[0])
    y[moved] = float(np.nextafter(np.float32(y[moved]), np.float32(np.inf)))  # one binary32 ulp up
    changed(folder, reference, y=y, rampActive=ramp)
    assert fmutrace.compare(fmu, tmp_path / "late", mode=fmutrace.Ulps(1, "binary32")).passed
    assert not fmutrace.compare(fmu, tmp_path / "late", mode=fmutrace.Ulps(0, "binary32")).passed


def test_a_sparser_reference_sees_the_results_changes_at_its_samples_only():
    """A reference every third cycle: a ramp that moves every cycle agrees
    at each of its samples; a flip and back between two samples is not
    seen; a change one cycle late across a sample is one cycle late."""
    ramp = np.arange(20.0)
    reference = trace(GRID[::3], b=ramp[::3])
    assert compare_traces(trace(GRID, b=ramp), reference, fmutrace.Discrete(0)).passed
    flat = np.zeros(20)
    blip = flat.copy()
    blip[4] = 1  # between the samples at cycles 3 and 6
    assert compare_traces(trace(GRID, b=blip), trace(GRID[::3], b=flat[::3]), fmutrace.Discrete(0)).passed
    sparse_step = trace(GRID[::3], b=step_at(6)[::3])  # changes in (3, 6]
    assert compare_traces(trace(GRID, b=step_at(7)), sparse_step, fmutrace.Discrete(1)).passed
    assert not compare_traces(trace(GRID, b=step_at(7)), sparse_step, fmutrace.Discrete(0)).passed
    assert not compare_traces(trace(GRID, b=step_at(8)), sparse_step, fmutrace.Discrete(1)).passed


def test_criteria_refuse_what_is_not_a_mode():
    with pytest.raises(fmutrace.InputError, match="the mode of 'y' must be a mode object, not 'exact'"):
        fmutrace.Criteria({"y": "exact"})
    with pytest.raises(fmutrace.InputError, match="must be a mode object"):
        fmutrace.Criteria({"*": fmutrace.Criteria()})
    with pytest.raises(fmutrace.InputError, match="Discrete.cycles must be a whole number >= 0, not 1.5"):
        fmutrace.Discrete(1.5)
    with pytest.raises(fmutrace.InputError, match="Ulps.arithmetic must be one of binary32, binary64"):
        fmutrace.Ulps(1, "decimal64")


def test_a_campaign_with_criteria_resumes_and_refuses_other_criteria(tmp_path):
    folder, reference = own_output_case(tmp_path / "cases")
    report = tmp_path / "report"
    assert command(tmp_path / "cases", "--signal", "ramp*=discrete:cycles=1", "--report", report)[0] == 0
    status, out, _ = command(tmp_path / "cases", "--signal", "ramp*=discrete:cycles=1", "--report", report, "--resume")
    assert status == 0 and "on the journal" in out, out
    status, _, err = command(tmp_path / "cases", "--signal", "ramp*=discrete:cycles=2", "--report", report, "--resume")
    assert status == 2 and "fmutrace: error:" in err, err
