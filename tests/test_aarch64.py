"""The FMI 3 FMUs' aarch64-linux binaries, cross-compiled by the same CMake
project (cmake/CrossBuilds.cmake), run under Debian's qemu-user: the C
lifecycle harness cross-compiled for aarch64 passes, and every reference
scenario of every model driven by the same script (tests/c/run_trace.c)
prints the same bits as the x86_64 binary."""
import os
import zipfile

import pytest
from fmpy import read_model_description

from support.fmu_driver import BUILD_DIR, MODELS, fmu_file
from support.importers import input_values
from support.process import run as run_bounded
from support.scenarios import discover

pytestmark = pytest.mark.skipif(os.environ.get("RL_SANITIZED") == "1",
                                reason="sanitizer build: no cross builds; the release build runs these")

QEMU = [os.environ.get("RL_QEMU_AARCH64") or "qemu-aarch64", "-L", "/usr/aarch64-linux-gnu"]
CROSS = BUILD_DIR / "aarch64"
SCENARIOS = discover()
KINDS = {"Float64": "F", "Int32": "I", "Enumeration": "L", "Boolean": "B"}


def test_every_fmi3_fmu_carries_an_aarch64_binary():
    for model in MODELS:
        with zipfile.ZipFile(fmu_file(model, 3)) as z:
            assert f"binaries/aarch64-linux/{model}.so" in z.namelist()
        with zipfile.ZipFile(fmu_file(model, 2)) as z:
            assert not any("aarch64" in n for n in z.namelist())  # FMI 2 names no such platform


def test_lifecycle_harness_under_emulation():
    done = run_bounded(QEMU + [str(CROSS / "test_lifecycle"), "3", str(BUILD_DIR / "stage" / "fmi3" / "RateLimiter"),
                               "2000", "200"], timeout=600, what="test_lifecycle under qemu-aarch64")
    assert done.returncode == 0, done.stdout + done.stderr
    assert "FMI 3: passed" in done.stdout


def script(scenario, md):
    """The scenario as run_trace's script: start values and the inputs at
    the start, initialization, then per step the inputs (a row holds from
    its time on), the step, the recorded outputs."""
    variables = {v.name: v for v in md.modelVariables}

    def set_line(name, value):
        v = variables[name]
        kind = KINDS[v.type]
        literal = float(value).hex() if kind == "F" else str(int(value))
        return f"set {kind} {v.valueReference} {literal}"

    def get_lines():
        return [f"get {KINDS[variables[name].type]} {variables[name].valueReference}" for name in scenario.outputs]

    o = scenario.options
    start, h = o["StartTime"], o["StepSize"]
    n = round((o["StopTime"] - start) / h)
    times = [start + k * h for k in range(n + 1)]
    lines = [set_line(name, value) for name, value in scenario.start_values.items()]
    lines += [set_line(name, value) for name, value in input_values(scenario, start).items()]
    lines += [f"init {start.hex()}"] + get_lines()
    for t, end in zip(times, times[1:]):
        lines += [set_line(name, value) for name, value in input_values(scenario, t).items()]
        lines += [f"step {t.hex()} {(end - t).hex()}"] + get_lines()
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("scenario", SCENARIOS, ids=[s.id for s in SCENARIOS])
def test_scenario_gives_the_same_bits_on_aarch64(scenario, tmp_path):
    stage = BUILD_DIR / "stage" / "fmi3" / scenario.model
    md = read_model_description(str(stage / "modelDescription.xml"))
    (tmp_path / "script").write_text(script(scenario, md))
    outputs = {}
    for platform, command in (("x86_64-linux", [str(BUILD_DIR / "run_trace")]),
                              ("aarch64-linux", QEMU + [str(CROSS / "run_trace")])):
        binary = stage / "binaries" / platform / f"{scenario.model}.so"
        with open(tmp_path / "script") as script_file:
            done = run_bounded(command + [str(binary), md.guid], timeout=300, stdin=script_file,
                               what=f"{scenario.id} on {platform}")
        assert done.returncode == 0, done.stderr
        outputs[platform] = done.stdout
    lines = outputs["x86_64-linux"].splitlines()
    assert len(lines) == (round((scenario.options["StopTime"] - scenario.options["StartTime"])
                                / scenario.options["StepSize"]) + 1) * len(scenario.outputs)
    assert outputs["aarch64-linux"] == outputs["x86_64-linux"]


def test_the_harness_gives_the_reference(tmp_path):
    """run_trace's numbers are the FMU's: a scenario through it on x86_64
    gives its hand-worked reference."""
    scenario = next(s for s in SCENARIOS if s.id == "RateLimiter/asymmetric")
    stage = BUILD_DIR / "stage" / "fmi3" / "RateLimiter"
    md = read_model_description(str(stage / "modelDescription.xml"))
    (tmp_path / "script").write_text(script(scenario, md))
    with open(tmp_path / "script") as script_file:
        done = run_bounded([str(BUILD_DIR / "run_trace"), str(stage / "binaries" / "x86_64-linux" / "RateLimiter.so"),
                            md.guid], timeout=60, stdin=script_file, what="run_trace")
    assert done.returncode == 0, done.stderr
    values = [float.fromhex(line) for line in done.stdout.split()]
    assert values == [float(v) for v in scenario.reference["y"]]

