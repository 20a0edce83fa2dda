"""Floating-point traps, as a real-time target runs with them (a TwinCAT
task, a PLC runtime): the shipped binaries of every model, FMI 2 and FMI 3,
driven by the C harness tests/c/run_trace.c with FE_INVALID, FE_DIVBYZERO
and FE_OVERFLOW enabled. Any of them raised in any call is SIGFPE: the
harness names the exception and the script line and fails. Every reference
scenario gives its reference so, and the hostile values of test_hostile.py
(NaN, +-inf, subnormals, +-1e308 in every input and parameter, at the start
and mid-run; the smallest and the largest step; a communication point at
the far end of the range from the FMU's time) run without a trap. As Model
Exchange (run_trace --model-exchange: time events, event updates,
Continuous-Time Mode) too: every scenario, with cycleTime its step, gives
the trapped Co-Simulation run's outputs, and the hostile values trap
nothing."""

import math
import os
import sys

import numpy as np
import pytest
from fmpy import read_model_description

from support.fmu_driver import BUILD_DIR, MODELS
from support.process import run as run_bounded
from support.run_trace import HARNESS, KINDS, reference_script, run_script, script_parts
from support.scenarios import discover
from test_hostile import HOSTILE, coerce, in_declared_range

pytestmark = pytest.mark.skipif(
    os.environ.get("RL_SANITIZED") == "1", reason="run_trace is built in the release tree only"
)

SCENARIOS = discover()
PLATFORM = {2: "linux64", 3: "x86_64-linux"}
TRAPS = {2: ["--fmi2", "--trap"], 3: ["--trap"]}


def staged(model, version):
    stage = BUILD_DIR / "stage" / f"fmi{version}" / model
    return stage, read_model_description(str(stage / "modelDescription.xml"))


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("scenario", SCENARIOS, ids=[s.name for s in SCENARIOS])
def test_scenario_runs_trapped_and_gives_its_reference(scenario, version, tmp_path):
    stage, md = staged(scenario.model, version)
    text, check = reference_script(scenario, md)
    check(
        run_script(
            PLATFORM[version],
            stage,
            scenario.model,
            md.guid,
            text,
            tmp_path,
            f"{scenario.name} (FMI {version}) with traps",
            options=TRAPS[version],
        )
    )


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("scenario", SCENARIOS, ids=[s.name for s in SCENARIOS])
def test_model_exchange_runs_trapped_and_gives_co_simulations_outputs(scenario, version, tmp_path):
    """cycleTime = the scenario's step, the same script as Model Exchange
    and as Co-Simulation, both trapped: the same text, line for line."""
    stage, md = staged(scenario.model, version)
    cycle_time = next(v for v in md.modelVariables if v.name == "cycleTime")
    head, blocks = script_parts(scenario, md)
    init = next(k for k, line in enumerate(head) if line.startswith("init"))  # after the scenario's start values
    head.insert(init, f"set F {cycle_time.valueReference} {float(scenario.options['StepSize']).hex()}")
    text = "\n".join(head + [line for block in blocks for line in block]) + "\n"
    runs = [
        run_script(
            PLATFORM[version],
            stage,
            scenario.model,
            md.guid,
            text,
            tmp_path / interface,
            f"{scenario.name} (FMI {version}, {interface}) with traps",
            options=TRAPS[version] + extra,
        )
        for interface, extra in (("cs", []), ("me", ["--model-exchange"]))
        if (tmp_path / interface).mkdir() is None
    ]
    assert runs[0] == runs[1]
    assert len(runs[0]) == (len(blocks) + 1) * len(scenario.outputs)


def test_a_raised_exception_is_caught_and_named(tmp_path):
    """The traps are on: a binary whose instantiate compares a NaN by <
    (as the kernel's limit check once did) stops the harness with SIGFPE,
    reported as FE_INVALID; without --trap it runs."""
    names = [
        "EnterInitializationMode",
        "ExitInitializationMode",
        "DoStep",
        "SetFloat64",
        "SetInt32",
        "SetInt64",
        "SetBoolean",
        "GetFloat64",
        "GetInt32",
        "GetBoolean",
        "FreeInstance",
        "GetFMUState",
        "SetFMUState",
        "FreeFMUState",
        "SerializedFMUStateSize",
        "SerializeFMUState",
        "DeserializeFMUState",
        "InstantiateModelExchange",
        "UpdateDiscreteStates",
        "EnterContinuousTimeMode",
        "SetTime",
        "EnterEventMode",
    ]
    source = tmp_path / "raise.c"
    source.write_text(
        "#include <math.h>\nvolatile double limit = NAN;\nstatic int instance;\n"
        "void *fmi3InstantiateCoSimulation(void) { return limit < 1.0 ? 0 : &instance; }\n"
        + "".join(f"int fmi3{name}(void) {{ return 0; }}\n" for name in names)
    )
    library = tmp_path / "raise.so"
    built = run_bounded(["cc", "-shared", "-fPIC", str(source), "-o", str(library)], timeout=60, what="cc")
    assert built.returncode == 0, built.stderr
    (tmp_path / "empty").write_text("")
    for options, code in (([], 0), (["--trap"], 3)):
        with open(tmp_path / "empty") as empty:
            done = run_bounded(
                HARNESS["x86_64-linux"] + options + [str(library), "token"], timeout=60, stdin=empty, what="run_trace"
            )
        assert done.returncode == code, (options, done.returncode, done.stderr)
    assert "SIGFPE, FE_INVALID raised" in done.stderr, done.stderr


def value_line(variable, value):
    kind = KINDS[variable.type]
    return f"set {kind} {variable.valueReference} {float(value).hex() if kind == 'F' else int(value)}"


def hostile_script(md):
    """Every input and parameter in turn at every hostile value, at the
    start and (not fixed) again mid-run after a good value, each case on a
    new instance; then the smallest and the largest steps. Returns the
    script and the line numbers of the sets that must be refused (a value
    outside a declared range)."""
    outputs = [v for v in md.modelVariables if v.causality == "output"]
    gets = [f"get {KINDS[v.type]} {v.valueReference}" for v in outputs]
    lines, refused = [], set()

    def add(line, refuse=False):
        lines.append(line)
        if refuse:
            refused.add(len(lines))

    for variable in (v for v in md.modelVariables if v.causality in ("input", "parameter")):
        for hostile in HOSTILE:
            value = coerce(variable, hostile)
            if value is None:
                continue
            outside = not in_declared_range(variable, value)
            add("new")
            add(value_line(variable, value), refuse=outside)
            add("init 0x0p+0")
            t = 0.0
            for k, h in enumerate([0.1, 0.25, 1.0, 0.1, 0.5, 2.0]):
                if variable.variability != "fixed" and k in (1, 3):
                    good = coerce(variable, 1.0)
                    # (after a refused start the instance is in its error state: skipped up to "new")
                    add(value_line(variable, good if k == 1 else value))
                add(f"step {t.hex()} {h.hex()}")
                lines.extend(gets)
                t += h
    for h in (5e-324, 1e-300, sys.float_info.max):
        add("new")
        add("init 0x0p+0")
        add(f"step {(0.0).hex()} {h.hex()}")
        lines.extend(gets)
        input_u = next(v for v in md.modelVariables if v.causality == "input" and KINDS[v.type] == "F")
        add(value_line(input_u, 5.0))
        add(f"step {h.hex()} {h.hex()}")
        lines.extend(gets)
    # a communication point of the opposite sign at the far end of the range,
    # after steps that could take the common one: t - time overflows if taken as it is
    for start in (1e307, -1e307):
        add("new")
        add(f"init {start.hex()}")
        t, h = start, 1e300
        for _ in range(3):
            add(f"step {t.hex()} {h.hex()}")
            lines.extend(gets)
            t += h
        add(f"step {math.copysign(sys.float_info.max, -start).hex()} {h.hex()}")
    return "\n".join(lines) + "\n", refused


@pytest.mark.parametrize("interface", ["Co-Simulation", "Model Exchange"])
@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("model", MODELS)
def test_hostile_values_raise_no_floating_point_exception(model, version, interface, tmp_path):
    stage, md = staged(model, version)
    text, must_refuse = hostile_script(md)
    extra = ["--model-exchange"] if interface == "Model Exchange" else []
    lines = run_script(
        PLATFORM[version],
        stage,
        model,
        md.guid,
        text,
        tmp_path,
        f"{model} (FMI {version}, {interface}) hostile",
        options=TRAPS[version] + ["--keep-going"] + extra,
    )
    refused = {int(line.split()[1]) for line in lines if line.startswith("refused")}
    script_lines = text.splitlines()
    # every value outside a declared range is refused, and nothing else but
    # a step that would run too many cycles or end past the largest time
    assert must_refuse <= refused, sorted(must_refuse - refused)[:5]
    others = [script_lines[n - 1] for n in sorted(refused - must_refuse)]
    assert all(line.startswith("step") for line in others), others[:5]
    assert len(lines) > len(refused)


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_a_per_cycle_limit_at_the_top_of_binary32_keeps_a_real_ramp_off_the_common_step(sign, version, tmp_path):
    """RateLimit (REAL) at 1 s cycles, 3e38 per s the way the ramp goes and
    1 per s the other: y + maxUp (or y - maxDown) of a steady ramp from
    |y| = 6e37 is beyond binary32's largest value, so the unchecked common
    step would overflow as it rounds to binary32 (RL_STEADY_BELOW,
    rate_limiter.h). Trapped, the block takes the general step, and each y
    is u, less than one cycle's limit away, rounded to binary32."""
    stage, md = staged("RateLimit", version)
    by_name = {v.name: v for v in md.modelVariables}
    up, down = (3e38, 1.0) if sign > 0 else (1.0, 3e38)
    inputs = [0.0, sign * 6e37, sign * 7e37]
    lines = [
        "new",
        value_line(by_name["UpRatePar"], up),
        value_line(by_name["DownRatePar"], down),
        value_line(by_name["In"], inputs[0]),
        "init 0x0p+0",
    ]
    for k, u in enumerate(inputs):
        lines += [
            value_line(by_name["In"], u),
            f"step {float(k).hex()} {(1.0).hex()}",
            f"get F {by_name['Out'].valueReference}",
        ]
    outputs = run_script(
        PLATFORM[version],
        stage,
        "RateLimit",
        md.guid,
        "\n".join(lines) + "\n",
        tmp_path,
        f"RateLimit (FMI {version}) at binary32's top",
        options=TRAPS[version],
    )
    assert [float.fromhex(y) for y in outputs] == [float(np.float32(u)) for u in inputs]
