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

from support.fmu_driver import BUILD_DIR, MODELS, SCHEDULED_EXECUTION_FOLDER, fmu_file
from support.process import run as run_bounded
from support.run_trace import QEMU, halves, run_script, script
from support.scenarios import discover

pytestmark = pytest.mark.skipif(
    os.environ.get("RL_SANITIZED") == "1", reason="sanitizer build: no cross builds; the release build runs these"
)

CROSS = BUILD_DIR / "aarch64"
SCENARIOS = discover()


def test_every_fmi3_fmu_carries_an_aarch64_binary():
    for model in MODELS:
        with zipfile.ZipFile(fmu_file(model, 3)) as z:
            assert f"binaries/aarch64-linux/{model}.so" in z.namelist()
        with zipfile.ZipFile(fmu_file(model, 2)) as z:
            assert not any("aarch64" in n for n in z.namelist())  # FMI 2 names no such platform


def test_lifecycle_harness_under_emulation():
    """The harness on FMI 3 runs the Co-Simulation and Model Exchange FMU and the Scheduled Execution one."""
    stages = [BUILD_DIR / "stage" / folder / "RateLimiter" for folder in ("fmi3", SCHEDULED_EXECUTION_FOLDER)]
    done = run_bounded(
        QEMU + [str(CROSS / "test_lifecycle"), "3", str(stages[0]), "2000", "200", str(stages[1])],
        timeout=600,
        what="test_lifecycle under qemu-aarch64",
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "FMI 3: passed" in done.stdout


@pytest.mark.parametrize("scenario", SCENARIOS, ids=[s.name for s in SCENARIOS])
def test_scenario_gives_the_same_bits_on_aarch64(scenario, tmp_path):
    stage = BUILD_DIR / "stage" / "fmi3" / scenario.model
    md = read_model_description(str(stage / "modelDescription.xml"))
    text = script(scenario, md)
    native, emulated = (
        run_script(platform, stage, scenario.model, md.guid, text, tmp_path, f"{scenario.name} on {platform}")
        for platform in ("x86_64-linux", "aarch64-linux")
    )
    o = scenario.options
    assert len(native) == (round((o["StopTime"] - o["StartTime"]) / o["StepSize"]) + 1) * len(scenario.outputs)
    assert emulated == native


def test_the_harness_gives_the_reference(tmp_path):
    """run_trace's numbers are the FMU's: a scenario through it on x86_64
    gives its hand-worked reference."""
    scenario = next(s for s in SCENARIOS if s.name == "RateLimiter/asymmetric")
    stage = BUILD_DIR / "stage" / "fmi3" / "RateLimiter"
    md = read_model_description(str(stage / "modelDescription.xml"))
    lines = run_script("x86_64-linux", stage, "RateLimiter", md.guid, script(scenario, md), tmp_path, "run_trace")
    assert [float.fromhex(line) for line in lines] == [float(v) for v in scenario.reference["y"]]


@pytest.mark.parametrize("saved_on,restored_on", [("x86_64-linux", "aarch64-linux"), ("aarch64-linux", "x86_64-linux")])
@pytest.mark.parametrize(
    "name",
    [
        "RateLimiter/asymmetric",
        "RateLimiter/duration_jump",
        "Ramp/ttime_tuned_in_run",
        "LGF_LimRateOfChangeAdvancedCI/inverted_limits",
        "RateLimit/duration_48h",
    ],
)
def test_a_state_serialized_on_one_platform_continues_on_the_other(name, saved_on, restored_on, tmp_path):
    scenario = next(s for s in SCENARIOS if s.name == name)
    stage = BUILD_DIR / "stage" / "fmi3" / scenario.model
    md = read_model_description(str(stage / "modelDescription.xml"))
    first, second, whole_script = halves(scenario, md, "state.bin")
    whole = run_script("x86_64-linux", stage, scenario.model, md.guid, whole_script, tmp_path, "whole run")
    before = run_script(saved_on, stage, scenario.model, md.guid, first, tmp_path, f"first half on {saved_on}")
    assert (tmp_path / "state.bin").stat().st_size > 0
    after = run_script(restored_on, stage, scenario.model, md.guid, second, tmp_path, f"second half on {restored_on}")
    assert len(whole) > len(before) > 0
    assert before + after == whole
