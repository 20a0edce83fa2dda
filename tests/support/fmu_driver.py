"""A thin, version-neutral driver over fmpy's low-level FMI 2 / FMI 3 API
that keeps every log message the FMU sends, for the tests."""

import ctypes
import os
from pathlib import Path

from fmpy import extract, read_model_description
from fmpy import calloc, free
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import (
    FMU2Model,
    FMU2Slave,
    fmi2CallbackAllocateMemoryTYPE,
    fmi2CallbackFreeMemoryTYPE,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
)
from fmpy.fmi3 import FMU3Model, FMU3ScheduledExecution, FMU3Slave

REPO = Path(__file__).resolve().parents[2]
TESTS = REPO / "tests"  # the working directory of the helper scripts (python -m support.x)
BUILD_DIR = Path(os.environ.get("RL_BUILD_DIR", REPO / "build"))

# the product models: one TOML file each
MODELS = sorted(p.stem for p in (REPO / "modelDescription").glob("*.toml"))

_unzipped = {}


# the FMUs of FMI 3 Scheduled Execution alone, beside fmi3/'s Co-Simulation and Model Exchange (cmake/Fmu.cmake)
SCHEDULED_EXECUTION_FOLDER = "fmi3-se"


def fmu_file(model, version, scheduled=False):
    """scheduled: the FMI 3 Scheduled Execution FMU (same binary, its own model description)."""
    return BUILD_DIR / (SCHEDULED_EXECUTION_FOLDER if scheduled else f"fmi{version}") / f"{model}.fmu"


def unzipped(model, version, scheduled=False):
    """The FMU extracted once per test session."""
    key = (model, version, scheduled)
    if key not in _unzipped:
        _unzipped[key] = extract(str(fmu_file(model, version, scheduled)))
    return _unzipped[key]


def clock_vr(model):
    """The value reference of the Clock cyclicInterrupt, as the Scheduled Execution FMU declares it; its binary is
    the FMI 3 Co-Simulation and Model Exchange FMU's, whose model description has no Clock."""
    md = read_model_description(unzipped(model, 3, scheduled=True))
    (clock,) = (v for v in md.modelVariables if v.type == "Clock")
    return clock.valueReference


class Instance:
    """One FMU instance. Values are read and written by variable name."""

    def __init__(
        self,
        model="RateLimiter",
        version=2,
        name="test",
        logging=True,
        unzipdir=None,
        model_exchange=False,
        scheduled=False,
    ):
        """scheduled: FMI 3 Scheduled Execution, through fmpy's own wrapper (its
        preemption callbacks do nothing)."""
        self.version = version
        self.model = model
        self.model_exchange = model_exchange
        self.scheduled = scheduled
        self.unzipdir = unzipdir or unzipped(model, version, scheduled)
        self.md = read_model_description(self.unzipdir)
        self.variables = {v.name: v for v in self.md.modelVariables}
        self.messages = []
        self.t = 0.0
        identifier = (self.md.scheduledExecution if scheduled else self.md.coSimulation).modelIdentifier
        if version == 2:
            self.fmu = (FMU2Model if model_exchange else FMU2Slave)(
                guid=self.md.guid, unzipDirectory=self.unzipdir, modelIdentifier=identifier, instanceName=name
            )
            self.callbacks = fmi2CallbackFunctions()
            self.callbacks.logger = fmi2CallbackLoggerTYPE(self._log2)
            self.callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
            self.callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
            self.fmu.instantiate(callbacks=self.callbacks, loggingOn=logging)
        else:
            self.fmu = (FMU3Model if model_exchange else FMU3ScheduledExecution if scheduled else FMU3Slave)(
                guid=self.md.guid, unzipDirectory=self.unzipdir, modelIdentifier=identifier, instanceName=name
            )
            self.fmu.instantiate(loggingOn=logging, logMessage=self._log3)

    def _log2(self, environment, name, status, category, message):
        self.messages.append((status, category.decode(), message.decode()))

    def _log3(self, environment, status, category, message):
        self.messages.append((status, category.decode(), message.decode()))

    def vr(self, name):
        return self.variables[name].valueReference

    def _accessors(self, variable):
        f, kind = self.fmu, variable.type
        if self.version == 2:
            table = {
                "Real": (f.getReal, f.setReal),
                "Integer": (f.getInteger, f.setInteger),
                "Enumeration": (f.getInteger, f.setInteger),
                "Boolean": (f.getBoolean, f.setBoolean),
            }
        else:
            table = {
                "Float64": (f.getFloat64, f.setFloat64),
                "Int32": (f.getInt32, f.setInt32),
                "Enumeration": (f.getInt64, f.setInt64),
                "Boolean": (f.getBoolean, f.setBoolean),
            }
        return table[kind]

    def set(self, **values):
        for name, value in values.items():
            variable = self.variables[name]
            setter = self._accessors(variable)[1]
            if variable.type in ("Integer", "Int32", "Enumeration"):
                value = int(value)
            elif variable.type == "Boolean":
                value = bool(value)
            setter([variable.valueReference], [value])

    def get(self, name):
        variable = self.variables[name]
        value = self._accessors(variable)[0]([variable.valueReference])[0]
        return bool(value) if variable.type == "Boolean" else value

    def outputs(self, names):
        return {n: self.get(n) for n in names}

    def start(self, start_time=0.0, **start_values):
        """Set start values, then initialise at start_time."""
        self.set(**start_values)
        self.enter_initialization(start_time)
        self.fmu.exitInitializationMode()

    def enter_initialization(self, start_time=0.0):
        """Into Initialization Mode at start_time (FMI 2: after fmi2SetupExperiment)."""
        self.t = start_time
        if self.version == 2:
            self.fmu.setupExperiment(startTime=start_time)
            self.fmu.enterInitializationMode()
        else:
            self.fmu.enterInitializationMode(startTime=start_time)

    def step(self, h):
        self.fmu.doStep(currentCommunicationPoint=self.t, communicationStepSize=h)
        self.t += h

    def raw_step(self, h):
        """doStep through ctypes alone, returning the FMI status (fmpy's
        wrapper hides warnings)."""
        return self.raw_step_at(self.t, h)

    def raw_step_at(self, t, h):
        """doStep(t, h) through ctypes alone; the driver's time is t + h
        after a step that passed."""
        dll, flag, when = self.fmu.dll, ctypes.c_bool(), ctypes.c_double()
        if self.version == 2:
            do_step = dll.fmi2DoStep
            do_step.argtypes = [ctypes.c_void_p, ctypes.c_double, ctypes.c_double, ctypes.c_int]
            status = do_step(self.fmu.component, t, h, 1)
        else:
            do_step = dll.fmi3DoStep
            do_step.argtypes = [ctypes.c_void_p, ctypes.c_double, ctypes.c_double, ctypes.c_bool] + [
                ctypes.c_void_p
            ] * 4
            status = do_step(
                self.fmu.component,
                t,
                h,
                True,
                ctypes.byref(flag),
                ctypes.byref(flag),
                ctypes.byref(flag),
                ctypes.byref(when),
            )
        if status <= 1:
            self.t = t + h
        return status

    def raw_activate(self, t):
        """fmi3ActivateModelPartition of the Clock at t, through ctypes alone; the FMI status."""
        activate = self.fmu.dll.fmi3ActivateModelPartition
        activate.argtypes = [ctypes.c_void_p, ctypes.c_uint32, ctypes.c_double]
        activate.restype = ctypes.c_int
        return activate(self.fmu.component, clock_vr(self.model), t)

    def restore(self, state, t):
        """Set an FMU state taken at time t; the driver's clock goes back with it (set by the test, not read
        from the FMU, so a state that loses its time is caught at the next step)."""
        state_api(self)["set"](state)
        self.t = t

    def errors(self):
        return [m for m in self.messages if m[0] >= 3]

    def free(self):
        """Free the instance (fmpy also unloads the library)."""
        self.fmu.freeInstance()

    def release(self):
        """Free the instance but keep the library loaded, for when other
        instances of the same FMU are still running."""
        free_instance = self.fmu.fmi2FreeInstance if self.version == 2 else self.fmu.fmi3FreeInstance
        free_instance(self.fmu.component)


def call_status(function, *args, **kwargs):
    """The FMI status of an fmpy call: 0 if it passed, else what it raised."""
    try:
        function(*args, **kwargs)
        return 0
    except FMICallException as exception:
        return exception.status


# outputs recorded by run_steps
STATE_OUTPUTS = ("y", "runningTime", "status", "rampActive")


def state_api(fmu):
    """The FMU-state functions of fmpy's slave, by one name for both versions."""
    f = fmu.fmu
    if fmu.version == 2:
        return {
            "get": f.getFMUstate,
            "set": f.setFMUstate,
            "free": f.freeFMUstate,
            "serialize": f.serializeFMUstate,
            "deserialize": f.deSerializeFMUstate,
        }
    return {
        "get": f.getFMUState,
        "set": f.setFMUState,
        "free": f.freeFMUState,
        "serialize": f.serializeFMUState,
        "deserialize": f.deserializeFMUState,
    }


# the FMU-state functions' exported names, for calls through ctypes
STATE_FUNCTIONS = {
    2: {
        "get": "fmi2GetFMUstate",
        "set": "fmi2SetFMUstate",
        "size": "fmi2SerializedFMUstateSize",
        "serialize": "fmi2SerializeFMUstate",
        "deserialize": "fmi2DeSerializeFMUstate",
        "free": "fmi2FreeFMUstate",
    },
    3: {
        "get": "fmi3GetFMUState",
        "set": "fmi3SetFMUState",
        "size": "fmi3SerializedFMUStateSize",
        "serialize": "fmi3SerializeFMUState",
        "deserialize": "fmi3DeserializeFMUState",
        "free": "fmi3FreeFMUState",
    },
}


def run_steps(fmu, steps, names=STATE_OUTPUTS):
    """Set inputs, step, and record the outputs as exact hex floats."""
    trace = []
    for h, inputs in steps:
        fmu.set(**inputs)
        fmu.step(h)
        trace.append([float(fmu.get(n)).hex() for n in names])
    return trace
