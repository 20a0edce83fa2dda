"""The one pipeline (fmutrace._pipeline) reads, runs and compares a case
chunk by chunk; its outcome is the whole trace's (the result of
Runner.run compared by comparison.compare_traces on the whole arrays),
bit for bit: status, messages and every failing signal's deviation, on
every reference scenario (in chunks of a few steps and a few rows, so
every boundary case occurs, and in one chunk) and on references made to
fail (one ulp off, a sample the result lacks, a repeated time), exact and
with a tolerance. `fmutrace run` in chunks writes what simulate gives.
Its progress shows on a terminal only."""

import io
import re
import shutil

from pathlib import Path

import numpy as np
import pytest

from fmutrace import Exact, Tolerance, read_trace, write_trace
from fmutrace._pipeline import CaseFiles, Streaming, run_folder_case
from fmutrace._progress import SampleProgress
from fmutrace._simulation import SimulationOptions, simulate, simulate_chunks
from fmutrace._traces import TraceWriter, last_time
from fmutrace._worker import CaseSettings, Target, worker_fmu
from support.scenarios import SCENARIO_ROOT, fmu_path
from support.fmu_driver import BUILD_DIR
from support.whole_case import on_the_whole

FOLDERS = sorted(p.parent for p in SCENARIO_ROOT.glob("*/*/*_ref.csv"))
MODES = [Exact(), Tolerance(rel_tol=1e-12, abs_tol=0.0)]


def outcomes(folder, version, mode, steps, chunk_bytes):
    path = fmu_path(BUILD_DIR, folder.parent.name, version)
    runner, fmu = worker_fmu(path.read_bytes(), str(path))
    labels = {"fmu": fmu.label, "fmu_file": str(path), "fmu_folder": "f"}
    whole = on_the_whole(folder, runner, fmu, mode)
    long = run_folder_case(
        CaseFiles(folder, folder.name),
        Target(runner, fmu, labels),
        CaseSettings(mode, "none"),
        Streaming(steps_per_chunk=steps, chunk_bytes=chunk_bytes),
    )
    return whole, long


def same(whole, long):
    status, messages, deviations, _ = whole
    assert long.status == status
    assert long.messages == messages
    assert [d.to_json() for d in long.deviations] == [d.to_json() for d in deviations]


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("steps,chunk_bytes", [(1, 8), (4, 40), (1000, 1 << 20)])
def test_every_reference_scenario_chunked_as_in_memory(version, steps, chunk_bytes):
    for folder in FOLDERS:  # single input rows and inputs between communication points (fmpy's loop) too
        whole, long = outcomes(folder, version, MODES[0], steps, chunk_bytes)
        same(whole, long)


def failing_copy(tmp_path, how):
    source = SCENARIO_ROOT / "RateLimiter" / "step_up"
    folder = tmp_path / "RateLimiter" / how
    shutil.copytree(source, folder)
    ref = read_trace(folder / "RateLimiter_ref.csv")
    if how == "ulp":
        ref["y"][5] = np.nextafter(ref["y"][5], np.inf)
        ref["y"][9] = ref["y"][9] + 0.5
    elif how == "absent":
        ref["time"][7] = ref["time"][7] + 0.2
    elif how == "repeated":
        ref = np.concatenate([ref[:4], ref[3:4], ref[4:]])
        ref["y"][3] = 99.0  # the first of two rows at one time: not compared
    write_trace(folder / "RateLimiter_ref.csv", ref)
    return folder


@pytest.mark.parametrize("how", ["ulp", "absent", "repeated"])
@pytest.mark.parametrize("mode", MODES, ids=["exact", "tolerance"])
def test_failing_references_chunked_as_in_memory(how, mode, tmp_path):
    folder = failing_copy(tmp_path, how)
    for steps, chunk_bytes in [(1, 8), (3, 30), (100, 1 << 20)]:
        whole, long = outcomes(folder, 3, mode, steps, chunk_bytes)
        same(whole, long)
    assert long.passed == (how == "repeated")


@pytest.mark.parametrize("spill", [0, 1 << 22], ids=["in-a-file-as-made", "in-memory-until-kept"])
def test_a_long_failing_case_plots_a_zoom_and_keeps_its_result(spill, tmp_path, monkeypatch):
    import fmutrace._pipeline as pipeline

    monkeypatch.setattr(pipeline, "SPILL_BYTES", spill)
    monkeypatch.setattr(pipeline.tempfile, "tempdir", str(tmp_path / "temp"))
    (tmp_path / "temp").mkdir()
    folder = failing_copy(tmp_path, "ulp")
    path = fmu_path(BUILD_DIR, "RateLimiter", 3)
    runner, fmu = worker_fmu(path.read_bytes(), str(path))
    labels = {"fmu": fmu.label, "fmu_file": str(path), "fmu_folder": "f"}
    settings = {"keep_result": True, "steps_per_chunk": 2, "chunk_bytes": 16}
    long = run_folder_case(
        CaseFiles(folder, "ulp"),
        Target(runner, fmu, labels),
        CaseSettings(Exact(), "failed", png=True),
        Streaming(**settings),
    )
    assert not long.passed and long.png.startswith(b"\x89PNG") and long.plot_js.startswith("window.fmutracePlot")
    whole = on_the_whole(folder, runner, fmu, Exact())
    write_trace(tmp_path / "whole.csv", whole[3])
    out = Path(long.result_path)
    assert out.parent == tmp_path / "temp" and out.read_bytes() == (tmp_path / "whole.csv").read_bytes()
    passing = run_folder_case(  # no plot: no result file, none left behind
        CaseFiles(SCENARIO_ROOT / "RateLimiter" / "step_up", "step_up"),
        Target(runner, fmu, labels),
        CaseSettings(Exact(), "failed"),
        Streaming(**settings),
    )
    assert passing.passed and not passing.result_path and sorted((tmp_path / "temp").iterdir()) == [out]


def test_run_in_chunks_writes_what_simulate_gives(tmp_path):
    scenario = SCENARIO_ROOT / "RateLimiter" / "asymmetric"
    path = fmu_path(BUILD_DIR, "RateLimiter", 3)
    start = {"rateUpPar": "2.0", "rateDownPar": "0.5"}
    written = 0
    with open(tmp_path / "long.csv", "w", newline="\n") as out:
        writer = None
        for chunk in simulate_chunks(
            path,
            scenario / "RateLimiter_in.csv",
            SimulationOptions(start, 0.0, 8.0, 0.5),
            chunk_bytes=8,
            steps_per_chunk=3,
        ):
            writer = writer or TraceWriter(out, chunk.dtype.names)
            writer.write(chunk)
            written += len(chunk)
    whole = simulate(
        path, scenario / "RateLimiter_in.csv", start_values=start, start_time=0.0, stop_time=8.0, step_size=0.5
    )
    write_trace(tmp_path / "whole.csv", whole)
    assert written == len(whole)
    assert (tmp_path / "long.csv").read_bytes() == (tmp_path / "whole.csv").read_bytes()


class Stream(io.StringIO):
    def __init__(self, terminal):
        super().__init__()
        self.terminal = terminal

    def isatty(self):
        return self.terminal


@pytest.mark.parametrize("terminal", [True, False])
def test_a_long_case_shows_its_progress_on_a_terminal_only(terminal, monkeypatch):
    monkeypatch.setattr(SampleProgress, "AFTER_SECONDS", 0.0)
    monkeypatch.setattr(SampleProgress, "EVERY_SECONDS", 0.0)
    stream = Stream(terminal)
    bar = SampleProgress(1_000_000, stream)
    bar.update(250_000)
    bar.update(1_000_000)
    bar.close()
    if terminal:
        lines = stream.getvalue().split("\r")
        assert re.fullmatch(r"250,000/1,000,000 samples, [0-9.]+ M/s, [0-9]+ s left ", lines[1])
        assert lines[-1].startswith("1,000,000/1,000,000 samples") and lines[-1].endswith(" 0 s left \n")
    else:
        assert stream.getvalue() == ""


@pytest.mark.parametrize("width", [10, 5000, 100_000])
def test_the_stop_time_is_read_from_a_last_line_of_any_length(width, tmp_path):
    names = ["time"] + [f"s{i}" for i in range(width // 10)]
    lines = [
        ",".join(names),
        ",".join(["0.5"] + ["1.25"] * (len(names) - 1)),
        ",".join(["7.75"] + ["0.123456789"] * (len(names) - 1)),
    ]
    path = tmp_path / "wide.csv"
    path.write_text("\n".join(lines) + "\n\n")
    assert last_time(path) == 7.75


@pytest.mark.parametrize("parts", [1, 2, 7])
def test_a_verdict_given_in_chunks_is_the_verdict_on_the_whole(parts):
    from fmutrace._comparison import Band, Verdict, verdict_of

    rng = np.random.default_rng(parts)
    times = np.arange(50) * 0.1
    expected = rng.integers(-3, 4, 50).astype(float)
    values = expected.copy()
    values[[4, 17, 30]] += [0.5, -2.0, 2.0]
    values[40] = np.nan  # an infinite excess: the largest
    for mode in MODES:
        lower, upper, ok = mode.bounds(values, expected)
        band = Band(times, values, lower, upper, ok, values - expected)
        verdict = Verdict("y")
        for piece in np.array_split(np.arange(50), parts):
            verdict.add(Band(*(a[piece] for a in (times, values, lower, upper, ok, values - expected))))
        assert verdict.deviation.to_json() == verdict_of("y", band).to_json()
        assert verdict.deviation.largest_at == times[40] and verdict.deviation.time == times[4]
