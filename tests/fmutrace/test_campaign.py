"""A regression campaign on a Dask distributed cluster (the cluster fixture
of conftest.py: a scheduler and two workers on loopback): the scenarios
sent to them with their FMUs (or read by them, --shared-files), and the
report the same as a serial run in this process (table, results and
plots; only the timings differ)."""

import tempfile
import zipfile
from pathlib import Path

import numpy as np
import pytest

import fmutrace
from fmutrace._executors import package_zip
from support.fmu_driver import BUILD_DIR, REPO
from support.reports import without_timings
from support.scenarios import FMI_VERSIONS, SCENARIO_ROOT, discover, fmu_path


@pytest.mark.cluster
def test_campaign_on_a_distributed_cluster_equals_the_serial_run(cluster, tmp_path):
    fmus = [fmu_path(BUILD_DIR, model, version) for model in ("RateLimiter", "Ramp") for version in FMI_VERSIONS]
    cases = [SCENARIO_ROOT / "RateLimiter", SCENARIO_ROOT / "Ramp"]
    distributed = fmutrace.compare(
        fmus,
        cases,
        report=tmp_path / "distributed",
        run=fmutrace.RunOptions(scheduler=cluster, cluster_timeout=600),
        plots="png",
    )
    assert distributed.where == f"Dask, 2 workers at {cluster}"
    shared = fmutrace.compare(
        fmus, cases, run=fmutrace.RunOptions(scheduler=cluster, shared_files=True, cluster_timeout=600)
    )
    serial = fmutrace.compare(fmus, cases, report=tmp_path / "serial", run=fmutrace.RunOptions(jobs=1), plots="png")
    assert [(o.case, o.status) for o in shared.cases] == [(o.case, o.status) for o in serial.cases]
    assert serial.where == "1 process"
    assert len(serial.cases) == 2 * len(discover(["RateLimiter", "Ramp"]))
    assert [(o.case, o.fmu, o.status, o.messages) for o in distributed.cases] == [
        (o.case, o.fmu, o.status, o.messages) for o in serial.cases
    ]
    assert distributed.passed
    for a, b in zip(distributed.cases, serial.cases, strict=True):
        for name in a.result.dtype.names:
            assert np.array_equal(a.result[name], b.result[name], equal_nan=True)
        assert a.png == b.png  # the same plot, byte for byte
        for made in (a.plot, a.plot_data):  # (the static figure and the page's plot data)
            assert (tmp_path / "distributed" / made).read_bytes() == (tmp_path / "serial" / made).read_bytes()
        assert (tmp_path / "distributed" / a.csv).read_bytes() == (tmp_path / "serial" / b.csv).read_bytes()
    for page in ("index.html", "summary.md", "results.json"):
        assert without_timings((tmp_path / "distributed" / page).read_text()) == without_timings(
            (tmp_path / "serial" / page).read_text()
        )


def test_the_package_sent_to_the_workers_is_this_fmutrace():
    """Dask workers import the fmutrace that compare uploads: the zip holds
    this process's sources, made in a folder of this process (no file left
    in the shared temporary folder by an earlier process with the same id)."""
    package = REPO / "fmutrace" / "src" / "fmutrace"  # not fmutrace.__file__: a local cluster's scheduler, in
    # this process, imports the uploaded zip too
    with zipfile.ZipFile(package_zip()) as z:
        assert sorted(z.namelist()) == sorted(
            f"fmutrace/{s.relative_to(package).as_posix()}" for s in package.rglob("*.py")
        )
        for name in z.namelist():
            assert z.read(name) == (package.parent / name).read_bytes(), name
    assert package_zip() == package_zip() and package_zip().parent != Path(tempfile.gettempdir())
