"""The Windows x86_64 binaries in the FMUs (cross-compiled with mingw-w64)
run reference scenarios through fmpy's wine remoting (Debian's wine64):
the FMU with only its win64 binary, fmpy's TCP client in its place on
linux64 and the server under wine; the numbers equal the linux64 binary's
bit for bit, and the reference."""
import contextlib
import os
import shutil
import signal
import subprocess
import sys
import time
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy import extract
from fmpy.util import add_remoting, read_csv

from fmu_driver import BUILD_DIR, fmu_file
from reference import SCENARIO_ROOT, compare, load

HERE = Path(__file__).resolve().parent
pytestmark = pytest.mark.skipif(os.environ.get("RL_SANITIZED") == "1",
                                reason="the sanitizer build makes Linux binaries only; the release build runs this")
WINE_DIR = os.environ.get("RL_WINE_DIR", "/usr/lib/wine")
SCENARIOS = ["RateLimiter/step_up", "RateLimiter/cycle_steps_of_10", "RateLimiter/status_errors",
             "LGF_LimRateOfChangeCI/rate_100ms", "RateLimit/duration_jump", "Ramp/ttime_10s_both_ways"]


@pytest.fixture(scope="module")
def wine():
    """The wine prefix made once (wineboot), before any run."""
    env = dict(os.environ, PATH=f"{WINE_DIR}:{os.environ['PATH']}",
               WINEPREFIX=str((Path(BUILD_DIR) / "wineprefix").resolve()), WINEDEBUG="-all")
    subprocess.run([str(Path(WINE_DIR) / "wine64"), "wineboot", "--init"], env=env, capture_output=True, timeout=300)
    stop_wine(env)
    yield env
    stop_wine(env)


def stop_wine(env):
    """Stop the wineserver and wait until it is gone: a wine started while
    the old server is still exiting dies on arrival, and fmpy's client
    then waits for its remoting server for ever."""
    wineserver = str(Path(WINE_DIR) / "wineserver")
    subprocess.run([wineserver, "--kill"], env=env, capture_output=True, timeout=60)
    subprocess.run([wineserver, "--wait"], env=env, capture_output=True, timeout=60)


def remoting_servers():
    """Process ids of fmpy's remoting servers (from /proc: no procps needed)."""
    found = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                if b"server_tcp.exe" in (entry / "cmdline").read_bytes():
                    found.append(int(entry.name))
            except OSError:
                pass
    return found


def run(env, fmu, scenario, out):
    stop_wine(env)
    try:
        process = subprocess.run([sys.executable, str(HERE / "importers.py"), "fmpy-fixed", str(scenario.folder),
                                  str(fmu), str(out)], capture_output=True, text=True, timeout=180, env=env)
    finally:
        # fmpy's remoting server listens on a fixed port: one left running
        # would answer the next FMU's client
        for _ in range(100):
            servers = remoting_servers()
            if not servers:
                break
            for pid in servers:
                with contextlib.suppress(OSError):
                    os.kill(pid, signal.SIGTERM)
            time.sleep(0.1)
        stop_wine(env)
    assert process.returncode == 0, (process.stdout + process.stderr)[-3000:]
    return np.atleast_1d(read_csv(str(out)))


@pytest.mark.parametrize("name", SCENARIOS)
def test_win64_binary_under_wine_equals_linux64(name, wine, tmp_path):
    assert (Path(WINE_DIR) / "wine64").exists(), "wine64 is installed by the configure step"
    scenario = load(SCENARIO_ROOT / name)
    fmu = fmu_file(scenario.model, 2)
    with zipfile.ZipFile(fmu) as z:
        assert f"binaries/win64/{scenario.model}.dll" in z.namelist()
    windows_only = Path(extract(str(fmu), str(tmp_path / "fmu")))
    shutil.rmtree(windows_only / "binaries" / "linux64")
    add_remoting(str(windows_only), host_platform="linux64", remote_platform="win64")
    on_windows = run(wine, windows_only, scenario, tmp_path / "win64.csv")
    on_linux = run(wine, fmu, scenario, tmp_path / "linux64.csv")
    assert len(on_windows) == len(on_linux) > 1
    for column in on_linux.dtype.names:
        assert np.array_equal(on_windows[column], on_linux[column], equal_nan=True), column
    assert not compare(scenario, on_windows)
