"""The tube on chunks (fmutrace._pipeline: each result sample against the
reference within the tube's time around it, the reference kept from the
row before that window to a row after it) gives the outcome Tube.bands
gives on the whole: status, messages and every failing signal's
deviation, on every reference scenario in chunks of one step and a few
bytes (every window crosses chunk boundaries), and on references made
to fail, with repeated times and with fewer samples than the result."""

import shutil

import numpy as np
import pytest

import fmutrace
from fmutrace import Tube, read_trace, write_trace
from fmutrace._pipeline import CaseFiles, Streaming, run_folder_case
from fmutrace._worker import CaseSettings, Target, run_case, worker_fmu
from support.fmu_driver import BUILD_DIR
from support.whole_case import on_the_whole
from support.scenarios import SCENARIO_ROOT, fmu_path

FOLDERS = sorted(p.parent for p in SCENARIO_ROOT.glob("*/*/*_ref.csv"))
# a window within one step, across a few steps (the scenarios' steps are 0.1 to 1 s), across many
TUBES = [Tube(0.05, 0.0), Tube(0.5, 1e-9), Tube(3.0, 0.25)]


def outcomes(folder, model, mode, steps, chunk_bytes):
    path = fmu_path(BUILD_DIR, model, 3)
    runner, fmu = worker_fmu(path.read_bytes(), str(path))
    target = Target(runner, fmu, {"fmu": fmu.label, "fmu_file": str(path), "fmu_folder": "f"})
    whole = on_the_whole(folder, runner, fmu, mode)
    long = run_folder_case(
        CaseFiles(folder, folder.name),
        target,
        CaseSettings(mode, "none"),
        Streaming(steps_per_chunk=steps, chunk_bytes=chunk_bytes),
    )
    return whole, long


def same(whole, long):
    """whole: on_the_whole's (status, messages, failing deviations, result), or a CaseOutcome."""
    if not isinstance(whole, tuple):
        whole = (whole.status, whole.messages, whole.deviations, None)
    status, messages, deviations, _ = whole
    assert (long.status, long.messages) == (status, messages)
    assert [d.to_json() for d in long.deviations] == [d.to_json() for d in deviations]


# the narrow tube in the fast lane (the varied references below take all three there)
@pytest.mark.parametrize(
    "mode",
    [TUBES[0], pytest.param(TUBES[1], marks=pytest.mark.slow), pytest.param(TUBES[2], marks=pytest.mark.slow)],
    ids=["narrow", "few-steps", "wide"],
)
def test_every_reference_scenario_in_a_tube_chunked_as_in_memory(mode):
    for folder in FOLDERS:  # single input rows and inputs between communication points (fmpy's loop) too
        whole, long = outcomes(folder, folder.parent.name, mode, 1, 8)
        same(whole, long)


def varied(tmp_path, how):
    folder = tmp_path / "RateLimiter" / how
    shutil.copytree(SCENARIO_ROOT / "RateLimiter" / "step_up", folder)
    ref = read_trace(folder / "RateLimiter_ref.csv")
    if how == "off":
        ref["y"][9] = ref["y"][9] + 0.5
        ref["y"][-1] = ref["y"][-1] - 7.0
    elif how == "repeated":
        ref = np.concatenate([ref[:4], ref[3:4], ref[4:]])
        ref["y"][3] = 99.0  # an event: the polyline jumps there
    elif how == "spike":
        ref["y"][9] = ref["y"][9] + 10.0  # t = 4.5: a one-sample spike in the reference
    elif how == "shorter":
        ref = ref[2:-3]  # result samples before and after the reference: outside its time range
    write_trace(folder / "RateLimiter_ref.csv", ref)
    return folder


@pytest.mark.parametrize("how", ["off", "repeated", "shorter", "spike"])
@pytest.mark.parametrize("mode", TUBES, ids=["narrow", "few-steps", "wide"])
def test_varied_references_in_a_tube_chunked_as_in_memory(how, mode, tmp_path):
    folder = varied(tmp_path, how)
    for steps, chunk_bytes in [(1, 8), (3, 30), (100, 1 << 20)]:
        whole, long = outcomes(folder, "RateLimiter", mode, steps, chunk_bytes)
        same(whole, long)
    # the result is the original reference: an added sample only widens the tube (and on the second side, the
    # value up to an instant is not a sample), fewer samples narrow its range; the ramp reaches 10 at t = 6, the
    # last sample, there made 3: every window around t = 6 tops at 9 (t = 5.5) + 0.25 at the most
    if how == "spike":  # outside the tube around the result, where the run holds its whole window (t <= 3 s before)
        assert whole[0] == ("pass" if mode.time > 1.5 else "fail"), whole[1]
        # (a tube narrower than the cycle: the spike is the whole window around the result's sample, too)
        assert mode.time > 1.5 or "the reference leaves the tube around the result" in whole[1][0], whole[1]
        return
    assert (whole[0] == "pass") == (how != "off")


SAMPLES = SCENARIO_ROOT.parent / "recordings"
TABLES = [
    ("codesys_v3_ratelimiter.csv", "RateLimiter"),
    ("plain_ratelimiter.tsv", "RateLimiter"),
    ("tia_portal_siemens.csv", "LGF_LimRateOfChangeCI"),
]


@pytest.mark.parametrize("mode", TUBES, ids=["narrow", "few-steps", "wide"])
@pytest.mark.parametrize(
    "name, model", TABLES + [("perturbed", "LGF_LimRateOfChangeCI")], ids=[t[0] for t in TABLES] + ["perturbed"]
)
def test_table_exports_in_a_tube_streamed_as_in_memory(name, model, mode, monkeypatch, tmp_path):
    """A one-file recording streamed in blocks of a few lines (its head 400
    bytes), in a tube: the outcome run_case gives reading it whole; the
    TIA Portal export with an output 0.25 off in one row fails the
    narrow tube, and names the row."""
    from fmutrace import _recording as worker  # (where a recording is chosen to stream)
    from fmutrace._recording import run_streamed_recording
    from fmutrace.recordings import _stream as stream
    from fmutrace.recordings._options import RecordingOptions

    path = SAMPLES / name
    if name == "perturbed":
        lines = (SAMPLES / "tia_portal_siemens.csv").read_text(encoding="cp1252").splitlines()
        assert ";0,5;" in lines[16]
        lines[16] = lines[16].replace(";0,5;", ";0,75;")
        path = tmp_path / "tia_portal_siemens.csv"
        path.write_text("\r\n".join(lines) + "\r\n", encoding="cp1252")
    fmu_file = fmu_path(BUILD_DIR, model, 3)
    runner, fmu = worker_fmu(fmu_file.read_bytes(), str(fmu_file))
    target = Target(runner, fmu, {"fmu": fmu.label, "fmu_file": str(fmu_file), "fmu_folder": "f"})
    settings = CaseSettings(mode, "none", RecordingOptions())
    monkeypatch.setattr(worker, "streamable", lambda path: False)
    whole = run_case(str(path), path.name, None, target, settings)
    monkeypatch.setattr(stream, "HEAD_BYTES", 400)
    for block in (40, 120, 1 << 20):
        streamed = run_streamed_recording(
            str(path), path.name, target, settings, Streaming(block_bytes=block, steps_per_chunk=3)
        )
        assert streamed is not None and streamed.streamed
        same(whole, streamed)
    if name == "perturbed" and mode == TUBES[0]:
        assert not whole.passed and any("line 17" in m for m in whole.messages), whole.messages


@pytest.mark.parametrize("criteria", [False, True], ids=["tube", "per-signal criteria"])
def test_the_second_sides_deviation_is_plotted(criteria, tmp_path):
    """A spike of the reference fails on the tube's second side: its page's
    plot data hold that side's deviation (the reference outside the tube
    around the result) with the spike's excess at its time, streamed and
    judged whole alike; the first side's deviation is 0 there."""
    import json

    folder = varied(tmp_path, "spike")
    tube = Tube(0.5, 1e-9)
    mode = fmutrace.Criteria({"y": tube}) if criteria else tube
    path = fmu_path(BUILD_DIR, "RateLimiter", 3)
    runner, fmu = worker_fmu(path.read_bytes(), str(path))
    target = Target(runner, fmu, {"fmu": fmu.label, "fmu_file": str(path), "fmu_folder": "f"})
    outcome = run_folder_case(CaseFiles(folder, folder.name), target, CaseSettings(mode, "all"), Streaming(1, 8))
    assert outcome.status == "fail" and "the reference leaves the tube around the result" in outcome.messages[0]
    data = json.loads(outcome.plot_js.removeprefix("window.fmutracePlot = ").rstrip().removesuffix(";"))
    (y,) = [s for s in data["signals"] if s["name"] == "y"]
    times, back = y["back"]
    # 17 at t = 4.5; the result around it (t = 4 to 5) tops at 8, and the tube at 8 + 1e-9
    assert max(back) == pytest.approx(9.0 - 1e-9) and times[back.index(max(back))] == 4.5
    assert data["back_label"] == "the reference outside the tube around the result"


def tube_bounds_one_by_one(reference_time, reference_values, times, widths, span=None):
    """The tube's bounds as csv-compare's definition reads, one sample at a
    time (the oracle of the vectorized comparison._comparison_tube.tube_bounds):
    the extremes of the reference's samples within the window (its edges
    up to the times' rounding) and of its polyline at the window's ends."""

    def polyline_at(at):
        k = int(np.searchsorted(reference_time, at, side="right")) - 1
        if k >= len(reference_time) - 1:
            return float(reference_values[-1])
        t0, t1 = reference_time[k], reference_time[k + 1]
        if t1 == t0:
            return float(reference_values[k + 1])
        return float(reference_values[k] + (reference_values[k + 1] - reference_values[k]) * (at - t0) / (t1 - t0))

    tube_time, tube_value = widths
    lower, upper = np.full(len(times), np.nan), np.full(len(times), np.nan)
    t_first, t_last = span if span is not None else (reference_time[0], reference_time[-1])
    for i, t in enumerate(times):
        if not t_first <= t <= t_last:
            continue
        start, end = max(t - tube_time, t_first), min(t + tube_time, t_last)
        slack = 1e-9 * max(1.0, abs(t))
        lo = np.searchsorted(reference_time, start - slack, "left")
        hi = np.searchsorted(reference_time, end + slack, "right")
        with np.errstate(invalid="ignore"):
            window = np.concatenate([reference_values[lo:hi], [polyline_at(start), polyline_at(end)]])
        if not np.isnan(window).all():
            lower[i], upper[i] = np.nanmin(window) - tube_value, np.nanmax(window) + tube_value
    return lower, upper


# seeds 0, 4 and 8 draw references longer than two sparse tables (QUERIES);
# 8 keeps them in the fast lane, 0 and 4 run in the slow lane
@pytest.mark.parametrize("seed", [pytest.param(s, marks=pytest.mark.slow) if s in (0, 4) else s for s in range(12)])
def test_the_tubes_bounds_at_once_are_the_bounds_one_sample_at_a_time(seed):
    """Random references (repeated times, NaN samples, steps of several
    sizes), the result's times on and off them, tubes from none to wider
    than the trace, with and without a span: the same bounds."""
    from fmutrace._comparison_tube import QUERIES, tube_bounds

    rng = np.random.default_rng(seed)
    n = int(rng.integers(1, 3 * QUERIES if seed % 4 == 0 else 200))
    steps = rng.choice([0.0, 0.01, 0.1, 0.25], size=n - 1, p=[0.05, 0.55, 0.3, 0.1])
    times = np.round(np.concatenate([[rng.uniform(-1, 1)], rng.uniform(-1, 1) + np.cumsum(steps)]), 6)
    values = rng.normal(size=n).round(2)
    values[rng.random(n) < 0.05] = np.nan
    result_times = np.sort(np.concatenate([times, rng.uniform(times[0] - 1, times[-1] + 1, size=n // 2)]))
    span = None if seed % 3 else (times[0] - 0.5 * rng.random(), times[-1] + 0.5 * rng.random())
    for tube_time in (0.0, 0.01, 0.1, 0.35, 2.0, 1e3):
        widths = (tube_time, float(rng.choice([0.0, 1e-6, 0.5])))
        at_once = tube_bounds(times, values, result_times, widths, span)
        one_by_one = tube_bounds_one_by_one(times, values, result_times, widths, span)
        for got, want in zip(at_once, one_by_one, strict=True):
            assert np.array_equal(got, want, equal_nan=True), (
                tube_time,
                np.flatnonzero(~((got == want) | (np.isnan(got) & np.isnan(want)))),
            )
