"""The FMI 3 FMUs' aarch64-linux binaries, cross-compiled by the same CMake
project (cmake/CrossBuilds.cmake), run under Debian's qemu-user: the C
lifecycle harness cross-compiled for aarch64 passes, every reference
scenario of every model driven by the same script (tests/c/run_trace.c)
prints the same bits as the x86_64 binary, and an FMU state serialized by
one platform's binary is restored by the other's and continues bit for
bit."""
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


def script_parts(scenario, md):
    """The scenario as run_trace's script: the start (start values and the
    inputs at the start, initialization, the outputs) and one block per
    step (the inputs, a row holding from its time on; the step; the
    recorded outputs)."""
    variables = {v.name: v for v in md.modelVariables}

    def set_line(name, value):
        v = variables[name]
        kind = KINDS[v.type]
        literal = float(value).hex() if kind == "F" else str(int(value))
        return f"set {kind} {v.valueReference} {literal}"

    gets = [f"get {KINDS[variables[name].type]} {variables[name].valueReference}" for name in scenario.outputs]
    o = scenario.options
    start, h = o["StartTime"], o["StepSize"]
    n = round((o["StopTime"] - start) / h)
    times = [start + k * h for k in range(n + 1)]
    head = [set_line(name, value) for name, value in scenario.start_values.items()]
    head += [set_line(name, value) for name, value in input_values(scenario, start).items()]
    head += [f"init {start.hex()}"] + gets
    blocks = [[set_line(name, value) for name, value in input_values(scenario, t).items()]
              + [f"step {t.hex()} {(end - t).hex()}"] + gets for t, end in zip(times, times[1:])]
    return head, blocks


def script(scenario, md):
    head, blocks = script_parts(scenario, md)
    return "\n".join(head + [line for block in blocks for line in block]) + "\n"


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



def run_script(platform, stage, model, token, text, tmp_path, what):
    (tmp_path / "script").write_text(text)
    command = [str(BUILD_DIR / "run_trace")] if platform == "x86_64-linux" else QEMU + [str(CROSS / "run_trace")]
    with open(tmp_path / "script") as script_file:
        done = run_bounded(command + [str(stage / "binaries" / platform / f"{model}.so"), token], timeout=300,
                           stdin=script_file, what=what, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    return done.stdout.splitlines()


@pytest.mark.parametrize("saved_on,restored_on", [("x86_64-linux", "aarch64-linux"), ("aarch64-linux", "x86_64-linux")])
@pytest.mark.parametrize("name", ["RateLimiter/asymmetric", "RateLimiter/duration_jump", "Ramp/ttime_tuned_in_run",
                                  "LGF_LimRateOfChangeAdvancedCI/inverted_limits", "RateLimit/duration_48h"])
def test_a_state_serialized_on_one_platform_continues_on_the_other(name, saved_on, restored_on, tmp_path):
    scenario = next(s for s in SCENARIOS if s.id == name)
    stage = BUILD_DIR / "stage" / "fmi3" / scenario.model
    md = read_model_description(str(stage / "modelDescription.xml"))
    head, blocks = script_parts(scenario, md)
    whole = run_script("x86_64-linux", stage, scenario.model, md.guid, script(scenario, md), tmp_path, "whole run")
    middle = len(blocks) // 2
    first = head + [line for block in blocks[:middle] for line in block] + ["save state.bin"]
    second = ["load state.bin"] + [line for block in blocks[middle:] for line in block]
    before = run_script(saved_on, stage, scenario.model, md.guid, "\n".join(first) + "\n", tmp_path,
                        f"first half on {saved_on}")
    assert (tmp_path / "state.bin").stat().st_size > 0
    after = run_script(restored_on, stage, scenario.model, md.guid, "\n".join(second) + "\n", tmp_path,
                       f"second half on {restored_on}")
    assert len(whole) > len(before) > 0
    assert before + after == whole
