"""Channels that share a name: each is read and kept, named by its position
too (NAME#COLUMN; NAME#K in MDF), and a map chooses one by that name or by
its column (#N); a map by the shared name, or a variable several of them
mean, is refused naming every candidate and how to choose. On the
ModbusScope sample (tests/recordings/samples.py: modbusscope, written from
ModbusScope's data file exporter's layout), on small files written here
and on an MDF 2 file of asammdf's own writer."""

import json
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from fmutrace import InputError, TraceError
from fmutrace.cli import FLAGS
from fmutrace.recordings import normalise, plan, read_recording
from fmutrace.recordings._options import RecordingOptions
from support.fmu_driver import BUILD_DIR
from support.mdf import mdf_of_groups
from support.process import run as run_bounded

SAMPLES = Path(__file__).parents[1] / "recordings"
sys.path.insert(0, str(SAMPLES))
import samples  # noqa: E402  (the generator beside the samples)

MODBUSSCOPE = SAMPLES / "modbusscope_ratelimiter.csv"
RATE_LIMITER = {v: BUILD_DIR / f"fmi{v}" / "RateLimiter.fmu" for v in (2, 3)}
FMUTRACE = Path(sys.executable).parent / "fmutrace"
SHARED = "Register 40001"


def variables_of(**causalities):
    return {name: SimpleNamespace(causality=c, variability="continuous") for name, c in causalities.items()}


RATE_LIMITER_VARIABLES = variables_of(u="input", y="output", rampActive="output")


def read_one(path):
    recordings = read_recording(path)
    assert len(recordings) == 1
    return recordings[0]


def compare(*args):
    return run_bounded([str(FMUTRACE), "compare", *map(str, args)], timeout=600, what="fmutrace compare")


# -- the ModbusScope sample: one register plotted on three axes ----------------------------
def test_a_modbusscope_data_file_keeps_its_three_same_named_columns():
    recording = read_one(MODBUSSCOPE)
    assert recording.format == "ModbusScope data file" and recording.time_unit == "ms"
    assert [(c.name, c.written, c.column) for c in recording.channels] == [
        ("Register 40001#2", SHARED, 2),
        ("Register 40001#3", SHARED, 3),
        ("Register 40001#4", SHARED, 4),
        ("Register 40002", "", 5),
    ]
    y, u = samples.RATE_LIMITER["y"], samples.RATE_LIMITER["u"]
    raw, value, per_minute, drive = (c.values.tolist() for c in recording.channels)
    assert raw == [v * 100 for v in y] and value == y and per_minute == [v * 60 for v in y] and drive == u
    # the label row is line 19 (after the comments, a note and '//'): samples from line 20
    assert all(c.lines.tolist() == list(range(20, 20 + len(y))) for c in recording.channels)
    assert recording.channels[0].stamps.tolist() == [12 + 250 * k for k in range(len(y))]


def test_a_map_by_the_shared_name_is_refused_with_every_candidate_and_how_to_choose():
    recording = read_one(MODBUSSCOPE)
    with pytest.raises(InputError) as error:
        plan(recording, RATE_LIMITER_VARIABLES, "RateLimiter", [("y", SHARED)], names=FLAGS)
    assert str(error.value) == (
        f"--map \"y=Register 40001\": 3 channels of {MODBUSSCOPE} are 'Register 40001': 'Register 40001#2' "
        "(column 2); 'Register 40001#3' (column 3); 'Register 40001#4' (column 4); "
        'map one by its name, e.g. --map "y=Register 40001#2", or by its column, e.g. --map y=#2'
    )
    with pytest.raises(InputError) as error:  # a Python caller's words
        plan(recording, RATE_LIMITER_VARIABLES, "RateLimiter", [("y", SHARED)])
    assert str(error.value).endswith(
        "map one by its name, e.g. RecordingOptions(maps={'y': 'Register 40001#2'}), or by its column, "
        "e.g. RecordingOptions(maps={'y': '#2'})"
    )


@pytest.mark.parametrize("chosen", ["#3", "Register 40001#3"])
def test_a_same_named_column_is_chosen_by_its_column_or_its_name_made_unique(chosen):
    recording = read_one(MODBUSSCOPE)
    options = RecordingOptions(maps={"y": chosen, "u": "Register 40002"})
    result = plan(recording, RATE_LIMITER_VARIABLES, "RateLimiter", options.maps, options.names)
    assert [(v, c.name, c.column) for v, c in result.compares] == [("y", "Register 40001#3", 3)]
    assert [(v, c.column) for v, c in result.drives] == [("u", 5)]
    assert [(c.name, why) for c, why in result.ignored] == [
        ("Register 40001#2", "no variable of RateLimiter is named 'Register 40001'"),
        ("Register 40001#4", "no variable of RateLimiter is named 'Register 40001'"),
    ]


def test_a_map_to_a_column_that_holds_no_channel_names_the_columns_there_are():
    recording = read_one(MODBUSSCOPE)
    for column in ("#0", "#1", "#6"):  # before the first; the time column; past the last
        with pytest.raises(InputError) as error:
            plan(recording, RATE_LIMITER_VARIABLES, "RateLimiter", [("y", column)], names=FLAGS)
        assert str(error.value) == (
            f"--map y={column}: {MODBUSSCOPE} has no channel in column {column[1:]} (Register 40001#2 (column 2), "
            "Register 40001#3 (column 3), Register 40001#4 (column 4), Register 40002 (column 5))"
        )


def test_a_bad_cell_of_a_same_named_column_names_its_file_line_and_column(tmp_path):
    lines = MODBUSSCOPE.read_text().splitlines()
    assert lines[23] == "1012;100;1;60;2"
    lines[23] = "1012;100;1.0.0;60;2"
    path = tmp_path / "bad.csv"
    path.write_text("\r\n".join(lines) + "\r\n")
    with pytest.raises(TraceError) as error:
        read_recording(path)
    assert (error.value.path, error.value.line, error.value.column) == (str(path), 24, 3)
    assert "'1.0.0'" in str(error.value) and SHARED in str(error.value)


@pytest.mark.parametrize("version", [pytest.param(2, marks=pytest.mark.slow), 3])
def test_the_modbusscope_sample_compares_its_chosen_column_exactly(version, tmp_path):
    """End to end: y is the column that holds y (3); the raw count in column 2 fails at cycle 1. The
    file is read in blocks (streamed), whose columns are found by the channels' names."""
    fmu = RATE_LIMITER[version]
    done = compare(fmu, MODBUSSCOPE, "--map", "y=#3", "--map", "u=Register 40002", "--report", tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr
    assert json.loads((tmp_path / "results.json").read_text())["cases"][0]["streamed"] is True
    assert "ModbusScope data file" in done.stdout and "y <- Register 40001#3" in done.stdout
    done = compare(fmu, MODBUSSCOPE, "--map", "y=Register 40001#2", "--map", "u=Register 40002")
    assert done.returncode == 1, done.stdout + done.stderr
    assert "y <- Register 40001#2" in done.stdout
    assert f"y first differs at the recording's sample of cycle 1 ({MODBUSSCOPE}, line 21" in done.stdout
    done = compare(fmu, MODBUSSCOPE, "--map", f"y={SHARED}", "--map", "u=Register 40002")
    assert done.returncode == 2 and '--map "y=Register 40001": 3 channels of' in done.stdout + done.stderr


# -- the same rule for every reader ------------------------------------------------------
def test_channels_that_share_a_name_and_mean_a_variable_are_refused_each_named(tmp_path):
    path = tmp_path / "twice.csv"
    path.write_text("time,u,y,y\n0,0,0,1\n0.25,2,0.25,2\n")
    recording = read_one(path)
    assert [c.name for c in recording.channels] == ["u", "y#3", "y#4"]
    with pytest.raises(InputError) as error:
        plan(recording, RATE_LIMITER_VARIABLES, "RateLimiter", names=FLAGS)
    assert str(error.value) == (
        f"{path}: channels 'y#3' (column 3 of {path}) and 'y#4' (column 4 of {path}) both mean y: "
        "say which with --map y=CHANNEL, e.g. --map y=y#3"
    )
    result = plan(recording, RATE_LIMITER_VARIABLES, "RateLimiter", [("y", "#4")])
    assert [(v, c.name) for v, c in result.compares] == [("y", "y#4")]
    assert [(c.name, why) for c, why in result.ignored] == [("y#3", "y is mapped to 'y#4'")]


def test_a_made_name_another_column_has_gets_its_column_again(tmp_path):
    path = tmp_path / "taken.csv"
    path.write_text("time;y;y;y#2\n0;1;2;3\n")
    assert [c.name for c in read_one(path).channels] == ["y#2#2", "y#3", "y#2"]


def test_scope_view_channels_of_one_symbol_or_one_name_are_chosen_by_column(tmp_path):
    """TwinCAT Scope View: channels may share their SymbolName (scaled, shifted copies: the corpus's
    nine of MAIN.var_REAL) and even their Name; the same rule names and chooses them."""
    path = tmp_path / "same_symbol.csv"
    path.write_text(
        "Name\tScope\nFile\tx.csv\n\n\n"
        "Name\tvar_REAL32\tName\tfunc_scaled\tName\tfunc_scaled\tName\tu\n"
        "SampleTime[ms]\t1\tSampleTime[ms]\t1\tSampleTime[ms]\t1\tSampleTime[ms]\t1\n"
        "SymbolName\tMAIN.var_REAL\tSymbolName\tMAIN.var_REAL\tSymbolName\tMAIN.var_REAL\tSymbolName\tMAIN.u\n"
        "\n0\t1\t0\t-1\t0\t7\t0\t5\n1\t2\t1\t-2\t1\t8\t1\t5\n"
    )
    recording = normalise(read_one(path))
    assert [(c.name, c.column) for c in recording.channels] == [
        ("var_REAL32", 2),
        ("func_scaled#4", 4),
        ("func_scaled#6", 6),
        ("u", 8),
    ]
    with pytest.raises(InputError) as error:
        plan(recording, RATE_LIMITER_VARIABLES, "M", [("y", "MAIN.var_REAL")], names=FLAGS)
    assert str(error.value) == (
        f"--map y=MAIN.var_REAL: 3 channels of {path} are 'MAIN.var_REAL': 'var_REAL32' (symbol "
        "'MAIN.var_REAL', column 2); 'func_scaled#4' (symbol 'MAIN.var_REAL', column 4); 'func_scaled#6' "
        "(symbol 'MAIN.var_REAL', column 6); map one by its name, e.g. --map y=var_REAL32, or by its column, "
        "e.g. --map y=#2"
    )
    with pytest.raises(InputError, match=r"--map y=func_scaled: 2 channels of .* are 'func_scaled'"):
        plan(recording, RATE_LIMITER_VARIABLES, "M", [("y", "func_scaled")], names=FLAGS)
    for chosen in ("#6", "func_scaled#6"):
        result = plan(recording, RATE_LIMITER_VARIABLES, "M", [("y", chosen)])
        assert [(v, c.values.tolist()) for v, c in result.compares] == [("y", [7.0, 8.0])]


def test_an_mdf_2_file_is_named_mdf_2(tmp_path):
    values = samples.SIEMENS["value"]
    path = mdf_of_groups(tmp_path / "old.mdf", [(np.arange(len(values)) * 0.25, {"value": values})], version="2.00")
    assert Path(path).read_bytes()[:12] == b"MDF     2.00"  # the identification block: asammdf wrote MDF 2.00
    recording = read_one(path)
    assert recording.format == "ASAM MDF 2"
    assert [(c.name, c.values.tolist()) for c in recording.channels] == [("value", samples.SIEMENS["value"])]


def test_mdf_channels_of_one_name_in_several_groups_are_each_kept_and_chosen_by_name(tmp_path):
    """MDF channels have no columns: the K-th channel of a name is NAME#K, in the file's order."""
    path = mdf_of_groups(tmp_path / "two.mf4", [([0, 0.25], {"y": [0, 1], "u": [0, 2]}), ([0, 0.25], {"y": [5, 6]})])
    recording = read_one(path)
    assert [c.name for c in recording.channels] == ["y#1", "u", "y#2"]
    with pytest.raises(InputError) as error:
        plan(recording, RATE_LIMITER_VARIABLES, "M", [("y", "y")], names=FLAGS)
    assert str(error.value) == (
        f"--map y=y: 2 channels of {path} are 'y': 'y#1' (in {path}); 'y#2' (in {path}); "
        "map one by its name, e.g. --map y=y#1"
    )
    result = plan(recording, RATE_LIMITER_VARIABLES, "M", [("y", "y#2")])
    assert [(v, c.values.tolist()) for v, c in result.compares] == [("y", [5.0, 6.0])]
    for column in ("#0", "#2"):
        with pytest.raises(InputError, match=r"has no channel in column \d \(its channels have no columns \(MDF\)"):
            plan(recording, RATE_LIMITER_VARIABLES, "M", [("y", column)])


def test_a_modbusscope_file_with_absolute_times_reads_its_day_first_dates(tmp_path):
    """ModbusScope's 'absolute times' write dd/MM/yyyy HH:mm:ss and the locale's decimal mark before
    the ms (its FormatDateTime) in the column still labelled 'Time (ms)'."""
    path = tmp_path / "absolute.csv"
    path.write_text(
        "//ModbusScope version;3.6.0\r\n//\r\nTime (ms);Register 40001;Register 40001\r\n"
        "01/02/2026 23:59:59,900;0;0\r\n02/02/2026 00:00:00,150;25;0,25\r\n"
    )
    recording = normalise(read_one(path))
    assert recording.time_unit == "date"
    assert [(c.name, c.times.tolist(), c.values.tolist()) for c in recording.channels] == [
        ("Register 40001#2", [0.0, 0.25], [0.0, 25.0]),
        ("Register 40001#3", [0.0, 0.25], [0.0, 0.25]),
    ]
