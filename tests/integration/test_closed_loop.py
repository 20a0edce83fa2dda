"""A closed loop in real co-simulations: the FirstOrderLag fixture (plant
and proportional controller, built by CMake) and RateLimiter, coupled in
ecospy (FMI 2 and 3), libcosimpy (FMI 2) and a scripted fmpy loop (FMI 2
and 3), and the SSP package build/ssp/RateLimiterLoop.ssp run unchanged by
ecospy and libcosimpy, each in its own process. All must agree with an
oracle: the rate limiter of docs/rules.md (tests/support/oracle.py) and the
plant's exact step response, coupled the same way (at each communication point the
outputs go to the inputs, then both step). fmpy's SSP support reads the
package and runs it, with a master of its own (it does not apply the
components' parameter bindings, and it steps and records in another
order): its run is checked for what it is. The package's XML is valid
against the SSP 1.0 schemas fmpy ships."""

import math
import os
import sys
import tomllib
import zipfile
from pathlib import Path

import numpy as np
import pytest
from fmpy import read_model_description
from fmpy.util import read_csv

from support.closed_loop import H, LIMITER, N, PLANT
from support.fmu_driver import BUILD_DIR, REPO, TESTS, fmu_file
from support.process import run as run_bounded
from support.oracle import oracle_for

RUNS = [
    ("fmpy", 2),
    ("fmpy", 3),
    ("ecospy", 2),
    ("ecospy", 3),
    ("libcosimpy", 2),
    ("ssp-ecospy", 2),
    ("ssp-libcosimpy", 2),
]


def oracle_loop():
    """At each communication point the outputs go to the inputs, then both
    step."""
    vr = {v.name: v.valueReference for v in read_model_description(str(fmu_file("RateLimiter", 2))).modelVariables}
    limiter = oracle_for("RateLimiter", vr, dict(LIMITER))
    y = limiter.outputs()["y"]
    x = PLANT["x0"]
    rows = []
    for k in range(N):
        t = k * H
        demand = PLANT["Kp"] * (PLANT["setpoint"] - x)
        command = y
        y = limiter.do_step(t, H, {"u": demand})["y"]
        x = command + (x - command) * math.exp(-H / PLANT["tau"])
        rows.append(((k + 1) * H, y, x))
    return rows


@pytest.mark.parametrize("importer,version", RUNS, ids=[f"{i}-fmi{v}" for i, v in RUNS])
def test_closed_loop_agrees_with_the_oracle(importer, version, tmp_path):
    out = tmp_path / "loop.csv"
    environment = dict(os.environ)
    if importer == "ssp-ecospy" and "ASAN_OPTIONS" in environment:
        # the sanitizer tree preloads ASan into Python: it finds a new/delete
        # size mismatch inside Ecos's own ecos::load_ssp (libecosc.so, not
        # ours); the FMUs' checks stay on
        environment["ASAN_OPTIONS"] += ":new_delete_type_mismatch=0"
    process = run_bounded(
        [sys.executable, "-m", "support.closed_loop", importer, str(version), str(BUILD_DIR), str(out)],
        timeout=300,
        what=f"the closed loop in {importer} (FMI {version})",
        cwd=TESTS,
        env=environment,
    )
    assert process.returncode == 0, (process.stdout + process.stderr)[-3000:]
    result = np.atleast_1d(read_csv(str(out)))
    expected = oracle_loop()
    assert len(result) == len(expected) == N
    for row, (t, y, x) in zip(result, expected, strict=True):
        assert row["time"] == pytest.approx(t, rel=1e-12)
        assert row["y"] == pytest.approx(y, rel=1e-12, abs=1e-12), (t, row["y"], y)
        assert row["x"] == pytest.approx(x, rel=1e-12, abs=1e-12), (t, row["x"], x)
    # the loop settles where the controller's demand equals the plant output
    settle = PLANT["Kp"] * PLANT["setpoint"] / (1 + PLANT["Kp"])
    assert abs(result["x"][-1] - settle) < 0.05


def test_the_ssp_package_is_valid_against_the_ssp_schemas():
    import fmpy
    from lxml import etree

    schemas = Path(fmpy.__file__).parent / "ssp" / "schema"
    package = BUILD_DIR / "ssp" / "RateLimiterLoop.ssp"
    with zipfile.ZipFile(package) as z:
        names = set(z.namelist())
        assert {
            "SystemStructure.ssd",
            "resources/RateLimiter.fmu",
            "resources/FirstOrderLag.fmu",
            "resources/rl.ssv",
            "resources/plant.ssv",
        } <= names
        for name, schema in [
            ("SystemStructure.ssd", "SystemStructureDescription.xsd"),
            ("resources/rl.ssv", "SystemStructureParameterValues.xsd"),
            ("resources/plant.ssv", "SystemStructureParameterValues.xsd"),
        ]:
            validator = etree.XMLSchema(etree.parse(str(schemas / schema)))
            document = etree.fromstring(z.read(name))
            assert validator.validate(document), (name, validator.error_log)
        with z.open("resources/RateLimiter.fmu") as inside:
            assert inside.read() == (BUILD_DIR / "fmi2" / "RateLimiter.fmu").read_bytes()


def test_the_ssp_package_names_omsimulators_master_algorithm():
    """Beside the standard content, the system carries OMSimulator's
    vendor annotation with its master algorithm: a fixed-step master
    ("oms-ma") at the system's step size (OMSimulator refuses a system
    without one; docs/testing.md has the run)."""
    from lxml import etree

    with zipfile.ZipFile(BUILD_DIR / "ssp" / "RateLimiterLoop.ssp") as z:
        ssd = etree.fromstring(z.read("SystemStructure.ssd"))
    ns = {
        "ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
        "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon",
        "oms": "https://raw.githubusercontent.com/OpenModelica/OMSimulator/master/schema/oms.xsd",
    }
    masters = ssd.findall(
        "ssd:System/ssd:Annotations/ssc:Annotation[@type='org.openmodelica']/oms:Annotations/"
        "oms:SimulationInformation/oms:FixedStepMaster",
        ns,
    )
    system = tomllib.loads((REPO / "modelDescription" / "systems" / "RateLimiterLoop.toml").read_text())["system"]
    assert len(masters) == 1 and masters[0].get("description") == "oms-ma"
    assert float(masters[0].get("stepSize")) == system["stepSize"]
    experiment = ssd.find("ssd:DefaultExperiment", ns)
    assert float(experiment.get("stopTime")) == system["stopTime"]


def test_a_broken_package_fails_the_schema():
    """The validation can fail: a connector without its kind."""
    import fmpy
    from lxml import etree

    schemas = Path(fmpy.__file__).parent / "ssp" / "schema"
    with zipfile.ZipFile(BUILD_DIR / "ssp" / "RateLimiterLoop.ssp") as z:
        text = z.read("SystemStructure.ssd").decode().replace(' kind="input"', "", 1)
    validator = etree.XMLSchema(etree.parse(str(schemas / "SystemStructureDescription.xsd")))
    assert not validator.validate(etree.fromstring(text.encode()))


def test_fmpy_reads_the_ssp_package_and_runs_it_its_own_way(tmp_path):
    """fmpy 0.3.32's SSP support: read_ssd finds the components, the
    connections and the bindings with the TOML's values; simulate_ssp runs
    the loop (given the SSV values as its parameter set: it does not apply
    bindings) to the same steady state, but not step for step as the
    oracle couples: its master takes the first step before any connection
    is transferred (the inputs at 0) and records each row after its step
    under the step's start time."""
    from fmpy.ssp.ssd import read_ssd, read_ssv

    package = str(BUILD_DIR / "ssp" / "RateLimiterLoop.ssp")
    ssd = read_ssd(package)
    assert sorted(e.name for e in ssd.system.elements) == ["plant", "rl"]
    assert sorted((c.startElement, c.startConnector, c.endElement, c.endConnector) for c in ssd.system.connections) == [
        ("plant", "demand", "rl", "u"),
        ("rl", "y", "plant", "command"),
    ]
    for element in ssd.system.elements:
        values = {
            p.name: float(p.value)
            for b in element.parameterBindings
            for p in read_ssv(package, resource=b.source).parameters
        }
        assert values == (LIMITER if element.name == "rl" else PLANT)
    out = tmp_path / "loop.csv"
    process = run_bounded(
        [sys.executable, "-m", "support.closed_loop", "ssp-fmpy", "2", str(BUILD_DIR), str(out)],
        timeout=300,
        what="the SSP package in fmpy",
        cwd=TESTS,
    )
    assert process.returncode == 0, (process.stdout + process.stderr)[-3000:]
    result = np.atleast_1d(read_csv(str(out)))
    assert len(result) == N
    settle = PLANT["Kp"] * PLANT["setpoint"] / (1 + PLANT["Kp"])
    assert abs(result["x"][-1] - settle) < 0.05
    assert abs(result["x"][-1] - oracle_loop()[-1][2]) < 0.05
    assert result["x"][0] != oracle_loop()[0][2]  # not the oracle's coupling: said above
