"""fmi.md, FMI behaviour: instances are independent and run concurrently on
different threads (ctypes releases the GIL inside every FMI call)."""

import math
from concurrent.futures import ThreadPoolExecutor

import pytest

from support.fmu_driver import Instance, unzipped

THREADS = 8


def run(version, k):
    """A run that differs per k: rates, sub-cycling, NaN, bypass."""
    fmu = Instance("RateLimiter", version, name=f"thread{k}", unzipdir=unzipped("RateLimiter", version))
    fmu.start(rateUpPar=0.5 + k, rateDownPar=0.25 * (k + 1), cycleTime=0.01 * (k % 3), durationPar=5.0)
    trace = []
    for n in range(2000):
        u = math.nan if n % 97 == 13 else float((n * (k + 3)) % 50)
        fmu.set(u=u, bypass=(n % 211) < 7)
        fmu.step(0.1)
        trace.append((float(fmu.get("y")).hex(), float(fmu.get("runningTime")).hex(), fmu.get("status")))
    return fmu, trace


@pytest.mark.parametrize("version", [2, 3])
def test_threaded_instances_match_serial_runs(version):
    serial = []
    for k in range(THREADS):
        fmu, trace = run(version, k)
        serial.append(trace)
        fmu.release()
    with ThreadPoolExecutor(max_workers=THREADS) as pool:
        results = list(pool.map(lambda k: run(version, k), range(THREADS)))
    for fmu, _ in results:
        fmu.release()
    assert [trace for _, trace in results] == serial
    assert len({tuple(t[-1]) for t in serial}) > 1  # the runs really differ
