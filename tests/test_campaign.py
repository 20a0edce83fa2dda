"""A regression campaign on a Dask distributed cluster: a scheduler and two
workers started here on loopback, the scenarios sent to them with their
FMUs, and the report the same as a serial run in this process (table,
results and plots; only the timings differ)."""
import json
import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from fmu_driver import BUILD_DIR
from reference import campaign, discover, write_outputs, write_report

BIN = Path(sys.executable).parent


@pytest.fixture
def cluster(tmp_path):
    scheduler_file = tmp_path / "scheduler.json"
    common = ["--no-dashboard"]
    processes = [subprocess.Popen([str(BIN / "dask"), "scheduler", "--host", "127.0.0.1", "--port", "0",
                                   "--scheduler-file", str(scheduler_file)] + common,
                                  stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    try:
        for _ in range(200):
            if scheduler_file.exists() and scheduler_file.stat().st_size:
                break
            time.sleep(0.1)
        address = json.loads(scheduler_file.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        for name in ("worker-a", "worker-b"):
            processes.append(subprocess.Popen([str(BIN / "dask"), "worker", address, "--nworkers", "1",
                                               "--nthreads", "1", "--name", name, "--host", "127.0.0.1"] + common,
                                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        from dask.distributed import Client
        with Client(address) as client:
            client.wait_for_workers(2, timeout=60)
        yield address
    finally:
        for p in reversed(processes):
            p.terminate()
        for p in processes:
            p.wait(timeout=30)


def report(runs, where, folder):
    outcomes = []
    for outcome, scenario, result, png in runs:
        write_outputs(outcome, scenario, result, png, folder)
        outcomes.append(outcome)
    write_report(outcomes, folder, 0.0, where)
    return outcomes


def without_timings(text):
    text = re.sub(r"wall time [0-9.]+ s on [^<\n]*", "wall time", text)
    return re.sub(r"<td>[0-9]+\.[0-9]{2}</td>|\| [0-9]+\.[0-9]{2} \|", "T", text)


def test_campaign_on_a_distributed_cluster_equals_the_serial_run(cluster, tmp_path):
    scenarios = discover(["RateLimiter", "Ramp"])
    distributed, where = campaign(scenarios, BUILD_DIR, scheduler=cluster)
    assert where == f"Dask, 2 workers at {cluster}"
    serial, _ = campaign(scenarios, BUILD_DIR, serial=True)
    a = report(distributed, where, tmp_path / "distributed")
    b = report(serial, "serial", tmp_path / "serial")
    assert [(o.scenario, o.version, o.problems) for o in a] == [(o.scenario, o.version, o.problems) for o in b]
    assert all(o.passed for o in a)
    for (_, _, ra, pa), (_, _, rb, pb) in zip(distributed, serial):
        for name in ra.dtype.names:
            assert np.array_equal(ra[name], rb[name], equal_nan=True)
        assert pa == pb  # the same plot, byte for byte
    for page in ("index.html", "summary.md"):
        assert without_timings((tmp_path / "distributed" / page).read_text()) == \
            without_timings((tmp_path / "serial" / page).read_text())
