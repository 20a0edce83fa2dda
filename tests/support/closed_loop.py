#!/usr/bin/env python3
"""A closed loop: the FirstOrderLag fixture's controller demand drives
RateLimiter, whose output is the plant's actuator command. Run by one
importer (one process each), communication step H, N steps; writes time,
RateLimiter y and plant x after every step.

    python -m support.closed_loop <fmpy|ecospy|libcosimpy> <FMI version> <build dir> <result.csv>
"""
import sys
from pathlib import Path

import numpy as np
from fmpy import extract, read_model_description
from fmpy.util import write_csv


H, N = 0.1, 100
PLANT = {"tau": 2.0, "Kp": 0.8, "setpoint": 10.0, "x0": 0.0}
# u starts as the first transfer makes it, so that initialisation does not
# depend on whether an importer transfers before or after it; initMode
# keeps its default (the output starts at u): Ecos and libcosim cannot set
# Enumeration variables
LIMITER = {"rateUpPar": 1.0, "rateDownPar": 1.0, "u": PLANT["Kp"] * (PLANT["setpoint"] - PLANT["x0"])}


def paths(build, version):
    return (Path(build) / f"fmi{version}" / "RateLimiter.fmu",
            Path(build) / "fixtures" / f"fmi{version}" / "FirstOrderLag.fmu")


def run_fmpy(build, version):
    """Jacobi coupling by hand with fmpy's low-level API: at each
    communication point the outputs go to the inputs, then both step."""
    from support.fmu_driver import Instance

    rl_path, plant_path = paths(build, version)
    rl = Instance("RateLimiter", version, unzipdir=extract(str(rl_path)))
    plant = Instance("FirstOrderLag", version, unzipdir=extract(str(plant_path)))
    rl.start(**LIMITER)
    plant.start(**PLANT)
    rows = []
    for k in range(N):
        t = k * H
        demand, y = plant.get("demand"), rl.get("y")
        rl.set(u=demand)
        plant.set(command=y)
        rl.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=H)
        plant.fmu.doStep(currentCommunicationPoint=t, communicationStepSize=H)
        rows.append(((k + 1) * H, rl.get("y"), plant.get("x")))
    rl.release()
    plant.free()
    return rows


def run_ecospy(build, version):
    from ecospy import EcosSimulation, EcosSimulationStructure

    rl_path, plant_path = paths(build, version)
    structure = EcosSimulationStructure()
    structure.add_model("rl", str(rl_path))
    structure.add_model("plant", str(plant_path))
    structure.make_real_connection("plant::demand", "rl::u")
    structure.make_real_connection("rl::y", "plant::command")
    parameters = {f"plant::{k}": v for k, v in PLANT.items()}
    parameters.update({f"rl::{k}": v for k, v in LIMITER.items()})
    structure.add_parameter_set("loop", parameters)
    simulation = EcosSimulation(structure=structure, step_size=H)
    simulation.init(0.0, "loop")
    rows = []
    for k in range(N):
        simulation.step()
        rows.append(((k + 1) * H, simulation.get_real("rl::y"), simulation.get_real("plant::x")))
    simulation.terminate()
    simulation.free()
    return rows


def run_libcosimpy(build, version):
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    log_output_level(CosimLogLevel.ERROR)
    rl_path, plant_path = paths(build, version)
    vr_rl = {v.name: v.valueReference for v in read_model_description(str(rl_path)).modelVariables}
    vr_plant = {v.name: v.valueReference for v in read_model_description(str(plant_path)).modelVariables}
    execution = CosimExecution.from_step_size(step_size=int(round(H * 1e9)))
    rl = execution.add_local_slave(CosimLocalSlave(fmu_path=str(rl_path), instance_name="rl"))
    plant = execution.add_local_slave(CosimLocalSlave(fmu_path=str(plant_path), instance_name="plant"))
    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)
    for name, value in PLANT.items():
        execution.real_initial_value(plant, vr_plant[name], value)
    for name, value in LIMITER.items():
        execution.real_initial_value(rl, vr_rl[name], value)
    execution.connect_real_variables(plant, vr_plant["demand"], rl, vr_rl["u"])
    execution.connect_real_variables(rl, vr_rl["y"], plant, vr_plant["command"])
    rows = []
    for k in range(N):
        execution.step(1)
        rows.append(((k + 1) * H, observer.last_real_values(rl, [vr_rl["y"]])[0],
                     observer.last_real_values(plant, [vr_plant["x"]])[0]))
    return rows


RUNNERS = {"fmpy": run_fmpy, "ecospy": run_ecospy, "libcosimpy": run_libcosimpy}


def main(importer, version, build, out):
    rows = RUNNERS[importer](build, int(version))
    write_csv(out, np.array(rows, dtype=[("time", np.float64), ("y", np.float64), ("x", np.float64)]))
    return 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:]))
