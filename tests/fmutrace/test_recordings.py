"""fmutrace's readers of recordings as controllers' recorders export them
(fmutrace.recordings), on the sample recordings in tests/recordings
(written by tests/recordings/samples.py from each export's documented
structure) and on small files written here for each rule and each bad
input. The samples' values are worked by hand (samples.py) and checked
here against the tests' independent oracle; none comes from an FMU."""

import math
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from fmutrace import InputError, TraceError
from fmutrace.cli import FLAGS
from fmutrace.recordings import FORMAT_NAMES, is_recording, last_component, normalise, plan, read_file, read_recording
from fmutrace._recorded import recorded_case
from fmutrace.recordings._align import align
from fmutrace.recordings._options import RecordingOptions
from fmutrace.recordings._text import decode, numbers
from fmutrace._traces import split_cells as split
from fmutrace.recordings._timebase import parse_date, unit_in_name
from support.mdf import mdf_of_groups
from support.oracle import oracle_for

SAMPLES = Path(__file__).parents[1] / "recordings"
sys.path.insert(0, str(SAMPLES))
import samples  # noqa: E402  (the generator beside the samples)

CYCLE = samples.CYCLE


def read_one(path, **normalise_options):
    recordings = read_recording(path)
    assert len(recordings) == 1
    return normalise(recordings[0], **normalise_options)


def channel(recording, name):
    return next(c for c in recording.channels if last_component(c.symbol or c.name) == name)


# -- the samples are the hand-worked tables, as each export writes them ---------------
def test_the_sample_files_are_what_their_generator_writes():
    for name in samples.SAMPLES:
        assert (SAMPLES / name).read_bytes() == samples.sample_bytes(name), name


@pytest.mark.parametrize(
    "model, table, inputs, outputs",
    [
        ("LGF_LimRateOfChangeCI", samples.SIEMENS, ("value", "setChangeRate"), ("delayedValue", "status")),
        ("RateLimiter", samples.RATE_LIMITER, ("u",), ("y", "rampActive")),
    ],
)
def test_the_hand_worked_tables_agree_with_the_oracle(model, table, inputs, outputs):
    """Each row is one cycle: the oracle steps from k*h with the row's inputs and its outputs after the
    step are the row's outputs (the recorder's convention)."""
    vr = {
        name: i
        for i, name in enumerate(
            list(table) + ["rateUp", "rateDown", "bypassValue", "duration", "callOB", "cycleTime", "setChangeRate"]
        )
    }
    first = {name: float(table[name][0]) for name in inputs}
    oracle = oracle_for(model, vr, first)
    for k in range(len(table[inputs[0]])):
        out = oracle.do_step(k * CYCLE, CYCLE, {name: float(table[name][k]) for name in inputs})
        for name in outputs:
            assert float(out[name]) == float(table[name][k]), (name, k)


EVERY_CYCLE_SIEMENS = {
    "twincat_siemens.csv": ("Beckhoff TwinCAT Scope View CSV export", "ms", "UTF-8"),
    "tia_portal_siemens.csv": ("Siemens TIA Portal trace CSV export", "ms", "Windows-1252"),
    "wincc_siemens.csv": ("WinCC data log CSV", "OLE days", "UTF-16"),
    "niagara_siemens": ("Niagara history export", "date", "UTF-8"),
}


@pytest.mark.parametrize("name", sorted(EVERY_CYCLE_SIEMENS))
def test_every_cycle_recordings_of_the_siemens_block_read_as_written(name):
    recording = read_one(SAMPLES / name)
    label, unit, encoding = EVERY_CYCLE_SIEMENS[name]
    assert (recording.format, recording.time_unit, recording.encoding) == (label, unit, encoding)
    assert recording.step_size == CYCLE
    for variable in ("value", "setChangeRate", "delayedValue"):
        found = next(c for c in recording.channels if last_component(c.symbol or c.name).endswith(variable))
        assert found.values.tolist() == [float(v) for v in samples.SIEMENS[variable]]
        # WinCC's Time_ms is OLE days to 4 decimals: within 9 us of the cycle
        assert np.abs(found.times - np.arange(14) * CYCLE).max() <= (9e-6 if unit == "OLE days" else 0.0)


def test_twincat_for_each_sampletime_with_filetime_keeps_each_groups_time_base():
    recording = read_one(SAMPLES / "twincat_siemens_outputs_every_3rd_cycle.csv")
    assert recording.time_unit == "FILETIME" and recording.sample_time == CYCLE
    value, delayed = channel(recording, "value"), channel(recording, "delayedValue")
    assert value.symbol == "MAIN.fbRamp.value"
    assert value.times.tolist() == [k * CYCLE for k in range(14)]
    assert delayed.times.tolist() == [k * CYCLE for k in range(0, 14, 3)]
    assert delayed.values.tolist() == [0, 2, 3.5, 1.5, -1.5]
    assert delayed.lines.tolist() == [13, 16, 19, 22, 25]


@pytest.mark.parametrize(
    "name, label, unit, options",
    [
        ("codesys23_ratelimiter.txt", "CODESYS 2.3 trace (ASCII file)", "cycles", {"step_size": CYCLE}),
        ("codesys_v3_ratelimiter.csv", "CODESYS V3 trace export", "us", {}),
        ("plain_ratelimiter.tsv", "CSV/TSV table", "s", {}),
        ("plain_ratelimiter_spaces.txt", "CSV/TSV table", "s", {}),
    ],
)
def test_every_cycle_recordings_of_rate_limiter_read_as_written(name, label, unit, options):
    recording = read_one(SAMPLES / name, **options)
    assert (recording.format, recording.time_unit, recording.step_size) == (label, unit, CYCLE)
    for variable in ("u", "y"):
        found = channel(recording, variable)
        assert found.values.tolist() == [float(v) for v in samples.RATE_LIMITER[variable]]
        assert found.times.tolist() == [k * CYCLE for k in range(16)]
    if "rampActive" in [last_component(c.name) for c in recording.channels]:
        assert channel(recording, "rampActive").values.tolist() == samples.RATE_LIMITER["rampActive"]


def test_mdf4_channels_keep_their_groups_time_bases(tmp_path):
    recording = read_one(samples.write_mdf(tmp_path / "ramp.mf4", outputs_every=3))
    assert recording.format == "ASAM MDF4" and recording.time_unit == "s"
    assert [c.name for c in recording.channels] == [
        "MAIN.fbRamp.value",
        "MAIN.fbRamp.setChangeRate",
        "MAIN.fbRamp.delayedValue",
    ]
    assert channel(recording, "delayedValue").times.tolist() == [0.0, 0.75, 1.5, 2.25, 3.0]
    assert channel(recording, "value").values.tolist() == samples.SIEMENS["value"]


def _mdf_block_field(data, block_id, offset_after_links):
    """The byte offset of a field of the first block block_id (MDF 4: a block is its id, 4 reserved
    bytes, its length and its link count as uint64, the links, then its data)."""
    at = data.index(block_id)
    links = int.from_bytes(data[at + 16 : at + 24], "little")
    return at + 24 + 8 * links + offset_after_links


def _asammdf_channels(path):
    from asammdf import MDF

    mdf = MDF(str(path))
    try:
        return {
            mdf.get(group=g, index=i).name: (mdf.get(group=g, index=i).timestamps, mdf.get(group=g, index=i).samples)
            for g, group in enumerate(mdf.groups)
            for i in range(len(group.channels))
            if i != mdf.masters_db.get(g)
        }
    finally:
        mdf.close()


def test_an_mdf4_file_its_logger_has_not_finalized_is_read_as_asammdf_reads_it(tmp_path):
    """MDF 4.1, 'Unfinalized MDF': the identification is 'UnFinMF ' and the standard flags (uint16 at
    byte 60) say what the writer left undone; bit 0: the channel groups' cycle counts (left 0 here)."""
    data = bytearray(samples.write_mdf(tmp_path / "finalized.mf4", outputs_every=3).read_bytes())
    data[:8] = b"UnFinMF "
    data[60:62] = (1).to_bytes(2, "little")
    count = _mdf_block_field(data, b"##CG", 8)  # record id, then the cycle count
    data[count : count + 8] = bytes(8)
    path = tmp_path / "logger.mf4"
    path.write_bytes(bytes(data))
    recording = read_one(path)
    assert recording.format == "ASAM MDF4"
    assert any("not finalized" in note for note in recording.notes)
    expected = _asammdf_channels(path)
    assert [c.name for c in recording.channels] == list(expected)
    for found in recording.channels:
        stamps, values = expected[found.name]
        assert found.stamps.tolist() == stamps.tolist() and found.values.tolist() == values.tolist()
    assert channel(recording, "delayedValue").times.tolist() == [0.0, 0.75, 1.5, 2.25, 3.0]


def test_an_mdf_3_file_is_named_mdf_3(tmp_path):
    from asammdf import MDF, Signal

    mdf = MDF(version="3.30")
    mdf.append([Signal(np.array(samples.SIEMENS["value"], dtype=float), np.arange(14) * CYCLE, name="value")])
    mdf.save(str(tmp_path / "old.mdf"), overwrite=True)
    mdf.close()
    recording = read_one(tmp_path / "old.mdf")
    assert recording.format == "ASAM MDF 3"
    assert channel(recording, "value").values.tolist() == samples.SIEMENS["value"]


def test_an_mdf_channel_group_declaring_more_samples_than_the_step_bound_is_refused_unread(tmp_path):
    """A channel group's cycle count (uint64 after its record id) is what its data blocks hold; a small
    (compressed) file may declare hundreds of millions: refused before they are read, named."""
    data = bytearray(samples.write_mdf(tmp_path / "finalized.mf4").read_bytes())
    count = _mdf_block_field(data, b"##CG", 8)
    data[count : count + 8] = (300_000_000).to_bytes(8, "little")
    path = tmp_path / "huge.mf4"
    path.write_bytes(bytes(data))
    with pytest.raises(TraceError) as error:
        read_file(path)
    assert str(error.value) == (
        f"{path}: channel 'MAIN.fbRamp.value' (and 1 more) of channel group 0: 300,000,000 samples, each a "
        "cycle of its own: more than the bound of 200,000,000 steps"
    )


def test_niagara_points_are_named_by_their_file_unless_the_file_names_them():
    recording = read_one(SAMPLES / "niagara_siemens")
    assert sorted(c.name for c in recording.channels) == ["delayedValue", "setChangeRate", "value"]
    given_as_files = read_recording(sorted((SAMPLES / "niagara_siemens").iterdir()))
    assert len(given_as_files) == 1 and len(given_as_files[0].channels) == 3


# -- values, encodings, separators -------------------------------------------------------
def test_values_as_plcs_print_them():
    cells = np.array(["TRUE", "false", "16#00FF", "16#8_200", "WORD#16#0010", "REAL#1.5", "2#101", "-3,25", "1e3"])
    assert numbers(cells, True, None).tolist() == [1, 0, 255, 0x8200, 16, 1.5, 5, -3.25, 1000]
    assert numbers(np.array(["1,5", "2"]), True, None).tolist() == [1.5, 2.0]


def test_a_cell_that_is_no_value_is_named_with_its_line_and_column(tmp_path):
    path = tmp_path / "trace.csv"
    path.write_text("time;u;y\n0;1;16#0000\n0,25;1;16#00G0\n")
    with pytest.raises(TraceError) as error:
        read_file(path)
    assert (error.value.line, error.value.column) == (3, 3)
    assert "'16#00G0' in column 'y' is not a number" in str(error.value)


@pytest.mark.parametrize("encoding", ["utf-8", "utf-8-sig", "utf-16", "utf-16-le", "utf-16-be", "cp1252"])
def test_encodings_recorders_write(encoding):
    text = "Zeit [ms];Ausgang °C;u\n0;1,5;2\n250;2,5;3\n"
    decoded, label = decode("x", text.encode(encoding))
    assert decoded.removeprefix("\ufeff") == text
    assert label.split()[0].replace("-", "").lower()[:5] in encoding.replace("-", "").lower() + "windows"


def test_splitting_keeps_the_quotes_inside_a_name():
    assert split('Index;"DB_Ramp".value;"a;b";"""DB"".x"', ";") == ["Index", '"DB_Ramp".value', "a;b", '"DB".x']
    assert split("  0   2.5\t TRUE ", " ") == ["0", "2.5", "TRUE"]


def test_a_twincat_eof_line_ends_the_table():
    recording = read_one(SAMPLES / "twincat_siemens.csv")
    assert len(channel(recording, "value").values) == 14


# -- time ---------------------------------------------------------------------------------
def test_units_named_in_a_column():
    assert [
        unit_in_name(n)
        for n in ("Time [ms]", "Zeit (ms)", "Time_ms", "time/s", "Timestamp [µs]", "t", "cycle [cycles]")
    ] == ["ms", "ms", "ms", "s", "us", None, "cycles"]


def test_dates_as_recorders_print_them():
    base = parse_date("2026-11-20T14:00:00Z")
    assert parse_date("2026-11-20 15:00:00.250+01:00") - base == 250_000_000
    assert parse_date("20.11.2026 14:00:01,5") - base == 1_500_000_000
    assert parse_date("20-Nov-26 02:00:00.125 PM CET") - base == 125_000_000
    assert parse_date("20-Nov-26 12:00:00.000 AM UTC") - base == -14 * 3600 * 10**9
    assert parse_date("yesterday") is None


def test_filetime_stamps_lose_no_resolution(tmp_path):
    """FILETIME (1.3e17 ticks) is beyond float64's integers: stamps 1 tick apart stay 100 ns apart."""
    base = 134081208000000001
    path = tmp_path / "t.csv"
    path.write_text("time [FILETIME];u\n" + "".join(f"{base + k * 2500000};{k}\n" for k in range(3)))
    recording = read_recording(path)[0]
    assert recording.channels[0].stamps.dtype == np.int64
    recording.time_unit = "FILETIME"
    normalise(recording)
    assert recording.channels[0].times.tolist() == [0.0, 0.25, 0.5]


def test_a_unit_that_would_mean_an_absurd_number_of_steps_is_refused_naming_it(tmp_path):
    """A controller's microsecond counter in a column that names no unit, read as seconds."""
    path = tmp_path / "counter.csv"
    path.write_text("time;u;y\n" + "".join(f"{5000000000 + k * 10000};1;1\n" for k in range(4)))
    with pytest.raises(InputError, match=r"read as seconds \(assumed: column 'time' names no unit\).*--time-unit"):
        normalise(read_recording(path)[0], step_size=0.01, names=FLAGS)  # the command's words
    with pytest.raises(InputError, match=r"names no unit\).*give RecordingOptions\(time_unit=\.\.\.\) \(s, ms"):
        normalise(read_recording(path)[0], step_size=0.01)  # a Python caller's
    recording = normalise(read_recording(path)[0], time_unit="us")
    assert recording.step_size == 0.01


def test_stamps_of_a_column_without_a_unit_are_known_by_their_size(tmp_path):
    path = tmp_path / "filetime.csv"
    path.write_text("time;u;y\n" + "".join(f"{134081208000000000 + k * 100000};1;1\n" for k in range(4)))
    recording = normalise(read_recording(path)[0])
    assert (recording.time_unit, recording.step_size) == ("FILETIME", 0.01)
    path.write_text("time;u;y\n" + "".join(f"{1795186800000 + k * 10};1;1\n" for k in range(4)))
    recording = normalise(read_recording(path)[0])
    assert (recording.time_unit, recording.step_size) == ("ms", 0.01)
    assert "Unix time in ms" in recording.time_source


def test_a_stamp_off_its_cycle_is_reported_and_two_on_one_cycle_refused(tmp_path):
    """The grid of the four stamps, worked by hand: the least-squares line of 0, 10.0004, 23 and 30 ms
    over cycles 0 to 3 is 10.29996 ms per cycle from 0.30006 ms (slope 51.4998 / 5, the mean 15.7501 less
    1.5 slopes), which puts them -0.029, -0.058, +0.204 and -0.117 cycles off their cycles: two more than
    a tenth, the first at line 4 (23 ms). With a step of 20 ms, the narrowest arc of a 20 ms circle
    that holds them runs from 0 to 10.0004 ms: cycle 0 (from 5.0002 ms less half a cycle) holds the
    first two, which the line of 21.5 ms per cycle keeps together: refused at the second, line 3."""
    path = tmp_path / "jitter.csv"
    path.write_text("time [ms];u;y\n0;1;1\n10.0004;1;1\n23;1;1\n30;1;1\n")
    recording = normalise(read_recording(path)[0])
    assert recording.step_size == 0.01
    variables = variables_of(u="input", y="output")
    aligned = align(recording, plan(recording, variables, "M"))
    assert any(
        "u: 2 of its 4 time stamps are more than 0.1 of a cycle" in n
        and "line 4: t=0.023 s, +0.204 cycles from cycle 2" in n
        for n in aligned.notes
    ), aligned.notes
    assert aligned.grid.period == pytest.approx(0.01029996, rel=1e-9)
    recording = normalise(read_recording(path)[0], step_size=0.02)
    with pytest.raises(
        InputError,
        match=r"line 3: samples of u at t=0 s and t=0.0100004 s fall on the same cycle of 0.02 s",
    ):
        align(recording, plan(recording, variables, "M"))


def test_a_sample_more_than_half_a_cycle_out_of_turn_goes_to_the_free_cycle_beside_it(tmp_path):
    """Thirty samples of a 10 ms cycle. The fourth is stamped 35.6 ms, 0.44 of a cycle before the 40 ms
    of the fifth: both nearest to cycle 4, while cycle 3 has none. The sample is put on cycle 3 (0.56 of a
    cycle after it, a message that came late), said in a note, and counted in the jitter; nothing is
    missing. Stamped 14 ms instead, between the 10 and 20 ms of cycles 1 and 2, it has no free cycle
    beside it: refused, as two samples on one cycle."""
    variables = variables_of(u="input", y="output")
    stamps = [0.0, 10.0, 20.0, 35.6] + [10.0 * k for k in range(4, 30)]
    path = tmp_path / "late.csv"
    path.write_text("time [ms];u;y\n" + "".join(f"{t};1;1\n" for t in stamps))
    recording = normalise(read_recording(path)[0])
    aligned = align(recording, plan(recording, variables, "M"))
    said = [n for n in aligned.notes if "more than half a cycle" in n]
    assert [n.split(":")[0] for n in said] == ["u", "y"]  # (each channel's own note)
    assert said[0].startswith("u: 1 of its 30 samples are more than half a cycle from their cycle")
    assert "line 5: t=0.0356 s, 0.5" in said[0] and "of a cycle after its cycle" in said[0]
    assert 0.5 < aligned.clock["largest_percent"] / 100 < 0.6 and aligned.clock["missing_cycles"] == 0
    assert aligned.inputs is not None and len(aligned.inputs) == 30
    stamps[3] = 14.0
    path.write_text("time [ms];u;y\n" + "".join(f"{t};1;1\n" for t in sorted(stamps)))
    recording = normalise(read_recording(path)[0])
    with pytest.raises(InputError, match=r"line 4: samples of u at t=0.01 s and t=0.014 s fall on the same cycle"):
        align(recording, plan(recording, variables, "M"))


# -- formats: recognised from the content, or refused with the reasons -----------------------
def test_a_file_of_no_known_format_says_what_was_tried_and_why_not(tmp_path):
    path = tmp_path / "notes.txt"
    path.write_text("Commissioning notes\nthe ramp looked fine\n")
    with pytest.raises(TraceError) as error:
        read_file(path)
    message = str(error.value)
    assert message.startswith(f"{path}: no known recording format; tried ASAM MDF (2, 3 or 4): not MDF")
    for name in FORMAT_NAMES:
        assert f"{name}: " in message
    assert "no channel header block" in message and "VarName, TimeString" in message


def test_a_table_without_a_time_column_is_refused_at_its_header(tmp_path):
    path = tmp_path / "no_time.csv"
    path.write_text("Trace export\nvalue,delayedValue\n1,2\n3,4\n")
    with pytest.raises(TraceError, match="no header line with a time column"):
        read_file(path)


def test_a_row_with_more_cells_than_the_header_is_refused(tmp_path):
    path = tmp_path / "long.csv"
    path.write_text("time,u\n0,1\n1,2,3\n")
    with pytest.raises(TraceError) as error:
        read_file(path)
    assert (error.value.line, error.value.column) == (3, 3)


def test_time_going_backwards_is_refused(tmp_path):
    path = tmp_path / "back.csv"
    path.write_text("time,u\n0,1\n0.5,2\n0.25,3\n")
    with pytest.raises(TraceError, match="time goes backwards") as error:
        read_file(path)
    assert error.value.line == 4


def test_a_folder_of_cases_is_no_recording(tmp_path):
    (tmp_path / "case").mkdir()
    (tmp_path / "case" / "M_ref.csv").write_text("time,y\n0,0\n")
    assert not is_recording(tmp_path) and is_recording(SAMPLES / "niagara_siemens")
    assert is_recording(SAMPLES / "twincat_siemens.csv")


# -- channels to variables -----------------------------------------------------------------
def variables_of(**causalities):
    def variable(causality):
        kind, _, variability = causality.partition(":")
        return SimpleNamespace(causality=kind, variability=variability or "continuous")

    return {name: variable(c) for name, c in causalities.items()}


SIEMENS_VARIABLES = variables_of(
    value="input",
    setChangeRate="input",
    delayedValue="output",
    status="output",
    callOB="parameter:fixed",
    cycleTime="parameter:fixed",
)


def test_channels_mean_the_variable_of_their_last_name_component():
    assert [
        last_component(n)
        for n in (
            "MAIN.fbRamp.delayedValue",
            '"DB_Ramp".delayedValue',
            "Application.PLC_PRG.fbRamp.delayedValue",
            '"DB.Ramp".x',
        )
    ] == ["delayedValue", "delayedValue", "delayedValue", "x"]
    recording = read_one(SAMPLES / "tia_portal_siemens.csv")
    result = plan(recording, SIEMENS_VARIABLES, "LGF_LimRateOfChangeCI")
    assert [v for v, _ in result.drives] == ["value", "setChangeRate"]
    assert [v for v, _ in result.compares] == ["delayedValue", "status"]
    assert [(c.name, why) for c, why in result.ignored] == [
        ('"DB_Ramp".enDefaultOutValue', "no variable of LGF_LimRateOfChangeCI is named 'enDefaultOutValue'")
    ]


def test_map_names_a_channel_for_a_variable_and_roles_follow_the_variable():
    recording = read_one(SAMPLES / "wincc_siemens.csv")
    maps = [("value", "DB_Ramp_value"), ("delayedValue", "DB_Ramp_delayedValue"), ("callOB", "DB_Ramp_setChangeRate")]
    result = plan(recording, SIEMENS_VARIABLES, "M", maps)
    assert [(v, c.name) for v, c in result.drives] == [("value", "DB_Ramp_value")]
    assert [(v, c.name) for v, c in result.compares] == [("delayedValue", "DB_Ramp_delayedValue")]
    assert [c.name for c, _ in result.ignored] == ["DB_Ramp_setChangeRate"]
    assert "callOB is a fixed parameter" in result.ignored[0][1]
    with pytest.raises(InputError, match="has no channel 'nope'"):
        plan(recording, SIEMENS_VARIABLES, "M", [("value", "nope")])
    with pytest.raises(InputError, match="M has no variable 'nope'"):
        plan(recording, SIEMENS_VARIABLES, "M", [("nope", "DB_Ramp_value")])


def test_a_channel_without_samples_is_ignored(tmp_path):
    path = tmp_path / "empty_column.csv"
    path.write_text("time;value;delayedValue;status\n0;1;0;\n0,25;1;1;\n")
    result = plan(read_one(path), SIEMENS_VARIABLES, "M")
    assert [(c.name, why) for c, why in result.ignored] == [("status", "no samples")]
    assert [v for v, _ in result.compares] == ["delayedValue"]


def test_two_channels_meaning_one_variable_are_refused(tmp_path):
    path = tmp_path / "twice.csv"
    path.write_text("time,MAIN.a.value,MAIN.b.value,delayedValue\n0,1,2,0\n")
    recording = read_recording(path)[0]
    with pytest.raises(
        InputError,
        match=r"'MAIN.a.value' \(column 2 of .*twice.csv\) and 'MAIN.b.value' "
        r"\(column 3 of .* both mean value: .*--map",
    ):
        plan(recording, SIEMENS_VARIABLES, "M", names=FLAGS)  # the command's words
    with pytest.raises(
        InputError, match=r"both mean value: say which with RecordingOptions\(maps=\{'value': 'CHANNEL'\}\)"
    ):
        plan(recording, SIEMENS_VARIABLES, "M")  # a Python caller's


# -- the recorder's timing on fmpy's steps --------------------------------------------------------
def test_a_row_drives_its_cycle_and_its_output_is_that_cycles_result():
    recording = read_one(SAMPLES / "twincat_siemens_outputs_every_3rd_cycle.csv")
    result = plan(recording, SIEMENS_VARIABLES, "M")
    aligned = align(recording, result)
    assert aligned.inputs["time"].tolist() == [k * CYCLE for k in range(14)]
    assert aligned.inputs["value"].tolist() == samples.SIEMENS["value"]
    [reference] = aligned.references
    assert reference["time"].tolist() == [(k + 1) * CYCLE for k in range(0, 14, 3)]
    assert (aligned.start_time, aligned.stop_time) == (0.0, 13 * CYCLE + CYCLE)
    assert aligned.coarse == ""
    fmi = align(recording, result, timing="fmi")
    assert fmi.references[0]["time"].tolist() == [k * CYCLE for k in range(0, 14, 3)]


def test_inputs_sampled_coarser_than_the_step_are_explained_with_a_tolerance(tmp_path):
    path = tmp_path / "coarse.csv"
    rows = [(k, samples.SIEMENS["value"][k], samples.SIEMENS["delayedValue"][k]) for k in range(0, 14, 3)]
    path.write_text(
        "time [ms];value;setChangeRate;delayedValue\n" + "".join(f"{k * 250};{v};4;{y}\n" for k, v, y in rows)
    )
    recording = normalise(read_recording(path)[0], step_size=CYCLE)
    aligned = align(recording, plan(recording, SIEMENS_VARIABLES, "M"), names=FLAGS)  # the command's words
    assert "value every 3 cycles" in aligned.coarse and "by up to 2 cycles" in aligned.coarse
    # delayedValue moves by 1 a cycle at most between its samples (1.5 -> -1.5 in 3 cycles): 2 in 2 cycles
    assert "--tube-time 0.5 --tube-value 0" in aligned.coarse and "--abs-tol 2 " in aligned.coarse
    in_python = align(recording, plan(recording, SIEMENS_VARIABLES, "M")).coarse  # a Python caller's
    assert "allows that lag: Tube(time=0.5, value=0), or Tolerance(abs_tol=2) (the largest change" in in_python
    assert aligned.inputs["time"].tolist() == [k * CYCLE for k in range(0, 14, 3)]


def test_a_recording_without_outputs_of_the_fmu_is_refused():
    recording = read_one(SAMPLES / "plain_ratelimiter.tsv")
    with pytest.raises(InputError, match="no channel is an output of M: nothing to compare"):
        align(recording, plan(recording, variables_of(u="input", y="local"), "M"), label="M")


def test_a_recording_is_columnar():
    recording = read_one(SAMPLES / "codesys_v3_ratelimiter.csv")
    for c in recording.channels:
        assert isinstance(c.values, np.ndarray) and c.values.dtype == np.float64
        assert isinstance(c.times, np.ndarray) and c.times.dtype == np.float64
    assert math.isfinite(sum(float(c.values.sum()) for c in recording.channels))


def test_a_table_of_absolute_time_stamps(tmp_path):
    path = tmp_path / "dates.csv"
    path.write_text(
        "Timestamp;u;y\n2026-11-20T14:00:00.000+01:00;0;0\n2026-11-20T14:00:00.250+01:00;2;0,25\n"
        "2026-11-20T13:00:00.500Z;2;0,5\n"
    )
    recording = read_one(path)
    assert (recording.time_unit, recording.step_size) == ("date", 0.25)
    assert channel(recording, "y").times.tolist() == [0.0, 0.25, 0.5]
    assert channel(recording, "y").values.tolist() == [0.0, 0.25, 0.5]


def test_twincat_without_time_columns_takes_the_time_from_the_sample_time(tmp_path):
    """Timelines 'None', ',' as the separator (so a decimal point): row k is at k * SampleTime."""
    path = tmp_path / "none.csv"
    path.write_text(
        "Name,Scope\nFile,none.csv\n\n\nName,value,delayedValue\nData-Type,REAL64,REAL64\n"
        "SampleTime[ms],250,250\nSymbolName,MAIN.fbRamp.value,MAIN.fbRamp.delayedValue\n\n"
        "0,0\n3.5,1\n3.5,2\n"
    )
    recording = read_one(path)
    assert (recording.format, recording.time_unit) == ("Beckhoff TwinCAT Scope View CSV export", "ms")
    assert channel(recording, "value").times.tolist() == [0.0, 0.25, 0.5]
    assert channel(recording, "delayedValue").values.tolist() == [0.0, 1.0, 2.0]


def test_codesys23_with_a_time_column_in_milliseconds(tmp_path):
    path = tmp_path / "trace.txt"
    path.write_text("Ramp trace\nD:\\PROJECTS\\RAMP.PRO\nTime PLC_PRG.u PLC_PRG.y\n0 0 0\n250 2 0.25\n500 2 0.5\n")
    recording = read_one(path)
    assert (recording.time_unit, recording.step_size) == ("ms", 0.25)
    assert channel(recording, "y").values.tolist() == [0.0, 0.25, 0.5]


@pytest.mark.parametrize(
    "body",
    [
        "0;1,5;TRUE\n0,25; 2 ;FALSE\n0,5;3;16#00FF\n",  # blanks around cells, decimal commas, literals
        "0\t1\t2\n1\t\t3\nEOF\n\n",  # an empty cell, the EOF tag, trailing blank lines
    ],
)
def test_the_one_split_of_a_plain_body_equals_the_line_by_line_reading(tmp_path, body):
    from fmutrace.recordings import _grid as grid, _text as texts

    separator = ";" if ";" in body else "\t"
    path = tmp_path / "t.csv"
    path.write_text(f"time{separator}a{separator}b\n" + body)
    decoded = texts.read(path)
    cells, lines = grid.uniform_table(decoded, 1, separator, 3)
    rows, numbers = grid.body(decoded, 1, separator)
    assert cells.tolist() == grid.grid(rows, 3).tolist() and lines.tolist() == numbers.tolist()


@pytest.mark.parametrize("body", ['0;"1";2\n', "0;1;2\n\n1;2;3\n", "0;1\n", "0;1;2;3\n"])
def test_bodies_the_one_split_cannot_read_go_line_by_line(tmp_path, body):
    from fmutrace.recordings import _grid as grid, _text as texts

    path = tmp_path / "t.csv"
    path.write_text("time;a;b\n" + body)
    assert grid.uniform_table(texts.read(path), 1, ";", 3) is None


def test_twincat_sample_time_with_a_decimal_comma_in_a_comma_separated_export(tmp_path):
    """Scope View writes 'SampleTime[ms],0,2' in a ',' export (a decimal comma the separator splits):
    one channel's group of two cells is one number; where that cannot be told, the row is named."""
    head = "Name,Scope\nFile,x.csv\n\n\n"
    path = tmp_path / "comma.csv"
    path.write_text(
        head + "Name,fast,Name,slow,other\nSampleTime[ms],0,2,SampleTime[ms],1,1\n"
        "SymbolName,MAIN.fast,SymbolName,MAIN.slow,MAIN.other\n\n0,1,0,5,6\n0.2,2\n0.4,3\n"
    )
    recording = read_one(path)
    assert recording.sample_time == 0.0002
    assert channel(recording, "fast").times.tolist() == [0.0, 0.0002, 0.0004]
    assert channel(recording, "slow").values.tolist() == [5.0]
    path.write_text(head + "Name,fast,Name,slow,other\nSampleTime[ms],0,2,SampleTime[ms],1,1,5\n\n0,1,0,5,6\n")
    with pytest.raises(
        TraceError,
        match=r"line 6, column 4: the row 'SampleTime\[ms\]' has 3 cells for 2 channels "
        r"\(a decimal comma, ',' separating\?\)",
    ):
        read_file(path)


def test_twincat_for_each_sampletime_whose_header_rows_leave_out_their_trailing_empty_cells(tmp_path):
    """Scope View's 'For each sampletime' export writes a property row without its last empty cells
    ('SymbolComment', then nothing for the channels of the last group)."""
    path = tmp_path / "per_sample_time.csv"
    path.write_text(
        "Name\tScope\nFile\tx.csv\n\n\n"
        "Name\ta\tb\tName\tc\td\n"
        "SymbolComment\t\t\tSymbolComment\n"
        "SampleTime[ms]\t1\t1\tSampleTime[ms]\t2\t2\n"
        "SymbolName\tMAIN.a\tMAIN.b\tSymbolName\tMAIN.c\tMAIN.d\n"
        "\n0\t1\t2\t0\t3\t4\n1\t5\t6\n2\t7\t8\t2\t9\t10\n"
    )
    recording = read_one(path)
    assert recording.sample_time == 0.001
    assert channel(recording, "a").times.tolist() == [0.0, 0.001, 0.002]
    assert channel(recording, "b").values.tolist() == [2.0, 6.0, 8.0]
    assert channel(recording, "c").times.tolist() == [0.0, 0.002]
    assert channel(recording, "d").values.tolist() == [4.0, 10.0]
    assert channel(recording, "d").symbol == "MAIN.d"


WINCC_HEADER = '"VarName";"TimeString";"VarValue";"Validity";"Time_ms"'


def _wincc_row(tag, second, value, time_ms):
    return f'"{tag}";"20.11.2026 14:00:{second:02d}";{value};1;{time_ms}'


def test_wincc_system_rows_with_fewer_cells_are_no_samples(tmp_path):
    """$RT_OFF$ (runtime stopped), $RT_DIS$ (logging disabled) and $RT_COUNT$ (a count, fewer cells)."""
    base = 46346541666.6667  # 20.11.2026 14:00:00 as OLE days times 1e6
    lines = [WINCC_HEADER, _wincc_row("$RT_DIS$", 0, 0, "46346541655,0926"), '"$RT_COUNT$";3']
    lines += [_wincc_row("Ramp_y", k, k * 2, f"{base + k * 1e6 / 86400:.4f}".replace(".", ",")) for k in range(3)]
    lines.append(_wincc_row("$RT_OFF$", 3, 0, f"{base + 3e6 / 86400:.4f}".replace(".", ",")))
    path = tmp_path / "log.csv"
    path.write_text("\r\n".join(lines) + "\r\n")
    recording = read_one(path)
    assert [c.name for c in recording.channels] == ["Ramp_y"]
    assert recording.time_unit == "OLE days" and recording.step_size == 1.0
    y = recording.channels[0]
    assert y.values.tolist() == [0.0, 2.0, 4.0] and y.lines.tolist() == [4, 5, 6]
    assert np.abs(y.times - [0.0, 1.0, 2.0]).max() < 9e-6
    assert "3 marker rows" in recording.notes[0]


def test_wincc_time_ms_with_a_tab_for_its_decimal_mark_falls_back_to_time_string(tmp_path):
    """A PC whose locale wrote a tab for the decimal mark: Time_ms is no number, TimeString is the time."""
    lines = [WINCC_HEADER] + [_wincc_row("Ramp_y", k, k * 2, f"4634654{1666 + k * 12}\t{k}") for k in range(3)]
    path = tmp_path / "tab.csv"
    path.write_text("\r\n".join(lines) + "\r\n")
    recording = read_one(path)
    assert recording.time_unit == "date" and "Time_ms is damaged" in recording.time_source
    assert recording.channels[0].times.tolist() == [0.0, 1.0, 2.0]
    assert recording.notes == [
        f"{path}, line 2, column 5: '4634654{1666}\\t0' in column 'Time_ms' is not a number, TRUE/FALSE or an "
        "IEC literal (16#...): the time is TimeString's instead"
    ]


def test_a_map_to_a_symbol_several_channels_share_is_refused_naming_each(tmp_path):
    """Scope View channels of one symbol (scaled, shifted, ...): --map y=MAIN.var_REAL means none of them."""
    path = tmp_path / "same_symbol.csv"
    path.write_text(
        "Name\tScope\nFile\tx.csv\n\n\n"
        "Name\tvar_REAL32\tName\tfunc_scaled\tName\tu\n"
        "SampleTime[ms]\t1\tSampleTime[ms]\t1\tSampleTime[ms]\t1\n"
        "SymbolName\tMAIN.var_REAL\tSymbolName\tMAIN.var_REAL\tSymbolName\tMAIN.u\n"
        "\n0\t1\t0\t-1\t0\t5\n1\t2\t1\t-2\t1\t5\n"
    )
    recording = read_one(path)
    variables = variables_of(u="input", y="output")
    with pytest.raises(InputError) as error:
        plan(recording, variables, "M", [("y", "MAIN.var_REAL")], names=FLAGS)
    assert str(error.value) == (
        f"--map y=MAIN.var_REAL: 2 channels of {path} are 'MAIN.var_REAL': 'var_REAL32' (symbol "
        "'MAIN.var_REAL', column 2); 'func_scaled' (symbol 'MAIN.var_REAL', column 4); map one by its name, "
        "e.g. --map y=var_REAL32, or by its column, e.g. --map y=#2"
    )
    chosen = plan(recording, variables, "M", [("y", "func_scaled")])
    assert [(v, c.name) for v, c in chosen.compares] == [("y", "func_scaled")]
    with pytest.raises(InputError, match=r"2 channels of .* are 'var_REAL'"):  # a last component is no way out
        plan(recording, variables, "M", [("y", "var_REAL")])


def _fmu_of(**causalities):
    """What recorded_case needs of an FMU: its variables, label, model and start values."""
    return SimpleNamespace(
        variables=variables_of(**causalities), label="M", model="M", default_step=None, start_value=lambda n, v: v
    )


def test_the_step_comes_from_the_mapped_channels_not_from_unmapped_faster_ones(tmp_path):
    """A CAN log: Speed and Heading each 1 s apart (from t = 0.3 s), other messages at 100 Hz from t = 0."""
    fast = np.arange(500) / 100
    slow = 0.3 + np.arange(5)
    path = mdf_of_groups(
        tmp_path / "can.mf4",
        [(fast, {"EngineTemp": fast * 0, "Rpm": fast}), (slow, {"Speed": np.arange(5)}), (slow, {"Heading": [5] * 5})],
    )
    options = RecordingOptions(maps={"u": "Speed", "y": "Heading"}, names=FLAGS)
    case = recorded_case(path, _fmu_of(u="input", y="output"), "can", options)
    assert case.options["StepSize"] == 1.0
    assert case.inputs["time"].tolist() == [0.0, 1.0, 2.0, 3.0, 4.0]
    assert case.reference["time"].tolist() == [1.0, 2.0, 3.0, 4.0, 5.0]
    assert case.coarse == "" and not [n for n in case.notes if "off a cycle end" in n]


def test_an_unmapped_channel_at_time_zero_does_not_set_the_origin(tmp_path):
    """An XCP measurement: a calibration value at t = 0, the mapped channels every 1 ms from 0.5 ms."""
    daq = 0.0005 + np.arange(100) / 1000
    path = mdf_of_groups(
        tmp_path / "xcp.mf4", [([0.0], {"Calibration": [1.0]}), (daq, {"u": np.arange(100), "y": np.arange(100)})]
    )
    case = recorded_case(path, _fmu_of(u="input", y="output"), "xcp", RecordingOptions())
    assert case.options["StepSize"] == 0.001
    assert np.abs(case.inputs["time"] - np.arange(100) / 1000).max() < 1e-15
    assert not [n for n in case.notes if "off a cycle end" in n], case.notes
    assert "ignored: Calibration" in " ".join(case.notes)


def test_a_channel_off_the_grid_is_named_with_the_step_that_would_fit_it(tmp_path):
    """u every 0.25 s, y every 0.3 s: y's stamps are off a 0.25 s grid; a step of 0.3 s fits them."""
    path = mdf_of_groups(
        tmp_path / "two_rates.mf4",
        [(np.arange(13) * 0.25, {"u": np.zeros(13)}), (np.arange(10) * 0.3, {"y": np.zeros(10)})],
    )
    case = recorded_case(path, _fmu_of(u="input", y="output"), "r", RecordingOptions(names=FLAGS))
    [note] = [n for n in case.notes if n.startswith("y: ")]
    assert "more than 0.1 of a cycle" in note and note.endswith("Its own stamps fit a step of 0.3 s (--step-size 0.3).")


def test_a_wincc_log_of_too_many_steps_is_told_the_option_that_works(tmp_path):
    """Logged on change: five samples 1 ms apart, one an hour later. Its time stamps are OLE days, so
    no time unit applies: the advice is the step size, and with the step size given it is read."""
    base = 46346541666.6667
    stamps = [base + k * 1e3 / 86400 for k in range(5)] + [base + 3600e6 / 86400]
    lines = [WINCC_HEADER] + [_wincc_row("Ramp_y", 0, k, f"{t:.4f}") for k, t in enumerate(stamps)]
    path = tmp_path / "on_change.csv"
    path.write_text("\r\n".join(lines).replace(";", ",") + "\r\n")
    with pytest.raises(InputError) as error:
        normalise(read_recording(path)[0], names=FLAGS)
    assert str(error.value).endswith("steps for 6 samples: give the recorder's cycle with --step-size")
    assert "--time-unit" not in str(error.value)
    with pytest.raises(InputError, match="does not apply"):  # what the old advice led to
        normalise(read_recording(path)[0], time_unit="s", names=FLAGS)
    assert normalise(read_recording(path)[0], step_size=0.5, names=FLAGS).step_size == 0.5


def test_three_channels_meaning_one_variable_are_refused_naming_all_three(tmp_path):
    path = tmp_path / "thrice.csv"
    path.write_text("time,MAIN.a.value,MAIN.b.value,MAIN.c.value,delayedValue\n0,1,2,3,0\n")
    with pytest.raises(InputError) as error:
        plan(read_recording(path)[0], SIEMENS_VARIABLES, "M", names=FLAGS)
    assert str(error.value) == (
        f"{path}: channels 'MAIN.a.value' (column 2 of {path}), 'MAIN.b.value' (column 3 of {path}) and "
        f"'MAIN.c.value' (column 4 of {path}) all mean value: say which with --map value=CHANNEL, "
        "e.g. --map value=MAIN.a.value"
    )


def test_a_wincc_log_over_a_year_long_is_not_told_a_time_unit_which_its_stamps_refuse(tmp_path):
    base = 46346541666.6667
    lines = [WINCC_HEADER] + [_wincc_row("Ramp_y", 0, k, f"{base + k * 400e6:.4f}") for k in range(3)]  # 463 days apart
    path = tmp_path / "years.csv"
    path.write_text("\r\n".join(lines).replace(";", ",") + "\r\n")
    with pytest.raises(InputError) as error:
        normalise(read_recording(path)[0], names=FLAGS)
    assert str(error.value).endswith(
        "days): more than a year: compare a part of it (--time-unit does not apply to OLE days (days since 30 Dec "
        "1899, times 1e6))"
    )
