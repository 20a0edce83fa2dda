"""Every reference scenario of every model through other importers than
fmpy: ecospy (Ecos on fmi4c; FMI 2 and FMI 3) and libcosimpy (libcosim on
FMI Library; FMI 2). Each run is a subprocess (tests/support/importers.py), so that
an importer crash fails one test. Results must match the reference trace
to the last bits (the importers compute their own communication points;
fmpy's runs match it bit for bit).

What an importer cannot do is asserted, not skipped:
- libcosim and Ecos ignore Enumeration variables (FMI 2 and FMI 3) and say
  so in their log: a scenario that sets one is checked for that message and
  compared, bit for bit, with fmpy's low-level API making the same calls
  without the enumerations;
- both step on a fixed grid: a scenario whose inputs change between grid
  points (fmpy adds communication points there) is compared, bit for bit,
  with fmpy's low-level API making the same calls on the same grid."""

import sys

import numpy as np
import pytest
from fmpy import read_model_description
from fmpy.util import read_csv

from support.fmu_driver import BUILD_DIR, TESTS
from support.process import run as run_bounded
from fmutrace import Tolerance, compare_traces
from support.scenarios import discover, fmu_path

SCENARIOS = discover()
IMPORTERS = [("ecospy", 2), ("ecospy", 3), ("libcosimpy", 2)]


def enumerations_set(scenario, version):
    md = read_model_description(str(fmu_path(BUILD_DIR, scenario.model, version)))
    kinds = {v.name: v.type for v in md.modelVariables}
    names = set(scenario.start_values)
    if scenario.inputs is not None:
        names |= set(scenario.inputs.dtype.names) - {"time"}
    return sorted(n for n in names if kinds.get(n) == "Enumeration")


def run(importer, scenario, version, tmp_path):
    out = tmp_path / "result.csv"
    process = run_bounded(
        [
            sys.executable,
            "-m",
            "support.importers",
            importer,
            str(scenario.folder),
            str(fmu_path(BUILD_DIR, scenario.model, version)),
            str(out),
        ],
        timeout=300,
        what=f"{scenario.name} through {importer} (FMI {version})",
        cwd=TESTS,
    )
    assert process.returncode == 0, process.stderr[-3000:]
    return np.atleast_1d(read_csv(str(out))), process.stdout + process.stderr


@pytest.mark.parametrize("importer,version", IMPORTERS, ids=[f"{i}-fmi{v}" for i, v in IMPORTERS])
@pytest.mark.parametrize("scenario", SCENARIOS, ids=[s.name for s in SCENARIOS])
def test_scenario_through_importer(importer, version, scenario, tmp_path):
    result, log = run(importer, scenario, version, tmp_path)
    reference = scenario.reference
    if importer == "libcosimpy":
        # libcosim initialises in its first step: no row at StartTime
        reference = reference[1:]
    enums = enumerations_set(scenario, version)
    if enums:
        assert any(n in log for n in enums), log[-2000:]  # the importer said it ignores them
    if enums or off_grid(scenario):
        same_calls, _ = run("fmpy-fixed-no-enumerations" if enums else "fmpy-fixed", scenario, version, tmp_path)
        if importer == "libcosimpy":
            same_calls = same_calls[1:]
        assert len(result) == len(same_calls)
        for name in result.dtype.names:
            assert np.array_equal(result[name], same_calls[name], equal_nan=True), name
        return
    # the importer computes its own communication points (libcosim in whole
    # nanoseconds, Ecos by adding steps): where a value depends on the step
    # length (the Siemens blocks' per-cycle change), its last bits may differ
    # from the reference, which holds the values at fmpy's points
    problems = compare_traces(result, reference, Tolerance(rel_tol=1e-12, abs_tol=1e-15)).messages()
    assert not problems, problems[:10]


def off_grid(scenario):
    """Inputs that change between the points of the fixed step grid."""
    if scenario.inputs is None:
        return False
    o = scenario.options
    k = (scenario.inputs["time"] - o["StartTime"]) / o["StepSize"]
    return not np.allclose(k, np.round(k), rtol=0, atol=1e-9)
