"""fmutrace's fast paths equal its general paths, bit for bit:

- the Runner (one instance reused through reset, its own step loop in C,
  _steps.c, and in Python where that is not built)
  against fmpy.simulate_fmu on a fresh instance, on every reference
  scenario of every model and FMI version and on random traces (random
  inputs and parameters, Boolean and enumeration columns, events, steps
  that do not divide the run, off-grid inputs that fmpy's loop handles);
- the Runner's chunked loop (run_chunks: a long run chunk by chunk, its
  inputs read in chunks) against its whole-trace loop, on every reference
  scenario and on random traces, in chunks of a few steps and rows;
- NumPy's reader of plain CSV bodies and the chunked reader (trace_chunks:
  _rows.c's rows, pyarrow's where it stops or is not built) against the
  cell-by-cell reader, on random texts; _rows.c's numbers against
  Python's float, on random and hard decimal texts.
"""

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fmutrace import TraceError, read_trace, write_trace
from fmutrace import _runner as runner_module
from fmutrace._runner import FastLoopFailed, Runner, discrete_rows, input_events
from fmutrace._fmpy import Experiment, Signals, run_fmpy
from fmutrace import _traces as trace_module
from fmutrace._fmpy import held_to
from fmutrace._traces import NotPlain, trace_chunks
from fmpy.simulation import Input
from support.fmu_driver import BUILD_DIR, MODELS, REPO
from support.scenarios import discover, fmu_path

SCENARIOS = discover()
RUNNERS = {}


def runner(model, version):
    key = (model, version)
    if key not in RUNNERS:
        RUNNERS[key] = Runner(fmu_path(BUILD_DIR, model, version).read_bytes())
    return RUNNERS[key]


def same_bits(a, b):
    return a.dtype == b.dtype and a.tobytes() == b.tobytes()


def both(model, version, start, stop, step, inputs, start_values, outputs, tolerance=None):
    experiment, signals = Experiment(start, stop, step, tolerance), Signals(inputs, start_values, outputs)
    fast = runner(model, version).run(experiment, signals)
    plain = run_fmpy(str(fmu_path(BUILD_DIR, model, version)), None, experiment, signals)
    return fast, plain


@pytest.mark.parametrize("version", [2, 3])
def test_every_reference_scenario_bit_for_bit(version):
    r = {model: runner(model, version) for model in MODELS}
    fast_before = sum(x.fast_runs for x in r.values())
    for s in SCENARIOS:
        o = s.options
        fast, plain = both(
            s.model,
            version,
            o["StartTime"],
            o["StopTime"],
            o["StepSize"],
            s.inputs,
            s.start_values,
            s.outputs,
            o["RelTol"],
        )
        assert same_bits(fast, plain), s.name
    # the fast loop ran (not only fmpy's): all but the off-grid scenarios
    assert sum(x.fast_runs for x in r.values()) - fast_before >= len(SCENARIOS) - 4


def test_the_runner_says_why_a_trace_takes_fmpys_loop():
    r = runner("RateLimiter", 3)
    off_grid = np.array([(0.0, 1.0), (0.25, 2.0)], dtype=[("time", float), ("u", float)])
    assert "between communication points" in r.fast_path_problem(Experiment(0.0, 1.0, 0.1), off_grid, ["y"])
    assert "whole number of steps" in r.fast_path_problem(Experiment(0.0, 1.05, 0.1), None, ["y"])
    assert r.fast_path_problem(Experiment(0.0, 1.0, 0.1), off_grid[:1], ["y"]) is None


def test_a_trace_whose_inputs_need_fmpy_leaves_the_instance_to_the_next_trace():
    r = runner("RateLimiter", 2)
    on_grid = np.array([(0.0, 0.0), (0.2, 5.0)], dtype=[("time", float), ("u", float)])
    off_grid = np.array([(0.0, 1.0), (0.25, 2.0)], dtype=[("time", float), ("u", float)])
    r.run(Experiment(0.0, 1.0, 0.1), Signals(on_grid, {}, ["y"]))
    instance, fast, fmpy = r.fmu, r.fast_runs, r.fmpy_runs
    fast_off, plain_off = both("RateLimiter", 2, 0.0, 1.0, 0.1, off_grid, {"rateUpPar": 3.0}, ["y"])
    assert same_bits(fast_off, plain_off)
    assert (r.fast_runs, r.fmpy_runs) == (fast, fmpy + 1) and r.fmu is instance  # decided before the FMU was called
    fast_on, plain_on = both("RateLimiter", 2, 0.0, 1.0, 0.1, on_grid, {"rateUpPar": 3.0}, ["y", "status"])
    assert same_bits(fast_on, plain_on) and r.fast_runs == fast + 1 and r.fmu is instance


NAMES = {
    "RateLimiter": (
        ["u", "rateUp", "bypass", "hold", "yMax", "zeroRate"],
        ["y", "rampActive", "status", "dydt"],
        {"rateUpPar": (0.1, 5.0), "rateDownPar": (0.1, 5.0), "ratePeriod": (0.5, 2.0)},
    ),
    "Ramp": (["rIn", "tTime"], ["rOut", "xRampActive"], {"rVariation": (0.1, 20.0)}),
    "LGF_LimRateOfChangeAdvancedCI": (
        ["autoValue", "manOp", "manualValue", "track"],
        ["outputValue", "status", "highLim"],
        {},
    ),
}


@st.composite
def random_traces(draw):
    model = draw(st.sampled_from(sorted(NAMES)))
    inputs, outputs, parameters = NAMES[model]
    step = draw(st.sampled_from([0.1, 0.25, 0.5, 0.01]))
    steps = draw(st.integers(1, 60))
    stop = draw(st.sampled_from([steps * step] * 3 + [steps * step + step / 3]))  # the last: a partial last step
    columns = draw(st.lists(st.sampled_from(inputs), min_size=0, max_size=3, unique=True))
    rows = []
    if columns:
        t = 0.0
        for _ in range(draw(st.integers(1, 12))):
            on_grid = draw(st.sampled_from([True] * 9 + [False]))
            t += draw(st.integers(0, 8)) * step if on_grid else draw(st.floats(0.001, 2.0))
            rows.append((t, *[draw(value_of(name)) for name in columns]))
    table = np.array(rows, dtype=[("time", float)] + [(c, float) for c in columns]) if columns else None
    start_values = {name: draw(st.floats(*bounds)) for name, bounds in parameters.items() if draw(st.booleans())}
    recorded = draw(st.lists(st.sampled_from(outputs), min_size=1, max_size=len(outputs), unique=True))
    return model, 0.0, stop, step, table, start_values, recorded


def value_of(name):
    if name in ("bypass", "hold", "manOp", "track"):
        return st.sampled_from([0.0, 1.0])
    if name == "zeroRate":
        return st.sampled_from([1.0, 2.0])
    if name == "tTime":
        return st.sampled_from([1.0, 5.0, 10.0])
    return st.one_of(st.sampled_from([0.0, -1.0, 10.0, math.nan, math.inf]), st.floats(-100, 100))


@pytest.mark.slow
@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow], derandomize=True)
@given(trace=random_traces(), version=st.sampled_from([2, 3]))
def test_random_traces_bit_for_bit(trace, version):
    model, start, stop, step, inputs, start_values, outputs = trace
    fast, plain = both(model, version, start, stop, step, inputs, start_values, outputs)
    assert same_bits(fast, plain)


@pytest.mark.slow
def test_random_traces_take_the_fast_loop_mostly():
    """The property test above is not vacuous: most of its traces run the
    fast loop, some fmpy's (derandomized: the same traces on every run)."""
    before = {k: (r.fast_runs, r.fmpy_runs) for k, r in RUNNERS.items()}
    test_random_traces_bit_for_bit()
    fast = sum(r.fast_runs - before.get(k, (0, 0))[0] for k, r in RUNNERS.items())
    slow = sum(r.fmpy_runs - before.get(k, (0, 0))[1] for k, r in RUNNERS.items())
    assert fast > slow > 0, (fast, slow)


def test_a_runner_unpacks_what_the_fmu_runs_with_and_runs(tmp_path):
    """The description, the binaries and resources/ (the instance is given
    that folder) are unpacked; sources, documentation and extra/ (a hundred
    FMI-LS-REF files here, most of a start-up's time) are not."""
    import zipfile

    fmu = tmp_path / "RateLimiter.fmu"
    with zipfile.ZipFile(fmu_path(BUILD_DIR, "RateLimiter", 3)) as built, zipfile.ZipFile(fmu, "w") as copy:
        names = built.namelist()
        for name in names:
            copy.writestr(name, built.read(name))
        copy.writestr("resources/table.txt", "1 2 3\n")
    assert any(n.startswith("extra/") for n in names) and any(n.startswith("sources/") for n in names)
    r = Runner(fmu.read_bytes())
    unpacked = {p.relative_to(r.folder).as_posix() for p in Path(r.folder).rglob("*") if p.is_file()}
    expected = {n for n in names if n == "modelDescription.xml" or n.startswith("binaries/")}
    assert unpacked == expected | {"resources/table.txt"}
    inputs = np.array([(0.0, 0.0), (0.2, 5.0)], dtype=[("time", float), ("u", float)])
    experiment, signals = Experiment(0.0, 0.5, 0.1), Signals(inputs, {"rateUpPar": 10.0}, ["y"])
    result = r.run(experiment, signals)
    assert same_bits(result, run_fmpy(str(fmu), None, experiment, signals)) and result["y"][-1] > 0


def test_an_instance_that_failed_is_replaced_and_the_next_trace_is_right():
    bad = np.array([(0.0, 0.0, 1.0), (0.2, 1.0, 7.0)], dtype=[("time", float), ("u", float), ("zeroRate", float)])
    good = np.array([(0.0, 0.0), (0.2, 5.0)], dtype=[("time", float), ("u", float)])
    r = runner("RateLimiter", 3)
    with pytest.raises(Exception, match="zeroRate = 7 is outside its range"):
        r.run(Experiment(0.0, 1.0, 0.1), Signals(bad, {}, ["y"]))
    fast, plain = both("RateLimiter", 3, 0.0, 1.0, 0.1, good, {"rateUpPar": 3.0}, ["y", "status"])
    assert same_bits(fast, plain)


PYTHON_LOOP_RUNNERS = {}


def python_loop_runner(model, version):
    """A Runner of its own with the steps in Python (the loop used where
    _steps.c is not built): the shared RUNNERS keep theirs in C."""
    key = (model, version)
    if key not in PYTHON_LOOP_RUNNERS:
        r = PYTHON_LOOP_RUNNERS[key] = Runner(fmu_path(BUILD_DIR, model, version).read_bytes())
        r.c_loop = False
    return PYTHON_LOOP_RUNNERS[key]


def both_loops(model, version, *args):
    """(C loop's result, Python loop's result, whether both ran the fast
    loop); one ran it if and only if the other did."""
    c, python = runner(model, version), python_loop_runner(model, version)
    before = c.fast_runs, python.fast_runs
    start, stop, step, inputs, start_values, outputs, *tolerance = args
    experiment, signals = Experiment(start, stop, step, *tolerance), Signals(inputs, start_values, outputs)
    c_result, python_result = c.run(experiment, signals), python.run(experiment, signals)
    c_fast, python_fast = c.fast_runs > before[0], python.fast_runs > before[1]
    assert c_fast == python_fast and c.c_loop and not python.c_loop
    return c_result, python_result, c_fast


def test_the_step_loop_in_c_is_built():
    """The project's set-up compiles it (pip install of fmutrace): the fast loop's speed depends on it."""
    assert runner_module.C_STEPS is not None and runner("RateLimiter", 3).c_loop


def test_a_package_build_uses_the_pinned_setuptools():
    """pip install ./fmutrace builds in isolation with the build system's
    requires: the setuptools the venv pins, one that reads
    [[tool.setuptools.ext-modules]] (74.1 on), not whatever is newest."""
    import tomllib

    project = tomllib.loads((REPO / "fmutrace" / "pyproject.toml").read_text())
    assert "ext-modules" in project["tool"]["setuptools"]
    pins = [
        line
        for line in (REPO / "fmutrace" / "requirements.txt").read_text().splitlines()
        if line.startswith("setuptools==")
    ]
    assert project["build-system"]["requires"] == pins and len(pins) == 1
    assert tuple(map(int, pins[0].split("==")[1].split(".")[:2])) >= (74, 1)


@pytest.mark.parametrize("version", [2, 3])
def test_the_c_and_python_step_loops_agree_on_every_reference_scenario(version):
    fast = 0
    for s in SCENARIOS:
        o = s.options
        args = (o["StartTime"], o["StopTime"], o["StepSize"], s.inputs, s.start_values, s.outputs, o["RelTol"])
        c_result, python_result, both_fast = both_loops(s.model, version, *args)
        assert same_bits(python_result, c_result), s.name
        fast += both_fast
    assert fast >= len(SCENARIOS) - 4  # as in the comparison with fmpy: a few scenarios need fmpy's loop


LOOPS_FAST = []  # whether both loops ran fast, per example of the property test below


@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.too_slow], derandomize=True)
@given(trace=random_traces(), version=st.sampled_from([2, 3]))
def test_the_c_and_python_step_loops_agree_on_random_traces(trace, version):
    model, start, stop, step, inputs, start_values, outputs = trace
    c_result, python_result, both_fast = both_loops(model, version, start, stop, step, inputs, start_values, outputs)
    assert same_bits(python_result, c_result)
    LOOPS_FAST.append(both_fast)


def test_the_step_loops_agree_on_random_traces_that_run_them():
    """The property test above compares the two loops, not fmpy with fmpy:
    most of its traces run the fast loop (derandomized: the same traces)."""
    LOOPS_FAST.clear()
    test_the_c_and_python_step_loops_agree_on_random_traces()
    assert sum(LOOPS_FAST) > len(LOOPS_FAST) // 2, (sum(LOOPS_FAST), len(LOOPS_FAST))


def test_both_step_loops_stop_at_a_failing_call_as_fmpy_does():
    bad = np.array([(0.0, 0.0, 1.0), (0.2, 1.0, 7.0)], dtype=[("time", float), ("u", float), ("zeroRate", float)])
    for r in (runner("RateLimiter", 2), python_loop_runner("RateLimiter", 2)):
        through_fmpy = r.fmpy_runs
        with pytest.raises(Exception, match="zeroRate = 7 is outside its range"):
            r.run(Experiment(0.0, 1.0, 0.1), Signals(bad, {}, ["y"]))
        assert r.fmpy_runs == through_fmpy + 1  # the fast loop stopped and left the story to fmpy


def chunked(model, version, start, stop, step, inputs, start_values, outputs, steps, rows, tolerance=None):
    """run_chunks' result, joined, in chunks of steps steps and of rows input rows; None where it refuses."""
    inputs = held_to(inputs, stop)
    pieces = None if inputs is None else iter([inputs[i : i + rows] for i in range(0, len(inputs), rows)])
    names = () if inputs is None else inputs.dtype.names[1:]
    try:
        chunks = list(
            runner(model, version).run_chunks(
                Experiment(start, stop, step, tolerance),
                Signals(pieces, start_values, outputs),
                names,
                steps_per_chunk=steps,
            )
        )
    except FastLoopFailed:
        return None
    assert all(len(c) <= steps for c in chunks[1:]) and len(chunks[0]) <= steps + 1
    return np.concatenate(chunks)


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("steps,rows", [(1, 1), (3, 2), (7, 50)])
def test_chunked_runs_equal_whole_runs_on_every_reference_scenario(version, steps, rows):
    ran = 0
    for s in SCENARIOS:
        o = s.options
        args = (s.model, version, o["StartTime"], o["StopTime"], o["StepSize"], s.inputs, s.start_values, s.outputs)
        whole = runner(s.model, version).run(Experiment(*args[2:5], o["RelTol"]), Signals(*args[5:]))
        parts = chunked(*args, steps, rows, o["RelTol"])
        if parts is not None:
            assert same_bits(parts, whole), s.name
            ran += 1
    assert ran >= len(SCENARIOS) - 4  # all but the off-grid scenarios (those go through fmpy)


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow], derandomize=True)
@given(trace=random_traces(), version=st.sampled_from([2, 3]), steps=st.integers(1, 9), rows=st.integers(1, 5))
def test_chunked_runs_equal_whole_runs_on_random_traces(trace, version, steps, rows):
    model, start, stop, step, inputs, start_values, outputs = trace
    r = runner(model, version)
    parts = chunked(model, version, start, stop, step, inputs, start_values, outputs, steps, rows)
    through_fmpy = r.fmpy_runs
    whole = r.run(Experiment(start, stop, step), Signals(inputs, start_values, outputs))
    if parts is None:  # refused: the whole run needs fmpy's loop too
        assert r.fmpy_runs == through_fmpy + 1
    else:
        CHUNKED_RUNS.append(1)
        assert same_bits(parts, whole)


CHUNKED_RUNS = []


def test_random_traces_run_chunked_mostly():
    """The property test above is not vacuous (derandomized: the same traces on every run)."""
    CHUNKED_RUNS.clear()
    test_chunked_runs_equal_whole_runs_on_random_traces()
    assert len(CHUNKED_RUNS) > 75  # half: the others end in a partial step or have inputs off the grid


@settings(max_examples=300, deadline=None)
@given(
    t=st.lists(st.sampled_from([0.0, 0.1, 0.2, 0.2, 0.30000000000000004, 0.3, 1.0]), min_size=1, max_size=8),
    times=st.lists(
        st.sampled_from([0.0, 0.1, 0.2, 0.3, 0.30000000000000004, 0.5, 1.0, 2.0, -1.0]), min_size=1, max_size=6
    ),
    after_event=st.booleans(),
)
def test_input_rows_as_fmpy_interpolates_them(t, times, after_event):
    t = np.array(sorted(t))
    table = np.arange(len(t), dtype=float)[np.newaxis, :]
    rows = discrete_rows(t, np.array(times), after_event)
    for time, row in zip(times, rows, strict=True):
        values, _ = Input.interpolate(time, t, table, discrete=True, after_event=after_event)
        assert values[0] == row


@settings(max_examples=300, deadline=None)
@given(
    steps=st.lists(st.sampled_from([0.0, 0.1, 0.25]), min_size=0, max_size=12),
    values=st.lists(st.sampled_from([0.0, 1.0, -1.0, math.nan]), min_size=13, max_size=13),
)
def test_input_events_are_fmpys(steps, values):
    """The time events of a table of discrete columns, as fmpy's
    Input.findEvents finds them (its set of times, less its infinity)."""
    r = runner("RateLimiter", 3)
    t = np.cumsum([0.0] + steps)
    inputs = np.zeros(len(t), dtype=[("time", float), ("u", float), ("bypass", float)])
    inputs["time"], inputs["u"], inputs["bypass"] = t, values[: len(t)], values[::-1][: len(t)]
    expected = Input.findEvents(inputs, r.md)
    assert input_events(inputs).tolist() == expected[expected < math.inf].tolist()


# ---- the CSV reader's two paths ---------------------------------------------

TOKENS = [
    "0",
    "1",
    "-2.5",
    "1e-3",
    "1E+300",
    "nan",
    "NaN",
    "inf",
    "-inf",
    "Infinity",
    "0.1",
    ".5",
    "5.",
    "+3",
    " 7",
    "8 ",
    "true",
    "FALSE",
    "",
    "x",
    "1,5",
    '"4"',
    "0x10",
    "1_000",
    "1d5",
    "--1",
    "1e",
    "#",
    "1.0e-400",
]


@pytest.mark.parametrize("rows_in_c", [True, False], ids=["rows in C", "pyarrow only"])
@settings(max_examples=400, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    rows=st.lists(st.lists(st.sampled_from(TOKENS), min_size=2, max_size=2), min_size=0, max_size=5),
    times=st.lists(st.sampled_from(["0", "1", "2", "0.5", "nan", "-1"]), min_size=5, max_size=5),
    ending=st.sampled_from(["\n", "\r\n", ""]),
    blank=st.booleans(),
)
def test_plain_reader_equals_the_general_reader(rows_in_c, rows, times, ending, blank, tmp_path_factory, monkeypatch):
    if not rows_in_c:
        monkeypatch.setattr(trace_module, "C_ROWS", None)
    lines = ["time,a,b"] + [",".join([t] + r) for t, r in zip(times, rows, strict=False)]  # as many rows as drawn
    if blank and len(lines) > 2:
        lines.insert(2, "")
    text = ending.join(lines) + ending
    path = tmp_path_factory.mktemp("csv") / "trace.csv"
    path.write_text(text)
    general = _general(path)
    plain = _attempt(lambda: read_trace(path))
    assert type(plain) is type(general)
    if isinstance(general, np.ndarray):
        assert same_bits(plain, general)
    else:
        assert str(plain) == str(general)
    for chunk_bytes in (8, 1 << 20):  # pyarrow's reader reads what the general reader reads, or leaves it to it
        chunks = _attempt(lambda size=chunk_bytes: list(trace_chunks(path, chunk_bytes=size)))
        if isinstance(chunks, NotPlain):
            continue
        assert isinstance(general, np.ndarray), (text, chunks)
        assert same_bits(np.concatenate(chunks), general)


def c_rows(text: bytes, columns: int):
    """(rows as an (n, columns) array, where _rows.c stopped) of text's lines."""
    table = np.full((text.count(b"\n") + 1, columns), -1.0)
    ffi, stopped = trace_module._ROWS_FFI, trace_module._ROWS_FFI.new("size_t *")
    field_of = ffi.new("size_t[]", list(range(columns)))
    values = ffi.cast("double *", table.ctypes.data)
    read = trace_module.C_ROWS(text, len(text), columns, field_of, values, len(table), stopped)
    return table[:read], stopped[0]


def test_the_row_reader_in_c_is_built():
    """The project's set-up compiles it: a short case's reading costs pyarrow's 0.2 ms a file without it."""
    assert trace_module.C_ROWS is not None


# hard decimal texts: halfway between two doubles, at the ends of the range,
# more digits than a double holds, the fast path's edges (15 digits, 10^22)
HARD_NUMBERS = [
    "9007199254740993",  # 2^53 + 1: halfway, rounds to even
    "9007199254740995",
    "2.2250738585072011e-308",  # just below the least normal double
    "2.2250738585072014e-308",
    "4.9406564584124654e-324",  # the least subnormal
    "2.4703282292062327e-324",  # half of it: rounds to zero
    "2.4703282292062328e-324",  # just above half: rounds up
    "1.7976931348623157e308",
    "1.7976931348623159e308",  # rounds to infinity
    "1e23",  # not exact: the fast path ends at 10^22
    "1e22",
    "123456789012345e-22",
    "1234567890123456e-22",
    "0.1",
    "0.30000000000000004",
    "-0",
    "-0.0e5",
    "0e999",  # zero times a power beyond the table
    "0.000e-40",
    "000000000000000000000000000001.5",
    "1.00000000000000011102230246251565404236316680908203125",  # 1 + 2^-53 exactly: halfway, to even
    "1.00000000000000011102230246251565404236316680908203126",  # just above: rounds up
    "7.038531e-26",
    "8.533e+68",
    "0." + "0" * 400 + "1e400",
    "1" + "0" * 400 + "e-400",
    "1e-99999",
    "1e99999",
]


@pytest.mark.parametrize("text", HARD_NUMBERS)
def test_the_row_reader_in_c_rounds_hard_numbers_as_python_does(text):
    table, stopped = c_rows(f"{text},{text}\n".encode(), 2)
    assert stopped == len(text) * 2 + 2 and len(table) == 1
    expected = np.float64(float(text))
    assert table[0].tobytes() == np.array([expected, expected]).tobytes(), (text, table[0])


FINITE_REPRS = st.floats(allow_nan=False, allow_infinity=False).map(repr)
DECIMALS = st.from_regex(r"\A[+-]?([0-9]{1,25}(\.[0-9]{0,25})?|\.[0-9]{1,25})([eE][+-]?[0-9]{1,3})?\Z")


@pytest.mark.slow
@settings(max_examples=2000, deadline=None)
@given(texts=st.lists(st.one_of(DECIMALS, FINITE_REPRS), min_size=1, max_size=6))
def test_the_row_reader_in_c_reads_every_decimal_as_python_does(texts):
    """Every cell of the common form is read (none left to pyarrow), each
    to float()'s bits; the repr of doubles is the usual cell."""
    text = ",".join(texts).encode()
    table, stopped = c_rows(text, len(texts))
    assert stopped == len(text) and len(table) == 1
    assert table[0].tobytes() == np.array([float(t) for t in texts]).tobytes(), texts


@pytest.mark.parametrize(
    "text, rows, stopped",
    [
        (b"1,2\n3,4\n", 2, 8),
        (b"1,2\r\n\r\n\n3,4", 2, 11),  # empty lines skipped, the last line without its break
        (b"1,2\n3,4,5\n6,7\n", 1, 4),  # a cell too many: the line is left
        (b"1,2\n3\n", 1, 4),  # a cell too few
        (b"1,2\n3,\n", 1, 4),  # an empty cell
        (b"1,2\n 3,4\n", 1, 4),  # a space
        (b"1,2\nnan,4\n", 1, 4),  # not a decimal: pyarrow's or read_trace's to read
        (b"1,2\n3\r4,5\n", 1, 4),  # a carriage return inside a line (a line break to pyarrow)
        (b"1,2\n1_0,4\n", 1, 4),
        (b"1,2\n3,4\x00\n", 1, 4),
        (b"1,2\n.,4\n", 1, 4),
        (b"1,2\n1e,4\n", 1, 4),
        (b"1,2\n+,4\n", 1, 4),
        (b"", 0, 0),
    ],
)
def test_the_row_reader_in_c_stops_at_the_first_line_it_does_not_take(text, rows, stopped):
    table, at = c_rows(text, 2)
    assert (len(table), at) == (rows, stopped)
    assert table.tolist() == [[1.0, 2.0], [3.0, 4.0]][:rows]


def test_a_block_read_partly_in_c_is_read_on_by_pyarrow(tmp_path):
    """Where _rows.c stops (an 'inf' here, the 5th row), pyarrow reads the block's rest: one chunk, every row."""
    lines = ["time,b,a"] + [f"{k},{k * 0.1!r},{'inf' if k == 4 else k}" for k in range(9)]
    path = tmp_path / "trace.csv"
    path.write_text("\n".join(lines) + "\n")
    (chunk,) = trace_chunks(path)
    assert same_bits(chunk, read_trace(path))
    assert chunk["a"][4] == math.inf and chunk["b"][8] == 8 * 0.1


def test_a_byte_order_mark_inside_a_file_is_left_to_read_trace(tmp_path):
    """pyarrow skips a byte-order mark at the start of what it reads: where
    _rows.c stops at one inside the file, the file is not plain, and
    read_trace names its cell."""
    path = tmp_path / "trace.csv"
    path.write_bytes(b"time,u\n1,2\n\xef\xbb\xbf3,4\n")
    with pytest.raises(NotPlain):
        list(trace_chunks(path))
    with pytest.raises(TraceError, match="line 3"):
        read_trace(path)


def _attempt(function):
    try:
        return function()
    except Exception as error:  # the reader's error is the answer to compare
        return error


def _general(path):
    saved = trace_module._plain_body
    trace_module._plain_body = lambda *args: None
    try:
        return _attempt(lambda: read_trace(path))
    finally:
        trace_module._plain_body = saved


@settings(max_examples=200, deadline=None)
@given(values=st.lists(st.floats(allow_nan=True, allow_infinity=True, width=64), min_size=1, max_size=20))
def test_written_traces_read_back_bit_for_bit(values, tmp_path_factory):
    trace = np.zeros(len(values), dtype=[("time", float), ("v", float), ("flag", bool)])
    trace["time"] = np.arange(len(values))
    trace["v"] = values
    trace["flag"] = [math.isnan(v) or v > 0 for v in values]
    path = tmp_path_factory.mktemp("csv") / "out.csv"
    write_trace(path, trace)
    back = read_trace(path)
    assert back["time"].tobytes() == trace["time"].tobytes()
    nan = np.isnan(trace["v"])
    assert (np.isnan(back["v"]) == nan).all()
    assert back["v"][~nan].tobytes() == trace["v"][~nan].tobytes()
    assert (back["flag"] == trace["flag"]).all()
