#!/usr/bin/env python3
"""Write the serialized FMU state an FMU carries (docs/fmi.md, "Reference
experiments"): the staged FMU, run with fmpy through the first half of the
communication steps of its first reference scenario (the smoke test's
first experiment), serialized as fmi2SerializeFMUstate/fmi3SerializeFMUState
give it. An importer deserializes it, continues the scenario's second half
and meets the reference: a test of its platform's state handling.

    state.py <stage folder> <FMI version> <scenarios folder of the model> <out file>

The inputs are the scenario's: a row holds from its time on (the last row
at or before a step's start), set before initialisation and each step.
What the FMU logs is printed, but for the block's status that the
scenario's reference expects (a scenario of an invalid call reports
16#8601 at every step, as it should): the build's output shows no warning
that is not one.
"""

import contextlib
import csv
import io
import re
import sys
from pathlib import Path

from fmpy import read_model_description
from fmpy.fmi2 import FMU2Slave
from fmpy.fmi3 import FMU3Slave
from references import half_steps, scenario_folders  # (this folder: the rules written once)

BOOLEAN = {"true": True, "false": False, "1": True, "0": False}


def rows(path):
    if not path.exists():
        return []
    with open(path, newline="") as file:
        return [row for row in csv.reader(file) if row and not row[0].startswith("#")]


class Driver:
    """One instance of the staged FMU, values set by name."""

    def __init__(self, stage, version):
        self.md = read_model_description(str(stage))
        self.version = version
        self.variables = {v.name: v for v in self.md.modelVariables}
        slave = FMU2Slave if version == 2 else FMU3Slave
        self.fmu = slave(
            guid=self.md.guid,
            unzipDirectory=str(stage),
            modelIdentifier=self.md.coSimulation.modelIdentifier,
            instanceName="state",
        )
        self.fmu.instantiate()

    def set(self, name, text):
        variable, f = self.variables[name], self.fmu
        vr, kind = [variable.valueReference], variable.type
        if kind == "Boolean":
            f.setBoolean(vr, [BOOLEAN[text.strip().lower()]])
        elif kind in ("Integer", "Int32"):
            (f.setInteger if self.version == 2 else f.setInt32)(vr, [int(text)])
        elif kind == "Enumeration":
            (f.setInteger if self.version == 2 else f.setInt64)(vr, [int(text)])
        else:
            (f.setReal if self.version == 2 else f.setFloat64)(vr, [float(text)])


def first_half_state(stage, version, scenario):
    """The serialized state after the first half of scenario's steps."""
    model = scenario.parent.name
    options = dict(rows(scenario / f"{model}_ref.opt"))
    start, step, half, _ = half_steps(options)
    stimuli = rows(scenario / f"{model}_in.csv")
    names, table = (stimuli[0], stimuli[1:]) if stimuli else ([], [])
    driver = Driver(stage, version)

    def set_inputs(t):
        held = [row for row in table if float(row[0]) <= t + step * 1e-9]
        if held:
            for name, text in zip(names[1:], held[-1][1:], strict=True):
                driver.set(name, text)

    for name, text in rows(scenario / f"{model}_start.csv"):
        driver.set(name, text)
    set_inputs(start)
    fmu = driver.fmu
    if version == 2:
        fmu.setupExperiment(startTime=start)
        fmu.enterInitializationMode()
    else:
        fmu.enterInitializationMode(startTime=start)
    fmu.exitInitializationMode()
    for k in range(half):
        t = start + k * step
        set_inputs(t)
        fmu.doStep(currentCommunicationPoint=t, communicationStepSize=step)
    if version == 2:
        state = fmu.getFMUstate()
        data = fmu.serializeFMUstate(state)
    else:
        state = fmu.getFMUState()
        data = fmu.serializeFMUState(state)
    fmu.terminate()
    fmu.freeInstance()
    return bytes(data)


STATUS_MESSAGE = re.compile(r"\[WARNING\] status 16#([0-9A-F]{4})\b")  # the block's status, as the FMU logs it


def unexpected(log, reference):
    """The lines of what the FMU logged, but the warnings of a status the
    reference's status column holds."""
    table = rows(reference)
    column = table[0].index("status") if table and "status" in table[0] else None
    expected = {int(float(row[column])) for row in table[1:]} if column is not None else set()
    return [
        line
        for line in log.splitlines()
        if not ((found := STATUS_MESSAGE.match(line)) and int(found.group(1), 16) in expected)
    ]


def main(stage, version, scenarios, out):
    stage = Path(stage).resolve()
    model = read_model_description(str(stage)).coSimulation.modelIdentifier
    scenario = scenario_folders(scenarios, model)[0]
    with contextlib.redirect_stdout(io.StringIO()) as log:  # (fmpy prints the FMU's messages)
        data = first_half_state(stage, int(version), scenario)
    for line in unexpected(log.getvalue(), scenario / f"{model}_ref.csv"):
        print(line)
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    Path(out).write_bytes(data)
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 5:
        sys.exit(__doc__.split("\n\n")[1])
    sys.exit(main(*sys.argv[1:]))
