"""Fixtures shared by test files: a Dask distributed cluster on loopback."""

import json
import subprocess
import sys
import time
from pathlib import Path

import pytest

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
            return subprocess.Popen(
                [str(BIN / "dask")] + args + common, stdin=subprocess.DEVNULL, stdout=out, stderr=subprocess.STDOUT
            )

    processes = [
        start(["scheduler", "--host", "127.0.0.1", "--port", "0", "--scheduler-file", str(scheduler_file)], logs[0])
    ]
    try:
        deadline = time.monotonic() + START_SECONDS
        while not (scheduler_file.exists() and scheduler_file.stat().st_size):
            assert processes[0].poll() is None, f"the Dask scheduler exited: {log_tail(logs[0])}"
            assert time.monotonic() < deadline, (
                f"the Dask scheduler wrote no address within {START_SECONDS} s: {log_tail(logs[0])}"
            )
            time.sleep(0.1)
        address = json.loads(scheduler_file.read_text())["address"]
        assert address.startswith("tcp://127.0.0.1:")
        for name, log in zip(("worker-a", "worker-b"), logs[1:], strict=True):
            processes.append(
                start(
                    ["worker", address, "--nworkers", "1", "--nthreads", "1", "--name", name, "--host", "127.0.0.1"],
                    log,
                )
            )
        from dask.distributed import Client

        with Client(address, timeout=START_SECONDS) as client:
            try:
                client.wait_for_workers(2, timeout=START_SECONDS)
            except TimeoutError:
                raise AssertionError(
                    f"two Dask workers did not join within {START_SECONDS} s: "
                    + " | ".join(log_tail(log) for log in logs)
                ) from None
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
