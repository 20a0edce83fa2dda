"""A long one-file recording streamed in blocks (fmutrace.recordings._stream)
gives the in-memory path's outcome (worker.run_case reading the whole
file), bit for bit: status, messages (notes, the recorded sample at a
first deviation, with its line) and every failing signal's deviation.
On the table exports of tests/recordings and variants of them written
here (perturbed, off-cycle stamps, the other timing, a tolerance, a
printed 10 ms ramp), with a head and blocks of a few lines so that every
boundary occurs; and what the streamed path leaves to the in-memory one."""

import tempfile
from pathlib import Path

import numpy as np
import pytest

from fmutrace import Exact, Tolerance
from fmutrace import _recording as worker  # (where a recording is chosen to stream)
from fmutrace._fmu import Fmu
from fmutrace._recording import streamable, run_streamed_recording
from fmutrace.recordings import _stream as stream, _timebase as timebase
from fmutrace.recordings._options import RecordingOptions
from fmutrace._runner import Runner
from fmutrace._pipeline import Streaming
from fmutrace._worker import CaseSettings, Target, run_case, worker_fmu
from support.fmu_driver import BUILD_DIR
from support.scenarios import fmu_path

SAMPLES = Path(__file__).parents[1] / "recordings"


def outcomes(path, model, mode=None, options=None, head=400, block=120, version=3, monkeypatch=None):
    """(in memory, streamed) outcomes of the recording at path (exact, the default options unless given);
    streamed is None where the stream refused."""
    mode = Exact() if mode is None else mode
    options = RecordingOptions() if options is None else options
    fmu_file = fmu_path(BUILD_DIR, model, version)
    runner, fmu = worker_fmu(fmu_file.read_bytes(), str(fmu_file))
    labels = {"fmu": fmu.label, "fmu_file": str(fmu_file), "fmu_folder": "f"}
    monkeypatch.setattr(worker, "streamable", lambda path: False)
    whole = run_case(str(path), path.name, None, Target(runner, fmu, labels), CaseSettings(mode, "none", options))
    monkeypatch.setattr(stream, "HEAD_BYTES", head)
    streamed = run_streamed_recording(
        str(path),
        path.name,
        Target(runner, fmu, labels),
        CaseSettings(mode, "none", options),
        Streaming(block_bytes=block, steps_per_chunk=3),
    )
    return whole, streamed


def same(whole, streamed):
    assert streamed is not None and streamed.streamed and not whole.streamed  # told apart in results.json
    assert streamed.status == whole.status
    assert streamed.messages == whole.messages
    assert [d.to_json() for d in streamed.deviations] == [d.to_json() for d in whole.deviations]


def copy(tmp_path, name, edit=None, encoding="utf-8-sig"):
    """A sample recording, its lines edited (edit(lines) -> lines), written with CR LF."""
    lines = (SAMPLES / name).read_text(encoding=encoding).splitlines()
    path = tmp_path / name
    path.write_text("\r\n".join(edit(lines) if edit else lines) + "\r\n", encoding=encoding)
    return path


TABLES = [
    ("codesys_v3_ratelimiter.csv", "RateLimiter", "utf-8-sig"),
    ("plain_ratelimiter.tsv", "RateLimiter", "utf-8"),
    ("tia_portal_siemens.csv", "LGF_LimRateOfChangeCI", "cp1252"),
]


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("name, model, encoding", TABLES, ids=[t[0] for t in TABLES])
@pytest.mark.parametrize("head, block", [(400, 40), (400, 1 << 20), (1 << 20, 1)])
def test_table_exports_streamed_as_in_memory(name, model, encoding, head, block, version, monkeypatch):
    whole, streamed = outcomes(SAMPLES / name, model, head=head, block=block, version=version, monkeypatch=monkeypatch)
    same(whole, streamed)
    assert whole.passed


def perturbed(lines):
    lines[14] = lines[14].replace(";2,5;", ";2,5000001;")
    lines[16] = lines[16].replace(";0,5;", ";0,75;")
    return lines


def off_cycle(lines):
    """Stamps 80 ms late from the sixth row on, every other row: the grid of cycles they fit runs between
    the late ones and the others, each more than a tenth of the 250 ms cycle off it."""
    for i in range(10, len(lines), 2):
        cells = lines[i].split(";")
        cells[1] = str(int(cells[1]) + 80)
        lines[i] = ";".join(cells)
    return lines


@pytest.mark.parametrize("edit", [perturbed, off_cycle])
@pytest.mark.parametrize("mode", [Exact(), Tolerance(rel_tol=0.0, abs_tol=0.1)], ids=["exact", "tolerance"])
@pytest.mark.parametrize("timing", ["cycle", "fmi"])
def test_failing_and_noted_recordings_streamed_as_in_memory(edit, mode, timing, tmp_path, monkeypatch):
    path = copy(tmp_path, "tia_portal_siemens.csv", edit, encoding="cp1252")
    whole, streamed = outcomes(
        path, "LGF_LimRateOfChangeCI", mode, RecordingOptions(timing=timing), monkeypatch=monkeypatch
    )
    same(whole, streamed)
    if edit is perturbed and timing == "cycle" and isinstance(mode, Exact):
        assert not whole.passed and any(
            "first differs at the recording's sample of cycle 8" in m and "line 15" in m for m in whole.messages
        )
    if edit is off_cycle:
        assert any("off their cycle" in m for m in whole.messages)


def test_a_printed_10_ms_ramp_streamed_as_in_memory(tmp_path, monkeypatch):
    """Stamps in ms, printed decimals: the step from the whole file's intervals (10 ms), a failing exact
    comparison and a passing one within the printing."""
    rows = [(k * 10, 0 if k == 0 else 2, min(2.0, 0.01 * k)) for k in range(300)]
    path = tmp_path / "ramp_10ms.csv"
    path.write_text("Time [ms];u;y\n" + "".join(f"{t};{u};{y:.6f}\n".replace(".", ",") for t, u, y in rows))
    for mode in (Exact(), Tolerance(abs_tol=5e-7)):
        whole, streamed = outcomes(path, "RateLimiter", mode, monkeypatch=monkeypatch)
        same(whole, streamed)
    assert whole.passed and "step 0.01 s" in " ".join(whole.messages)


@pytest.mark.parametrize("lengths", ["recorded", "nominal"])
@pytest.mark.parametrize("overruns", [False, True])
@pytest.mark.parametrize("timing", ["cycle", "fmi"])
@pytest.mark.parametrize("block", [40, 1 << 20])
def test_jittered_stamps_streamed_as_in_memory(lengths, overruns, timing, block, tmp_path, monkeypatch):
    """Stamps in ms that jitter by up to 4 ms of a 10 ms cycle (and, with overruns, a cycle skipped now
    and then: cycles 1 and 2, 37, 100 to 103, 199), with recorded or nominal cycle lengths (RateLimiter,
    cycleTime 0, so each step's length shapes the ramp): the cycles the stream finds block by block, and
    the steps it makes in chunks of 3, are the ones made from the whole file: the same outcome,
    deviations, notes and missing cycles (the reference y is the input, which the ramp lags behind)."""
    rng = np.random.default_rng(11)
    cycles = np.arange(200)
    if overruns:
        cycles = np.setdiff1d(np.arange(204), [1, 2, 37, 100, 101, 102, 103, 199])
    stamps = cycles * 10 + np.concatenate([[0], rng.integers(-4, 5, len(cycles) - 1)])
    u = np.repeat([0.0, 3.0, -2.0, 5.0], 50)[: len(cycles)]
    path = tmp_path / "jittered.csv"
    path.write_text("Time [ms];u;y\n" + "".join(f"{t};{v};{v}\n" for t, v in zip(stamps, u, strict=True)))
    options = RecordingOptions(
        cycle_lengths=lengths, timing=timing, start_values=(("rateUpPar", "40"), ("rateDownPar", "40"))
    )
    whole, streamed = outcomes(path, "RateLimiter", options=options, head=1 << 20, block=block, monkeypatch=monkeypatch)
    same(whole, streamed)
    lines = ("cycle_s", "phase_s")  # (the line's sums merged block by block: the last bits may differ)
    assert {k: v for k, v in streamed.clock.items() if k not in lines} == {
        k: v for k, v in whole.clock.items() if k not in lines
    }
    assert [streamed.clock[k] for k in lines] == pytest.approx([whole.clock[k] for k in lines], rel=1e-12)
    assert not whole.passed and any(
        ("cycle lengths as recorded" in m) == (lengths == "recorded") for m in whole.messages
    )
    assert whole.clock["missing_cycles"] == (8 if overruns else 0)
    if overruns:
        assert whole.clock["first_missing"] == [1, 2, 37, 100, 101, 102, 103, 199]


def test_what_the_stream_leaves_to_the_in_memory_path(tmp_path, monkeypatch):
    """A repeated row (two on one cycle), an empty cell, a blank line inside, a step the head does not
    show: the stream refuses before anything is reported; the in-memory path reads or explains them. A
    skipped cycle (an overrun) the stream takes, as the in-memory path does."""

    def skipped(lines):
        return lines[:10] + lines[11:]

    def repeated(lines):
        return lines[:11] + lines[10:]

    def empty(lines):
        lines[12] = lines[12].replace(";4;", ";;")
        return lines

    def blank(lines):
        return lines[:12] + [""] + lines[12:]

    for edit in (repeated, empty, blank):
        path = copy(tmp_path, "tia_portal_siemens.csv", edit, encoding="cp1252")
        whole, streamed = outcomes(path, "LGF_LimRateOfChangeCI", monkeypatch=monkeypatch)
        assert streamed is None, edit.__name__
    path = copy(tmp_path, "tia_portal_siemens.csv", skipped, encoding="cp1252")
    whole, streamed = outcomes(path, "LGF_LimRateOfChangeCI", monkeypatch=monkeypatch)
    same(whole, streamed)
    assert any("1 of " in m and "cycles have no sample" in m for m in streamed.messages), streamed.messages
    # the head's rows every 10 ms, the rest every 20 ms: the whole file's median interval is 20 ms
    rows = [(k * 10, 1.0) for k in range(12)] + [(120 + k * 20, 1.0) for k in range(40)]
    path = tmp_path / "two_steps.csv"
    path.write_text("Time [ms];u;y\n" + "".join(f"{t};{u};{u}\n" for t, u in rows))
    whole, streamed = outcomes(path, "RateLimiter", head=120, monkeypatch=monkeypatch)
    assert streamed is None


def test_a_recording_the_stream_gives_up_on_gets_the_in_memory_outcome_and_its_run_is_closed(tmp_path, monkeypatch):
    """Through run_case, streamed first as a long recording is: an empty
    cell found after the FMU ran gives the in-memory path's outcome, and
    the stream's run (run_chunks, suspended at its last chunk) is closed."""

    def empty(lines):
        lines[12] = lines[12].replace(";4;", ";;")
        return lines

    path = copy(tmp_path, "tia_portal_siemens.csv", empty, encoding="cp1252")
    fmu_file = fmu_path(BUILD_DIR, "LGF_LimRateOfChangeCI", 3)
    runner, fmu = worker_fmu(fmu_file.read_bytes(), str(fmu_file))
    labels = {"fmu": fmu.label, "fmu_file": str(fmu_file), "fmu_folder": "f"}
    monkeypatch.setattr(worker, "streamable", lambda path: False)
    whole = run_case(
        str(path), path.name, None, Target(runner, fmu, labels), CaseSettings(Exact(), "none", RecordingOptions())
    )
    runs = []
    run_chunks = runner.run_chunks

    def kept_run_chunks(*args, **kwargs):
        runs.append(run_chunks(*args, **kwargs))
        return runs[-1]

    monkeypatch.setattr(runner, "run_chunks", kept_run_chunks)
    monkeypatch.setattr(worker, "streamable", lambda path: True)
    monkeypatch.setattr(stream, "HEAD_BYTES", 400)
    first = run_case(
        str(path), path.name, None, Target(runner, fmu, labels), CaseSettings(Exact(), "none", RecordingOptions())
    )
    # the stream's run started, given up on and closed; the in-memory path's own run (the same Runner) done
    assert len(runs) == 2 and runs[0].gi_frame is None and runs[1].gi_frame is None
    assert (first.status, first.messages, first.streamed) == (whole.status, whole.messages, False)
    assert [d.to_json() for d in first.deviations] == [d.to_json() for d in whole.deviations]


def test_a_bad_time_column_is_refused_before_the_fmu_runs(tmp_path, monkeypatch):
    """A repeated row, time going backwards, a time cell that is no number
    (each past the head), a step the head does not show: the pass over the
    time column refuses the file before the FMU is instantiated (no run,
    no result file), and run_case gives the in-memory outcome, which names
    the file, line and column."""

    def repeated(lines):
        return lines[:17] + lines[16:]

    def backwards(lines):
        lines[16], lines[17] = lines[17], lines[16]
        return lines

    def not_a_number(lines):
        cells = lines[16].split(";")
        cells[1] = "12x"
        lines[16] = ";".join(cells)
        return lines

    def refused(path, model):
        """Whether the stream refuses the recording at path with its FMU never instantiated."""
        fmu_file = fmu_path(BUILD_DIR, model, 3)
        runner = Runner(fmu_file.read_bytes())  # its own: worker_fmu's are shared
        fmu = Fmu(str(fmu_file), runner.md)
        labels = {"fmu": fmu.label, "fmu_file": str(fmu_file), "fmu_folder": "f"}
        streamed = run_streamed_recording(
            str(path),
            path.name,
            Target(runner, fmu, labels),
            CaseSettings(Exact(), "all", RecordingOptions()),
            Streaming(keep_result=True, block_bytes=120),
        )
        return streamed is None and runner.fmu is None and runner.fast_runs == 0 and not any(temp.iterdir())

    temp = tmp_path / "temp"  # where a result file would be written
    temp.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(temp))

    monkeypatch.setattr(stream, "HEAD_BYTES", 400)
    for edit in (repeated, backwards, not_a_number):
        path = copy(tmp_path, "tia_portal_siemens.csv", edit, encoding="cp1252")
        assert len(b"".join(path.read_bytes().splitlines(keepends=True)[:16])) > 400  # the row is past the head
        assert refused(path, "LGF_LimRateOfChangeCI"), edit.__name__
    monkeypatch.setattr(worker, "streamable", lambda path: True)
    fmu_file = fmu_path(BUILD_DIR, "LGF_LimRateOfChangeCI", 3)
    runner = Runner(fmu_file.read_bytes())
    fmu = Fmu(str(fmu_file), runner.md)
    labels = {"fmu": fmu.label, "fmu_file": str(fmu_file), "fmu_folder": "f"}
    outcome = run_case(
        str(path), path.name, None, Target(runner, fmu, labels), CaseSettings(Exact(), "none", RecordingOptions())
    )
    assert (outcome.status, outcome.streamed, runner.fmu, runner.fast_runs) == ("invalid", False, None, 0)
    assert outcome.messages == [
        f"{path}, line 17, column 2: '12x' in column 'Time [ms]' is not a number, TRUE/FALSE or an IEC literal (16#...)"
    ]
    # the head's rows every 10 ms, the rest every 20 ms: the whole file's median interval is 20 ms
    rows = [(k * 10, 1.0) for k in range(12)] + [(120 + k * 20, 1.0) for k in range(40)]
    path = tmp_path / "two_steps.csv"
    path.write_text("Time [ms];u;y\n" + "".join(f"{t};{u};{u}\n" for t, u in rows))
    monkeypatch.setattr(stream, "HEAD_BYTES", 120)
    assert refused(path, "RateLimiter")


def test_intervals_median_is_numpys():
    rng = np.random.default_rng(5)
    for n in (1, 2, 3, 10, 11):
        times = np.cumsum(rng.choice([0.01, 0.010000000000000009, 0.009999999999999787, 0.0], n + 1))
        counted = timebase.Intervals()
        for piece in np.array_split(times, 3):
            if len(piece):
                counted.add(piece)
        steps = np.diff(times)
        steps = steps[steps > 0]
        assert counted.median() == (float(np.median(steps)) if len(steps) else None)


def test_a_short_one_file_export_is_streamed_too_and_other_recordings_read_whole():
    """No size decides the path: a one-file table export of a few lines is
    read in blocks as a 48 h one is; several files (a recording given as
    its parts) are read whole."""
    fmu_file = fmu_path(BUILD_DIR, "RateLimiter", 3)
    runner, fmu = worker_fmu(fmu_file.read_bytes(), str(fmu_file))
    labels = {"fmu": fmu.label, "fmu_file": str(fmu_file), "fmu_folder": "f"}
    path = SAMPLES / "plain_ratelimiter.tsv"
    assert path.stat().st_size < 4096 and streamable(path)
    outcome = run_case(str(path), path.name, None, Target(runner, fmu, labels), CaseSettings(Exact(), "none"))
    assert outcome.streamed and outcome.passed, outcome.messages
    siemens = fmu_path(BUILD_DIR, "LGF_LimRateOfChangeCI", 3)
    runner, fmu = worker_fmu(siemens.read_bytes(), str(siemens))
    labels = {"fmu": fmu.label, "fmu_file": str(siemens), "fmu_folder": "f"}
    folder = SAMPLES / "niagara_siemens"  # a Niagara history export: one file per point
    assert not streamable(folder)
    outcome = run_case(str(folder), folder.name, None, Target(runner, fmu, labels), CaseSettings(Exact(), "none"))
    assert not outcome.streamed and outcome.passed, outcome.messages
