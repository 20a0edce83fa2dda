"""The project's reference scenarios (tests/scenarios/<Model>/<name>/),
read, run and compared by fmutrace, the product code the main job runs."""

import math
from functools import lru_cache
from pathlib import Path

from fmutrace import Exact, Fmu, compare_traces, load_case
from fmutrace._fmpy import Experiment, Signals, run_fmpy

from support.fmu_driver import BUILD_DIR

SCENARIO_ROOT = Path(__file__).resolve().parents[1] / "scenarios"
FMI_VERSIONS = (2, 3)


def fmu_path(build_dir, model, version):
    return Path(build_dir) / f"fmi{version}" / f"{model}.fmu"


@lru_cache(maxsize=None)
def _fmu(model):
    return Fmu(fmu_path(BUILD_DIR, model, 2))


def load(folder):
    """The scenario in folder, named <Model>/<name>, checked against its FMU."""
    folder = Path(folder)
    return load_case(folder, _fmu(folder.parent.name), name=f"{folder.parent.name}/{folder.name}")


def discover(models=None):
    folders = sorted(p.parent for p in SCENARIO_ROOT.glob("*/*/*_ref.csv"))
    return [load(f) for f in folders if models is None or f.parent.name in models]


def simulate(scenario, fmu, fmi_type="CoSimulation", **start_values):
    """The scenario through fmpy.simulate_fmu on the FMU file fmu, as
    fmi_type, its start values updated by start_values."""
    o = scenario.options
    return run_fmpy(
        str(fmu),
        None,
        Experiment(o["StartTime"], o["StopTime"], o["StepSize"], o["RelTol"]),
        Signals(scenario.inputs, {**dict(scenario.start_values), **start_values}, scenario.outputs),
        fmi_type,
    )


def compare(scenario, result, reference=None):
    """Where result differs from the reference (or the rows of it given),
    bit for bit, as readable lines (none: the same)."""
    return compare_traces(result, scenario.reference if reference is None else reference, Exact()).messages()


def same(value, expected):
    """Bit for bit (any NaN matches any NaN)."""
    value, expected = float(value), float(expected)
    return (math.isnan(value) and math.isnan(expected)) or (
        value == expected and math.copysign(1, value) == math.copysign(1, expected)
    )
