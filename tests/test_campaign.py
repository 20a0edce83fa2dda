"""A regression campaign on a Dask distributed cluster: a scheduler and two
workers started here on loopback, the scenarios sent to them with their
FMUs (or read by them, --shared-files), and the report the same as a
serial run in this process (table, results and plots; only the timings
differ)."""
import json
import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import fmutrace
from support.fmu_driver import BUILD_DIR
from support.scenarios import FMI_VERSIONS, SCENARIO_ROOT, discover, fmu_path

BIN = Path(sys.executable).parent


START_SECONDS = 60


def log_tail(path):
    return path.read_text(errors="replace")[-2000:] if path.exists() else "(nothing)"


@pytest.fixture
def cluster(tmp_path):
    """A scheduler and two workers on loopback; every wait bounded, and a
    failure shows what they printed."""
    scheduler_file = tmp_path / "scheduler.json"
    logs = [tmp_path / "scheduler.log", tmp_path / "worker-a.log", tmp_path / "worker-b.log"]
    common = ["--no-dashboard"]

    def start(args, log):
        with open(log, "wb") as out:
            return subprocess.Popen([str(BIN / "dask")] + args + common, stdin=subprocess.DEVNULL, stdout=out,
                                    stderr=subprocess.STDOUT)

    processes = [start(["scheduler", "--host", "127.0.0.1", "--port", "0", "--scheduler-file", str(scheduler_file)],
                       logs[0])]
    try:
        deadline = time.monotonic() + START_SECONDS
        while not (scheduler_file.exists() and scheduler_file.stat().st_size):
            assert processes[0].poll() is None, f"the Dask scheduler exited: {log_tail(logs[0])}"
            assert time.monotonic() < deadline, \
                f"the Dask scheduler wrote no address within {START_SECONDS} s: {log_tail(logs[0])}"
            time.sleep(0.1)
        address = json.loads(scheduler_file.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        for name, log in zip(("worker-a", "worker-b"), logs[1:]):
            processes.append(start(["worker", address, "--nworkers", "1", "--nthreads", "1", "--name", name,
                                    "--host", "127.0.0.1"], log))
        from dask.distributed import Client
        with Client(address, timeout=START_SECONDS) as client:
            try:
                client.wait_for_workers(2, timeout=START_SECONDS)
            except TimeoutError:
                raise AssertionError(f"two Dask workers did not join within {START_SECONDS} s: "
                                     + " | ".join(log_tail(log) for log in logs)) from None
        yield address
    finally:
        for p in reversed(processes):
            p.terminate()
        for p in processes:
            try:
                p.wait(timeout=30)
            except subprocess.TimeoutExpired:
                p.kill()
                p.wait(timeout=30)


def without_timings(text):
    text = re.sub(r"\([0-9.]+ s on [^)]*\)\)?", "(T)", text)
    text = re.sub(r'"(seconds|where)": ("[^"]*"|[0-9.]+)', r'"\1": T', text)
    return re.sub(r"<td>[0-9]+\.[0-9]{2}</td>|\| [0-9]+\.[0-9]{2} \|", "T", text)


def test_campaign_on_a_distributed_cluster_equals_the_serial_run(cluster, tmp_path):
    fmus = [fmu_path(BUILD_DIR, model, version) for model in ("RateLimiter", "Ramp") for version in FMI_VERSIONS]
    cases = [SCENARIO_ROOT / "RateLimiter", SCENARIO_ROOT / "Ramp"]
    distributed = fmutrace.compare(fmus, cases, report=tmp_path / "distributed", scheduler=cluster, timeout=600)
    assert distributed.where == f"Dask, 2 workers at {cluster}"
    shared = fmutrace.compare(fmus, cases, scheduler=cluster, shared_files=True, timeout=600)
    serial = fmutrace.compare(fmus, cases, report=tmp_path / "serial", jobs=1)
    assert [(o.case, o.status) for o in shared.cases] == [(o.case, o.status) for o in serial.cases]
    assert serial.where == "1 process"
    assert len(serial.cases) == 2 * len(discover(["RateLimiter", "Ramp"]))
    assert [(o.case, o.fmu, o.status, o.messages) for o in distributed.cases] == \
        [(o.case, o.fmu, o.status, o.messages) for o in serial.cases]
    assert distributed.passed
    for a, b in zip(distributed.cases, serial.cases):
        for name in a.result.dtype.names:
            assert np.array_equal(a.result[name], b.result[name], equal_nan=True)
        assert a.png == b.png  # the same plot, byte for byte
        assert (tmp_path / "distributed" / a.csv).read_bytes() == (tmp_path / "serial" / b.csv).read_bytes()
    for page in ("index.html", "summary.md", "results.json"):
        assert without_timings((tmp_path / "distributed" / page).read_text()) == \
            without_timings((tmp_path / "serial" / page).read_text())
