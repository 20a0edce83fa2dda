"""Messages name a setting as its caller wrote it (docs/fmutrace.md,
Python API): a Python caller is told RecordingOptions(step_size=...) or
Tube(time=..., value=...), the command's user --step-size or --tube-time
(cli.FLAGS, carried down to the readers as RecordingOptions.names). No
module but the command's writes a flag into a message."""

import ast
import re
from pathlib import Path

import pytest

import fmutrace
from fmutrace._names import name_of
from fmutrace.cli import FLAGS
from support.cli import fmutrace_in_process
from support.fmu_driver import BUILD_DIR

PACKAGE = Path(__file__).resolve().parents[2] / "fmutrace" / "src" / "fmutrace"
SIEMENS = BUILD_DIR / "fmi3" / "LGF_LimRateOfChangeCI.fmu"
PASS_THROUGH = BUILD_DIR / "benchmarks" / "fmi3" / "PassThrough.fmu"
RECORDINGS = Path(__file__).parents[1] / "recordings"
FLAG = re.compile(r"(?<![\w-])--[a-z][a-z-]*")  # --map, --step-size; not x--y nor a rule of dashes


def flag_literals(source, name="<source>"):
    """(line, text) of each string literal of source that holds flag text,
    the literal parts of f-strings included; docstrings (which may explain
    the command) and comments aside."""
    tree = ast.parse(source, name)
    documented = (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)
    docstrings = {
        id(node.body[0].value)
        for node in ast.walk(tree)
        if isinstance(node, documented)
        and node.body
        and isinstance(node.body[0], ast.Expr)
        and isinstance(node.body[0].value, ast.Constant)
    }
    return sorted(
        (node.lineno, node.value)
        for node in ast.walk(tree)
        if isinstance(node, ast.Constant)
        and isinstance(node.value, str)
        and id(node) not in docstrings
        and FLAG.search(node.value)
    )


COMMANDS = ("cli.py", "pytest_plugin.py")  # fmutrace's commands, and the options its plugin adds to pytest's


def test_no_module_but_the_commands_writes_a_flag():
    found = {
        str(path.relative_to(PACKAGE)): flag_literals(path.read_text(), str(path))
        for path in sorted(PACKAGE.rglob("*.py"))
        if path.name not in COMMANDS
    }
    assert {name: literals for name, literals in found.items() if literals} == {}


def test_the_rule_finds_flag_text_in_messages_and_markers_not_in_docstrings_or_comments():
    source = '''"""Explains --map, as the command's docs do."""
def f(x):
    """give --step-size"""
    # --time-unit
    a = "x--y and ----"
    b = f"give the cycle time with --step-size {x}"
    return "--time-unit"
'''
    assert flag_literals(source) == [(6, "give the cycle time with --step-size "), (7, "--time-unit")]


@pytest.mark.parametrize(
    "names, settings, values, written",
    [
        ((), ("step_size",), {}, "RecordingOptions(step_size=...)"),
        (FLAGS, ("step_size",), {}, "--step-size"),
        ((), (), {"maps": ("y", "Y")}, "RecordingOptions(maps={'y': 'Y'})"),
        (FLAGS, (), {"maps": ("y", "Y")}, "--map y=Y"),
        ((), (), {"tube_time": 0.5, "tube_value": 0.0}, "Tube(time=0.5, value=0)"),
        (FLAGS, (), {"tube_time": 0.5, "tube_value": 0.0}, "--tube-time 0.5 --tube-value 0"),
        ((), (), {"time_unit": "us"}, "RecordingOptions(time_unit='us')"),
        (FLAGS, (), {"time_unit": "us"}, "--time-unit us"),
        ((), ("resume",), {}, "compare(resume=...)"),
        ({"step_size": "--cycle"}, ("step_size", "abs_tol"), {}, "--cycle Tolerance(abs_tol=...)"),  # words lacking
    ],
)
def test_a_setting_is_written_in_the_callers_words(names, settings, values, written):
    assert name_of(names, *settings, **values) == written


def test_the_callers_words_are_no_setting():
    """Options that differ in their words alone read recordings alike: equal, the same campaign."""
    command = fmutrace.RecordingOptions(step_size=0.25, names=FLAGS)
    assert command == fmutrace.RecordingOptions(step_size=0.25) and hash(command) == hash(
        fmutrace.RecordingOptions(step_size=0.25)
    )
    assert command.settings() == fmutrace.RecordingOptions(step_size=0.25).settings()
    with pytest.raises(fmutrace.InputError, match=r"^RecordingOptions\(time_unit=\.\.\.\) must be one of s, ms"):
        fmutrace.RecordingOptions(time_unit="h")
    with pytest.raises(fmutrace.InputError, match=r"^--time-unit must be one of s, ms"):
        fmutrace.RecordingOptions(time_unit="h", names=FLAGS)


def command(*args):
    """What the command fmutrace compare args prints (its entry point run in this process)."""
    done = fmutrace_in_process("compare", *args)
    return done.stdout + done.stderr


def in_python(fmu, path, **options):
    """The messages a library call gives for the recording at path (its case run in this process)."""
    campaign = fmutrace.compare(
        fmu, path, recording=fmutrace.RecordingOptions(**options), run=fmutrace.RunOptions(jobs=1)
    )
    return "\n".join(m for outcome in campaign.cases for m in outcome.messages)


COUNTER = "time;value;setChangeRate;delayedValue\n" + "".join(f"{5000000000 + k * 250000};0;4;0\n" for k in range(5))
DATES = "time,value,setChangeRate,delayedValue\n2026-11-20 14:03:11.000,0,4,0\n2026-11-20 14:03:11.250,0,4,0\n"
TWICE = "time,MAIN.a.value,MAIN.b.value,delayedValue\n0,1,2,0\n"
COARSE_STEP = "time [ms],value,delayedValue\n0,1,0\n10,1,0\n20,1,0\n"
TIA_EVERY_3RD = "tia_every_3rd.csv"  # the TIA Portal sample, its rows every 3rd cycle (written below)


def write_tia_every_3rd(path):
    lines = (RECORDINGS / "tia_portal_siemens.csv").read_text(encoding="cp1252").splitlines()
    path.write_text("\r\n".join(lines[:6] + lines[6::3]) + "\r\n", encoding="cp1252")


# (file: a sample's name or a text, the recording's options, the library's words, the command's words)
RECORDING_MESSAGES = {
    "map, no such channel": (
        "twincat_siemens.csv",
        {"maps": {"value": "nope"}},
        "RecordingOptions(maps={'value': 'nope'}): ",
        "--map value=nope: ",
    ),
    "map, no such variable": (
        "twincat_siemens.csv",
        {"maps": {"nope": "value"}},
        "RecordingOptions(maps={'nope': 'value'}): LGF_LimRateOfChangeCI (FMI 3) has no variable 'nope'",
        "--map nope=value: LGF_LimRateOfChangeCI (FMI 3) has no variable 'nope'",
    ),
    "map, two channels mean one variable": (
        TWICE,
        {},
        "both mean value: say which with RecordingOptions(maps={'value': 'CHANNEL'})",
        "both mean value: say which with --map value=CHANNEL",
    ),
    "map, no output": (
        "time,value\n0,1\n0.25,1\n",
        {},
        "map one with RecordingOptions(maps={'VARIABLE': 'CHANNEL'}))",
        "map one with --map VARIABLE=CHANNEL)",
    ),
    "step size, coarser than the recording": (
        COARSE_STEP,
        {"step_size": 0.25},
        "(give the recorder's cycle with RecordingOptions(step_size=...))",
        "(give the recorder's cycle with --step-size)",
    ),
    "step size, where the step came from": (
        "twincat_siemens.csv",
        {"step_size": 0.25},
        "step 0.25 s (RecordingOptions(step_size=...))",
        "step 0.25 s (--step-size)",
    ),
    "time unit, an absurd number of steps": (
        COUNTER,
        {"step_size": 0.25},
        "if that is not its unit, give RecordingOptions(time_unit=...) (s, ms, us, ns, cycles, filetime)",
        "if that is not its unit, give --time-unit (s, ms, us, ns, cycles, filetime)",
    ),
    "time unit, where the unit came from": (
        COUNTER,
        {"time_unit": "us"},
        "time as microseconds (RecordingOptions(time_unit=...))",
        "time as microseconds (--time-unit)",
    ),
    "time unit, dates take none": (
        DATES,
        {"time_unit": "s"},
        "its time stamps are dates and times: RecordingOptions(time_unit='s') does not apply",
        "its time stamps are dates and times: --time-unit s does not apply",
    ),
    "tube and tolerance, inputs sampled coarser than the step": (
        TIA_EVERY_3RD,
        {"step_size": 0.25},
        "allows that lag: Tube(time=0.5, value=0), or Tolerance(abs_tol=2) (the largest change",
        "allows that lag: --tube-time 0.5 --tube-value 0, or --abs-tol 2 (the largest change",
    ),
}


def _flags(options):
    """The command's flags for the options: the inverse of what RecordingOptions is given."""
    args = []
    for setting, value in options.items():
        pairs = value.items() if isinstance(value, dict) else [(None, value)]
        for name, item in pairs:
            args += [FLAGS[setting], f"{name}={item}" if name else item]
    return args


@pytest.mark.parametrize("kind", RECORDING_MESSAGES)
def test_a_recordings_message_names_the_api_setting_in_python_and_the_flag_in_the_command(kind, tmp_path):
    source, options, api_words, command_words = RECORDING_MESSAGES[kind]
    path = tmp_path / "recording.csv"
    if source == TIA_EVERY_3RD:
        write_tia_every_3rd(path)
    elif "\n" in source:
        path.write_text(source)
    else:
        path = RECORDINGS / source
    said = in_python(SIEMENS, path, **options)
    assert api_words in said and not FLAG.search(said), said
    said = command(SIEMENS, path, *_flags(options))
    assert command_words in said, said


def test_the_tubes_and_the_tolerances_messages_name_the_api_setting_in_python_and_the_flag_in_the_command():
    recording = RECORDINGS / "twincat_siemens.csv"
    with pytest.raises(fmutrace.InputError, match=r"value tolerance \(Tube\(time=\.\.\.\) and Tube\(value=\.\.\.\)\)$"):
        fmutrace.compare(SIEMENS, recording, tube_time=0.1)
    assert "value tolerance (--tube-time and --tube-value)\n" in command(SIEMENS, recording, "--tube-time", 0.1)
    with pytest.raises(fmutrace.InputError, match=r"^Tube\(value=\.\.\.\) must be a finite number >= 0, not inf$"):
        fmutrace.Tube(0.1, float("inf"))
    said = command(SIEMENS, recording, "--tube-time", 0.1, "--tube-value", "inf")
    assert "fmutrace: error: --tube-value must be a finite number >= 0, not inf\n" in said
    with pytest.raises(
        fmutrace.InputError, match=r"^Tolerance\(abs_tol=\.\.\.\) must be a finite number >= 0, not inf"
    ):
        fmutrace.Tolerance(abs_tol=float("inf"))
    said = command(SIEMENS, recording, "--abs-tol", "inf")
    assert "fmutrace: error: --abs-tol must be a finite number >= 0, not inf\n" in said


def test_resumes_message_names_the_api_setting_in_python_and_the_flag_in_the_command(tmp_path):
    cases = tmp_path / "cases" / "case"
    cases.mkdir(parents=True)
    (cases / "PassThrough_in.csv").write_text("time,u\n0,0\n0.2,1\n")
    # PassThrough's equation y(t + 0.1) = u(t), worked by hand
    (cases / "PassThrough_ref.csv").write_text("time,y\n0,0\n0.1,0\n0.2,0\n0.3,1\n0.4,1\n")
    (cases / "PassThrough_ref.opt").write_text("StartTime,0\nStopTime,0.4\nStepSize,0.1\n")
    report = tmp_path / "report"
    assert fmutrace.compare(PASS_THROUGH, cases, report=report).passed
    with pytest.raises(fmutrace.InputError, match=r"or start afresh without compare\(resume=\.\.\.\)$"):
        fmutrace.compare(PASS_THROUGH, cases, report=report, resume=True, mode=fmutrace.Tolerance(rel_tol=1e-3))
    said = command(PASS_THROUGH, cases, "--report", report, "--resume", "--rel-tol", "1e-3")
    assert "or start afresh without --resume\n" in said
