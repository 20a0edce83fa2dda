"""`fmutrace compare FMU RECORDING...` end to end, through its command's
entry point (in this process, support.cli) and the built FMUs (the Siemens block and RateLimiter), on the
sample recordings of tests/recordings (written from each export's
documented structure, values worked by hand: tests/recordings/samples.py)
and on variants of them written here: perturbed, coarsely sampled, bad."""

import json
import sys
from pathlib import Path

import pytest

import fmutrace
from support.fmu_driver import BUILD_DIR
from support.cli import fmutrace_in_process

SAMPLES = Path(__file__).parents[1] / "recordings"
sys.path.insert(0, str(SAMPLES))
import samples  # noqa: E402

SIEMENS = {v: BUILD_DIR / f"fmi{v}" / "LGF_LimRateOfChangeCI.fmu" for v in (2, 3)}
RATE_LIMITER = {v: BUILD_DIR / f"fmi{v}" / "RateLimiter.fmu" for v in (2, 3)}
PASS_THROUGH = BUILD_DIR / "benchmarks" / "fmi3" / "PassThrough.fmu"  # y is u, each cycle
WINCC_MAPS = [
    "--map",
    "value=DB_Ramp_value",
    "--map",
    "setChangeRate=DB_Ramp_setChangeRate",
    "--map",
    "delayedValue=DB_Ramp_delayedValue",
]


def compare(*args):
    return fmutrace_in_process("compare", *args)


def tia_rows():
    """The TIA Portal sample's lines (Windows-1252), to write variants of."""
    return (SAMPLES / "tia_portal_siemens.csv").read_text(encoding="cp1252").splitlines()


def write_tia(path, lines):
    path.write_text("\r\n".join(lines) + "\r\n", encoding="cp1252")
    return path


EVERY_CYCLE = [
    ("twincat_siemens.csv", SIEMENS, [], "Beckhoff TwinCAT Scope View CSV export"),
    ("tia_portal_siemens.csv", SIEMENS, [], "Siemens TIA Portal trace CSV export"),
    ("wincc_siemens.csv", SIEMENS, WINCC_MAPS, "WinCC data log CSV"),
    ("niagara_siemens", SIEMENS, [], "Niagara history export"),
    ("codesys23_ratelimiter.txt", RATE_LIMITER, ["--step-size", "0.25"], "CODESYS 2.3 trace (ASCII file)"),
    ("codesys_v3_ratelimiter.csv", RATE_LIMITER, [], "CODESYS V3 trace export"),
    ("plain_ratelimiter.tsv", RATE_LIMITER, [], "CSV/TSV table"),
    ("plain_ratelimiter_spaces.txt", RATE_LIMITER, [], "CSV/TSV table"),
]


# every format on FMI 3 in the fast lane, on FMI 2 in the slow lane
@pytest.mark.parametrize("version", [pytest.param(2, marks=pytest.mark.slow), 3])
@pytest.mark.parametrize("name, fmus, options, label", EVERY_CYCLE, ids=[e[0] for e in EVERY_CYCLE])
def test_every_cycle_recordings_pass_exactly(name, fmus, options, label, version):
    done = compare(fmus[version], SAMPLES / name, *options)
    assert done.returncode == 0, done.stdout + done.stderr
    assert f"PASS  {name} on" in done.stdout and label in done.stdout
    assert "1 of 1 cases pass" in done.stdout


def test_mdf4_recordings_pass_exactly_with_every_cycle_and_every_third_output(tmp_path):
    every = samples.write_mdf(tmp_path / "every_cycle.mf4")
    third = samples.write_mdf(tmp_path / "outputs_every_3rd_cycle.mf4", outputs_every=3)
    done = compare(SIEMENS[3], every, third)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "2 of 2 cases pass" in done.stdout and "ASAM MDF4" in done.stdout


def test_outputs_every_third_cycle_with_inputs_every_cycle_pass():
    done = compare(SIEMENS[3], SAMPLES / "twincat_siemens_outputs_every_3rd_cycle.csv")
    assert done.returncode == 0, done.stdout + done.stderr
    assert "time as FILETIME" in done.stdout


def test_a_perturbed_value_fails_naming_the_first_deviation(tmp_path):
    lines = tia_rows()
    assert lines[14].startswith("8;1500;-1,5;4;FALSE;2,5;")
    lines[14] = lines[14].replace(";2,5;", ";2,5000001;")
    lines[16] = lines[16].replace(";0,5;", ";0,75;")  # a second, later deviation
    done = compare(SIEMENS[3], write_tia(tmp_path / "perturbed.csv", lines))
    assert done.returncode == 1, done.stdout + done.stderr
    assert "FAIL  perturbed.csv on LGF_LimRateOfChangeCI (FMI 3)" in done.stdout
    # cycle 8's output is the FMU's at (8 + 1) * 0.25 s
    assert "delayedValue differs first at t=2.25: 2.5, expected 2.5000001" in done.stdout
    assert "2 of 14 samples differ" in done.stdout
    assert (
        f"delayedValue first differs at the recording's sample of cycle 8 ({tmp_path / 'perturbed.csv'}, line 15, "
        "t=2 s from its first sample): recorded 2.5000001, the FMU gives 2.5"
    ) in done.stdout


def test_the_other_timing_convention_is_an_option(tmp_path):
    """A table written as fmpy writes it (the output at t is the previous cycle's) passes with
    --timing fmi; the recorder's own table does not."""
    table = samples.RATE_LIMITER
    outputs = [0.0] + table["y"]  # at t = k*h: the output of cycle k-1, the initial one first
    inputs = table["u"] + [table["u"][-1]]
    path = tmp_path / "fmi_convention.csv"
    path.write_text(
        "time,u,y\n" + "".join(f"{k * 0.25},{u},{y}\n" for k, (u, y) in enumerate(zip(inputs, outputs, strict=True)))
    )
    assert compare(RATE_LIMITER[3], path, "--timing", "fmi").returncode == 0
    assert compare(RATE_LIMITER[3], path).returncode == 1
    done = compare(RATE_LIMITER[3], SAMPLES / "plain_ratelimiter.tsv", "--timing", "fmi")
    assert done.returncode == 1 and "y differs first at t=0.25: 0.0, expected 0.25" in done.stdout


def test_inputs_sampled_every_third_cycle_fail_with_a_meaningful_tolerance(tmp_path):
    lines = tia_rows()
    coarse = write_tia(tmp_path / "inputs_every_3rd_cycle.csv", lines[:6] + lines[6::3])
    done = compare(SIEMENS[3], coarse, "--step-size", "0.25")
    assert done.returncode == 1, done.stdout + done.stderr
    assert "the recording's inputs were sampled coarser than the step (value every 3 cycles" in done.stdout
    assert "may lead or lag the recorded one by up to 2 cycles" in done.stdout
    assert "--tube-time 0.5 --tube-value 0, or --abs-tol 2 " in done.stdout
    for tolerance in (["--tube-time", "0.5", "--tube-value", "0"], ["--abs-tol", "2"]):
        assert compare(SIEMENS[3], coarse, "--step-size", "0.25", *tolerance).returncode == 0


def test_channels_not_of_the_fmu_are_listed_as_ignored_in_the_output_and_report(tmp_path):
    lines = tia_rows()
    lines[5] += ';"DB_Ramp".temperature'
    lines[6:] = [line + ";21,5" for line in lines[6:]]
    done = compare(SIEMENS[3], write_tia(tmp_path / "more.csv", lines), "--report", tmp_path / "report")
    assert done.returncode == 0, done.stdout + done.stderr
    ignored = "ignored: \"DB_Ramp\".temperature (no variable of LGF_LimRateOfChangeCI (FMI 3) is named 'temperature')"
    assert ignored in done.stdout
    results = json.loads((tmp_path / "report" / "results.json").read_text())
    assert any(ignored in m for case in results["cases"] for m in case["messages"])


def test_from_python_with_cases_beside(tmp_path):
    campaign = fmutrace.compare(
        SIEMENS[3], [SAMPLES / "twincat_siemens.csv", Path(__file__).parents[1] / "scenarios" / "LGF_LimRateOfChangeCI"]
    )
    assert campaign.passed, campaign.summary()
    assert len(campaign.cases) > 1
    failing = fmutrace.compare(
        SIEMENS[3], SAMPLES / "wincc_siemens.csv", recording=fmutrace.RecordingOptions(maps={"value": "DB_Ramp_value"})
    )
    assert failing.exit_code == 2 and "no channel is an output" in failing.summary()


# -- bad input: exit 2, with the file, line and column ---------------------------------------
def bad(tmp_path, name, text, *options, encoding="utf-8"):
    path = tmp_path / name
    path.write_text(text, encoding=encoding)
    done = compare(SIEMENS[3], path, *options)
    assert done.returncode == 2, done.stdout + done.stderr
    return done.stderr


def test_a_file_of_no_known_format_says_which_formats_were_tried(tmp_path):
    said = bad(tmp_path, "notes.txt", "Commissioning notes\nthe ramp looked fine\n")
    assert "notes.txt: no known recording format; tried ASAM MDF (2, 3 or 4): not MDF" in said
    for name in (
        "Beckhoff TwinCAT Scope View CSV: no channel header block",
        "WinCC data log CSV: no header",
        "Niagara history export: no header",
        "CODESYS 2.3 trace (ASCII file): ",
        "table (TIA Portal trace CSV, CODESYS V3 export, CSV/TSV): no header line with a time column",
    ):
        assert name in said


def test_a_value_that_is_none_names_its_line_and_column(tmp_path):
    said = bad(
        tmp_path, "cell.csv", "time [ms];value;setChangeRate;delayedValue;status\n0;0;4;0;16#0000\n250;0;4;0;16#00G0\n"
    )
    assert "cell.csv, line 3, column 5: '16#00G0' in column 'status' is not a number" in said


def test_a_counter_read_as_seconds_is_refused_naming_the_unit_and_filetime_is_known(tmp_path):
    text = "time;value;setChangeRate;delayedValue\n" + "".join(f"{5000000000 + k * 250000};0;4;0\n" for k in range(5))
    said = bad(tmp_path, "counter.csv", text, "--step-size", "0.25")
    assert "with its time read as seconds (assumed: column 'time' names no unit)" in said and "--time-unit" in said
    assert compare(SIEMENS[3], tmp_path / "counter.csv", "--time-unit", "us").returncode == 0
    path = tmp_path / "filetime.csv"
    path.write_text(
        "time;value;setChangeRate;delayedValue\n"
        + "".join(f"{134081208000000000 + k * 2500000};0;4;0\n" for k in range(5))
    )
    done = compare(SIEMENS[3], path)
    assert done.returncode == 0 and "time as FILETIME" in done.stdout


def test_milliseconds_read_as_seconds_against_the_cycle_are_refused(tmp_path):
    text = "time,value,setChangeRate,delayedValue\n" + "".join(f"{k * 250},0,4,0\n" for k in range(14))
    said = bad(tmp_path, "ms.csv", text, "--step-size", "0.25")
    assert "would take 1.3e+04 steps for 14 samples" in said


@pytest.mark.parametrize(
    "name, text, message",
    [
        (
            "backwards.csv",
            "time,value,delayedValue\n0,1,0\n0.5,1,0\n0.25,1,0\n",
            "backwards.csv, line 4, column 1: time goes backwards",
        ),
        ("long_row.csv", "time,value,delayedValue\n0,1,0\n0.25,1,0,7\n", "long_row.csv, line 3, column 4: 4 cells"),
        (
            "twice.csv",
            "time,MAIN.a.value,MAIN.b.value,delayedValue\n0,1,2,0\n",
            "twice.csv) and 'MAIN.b.value' (column 3 of",
        ),
        ("no_output.csv", "time,value\n0,1\n0.25,1\n", "no channel is an output of LGF_LimRateOfChangeCI (FMI 3)"),
        ("empty.csv", "", "empty.csv: empty file"),
    ],
)
def test_bad_recordings_exit_2_with_their_message(tmp_path, name, text, message):
    assert message in bad(tmp_path, name, text)


def test_two_samples_on_one_cycle_are_refused(tmp_path):
    said = bad(tmp_path, "dense.csv", "time [ms],value,delayedValue\n0,1,0\n10,1,0\n20,1,0\n", "--step-size", "0.25")
    assert "dense.csv, line 3: samples of value at t=0 s and t=0.01 s fall on the same cycle of 0.25 s" in said


def test_set_gives_the_fmus_start_values(tmp_path):
    """rateUpPar 2 per second: 0.5 a 250 ms cycle, worked by hand; the default (1) gives 0.25."""
    path = tmp_path / "faster.csv"
    path.write_text(
        "time,u,y\n"
        + "".join(
            f"{k * 0.25},{u},{y}\n"
            for k, (u, y) in enumerate(zip([0, 2, 2, 2, 2, 2], [0, 0.5, 1, 1.5, 2, 2], strict=True))
        )
    )
    assert compare(RATE_LIMITER[3], path, "--set", "rateUpPar=2").returncode == 0
    done = compare(RATE_LIMITER[3], path)
    assert done.returncode == 1 and "y differs first at t=0.5: 0.25, expected 0.5" in done.stdout
    said = compare(RATE_LIMITER[3], path, "--set", "rateUpPar=fast").stderr
    assert "rateUpPar is a Float64: 'fast' is not a number" in said


def test_recordings_on_every_executor_and_niagara_histories_given_as_files(tmp_path):
    histories = sorted((SAMPLES / "niagara_siemens").iterdir())
    for options in (["--jobs", "2", "--report", tmp_path / "report"], ["--case-timeout", "120"]):
        done = compare(SIEMENS[3], SAMPLES / "twincat_siemens.csv", *histories, *options)
        assert done.returncode == 0, done.stdout + done.stderr
        assert "2 of 2 cases pass" in done.stdout and "PASS  niagara_siemens on" in done.stdout
    resumed = compare(
        SIEMENS[3], SAMPLES / "twincat_siemens.csv", *histories, "--report", tmp_path / "report", "--resume"
    )
    assert resumed.returncode == 0 and "on the journal" in resumed.stdout


def test_the_readmes_recording_command_passes():
    from support.fmu_driver import REPO

    [line] = [
        line
        for line in (REPO / "README.md").read_text().splitlines()
        if line.startswith("build/venv/bin/fmutrace compare") and "tests/recordings/" in line
    ]
    command, fmu, recording = line.split()[1:]
    assert command == "compare"
    done = compare(BUILD_DIR / Path(fmu).relative_to("build"), REPO / recording)
    assert done.returncode == 0, done.stdout + done.stderr


def test_a_10_ms_recording_with_printed_decimals_passes_within_them(tmp_path):
    """RateLimiter at a 10 ms cycle, its defaults (1 per second: 0.01 a cycle) from u = 0 to 2: y = 0.01 k
    until 2, as a recorder prints it (6 decimals): the FMU's sums of 0.01 are not those decimals' doubles,
    so only --abs-tol for the printing makes it pass."""
    rows = [(k * 10, 0 if k == 0 else 2, min(2.0, 0.01 * k)) for k in range(300)]
    path = tmp_path / "ramp_10ms.csv"
    path.write_text("Time [ms];u;y\n" + "".join(f"{t};{u};{y:.6f}\n".replace(".", ",") for t, u, y in rows))
    assert compare(RATE_LIMITER[3], path).returncode == 1
    done = compare(RATE_LIMITER[3], path, "--abs-tol", "5e-7")
    assert done.returncode == 0, done.stdout + done.stderr
    assert "step 0.01 s" in done.stdout


def test_a_case_of_more_messages_than_the_terminal_shows_says_how_many_and_where_they_are(tmp_path):
    """Twelve channels no variable is named after: 15 messages (the description, drives, compared, 12
    ignored); the command shows 10, then the count of the rest and the file that holds them all."""
    junk = [f"spare{n}" for n in range(12)]
    lines = ["time [ms];value;setChangeRate;delayedValue;" + ";".join(junk)]
    for k in range(14):
        row = [samples.SIEMENS[n][k] for n in ("value", "setChangeRate", "delayedValue")]
        lines.append(";".join([str(k * 250)] + [str(v) for v in row] + ["0"] * 12))
    path = tmp_path / "many.csv"
    path.write_text("\n".join(lines) + "\n")
    done = compare(SIEMENS[3], path)
    assert done.returncode == 0, done.stdout + done.stderr
    shown = [line for line in done.stdout.splitlines() if line.startswith("      ")]
    assert len(shown) == 11 and "ignored: spare6" in shown[9]
    assert shown[10] == "      (and 5 more messages: --report DIR writes all of them into DIR/results.json)"
    done = compare(SIEMENS[3], path, "--report", tmp_path / "report")
    assert f"(and 5 more messages: all of them in {tmp_path / 'report'}/results.json)" in done.stdout
    [case] = json.loads((tmp_path / "report" / "results.json").read_text())["cases"]
    assert len(case["messages"]) == 15 and case["messages"][-1].startswith("ignored: spare11")


@pytest.mark.parametrize("read", ["streamed", "whole"])
def test_times_in_messages_are_the_cycles_times_without_float_noise(tmp_path, read):
    """0.1 ms cycles: 42 * 0.0001 and 4.2 / 1000 are both 0.004200000000000001 in floats; the messages
    say 0.0042 (the time of cycle 42, computed from the whole cycle). A blank line makes the
    recording read whole instead of streamed: the same words."""
    rows = [f"{k / 10},{k},{-1 if k == 41 else k}" for k in range(60)]
    if read == "whole":
        rows.insert(30, "")
    path = tmp_path / "fast.csv"
    path.write_text("time [ms],u,y\n" + "\n".join(rows) + "\n")
    done = compare(PASS_THROUGH, path)
    assert done.returncode == 1, done.stdout + done.stderr
    assert "y differs first at t=0.0042: 41.0, expected -1.0" in done.stdout
    assert "the most by 42 at t=0.0042\n" in done.stdout
    line = 43 if read == "streamed" else 44
    assert f"sample of cycle 41 ({path}, line {line}, t=0.0041 s from its first sample)" in done.stdout
    assert "step 0.0001 s (the finest interval" in done.stdout and "00000" not in done.stdout


def test_a_folder_of_several_recordings_is_each_of_them(tmp_path):
    """docs/recordings.md: a RECORDING is one exported file, or a folder of them. Each file is a
    recording; the folder's single-point histories (Niagara) together are one."""
    folder = tmp_path / "plant"
    folder.mkdir()
    for name in ("twincat_siemens.csv", "tia_portal_siemens.csv"):
        (folder / name).write_bytes((SAMPLES / name).read_bytes())
    for point in (SAMPLES / "niagara_siemens").iterdir():
        (folder / point.name).write_bytes(point.read_bytes())
    done = compare(SIEMENS[3], folder)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "3 of 3 cases pass" in done.stdout
    for case in ("plant/tia_portal_siemens.csv", "plant/twincat_siemens.csv", "plant on"):
        assert f"PASS  {case}" in done.stdout


@pytest.mark.parametrize("read", ["streamed", "whole"])
def test_a_channel_that_drives_and_is_compared_is_noted_off_its_cycle_once(tmp_path, read):
    """u drives PassThrough's u and is compared with its y; its 21 stamps jitter by 0.3 of a cycle, every
    other one late. The grid of cycles they fit, worked by hand: 10 ms per cycle (the late ones lie
    evenly about the middle), from their mean offset, 3 ms * 10 / 21; so the 11 on time are 1/7 of a
    cycle early, the 10 late ones 11/70 of a cycle late: every stamp more than a tenth off."""
    rows = [f"{k * 10 + (3 if k % 2 else 0)},{k}" for k in range(21)]
    if read == "whole":
        rows.insert(10, "")
    path = tmp_path / "jitter.csv"
    path.write_text("time [ms],u\n" + "\n".join(rows) + "\n")
    done = compare(PASS_THROUGH, path, "--map", "u=u", "--map", "y=u", "--step-size", "0.01")
    assert done.returncode == 0, done.stdout + done.stderr
    assert done.stdout.count("u: 21 of its 21 time stamps are more than 0.1 of a cycle (0.001 s) off") == 1
    assert "jitter up to 15.7 % of a cycle (typical 14.3 %)" in done.stdout
