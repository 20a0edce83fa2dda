"""The Windows x86_64 binaries in the FMUs (cross-compiled with mingw-w64)
run reference scenarios through fmpy's wine remoting (Debian's wine64):
the FMU with only its win64 binary, fmpy's TCP client in its place on
linux64 and the server under wine (support/wine.py says why we start the
server ourselves); the numbers equal the linux64 binary's bit for bit, and
the reference."""

import os
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.util import read_csv

from support.fmu_driver import BUILD_DIR, TESTS, fmu_file
from support.scenarios import SCENARIO_ROOT, compare, load
from support.process import run
from support.run_trace import halves, run_script
from support.wine import RemotingServer, environment, make_prefix, remoting_copy

pytestmark = pytest.mark.skipif(
    os.environ.get("RL_SANITIZED") == "1",
    reason="the sanitizer build makes Linux binaries only; the release build runs this",
)
WINE_DIR = os.environ.get("RL_WINE_DIR", "/usr/lib/wine")
SCENARIOS = [
    "RateLimiter/step_up",
    "RateLimiter/cycle_steps_of_10",
    "RateLimiter/status_errors",
    "LGF_LimRateOfChangeCI/rate_100ms",
    "RateLimit/duration_jump",
    "Ramp/ttime_10s_both_ways",
    "RateLimiter/neg_rates_rising",
    "LGF_LimRateOfChangeAdvancedCI/quadrant_flags",
    "RateLimiter/accel_reversal",  # the acceleration limit's exact sums and fma on the win64 binary
]
CLIENT_SECONDS = 120  # a run takes under 1 s idle, a few on a busy machine


@pytest.fixture(scope="module")
def wine():
    """The wine prefix, made once (wineboot) before any run."""
    assert (Path(WINE_DIR) / "wine64").exists(), "wine64 is installed by the test set-up (command 2)"
    env = environment(WINE_DIR, (Path(BUILD_DIR) / "wineprefix").resolve())
    make_prefix(env, WINE_DIR)
    return env


def simulate(env, fmu_dir, scenario, out, what):
    """importers.py fmpy-fixed on an extracted FMU, bounded."""
    done = run(
        [sys.executable, "-m", "support.importers", "fmpy-fixed", str(scenario.folder), str(fmu_dir), str(out)],
        timeout=CLIENT_SECONDS,
        what=what,
        env=env,
        cwd=TESTS,
    )
    return done


def windows_and_linux(wine, scenario, tmp_path):
    """The scenario on the win64 binary under wine and on the linux64 one."""
    fmu = fmu_file(scenario.model, 2)
    with zipfile.ZipFile(fmu) as z:
        assert f"binaries/win64/{scenario.model}.dll" in z.namelist()
    extracted = Path(extract(str(fmu), str(tmp_path / "fmu")))
    windows_only = tmp_path / "win64"
    dll = remoting_copy(extracted, windows_only)
    server_exe = windows_only / "binaries" / "win64" / "server_tcp.exe"
    with RemotingServer(wine, WINE_DIR, server_exe, dll, tmp_path / "server.log") as server:
        try:
            done = simulate(
                wine, windows_only, scenario, tmp_path / "win64.csv", "fmpy's remoting client on the win64 binary"
            )
        except AssertionError as failure:
            raise AssertionError(f"{failure}\nthe server under wine printed:\n{server.output()}") from None
        assert done.returncode == 0, f"{done.stdout}{done.stderr}\nthe server printed:\n{server.output()}"
    done = simulate(wine, extracted, scenario, tmp_path / "linux64.csv", "fmpy on the linux64 binary")
    assert done.returncode == 0, done.stdout + done.stderr
    on_windows = np.atleast_1d(read_csv(str(tmp_path / "win64.csv")))
    on_linux = np.atleast_1d(read_csv(str(tmp_path / "linux64.csv")))
    assert len(on_windows) == len(on_linux) > 1
    for column in on_linux.dtype.names:
        assert np.array_equal(on_windows[column], on_linux[column], equal_nan=True), column
    return on_windows


@pytest.mark.parametrize("name", SCENARIOS)
def test_win64_binary_under_wine_equals_linux64(name, wine, tmp_path):
    scenario = load(SCENARIO_ROOT / name)
    assert not compare(scenario, windows_and_linux(wine, scenario, tmp_path))


def test_a_run_longer_than_the_servers_lock_file_poll(wine, tmp_path):
    """400 steps of step_up: longer than the 0.5 s after which fmpy's own
    server start loses its server (support/wine.py); the ramp of the
    reference ends at u = 10 and stays."""
    folder = tmp_path / "RateLimiter" / "long"
    folder.mkdir(parents=True)
    for f in (SCENARIO_ROOT / "RateLimiter/step_up").iterdir():
        text = f.read_text()
        if f.name.endswith("_ref.opt"):
            text = "".join(
                "StopTime,200.0\n" if line.startswith("StopTime") else line for line in text.splitlines(keepends=True)
            )
        (folder / f.name).write_text(text)
    result = windows_and_linux(wine, load(folder), tmp_path)
    assert len(result) == 401 and result["time"][-1] == 200.0
    assert np.all(result["y"][result["time"] >= 6.0] == 10.0)


@pytest.mark.parametrize(
    "saved_on,restored_on", [("x86_64-linux", "x86_64-windows"), ("x86_64-windows", "aarch64-linux")]
)
@pytest.mark.parametrize("name", ["RateLimiter/asymmetric", "LGF_LimRateOfChangeAdvancedCI/inverted_limits"])
def test_a_state_serialized_on_one_platform_continues_on_another(name, saved_on, restored_on, wine, tmp_path):
    """FMI 3 states are portable: half a run on one platform's binary, its
    state serialized to a file, the other half on another's (Windows under
    wine, aarch64 under qemu) gives the whole run's bits on x86_64 Linux
    (with test_aarch64's aarch64 -> x86_64 a full circle)."""
    scenario = load(SCENARIO_ROOT / name)
    stage = Path(BUILD_DIR) / "stage" / "fmi3" / scenario.model
    md = read_model_description(str(stage / "modelDescription.xml"))
    first, second, whole_script = halves(scenario, md, "state.bin")
    env = dict(wine, WINE_DIR=WINE_DIR)
    whole = run_script("x86_64-linux", stage, scenario.model, md.guid, whole_script, tmp_path, "whole run")
    before = run_script(saved_on, stage, scenario.model, md.guid, first, tmp_path, f"first half on {saved_on}", env)
    after = run_script(
        restored_on, stage, scenario.model, md.guid, second, tmp_path, f"second half on {restored_on}", env
    )
    assert len(whole) > len(before) > 0
    assert before + after == whole
