"""fmutrace end to end, through its command's entry point (in this
process, support.cli; the README's examples start the console script): on the project's FMUs
and on FMUs it did not write (the PassThrough and FirstOrderLag fixtures).
Every reference here is worked by hand from the fixture's equation or
computed by an oracle in this file, never taken from an FMU's output.

PassThrough: y(t + h) = u(t), y = 0 before the first step.
FirstOrderLag: x(t + h) = c + (x(t) - c) * exp(-h / tau), demand = Kp * (setpoint - x).
"""

import json
import math
import re
import shutil
import sys

import numpy as np
import pytest
from junitparser import JUnitXml

import fmutrace
from support.fmu_driver import BUILD_DIR, REPO
from support.cli import fmutrace_in_process
from support.process import run as run_bounded
from support.scenarios import SCENARIO_ROOT

PASS_THROUGH = {v: BUILD_DIR / "benchmarks" / f"fmi{v}" / "PassThrough.fmu" for v in (2, 3)}
LAG = {v: BUILD_DIR / "fixtures" / f"fmi{v}" / "FirstOrderLag.fmu" for v in (2, 3)}
RATE_LIMITER = {v: BUILD_DIR / f"fmi{v}" / "RateLimiter.fmu" for v in (2, 3)}


def fmutrace_cli(*args, cwd=None):
    return fmutrace_in_process(*args, cwd=cwd)


def write_case(folder, model, ref, inputs=None, opt=None, start=None):
    """A case folder from the files' texts."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / f"{model}_ref.csv").write_text(ref)
    for suffix, text in (("_in.csv", inputs), ("_ref.opt", opt), ("_start.csv", start)):
        if text is not None:
            (folder / f"{model}{suffix}").write_text(text)
    return folder


# PassThrough on h = 0.1: u is 1 up to 0.2 and 3 from then on
STEP_OPT = "StartTime,0\nStopTime,0.5\nStepSize,0.1\nRelTol,1e-6\n"
STEP_REF = "time,y\n0,0\n0.1,1\n0.2,1\n0.3,3\n0.4,3\n0.5,3\n"
DIALECTS = {
    "comma": "time,u\n0,1\n0.2,3\n",
    "semicolon": "time;u\n0;1\n0.2;3\n",
    "semicolon and decimal comma": '"time";"u"\n0;1\n0,2;3\n',
    "time named t": "t,u\n0,1\n0.2,3\n",
    "time named Time": "Time,u\n0,1\n0.2,3\n",
    "quoted names": '"time","u"\n0,1\n0.2,3\n',
    "blank lines, CRLF, no final newline": "\r\ntime,u\r\n\r\n0,1\r\n\r\n0.2,3",
    "time not the first column": "u,time\n1,0\n3,0.2\n",
    "comments and spaces": "# recorded by a PLC trace\ntime , u\n 0 , 1\n# the step\n0.2, 3\n",
    "event row": "time,u\n0,1\n0.2,1\n0.2,3\n",
}


# every dialect on FMI 3 in the fast lane, on FMI 2 in the slow lane
@pytest.mark.parametrize("version", [pytest.param(2, marks=pytest.mark.slow), 3])
@pytest.mark.parametrize("dialect", DIALECTS)
def test_each_csv_dialect_on_a_foreign_fmu(dialect, version, tmp_path):
    write_case(tmp_path / "step", "PassThrough", STEP_REF, DIALECTS[dialect], STEP_OPT)
    done = fmutrace_cli("compare", PASS_THROUGH[version], tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "1 of 1 cases pass" in done.stdout


def test_the_dialect_of_the_reference_too(tmp_path):
    write_case(
        tmp_path / "step",
        "PassThrough",
        '"Time";"y"\n0;0\n0,1;1\n\n0,2;1\n0,3;3\n0,4;3\n0,5;3',
        "time,u\n0,1\n0.2,3\n",
        STEP_OPT,
    )
    assert fmutrace_cli("compare", PASS_THROUGH[3], tmp_path).returncode == 0


def test_an_event_row_changes_the_value_at_that_instant(tmp_path):
    """u is 1 up to t = 0.2 and 3 from t = 0.2 on; the step from 0.2 sees 3.
    Read with the event's first row instead, y(0.3) would be 1."""
    write_case(tmp_path / "event", "PassThrough", STEP_REF, "time,u\n0,1\n0.2,1\n0.2,3\n0.5,3\n", STEP_OPT)
    assert fmutrace_cli("compare", PASS_THROUGH[3], tmp_path).returncode == 0
    write_case(tmp_path / "event", "PassThrough", STEP_REF.replace("0.3,3", "0.3,1"))
    done = fmutrace_cli("compare", PASS_THROUGH[3], tmp_path)
    assert done.returncode == 1
    assert "y differs first at t=0.3: 3.0, expected 1.0" in done.stdout


def test_an_event_row_in_a_reference(tmp_path):
    """A reference with the jump recorded as two rows at one instant: the
    exact mode compares the value from that instant on, the tube draws the
    jump."""
    ref = "time,y\n0,0\n0.1,1\n0.2,1\n0.3,1\n0.3,3\n0.4,3\n0.5,3\n"
    write_case(tmp_path / "event", "PassThrough", ref, "time,u\n0,1\n0.2,3\n", STEP_OPT)
    assert fmutrace_cli("compare", PASS_THROUGH[2], tmp_path).returncode == 0
    assert fmutrace_cli("compare", PASS_THROUGH[2], tmp_path, "--tube-time", 0, "--tube-value", 0).returncode == 0


def test_booleans_as_words_in_any_case(tmp_path):
    """The project's bypass scenario with its 0/1 inputs written as
    true/false words: the same hand-worked reference passes."""
    case = shutil.copytree(SCENARIO_ROOT / "RateLimiter" / "bypass", tmp_path / "bypass")
    text = (case / "RateLimiter_in.csv").read_text()
    header, *rows = text.strip().splitlines()
    column = header.split(",").index("bypass")
    words = iter(["true", "FALSE", "True", "false", "TRUE", "False"] * 10)
    new_rows = []
    for row in rows:
        cells = row.split(",")
        cells[column] = next(w for w in words if (w.lower() == "true") == (float(cells[column]) == 1))
        new_rows.append(",".join(cells))
    assert new_rows != rows
    (case / "RateLimiter_in.csv").write_text("\n".join([header] + new_rows) + "\n")
    done = fmutrace_cli("compare", RATE_LIMITER[3], RATE_LIMITER[2], tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "2 of 2 cases pass" in done.stdout


def test_every_project_scenario_in_the_semicolon_dialect(tmp_path):
    """All RateLimiter scenarios rewritten with ';', quoted names and a
    decimal comma: the same verdicts (all pass)."""
    root = shutil.copytree(SCENARIO_ROOT / "RateLimiter", tmp_path / "RateLimiter")
    for path in list(root.glob("*/*_in.csv")) + list(root.glob("*/*_ref.csv")):
        header, *rows = path.read_text().strip().splitlines()
        rows = [";".join(cell.replace(".", ",") for cell in row.split(",")) for row in rows]
        path.write_text(";".join(f'"{n}"' for n in header.split(",")) + "\n" + "\n".join(rows) + "\n")
    done = fmutrace_cli("compare", RATE_LIMITER[3], root, "--jobs", 1)
    assert done.returncode == 0, done.stdout[-3000:]
    assert re.search(r"(\d+) of \1 cases pass", done.stdout)


# ---- comparison modes, on FirstOrderLag with an oracle here ------------------

LAG_OPT = "StartTime,0\nStopTime,2\nStepSize,0.1\n"


def lag_oracle(command_rows, stop=2.0, h=0.1, tau=2.0, x0=0.0, setpoint=10.0, kp=1.0):
    """[(t, x, demand)] on the grid: the plant's exact step with the
    command held over each step (a row holds from its time on)."""
    x, rows = x0, []
    for k in range(round(stop / h) + 1):
        t = k * h
        rows.append((t, x, kp * (setpoint - x)))
        c = [value for time, value in command_rows if time <= t + 1e-12][-1]
        x = c + (x - c) * math.exp(-h / tau)
    return rows


LAG_INPUT = [(0.0, 5.0), (1.0, 2.0)]


def lag_case(folder, transform=lambda t, x: x, start=None):
    rows = lag_oracle(LAG_INPUT)
    ref = "time,x,demand\n" + "".join(f"{t!r},{transform(t, x)!r},{d!r}\n" for t, x, d in rows)
    inputs = "time,command\n" + "".join(f"{t},{c}\n" for t, c in LAG_INPUT)
    return write_case(folder, "FirstOrderLag", ref, inputs, LAG_OPT, start)


@pytest.mark.parametrize("version", [pytest.param(2, marks=pytest.mark.slow), 3])
def test_exact_mode_passes_bit_for_bit_and_fails_on_one_ulp(version, tmp_path):
    lag_case(tmp_path / "lag")
    assert fmutrace_cli("compare", LAG[version], tmp_path).returncode == 0
    lag_case(tmp_path / "lag", lambda t, x: math.nextafter(x, math.inf) if abs(t - 1.5) < 1e-9 else x)
    done = fmutrace_cli("compare", LAG[version], tmp_path)
    assert done.returncode == 1
    assert "x differs first at t=1.5" in done.stdout
    assert "1 of 21 samples differ" in done.stdout


@pytest.mark.parametrize(
    "flag,allowed,too_small,off",
    [("--rel-tol", 1e-6, 1e-8, lambda x: x * (1 + 1e-7)), ("--abs-tol", 1e-3, 1e-5, lambda x: x + 1e-4)],
)
def test_tolerance_modes(flag, allowed, too_small, off, tmp_path):
    lag_case(tmp_path / "lag", lambda t, x: off(x) if t > 0 else x)
    assert fmutrace_cli("compare", LAG[3], tmp_path).returncode == 1  # exact: differs
    assert fmutrace_cli("compare", LAG[3], tmp_path, flag, allowed).returncode == 0
    done = fmutrace_cli("compare", LAG[3], tmp_path, flag, too_small)
    assert done.returncode == 1
    assert "x leaves the band first at t=0.1" in done.stdout
    assert "20 of 21 samples outside" in done.stdout


def recorder_case(folder, start=None):
    """A trace recorder's view of FirstOrderLag under command 5 (x = 5 (1 -
    e^(-t/2))): every 0.25 s, not the FMU's 0.1 s grid, 4 decimals."""
    ref = "time,x\n" + "".join(f"{0.25 * k},{5 * (1 - math.exp(-0.25 * k / 2)):.4f}\n" for k in range(9))
    return write_case(folder, "FirstOrderLag", ref, "time,command\n0,5\n2,5\n", LAG_OPT, start)


def test_tube_for_traces_sampled_at_other_instants(tmp_path):
    """The polyline through the recorder's samples stays within 0.01 of
    the curve (its sag over 0.25 s is at most 0.25^2 / 8 * 5/4); 0.1 s of
    time covers that where the slope is at least 0.1 per 0.1 s."""
    recorder_case(tmp_path / "recorder")
    done = fmutrace_cli("compare", LAG[3], LAG[2], tmp_path, "--tube-time", 0.1, "--tube-value", 0.001)
    assert done.returncode == 0, done.stdout
    exact = fmutrace_cli("compare", LAG[3], tmp_path)
    assert exact.returncode == 1 and "the result has no sample at t=0.25" in exact.stdout


def test_tube_checks_the_result_where_the_reference_says_something(tmp_path):
    """A recording that ends at 1 s of a 2 s run: the samples after it are
    not checked (against the last recorded value they would fail: x keeps
    rising)."""
    case = recorder_case(tmp_path / "recorder")
    ref = case / "FirstOrderLag_ref.csv"
    ref.write_text("".join(line for line in ref.read_text().splitlines(keepends=True)[:6]))  # 0 .. 1 s
    done = fmutrace_cli(
        "compare", LAG[3], tmp_path, "--tube-time", 0.1, "--tube-value", 0.001, "--report", tmp_path / "report"
    )
    assert done.returncode == 0, done.stdout
    outcome = json.loads((tmp_path / "report" / "results.json").read_text())["cases"][0]
    assert outcome["status"] == "pass"


def test_tube_fails_where_the_result_leaves_it_and_says_by_how_much(tmp_path):
    recorder_case(tmp_path / "recorder", start="tau,1.0\n")  # twice as fast: leaves the tube at once
    done = fmutrace_cli(
        "compare", LAG[3], tmp_path, "--tube-time", 0.1, "--tube-value", 0.001, "--report", tmp_path / "report"
    )
    assert done.returncode == 1
    # at t = 0.1, x = 5 (1 - e^-0.1); the window [0, 0.2] of the reference's
    # polyline rises from 0 at t = 0 towards its sample at 0.25: its top is
    # at 0.2, four fifths of that sample
    case = json.loads((tmp_path / "report" / "results.json").read_text())["cases"][0]
    assert "plot_data" in case and not any(m.startswith("no plot") for m in case["messages"])  # (its page's plots)
    first = case["signals"][0]
    assert first["name"] == "x" and not first["passed"]
    upper = round(5 * (1 - math.exp(-0.125)), 4) * 0.2 / 0.25 + 0.001
    x = 5 * (1 - math.exp(-0.1))
    assert first["time"] == pytest.approx(0.1, rel=1e-12)
    assert first["value"] == pytest.approx(x, rel=1e-12)
    assert first["upper"] == pytest.approx(upper, rel=1e-12) and first["lower"] == pytest.approx(-0.001, abs=1e-12)
    assert first["excess"] == pytest.approx(x - upper, rel=1e-9)
    assert first["direction"] == "result"  # (the result's sample leaves the tube around the reference first)
    assert (
        f"x: the result leaves the tube around the reference first at t={first['time']!r}: {first['value']!r}, "
        "the tube there [" in done.stdout
    )


def test_the_tube_needs_both_widths_and_no_tolerance_beside_it(tmp_path):
    recorder_case(tmp_path / "recorder")
    for args, message in [
        (("--tube-time", 0.1), "needs both"),
        (("--tube-time", 0.1, "--tube-value", 0.1, "--rel-tol", 1e-3), "not both"),
        (("--tube-time", "inf", "--tube-value", 0), "tube-time must be a finite number >= 0"),
    ]:
        done = fmutrace_cli("compare", LAG[3], tmp_path, *args)
        assert done.returncode == 2 and message in done.stderr


# ---- bad input: exit 2, the file, line and column ---------------------------


def good_case(folder):
    return write_case(
        folder,
        "RateLimiter",
        "time,y\n0,0\n0.5,0\n1,0.5\n",
        "time,u\n0,0\n0.5,10\n",
        "StartTime,0\nStopTime,1\nStepSize,0.5\n",
        "rateUpPar,1\n",
    )


BAD = {
    "unknown column": (
        "RateLimiter_in.csv",
        "time,u,speed\n0,0,1\n",
        "RateLimiter_in.csv, line 1, column 3: unknown column 'speed'",
    ),
    "output as input column": (
        "RateLimiter_in.csv",
        "time,u,y\n0,0,1\n",
        "RateLimiter_in.csv, line 1, column 3: column 'y' is a discrete output",
    ),
    "non-numeric cell": (
        "RateLimiter_in.csv",
        "time,u\n0,0\n0.5,ten\n",
        "RateLimiter_in.csv, line 3, column 2: 'ten' in column 'u' is not a number",
    ),
    "empty cell": (
        "RateLimiter_in.csv",
        "time,u\n0,0\n0.5,\n",
        "RateLimiter_in.csv, line 3, column 2: an empty cell in column 'u'",
    ),
    "short row": ("RateLimiter_in.csv", "time,u\n0\n", "RateLimiter_in.csv, line 2, column 2: 1 cells"),
    "time going backwards": (
        "RateLimiter_in.csv",
        "time,u\n0,0\n0.5,10\n0.25,3\n",
        "RateLimiter_in.csv, line 4, column 1: time goes backwards: 0.25 after 0.5",
    ),
    "empty file": ("RateLimiter_in.csv", "", "RateLimiter_in.csv: empty file"),
    "header only": ("RateLimiter_ref.csv", "time,y\n", "RateLimiter_ref.csv, line 1: no samples"),
    "no time column": (
        "RateLimiter_ref.csv",
        "seconds,y\n0,0\n",
        "RateLimiter_ref.csv, line 1, column 1: no time column",
    ),
    "reference column not a variable": (
        "RateLimiter_ref.csv",
        "time,y,yFiltered\n0,0,0\n",
        "RateLimiter_ref.csv, line 1, column 3: column 'yFiltered' is not a variable of RateLimiter (FMI 3)",
    ),
    "start value below its minimum": (
        "RateLimiter_start.csv",
        "rateUpPar,1\ninitDelay,-1\n",
        "RateLimiter_start.csv, line 2, column 2: initDelay = -1 is outside its range [0, inf]",
    ),
    "enumeration value that does not exist": (
        "RateLimiter_start.csv",
        "zeroRate,7\n",
        "RateLimiter_start.csv, line 1, column 2: zeroRate is an enumeration ZeroRate: 7 is not one of its values",
    ),
    "enumeration value not whole": (
        "RateLimiter_start.csv",
        "zeroRate,1.5\n",
        "RateLimiter_start.csv, line 1, column 2: zeroRate is an Enumeration: '1.5' is not a whole number",
    ),
    "start value of an unknown variable": (
        "RateLimiter_start.csv",
        "rateUpPr,1\n",
        "RateLimiter_start.csv, line 1, column 1: 'rateUpPr' is not a variable",
    ),
    "Boolean start value": (
        "RateLimiter_start.csv",
        "bypass,yes\n",
        "RateLimiter_start.csv, line 1, column 2: bypass is a Boolean: 'yes' is not true, false",
    ),
    "unknown option": (
        "RateLimiter_ref.opt",
        "StartTime,0\nStoptime,1\n",
        "RateLimiter_ref.opt, line 2, column 1: unknown option 'Stoptime'",
    ),
}


@pytest.mark.slow
@pytest.mark.parametrize("bad", BAD)
def test_bad_input_exits_2_naming_file_line_and_column(bad, tmp_path):
    file, text, message = BAD[bad]
    case = good_case(tmp_path / "cases" / "one")
    assert fmutrace_cli("compare", RATE_LIMITER[3], tmp_path / "cases").returncode == 0
    (case / file).write_text(text)
    good_case(tmp_path / "cases" / "two")
    done = fmutrace_cli("compare", RATE_LIMITER[3], tmp_path / "cases", "--report", tmp_path / "report")
    assert done.returncode == 2, done.stdout + done.stderr
    assert done.stderr.startswith("fmutrace: error: ")
    assert message in done.stderr, done.stderr
    assert str(case / file) in done.stderr
    assert "1 of 2 cases pass, 0 differ, 1 invalid" in done.stdout  # the other case ran
    results = json.loads((tmp_path / "report" / "results.json").read_text())
    assert [(c["case"], c["status"]) for c in results["cases"]] == [("one", "invalid"), ("two", "pass")]


@pytest.mark.parametrize(
    "args,message",
    [
        (("run", "{fmu}", "--set", "initDelay=-1"), "initDelay = -1 is outside its range [0, inf]"),
        (
            ("run", "{fmu}", "--set", "y=1"),
            "'y' is a discrete output of RateLimiter (FMI 3): only parameters and inputs",
        ),
        (("run", "{fmu}", "--set", "nosuch=1"), "'nosuch' is not a variable of RateLimiter (FMI 3)"),
        (("run", "{fmu}", "--output", "nosuch"), "output 'nosuch' is not a variable"),
        (
            ("run", "{fmu}", "--step-size", "0.1", "--output-interval", "0.25", "--stop-time", "1"),
            "must be a whole multiple of the step size",
        ),
        (("run", "{fmu}", "--set", "rateUpPar"), "expected NAME=VALUE"),
        (("run", "missing.fmu"), "missing.fmu: no such FMU file"),
        (("compare", "{lag}"), "carries no FMI-LS-REF experiments (no extra/org.fmi-standard.fmi-ls-ref/fmi-ls"),
        (("compare", "{cases}"), "no FMU given"),
        (("compare", "{fmu}", "{nothing}"), "no such folder"),
        (("compare", "{lag}", "{cases}"), "no case of FirstOrderLag (FMI 3) (no FirstOrderLag_ref.csv)"),
        (("compare", "{fmu}", "{cases}", "--rel-tol", "-1"), "-1 must be >= 0"),
        (("frobnicate",), "invalid choice"),
    ],
)
def test_usage_errors_exit_2(args, message, tmp_path):
    good_case(tmp_path / "cases" / "one")
    names = {"fmu": RATE_LIMITER[3], "cases": tmp_path / "cases", "nothing": tmp_path / "nothing", "lag": LAG[3]}
    done = fmutrace_cli(*[a.format(**names) for a in args], cwd=tmp_path)
    assert done.returncode == 2, done.stdout + done.stderr
    assert message in done.stderr


# ---- run, the report, JUnit, the API --------------------------------------


def test_run_writes_the_result_and_reads_back_bit_for_bit(tmp_path):
    (tmp_path / "in.csv").write_text("time;u\n0;0\n0,5;10\n")
    out = tmp_path / "out.csv"
    done = fmutrace_cli(
        "run",
        RATE_LIMITER[3],
        "--input",
        tmp_path / "in.csv",
        "--set",
        "rateUpPar=3",
        "--step-size",
        0.1,
        "--stop-time",
        2,
        "--output",
        "y",
        "--output",
        "rampActive",
        "-o",
        out,
    )
    assert done.returncode == 0, done.stderr
    assert "21 samples of 2 signals" in done.stdout
    result = fmutrace.read_trace(out)
    assert result.dtype.names == ("time", "y", "rampActive")
    # u = 10 from t = 0.5 on: 3 per s, 0.3 per cycle from the step at 0.5
    assert list(result["y"]) == pytest.approx([0.0] * 6 + [0.3 * k for k in range(1, 16)], rel=1e-12, abs=0)
    assert list(result["rampActive"]) == [0.0] * 6 + [1.0] * 15
    api = fmutrace.simulate(
        RATE_LIMITER[3],
        input=tmp_path / "in.csv",
        start_values={"rateUpPar": "3"},
        step_size=0.1,
        stop_time=2,
        outputs=["y", "rampActive"],
    )
    assert np.array_equal(api["y"], result["y"])
    assert np.array_equal(api["time"], result["time"])


def test_run_to_standard_output_with_an_output_interval():
    done = fmutrace_cli("run", PASS_THROUGH[2], "--step-size", 0.1, "--output-interval", 0.5, "--stop-time", 2)
    assert done.returncode == 0, done.stderr
    lines = done.stdout.strip().splitlines()
    assert lines[0] == '"time","y"'
    assert [float(line.split(",")[0]) for line in lines[1:]] == pytest.approx([0, 0.5, 1, 1.5, 2])


def test_report_and_junit_xml_that_a_junit_parser_reads(tmp_path):
    lag_case(tmp_path / "cases" / "lag_exact")
    lag_case(tmp_path / "cases" / "lag_off", lambda t, x: x + 0.01 if t >= 1 else x)
    write_case(tmp_path / "cases" / "step", "PassThrough", STEP_REF, DIALECTS["comma"], STEP_OPT)
    report, junit = tmp_path / "report", tmp_path / "ci" / "junit.xml"
    junit.parent.mkdir()  # (--junit makes no folder: issue 51)
    done = fmutrace_cli(
        "compare",
        LAG[2],
        LAG[3],
        PASS_THROUGH[3],
        tmp_path / "cases",
        "--report",
        report,
        "--junit",
        junit,
        "--plots",
        "png",
    )
    assert done.returncode == 1
    assert "3 of 5 cases pass, 2 differ" in done.stdout
    assert "FAIL  lag_off on FirstOrderLag (FMI 2)" in done.stdout

    xml = JUnitXml.fromfile(str(junit))
    suites = {suite.name: suite for suite in xml}
    assert set(suites) == {"FirstOrderLag (FMI 2)", "FirstOrderLag (FMI 3)", "PassThrough (FMI 3)"}
    assert (xml.tests, xml.failures, xml.errors) == (5, 2, 0)
    lag2 = {case.name: case for case in suites["FirstOrderLag (FMI 2)"]}
    assert lag2["lag_exact"].is_passed
    failure = lag2["lag_off"].result[0]
    assert failure.message.startswith("x differs first at t=1.0")

    results = json.loads((report / "results.json").read_text())
    assert results["mode"] == "exact" and results["passed"] is False
    assert results["counts"] == {"pass": 3, "fail": 2, "error": 0, "invalid": 0}
    off = next(c for c in results["cases"] if c["case"] == "lag_off" and c["fmu"] == "FirstOrderLag (FMI 3)")
    x = next(s for s in off["signals"] if s["name"] == "x")
    assert x["time"] == 1.0 and x["excess"] == pytest.approx(0.01, rel=1e-9) and x["failed"] == 11
    html = (report / "index.html").read_text()
    rows = re.findall(r'<tr class="(\w+)" data-status', html)
    assert rows == ["fail", "fail", "pass", "pass", "pass"]  # one row per case, the failing ones first
    for case in results["cases"]:
        assert (report / case["plot"]).read_bytes().startswith(b"\x89PNG")
        assert fmutrace.read_trace(report / case["result_csv"]).dtype.names[0] == "time"
        assert f"[png]({case['plot']})" in (report / "summary.md").read_text()


def test_api_compare_returns_the_outcomes(tmp_path):
    lag_case(tmp_path / "lag")
    campaign = fmutrace.compare([LAG[2], LAG[3]], tmp_path / "lag", rel_tol=1e-12, report=tmp_path / "report")
    assert campaign.passed and campaign.exit_code == 0
    assert [(o.case, o.fmu) for o in campaign.cases] == [
        ("lag", "FirstOrderLag (FMI 2)"),
        ("lag", "FirstOrderLag (FMI 3)"),
    ]
    assert campaign.cases[0].result["x"][-1] == lag_oracle(LAG_INPUT)[-1][1]
    with pytest.raises(fmutrace.InputError, match="no such folder"):
        fmutrace.compare(LAG[3], tmp_path / "nothing")


def test_api_comparison_modes_as_objects(tmp_path):
    """A mode given as an object judges as the command's options that make
    it: x off by 1e-4 from t = 0.1 on fails exactly and within 1e-5, passes
    within 1e-3; the exit codes are the command's."""
    lag_case(tmp_path / "lag", lambda t, x: x + 1e-4 if t > 0 else x)
    exact = fmutrace.compare(LAG[3], tmp_path / "lag", mode=fmutrace.Exact())
    assert not exact.passed and exact.exit_code == 1 == fmutrace.SimulationError.exit_code
    assert exact.cases[0].status == fmutrace.Status.FAIL == "fail"
    assert fmutrace.compare(LAG[3], tmp_path / "lag", mode=fmutrace.Tolerance(abs_tol=1e-3)).passed
    narrow = fmutrace.compare(LAG[3], tmp_path / "lag", mode=fmutrace.Tolerance(abs_tol=1e-5))
    assert narrow.cases[0].messages[0].startswith("x leaves the band first at t=0.1")
    assert fmutrace.comparison_mode(abs_tol=1e-5) == fmutrace.Tolerance(abs_tol=1e-5)
    assert fmutrace.comparison_mode() == fmutrace.Exact()
    assert fmutrace.comparison_mode(tube_time=0.1, tube_value=1e-3) == fmutrace.Tube(0.1, 1e-3)
    # the command's words (tube-time) at the command's level: test_the_tube_needs_both_widths_and_no_tolerance_beside_it
    with pytest.raises(fmutrace.InputError, match=r"Tube\(time=\.\.\.\) must be a finite number >= 0") as refused:
        fmutrace.Tube(-1.0, 0.0)
    assert refused.value.exit_code == 2


@pytest.mark.parametrize("version", [2, 3])
def test_a_simulation_that_fails_is_an_error_case_not_a_crash(version, tmp_path):
    """zeroRate 7 in the input table (the checks cover start values, not
    every input sample): the FMU refuses it with an error status and a log
    message, the case is an error with the FMU's words, the others run."""
    good_case(tmp_path / "cases" / "good")
    refused = good_case(tmp_path / "cases" / "refused")
    (refused / "RateLimiter_in.csv").write_text("time,u,zeroRate\n0,0,1\n0.5,10,7\n")
    done = fmutrace_cli("compare", RATE_LIMITER[version], tmp_path / "cases")
    assert done.returncode == 1
    assert f"ERROR  refused on RateLimiter (FMI {version})" in done.stdout
    setter = "fmi2SetInteger" if version == 2 else "fmi3SetInt64"
    assert (
        f"the simulation failed: {setter} failed with status 3 (error); the FMU said: {setter}: zeroRate = 7 is "
        "outside its range [1, 2]" in done.stdout
    )
    assert "1 of 2 cases pass, 0 differ, 1 failed to simulate" in done.stdout


def test_progress_bar_only_on_a_terminal():
    import io

    class Terminal(io.StringIO):
        def isatty(self):
            return True

    for stream, expected in ((Terminal(), True), (io.StringIO(), False)):
        bar = fmutrace._progress.Progress(10, stream)
        bar.started -= 10  # a campaign that has run for ten seconds
        bar.update(4, 1)
        bar.close()
        assert ("[############..................] 4/10 cases, 1 failing" in stream.getvalue()) == expected
        assert (stream.getvalue() != "") == expected


def test_the_command_is_silent_when_not_on_a_terminal(tmp_path):
    good_case(tmp_path / "cases" / "one")
    done = fmutrace_cli("compare", RATE_LIMITER[2], tmp_path / "cases")
    assert "\r" not in done.stdout + done.stderr and done.stderr == ""


def readme_example():
    text = (REPO / "README.md").read_text()
    block = re.search(r"<!-- pytest example -->\s*```python\n(.*?)```", text, re.S)
    assert block, "the README has no pytest example"
    return block.group(1)


@pytest.mark.slow
def test_the_readme_pytest_example_runs(tmp_path):
    """The example as a user copies it into a test file; 'build/' is this
    run's build folder."""
    code = readme_example().replace('"build/', f'"{BUILD_DIR.as_posix()}/')
    (tmp_path / "test_my_traces.py").write_text(code)
    done = run_bounded(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", str(tmp_path)],
        timeout=600,
        what="the README's pytest example",
        cwd=REPO,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert re.search(r"\b[1-9]\d* passed", done.stdout)


def test_the_readme_run_example_runs_to_a_meaningful_stop_time(tmp_path):
    """The README's `run` lines as a user types them (its u.csv, then the
    command): y rises at rateUpPar = 2 per second from the step at t = 1 s
    (seen by the cycle (1, 1.1]) and holds the input's 10 from t = 6 s on."""
    text = (REPO / "README.md").read_text()
    lines = [
        line
        for block in re.findall(r"```sh\n(.*?)```", text, re.S)
        for line in block.splitlines()
        if line.startswith("printf ") or line.startswith("build/venv/bin/fmutrace run ")
    ]
    assert len(lines) == 2, lines
    (tmp_path / "build").symlink_to(BUILD_DIR)
    done = run_bounded(["sh", "-c", "\n".join(lines)], timeout=300, what="the README's run example", cwd=tmp_path)
    assert done.returncode == 0, done.stdout + done.stderr
    result = fmutrace.read_trace(tmp_path / "y.csv")
    t, y = result["time"], result["y"]
    assert len(t) == 81 and t[-1] == pytest.approx(8.0)
    expected = [min(max(2 * (k / 10 - 1), 0), 10) for k in range(81)]  # worked by hand, k: the step
    assert y == pytest.approx(expected, abs=1e-9)
    assert not (y == 0).all() and y[-1] == 10


def test_a_folder_of_links_to_case_folders_is_a_folder_of_cases(tmp_path):
    """As the benchmarks give a part of their cases: links to case folders
    (and a link loop) in a folder of their own; not a recording."""
    write_case(tmp_path / "cases" / "step", "PassThrough", STEP_REF, DIALECTS["comma"], STEP_OPT)
    linked = tmp_path / "linked"
    linked.mkdir()
    (linked / "step").symlink_to(tmp_path / "cases" / "step")
    (linked / "loop").symlink_to(linked)
    done = fmutrace_cli("compare", PASS_THROUGH[3], linked)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "1 of 1 cases pass" in done.stdout


@pytest.mark.parametrize("identity", ["128-bit inode", "negative device"])
def test_find_cases_takes_folder_identities_of_any_size(tmp_path, monkeypatch, identity):
    """Windows' ReFS gives 128-bit inode numbers, macOS a signed device:
    a case folder found twice (a link) is still found once."""
    import os
    from types import SimpleNamespace

    (tmp_path / "b").mkdir()
    (tmp_path / "b" / "M_ref.csv").write_text("time,y\n0,0\n")
    (tmp_path / "z").mkdir()
    (tmp_path / "z" / "link_to_b").symlink_to(tmp_path / "b")
    real_stat = os.stat

    def wide(path, *args, **kwargs):
        status = real_stat(path, *args, **kwargs)
        if identity == "128-bit inode":
            return SimpleNamespace(st_dev=status.st_dev, st_ino=status.st_ino + (1 << 100), st_mode=status.st_mode)
        return SimpleNamespace(st_dev=-1 - status.st_dev, st_ino=status.st_ino, st_mode=status.st_mode)

    with monkeypatch.context() as patched:
        patched.setattr(os, "stat", wide)
        found = fmutrace.find_cases([tmp_path], "M")
    assert found[:] == [(tmp_path / "b", "b")]


def test_find_cases_names_each_case_folder_once(tmp_path):
    """Names are the paths below the folder searched, sorted; a case folder
    given itself takes its own name; a name found below two folders given
    is prefixed with the second one's name; linked folders are followed,
    each folder once, and a link loop ends."""

    def case(folder):
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "M_ref.csv").write_text("time,y\n0,0\n")
        return folder

    one, two = tmp_path / "one", tmp_path / "two"
    case(one / "b")
    case(one / "a" / "deep")
    case(one / "a")
    case(two / "b")
    case(two / "c")
    (one / "z").mkdir()
    (one / "z" / "link_to_b").symlink_to(one / "b")  # b again: once, by its first path in sorted order
    (one / "0_link_to_c").symlink_to(two / "c")  # c, first reached from one: named there
    (one / "a" / "loop").symlink_to(one)  # a loop: ends
    (tmp_path / "other").mkdir()
    (one / "a" / "not_a_case").mkdir()
    found = fmutrace.find_cases([one, two], "M")
    assert [(str(folder.relative_to(tmp_path)), name) for folder, name in found] == [
        ("one/0_link_to_c", "0_link_to_c"),
        ("one/a", "a"),
        ("one/a/deep", "a/deep"),
        ("one/b", "b"),
        ("two/b", "two/b"),
    ]
    assert [name for _, name in fmutrace.find_cases([two / "c"], "M")] == ["c"]  # a case folder itself
    # case folders given themselves, two of one name: the second is prefixed with its own name
    assert fmutrace.find_cases([two / "c", one / "b", two / "b"], "M")[:] == [
        (one / "b", "b"),
        (two / "b", "b/b"),
        (two / "c", "c"),
    ]
    assert found[-1] == (two / "b", "two/b") and found[2:4] == [(one / "a" / "deep", "a/deep"), (one / "b", "b")]
    assert len(fmutrace.find_cases([tmp_path / "other"], "M")) == 0
    # c below two was found first through one's link: it takes no name, and three's c is plain c
    three = tmp_path / "three"
    case(three / "c")
    assert fmutrace.find_cases([one, two, three], "M")[-2:] == [(three / "c", "c"), (two / "b", "two/b")]


def test_a_report_that_fails_to_be_written_leaves_the_last_one_whole(tmp_path, monkeypatch):
    """index.html, summary.md and results.json are replaced together: a
    failure while the index is written leaves the three of the last
    campaign as they were."""
    from fmutrace import _report

    cases = shutil.copytree(SCENARIO_ROOT / "RateLimiter" / "bypass", tmp_path / "cases" / "bypass")
    report = tmp_path / "report"
    fmutrace.compare(RATE_LIMITER[3], cases.parent, report=report, run=fmutrace.RunOptions(jobs=1))
    files = ("index.html", "summary.md", "results.json")
    before = {name: (report / name).read_bytes() for name in files}

    def failing_head(*args):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(_report, "_index_head", failing_head)
    (cases / "RateLimiter_ref.csv").write_text((cases / "RateLimiter_ref.csv").read_text().replace(",0\n", ",7\n", 1))
    with pytest.raises(OSError, match="No space left"):
        fmutrace.compare(RATE_LIMITER[3], cases.parent, report=report, run=fmutrace.RunOptions(jobs=1))
    assert {name: (report / name).read_bytes() for name in files} == before
