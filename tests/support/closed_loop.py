#!/usr/bin/env python3
"""A closed loop: the FirstOrderLag fixture's controller demand drives
RateLimiter, whose output is the plant's actuator command. Run by one
importer (one process each), communication step H, N steps; writes time,
RateLimiter y and plant x after every step.

    python -m support.closed_loop <fmpy|ecospy|libcosimpy|ssp-ecospy|ssp-libcosimpy|ssp-fmpy> <FMI version>
                                  <build dir> <result.csv>

The ssp-* runs read build/ssp/RateLimiterLoop.ssp (FMI 2 FMUs) instead of
coupling the FMUs here.
"""

import sys
import tomllib
from pathlib import Path

import numpy as np
from fmpy import extract, read_model_description
from fmpy.util import write_csv


# the system's one description, also the SSP package's source
SYSTEM_TOML = Path(__file__).resolve().parents[2] / "modelDescription" / "systems" / "RateLimiterLoop.toml"
SYSTEM = tomllib.loads(SYSTEM_TOML.read_text())
H = SYSTEM["system"]["stepSize"]
N = round((SYSTEM["system"]["stopTime"] - SYSTEM["system"]["startTime"]) / H)
PLANT = next(c["parameters"] for c in SYSTEM["component"] if c["name"] == "plant")
LIMITER = next(c["parameters"] for c in SYSTEM["component"] if c["name"] == "rl")
assert LIMITER["u"] == PLANT["Kp"] * (PLANT["setpoint"] - PLANT["x0"])  # what the first transfer gives


def ssp_path(build):
    return Path(build) / "ssp" / "RateLimiterLoop.ssp"


def paths(build, version):
    return (
        Path(build) / f"fmi{version}" / "RateLimiter.fmu",
        Path(build) / "fixtures" / f"fmi{version}" / "FirstOrderLag.fmu",
    )


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


def ecos_rows(simulation):
    """N steps of an initialised Ecos simulation: (t, rl y, plant x) after each."""
    rows = []
    for k in range(N):
        simulation.step()
        rows.append(((k + 1) * H, simulation.get_real("rl::y"), simulation.get_real("plant::x")))
    simulation.terminate()
    simulation.free()
    return rows


def libcosim_rows(execution, rl, plant, vr_rl, vr_plant):
    """N steps of a libcosim execution: (t, rl y, plant x) after each."""
    from libcosimpy.CosimObserver import CosimObserver

    observer = CosimObserver.create_last_value()
    execution.add_observer(observer)
    rows = []
    for k in range(N):
        execution.step(1)
        rows.append(
            (
                (k + 1) * H,
                observer.last_real_values(rl, [vr_rl["y"]])[0],
                observer.last_real_values(plant, [vr_plant["x"]])[0],
            )
        )
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
    return ecos_rows(simulation)


def run_libcosimpy(build, version):
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimSlave import CosimLocalSlave

    log_output_level(CosimLogLevel.ERROR)
    rl_path, plant_path = paths(build, version)
    vr_rl = {v.name: v.valueReference for v in read_model_description(str(rl_path)).modelVariables}
    vr_plant = {v.name: v.valueReference for v in read_model_description(str(plant_path)).modelVariables}
    execution = CosimExecution.from_step_size(step_size=int(round(H * 1e9)))
    rl = execution.add_local_slave(CosimLocalSlave(fmu_path=str(rl_path), instance_name="rl"))
    plant = execution.add_local_slave(CosimLocalSlave(fmu_path=str(plant_path), instance_name="plant"))
    for name, value in PLANT.items():
        execution.real_initial_value(plant, vr_plant[name], value)
    for name, value in LIMITER.items():
        execution.real_initial_value(rl, vr_rl[name], value)
    execution.connect_real_variables(plant, vr_plant["demand"], rl, vr_rl["u"])
    execution.connect_real_variables(rl, vr_rl["y"], plant, vr_plant["command"])
    return libcosim_rows(execution, rl, plant, vr_rl, vr_plant)


def run_ssp_ecospy(build, version):
    """The SSP package as it is: Ecos reads it (the parameter set by the
    SSV files' name)."""
    from ecospy import EcosSimulation

    simulation = EcosSimulation(ssp_path=str(ssp_path(build)), step_size=H)
    simulation.init(0.0, SYSTEM["system"]["name"])
    return ecos_rows(simulation)


def run_ssp_libcosimpy(build, version):
    """The SSP package as it is: libcosim reads it (the step size given)."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level

    log_output_level(CosimLogLevel.ERROR)
    execution = CosimExecution.from_ssp_file(str(ssp_path(build)), step_size=int(round(H * 1e9)))
    index = {(s.name.decode() if isinstance(s.name, bytes) else s.name): s.index for s in execution.slave_infos()}
    vr_rl = {v.name: v.valueReference for v in read_model_description(str(paths(build, 2)[0])).modelVariables}
    vr_plant = {v.name: v.valueReference for v in read_model_description(str(paths(build, 2)[1])).modelVariables}
    return libcosim_rows(execution, index["rl"], index["plant"], vr_rl, vr_plant)


def run_ssp_fmpy(build, version):
    """fmpy's SSP support reads the package and runs it, but applies only a
    parameter set given to simulate_ssp, not the components' bindings: the
    SSV files' values, read from the package by fmpy, are given."""
    from fmpy.ssp.ssd import read_ssd, read_ssv
    from fmpy.ssp.simulation import simulate_ssp

    ssd = read_ssd(str(ssp_path(build)))
    parameters = []
    for component in ssd.system.elements:
        for binding in component.parameterBindings:
            for parameter in read_ssv(str(ssp_path(build)), resource=binding.source).parameters:
                parameter.name = f"{component.name}.{parameter.name}"
                parameters.append(parameter)
    parameter_set = read_ssv(str(ssp_path(build)), resource=ssd.system.elements[0].parameterBindings[0].source)
    parameter_set.parameters = parameters
    result = simulate_ssp(str(ssp_path(build)), stop_time=N * H, step_size=H, parameter_set=parameter_set)
    return [
        (float(t), float(y), float(x))
        for t, y, x in zip(result["time"], result["rl.y"], result["plant.x"], strict=True)
    ][1:]


RUNNERS = {
    "fmpy": run_fmpy,
    "ecospy": run_ecospy,
    "libcosimpy": run_libcosimpy,
    "ssp-ecospy": run_ssp_ecospy,
    "ssp-libcosimpy": run_ssp_libcosimpy,
    "ssp-fmpy": run_ssp_fmpy,
}


def main(importer, version, build, out):
    rows = RUNNERS[importer](build, int(version))
    write_csv(out, np.array(rows, dtype=[("time", np.float64), ("y", np.float64), ("x", np.float64)]))
    return 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:]))
