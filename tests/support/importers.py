#!/usr/bin/env python3
"""Run one reference scenario through another importer than fmpy, the way
fmpy runs it (start values and the inputs at t0 before initialisation; then
each step: inputs at t, step, outputs recorded at t + h), and write the
result CSV. One scenario per process, so that an importer that crashes
fails one test, not the suite.

    python -m support.importers <ecospy|libcosimpy|fmpy-fixed[-no-enumerations]> <scenario folder> <fmu> <result.csv>
"""

import sys
from itertools import pairwise
from pathlib import Path

import numpy as np
from fmpy import read_model_description
from fmpy.util import write_csv

from support.scenarios import load


def input_values(scenario, t):
    """Each input's value at t: the last row at or before t (rows hold)."""
    rows = scenario.inputs
    if rows is None:
        return {}
    tolerance = 1e-9 * max(1.0, abs(t))
    started = [i for i in range(len(rows)) if rows["time"][i] <= t + tolerance]
    if not started:
        return {}
    return {name: rows[name][started[-1]] for name in rows.dtype.names if name != "time"}


def steps(scenario):
    o = scenario.options
    n = int(round((o["StopTime"] - o["StartTime"]) / o["StepSize"]))
    return [o["StartTime"] + k * o["StepSize"] for k in range(n + 1)]


def typed(variable, value):
    kind = variable.type
    if kind == "Boolean":
        return bool(value)
    if kind in ("Integer", "Int32", "Int64", "Enumeration"):
        return int(value)
    return float(value)


def run_ecospy(scenario, fmu):
    from ecospy import EcosSimulation, EcosSimulationStructure

    md = read_model_description(str(fmu))
    variables = {v.name: v for v in md.modelVariables}
    o = scenario.options
    times = steps(scenario)
    structure = EcosSimulationStructure()
    structure.add_model("m", str(fmu))
    initial = dict(scenario.start_values)
    initial.update(input_values(scenario, times[0]))
    structure.add_parameter_set("initial", {f"m::{k}": typed(variables[k], v) for k, v in initial.items()})
    simulation = EcosSimulation(structure=structure, step_size=o["StepSize"])

    def get(name):
        kind = variables[name].type
        if kind == "Boolean":
            return simulation.get_bool(f"m::{name}")
        if kind in ("Integer", "Int32", "Int64", "Enumeration"):
            return simulation.get_integer(f"m::{name}")
        return simulation.get_real(f"m::{name}")

    def set_value(name, value):
        value = typed(variables[name], value)
        if isinstance(value, bool):
            simulation.set_bool(f"m::{name}", value)
        elif isinstance(value, int):
            simulation.set_integer(f"m::{name}", value)
        else:
            simulation.set_real(f"m::{name}", value)

    simulation.init(o["StartTime"], "initial")
    rows = [(times[0], *[get(n) for n in scenario.outputs])]
    for t, end in pairwise(times):
        for name, value in input_values(scenario, t).items():
            set_value(name, value)
        simulation.step()
        rows.append((end, *[get(n) for n in scenario.outputs]))
    simulation.terminate()
    simulation.free()
    return rows


def run_libcosimpy(scenario, fmu):
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimManipulator import CosimManipulator
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    log_output_level(CosimLogLevel.WARNING)
    md = read_model_description(str(fmu))
    variables = {v.name: v for v in md.modelVariables}
    o = scenario.options
    times = steps(scenario)
    execution = CosimExecution.from_step_size(step_size=int(round(o["StepSize"] * 1e9)))
    slave = execution.add_local_slave(CosimLocalSlave(fmu_path=str(fmu), instance_name="m"))
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)
    manipulator = CosimManipulator.create_override()
    execution.add_manipulator(manipulator)

    initial = dict(scenario.start_values)
    initial.update(input_values(scenario, times[0]))
    for name, value in initial.items():
        v, vr = variables[name], variables[name].valueReference
        value = typed(v, value)
        if isinstance(value, bool):
            execution.boolean_initial_value(slave, vr, value)
        elif isinstance(value, int):
            execution.integer_initial_value(slave, vr, value)
        else:
            execution.real_initial_value(slave, vr, value)

    def get(name):
        v = variables[name]
        if v.type == "Boolean":
            return observer.last_boolean_values(slave, [v.valueReference])[0]
        if v.type in ("Integer", "Enumeration"):
            return observer.last_integer_values(slave, [v.valueReference])[0]
        return observer.last_real_values(slave, [v.valueReference])[0]

    def set_value(name, value):
        v = variables[name]
        value = typed(v, value)
        if isinstance(value, bool):
            manipulator.slave_boolean_values(slave, [v.valueReference], [value])
        elif isinstance(value, int):
            manipulator.slave_integer_values(slave, [v.valueReference], [value])
        else:
            manipulator.slave_real_values(slave, [v.valueReference], [value])

    # libcosim initialises the slave in its first step and offers no
    # reading before it: the row at StartTime is not observable here
    rows = []
    for t, end in pairwise(times):
        for name, value in input_values(scenario, t).items():
            set_value(name, value)
        execution.step(1)
        rows.append((end, *[get(n) for n in scenario.outputs]))
    return rows


def run_fmpy_fixed(scenario, fmu, drop_enumerations=False):
    """fmpy's low-level API on the same fixed grid as the other importers
    (simulate_fmu would add communication points at input changes); with
    drop_enumerations, Enumeration start values and inputs are left out,
    as importers that cannot set them do."""
    from fmpy import extract

    from support.fmu_driver import Instance

    md = read_model_description(str(fmu))
    model = md.coSimulation.modelIdentifier
    version = 2 if md.fmiVersion.startswith("2") else 3
    unzipdir = str(fmu) if Path(fmu).is_dir() else extract(str(fmu))
    fmu_instance = Instance(model, version, unzipdir=unzipdir)
    variables = fmu_instance.variables
    times = steps(scenario)
    initial = dict(scenario.start_values)
    initial.update(input_values(scenario, times[0]))
    keep = (lambda k: variables[k].type != "Enumeration") if drop_enumerations else (lambda k: True)
    fmu_instance.start(start_time=times[0], **{k: typed(variables[k], v) for k, v in initial.items() if keep(k)})
    rows = [(times[0], *[fmu_instance.get(n) for n in scenario.outputs])]
    for t, end in pairwise(times):
        fmu_instance.set(**{k: typed(variables[k], v) for k, v in input_values(scenario, t).items() if keep(k)})
        fmu_instance.step(end - t)
        rows.append((end, *[fmu_instance.get(n) for n in scenario.outputs]))
    fmu_instance.free()
    return rows


IMPORTERS = {
    "ecospy": run_ecospy,
    "libcosimpy": run_libcosimpy,
    "fmpy-fixed": run_fmpy_fixed,
    "fmpy-fixed-no-enumerations": lambda s, f: run_fmpy_fixed(s, f, drop_enumerations=True),
}


def main(importer, folder, fmu, out):
    scenario = load(folder)
    rows = IMPORTERS[importer](scenario, Path(fmu))
    dtype = [("time", np.float64)] + [(n, np.float64) for n in scenario.outputs]
    result = np.array([tuple(float(x) for x in row) for row in rows], dtype=dtype)
    write_csv(out, result)
    return 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:]))
