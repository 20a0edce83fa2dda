"""FMI state-machine conformance: every exported function of the FMI API,
called in every state of each interface (Co-Simulation: Instantiated,
Initialization Mode, Step Mode, Terminated, and after an error; Model
Exchange: Event Mode and Continuous-Time Mode instead of Step Mode; FMI 3
Scheduled Execution: Clock Activation Mode) with valid arguments, returns
what the standard's state table requires. A refusal is fmiError with
exactly one log message naming the function; functions of capabilities
this FMU does not declare (derivatives, Configuration Mode, output
Clocks, ...) refuse in every state, and the functions of one interface
refuse an instance of another.

The allowed states below are written from the standards' tables (FMI
2.0.4 sections 3.2.3 and 4.2.4; FMI 3.0 sections 2.3, 3.2, 4.2 and 5.2),
not read from the FMU's own tables."""

import ctypes
import re
from ctypes import POINTER, c_bool, c_double, c_int, c_size_t, c_uint, c_void_p
from pathlib import Path

import pytest
from fmpy import __file__ as fmpy_file

from fmpy.fmi2 import fmi2EventInfo

from support.fmu_driver import Instance, call_status, clock_vr

STATES = ["Instantiated", "Initialization Mode", "Step Mode", "Terminated", "Error"]
ALL = set(STATES)
I, N, S, T, E = STATES  # noqa: E741 (the initials the tables below are written in)
# Model Exchange's own states
EV, C = "Event Mode", "Continuous-Time Mode"
ME_STATES = [I, N, EV, C, T, E]
ME_ALL = set(ME_STATES)
# Scheduled Execution's own state (FMI 3 only)
CA = "Clock Activation Mode"
SE_STATES = [I, N, CA, T, E]
# the interfaces an instance is made for
CS_, ME_, SE_ = "Co-Simulation", "Model Exchange", "Scheduled Execution"

# FMI 2.0.4, Co-Simulation: function -> states in which it may be called.
# (stepComplete, stepFailed and stepCanceled are Step Mode here: this FMU
# never returns fmi2Pending, so there is no stepInProgress.)
FMI2_ALLOWED = {
    "fmi2SetDebugLogging": ALL,
    "fmi2SetupExperiment": {I},
    "fmi2EnterInitializationMode": {I},
    "fmi2ExitInitializationMode": {N},
    "fmi2Terminate": {S},
    "fmi2Reset": ALL,
    "fmi2GetReal": {N, S, T, E},
    "fmi2GetInteger": {N, S, T, E},
    "fmi2GetBoolean": {N, S, T, E},
    "fmi2GetString": {N, S, T, E},
    "fmi2SetReal": {I, N, S},
    "fmi2SetInteger": {I, N, S},
    "fmi2SetBoolean": {I, N, S},
    "fmi2SetString": {I, N, S},
    "fmi2GetFMUstate": ALL,
    "fmi2SetFMUstate": ALL,
    "fmi2FreeFMUstate": ALL,
    "fmi2SerializedFMUstateSize": ALL,
    "fmi2SerializeFMUstate": ALL,
    "fmi2DeSerializeFMUstate": ALL,
    "fmi2DoStep": {S},
    "fmi2GetStatus": {S, T},
    "fmi2GetRealStatus": {S, T},
    "fmi2GetIntegerStatus": {S, T},
    "fmi2GetBooleanStatus": {S, T},
    "fmi2GetStringStatus": {S, T},
}

# FMI 2.0.4, Model Exchange (section 3.2.3, the table of allowed calls). fmi2SetTime in Event Mode:
# condition 8, a pure discrete-time FMU's next event instant, which this FMU is. fmi2SetReal in
# Continuous-Time Mode: condition 5, continuous-time inputs; this FMU's are discrete, and it takes their
# sets there too (BEYOND_THE_TABLE).
FMI2_ME_ALLOWED = {
    "fmi2SetDebugLogging": ME_ALL,
    "fmi2SetupExperiment": {I},
    "fmi2EnterInitializationMode": {I},
    "fmi2ExitInitializationMode": {N},
    "fmi2Terminate": {EV, C},
    "fmi2Reset": ME_ALL,
    "fmi2GetReal": {N, EV, C, T, E},
    "fmi2GetInteger": {N, EV, C, T, E},
    "fmi2GetBoolean": {N, EV, C, T, E},
    "fmi2GetString": {N, EV, C, T, E},
    "fmi2SetReal": {I, N, EV, C},
    "fmi2SetInteger": {I, N, EV},
    "fmi2SetBoolean": {I, N, EV},
    "fmi2SetString": {I, N, EV},
    "fmi2GetFMUstate": ME_ALL,
    "fmi2SetFMUstate": ME_ALL,
    "fmi2FreeFMUstate": ME_ALL,
    "fmi2SerializedFMUstateSize": ME_ALL,
    "fmi2SerializeFMUstate": ME_ALL,
    "fmi2DeSerializeFMUstate": ME_ALL,
    "fmi2EnterEventMode": {EV, C},
    "fmi2NewDiscreteStates": {EV},
    "fmi2EnterContinuousTimeMode": {EV},
    "fmi2CompletedIntegratorStep": {C},
    "fmi2SetTime": {EV, C},
    "fmi2SetContinuousStates": {C},
    "fmi2GetEventIndicators": {N, EV, C, T, E},
    "fmi2GetContinuousStates": {N, EV, C, T, E},
    "fmi2GetDerivatives": {N, EV, C, T, E},
    "fmi2GetNominalsOfContinuousStates": {I, EV, C, T, E},
}

# FMI 3.0, Co-Simulation without Event Mode. FMI 3 has no Error state:
# "If any function called in super state FMU State Settable returns
# fmi3Error, the FMU enters state Terminated." (FMI 3.0.2, section 2.3,
# Super State: FMU State Settable). So after an error the row of
# Terminated applies (FMI3_AFTER_ERROR), where fmi3Get{VariableType} is
# allowed ("retrieved values should only be used for debugging purposes")
# and the FMU-state functions, fmi3Reset and fmi3FreeInstance are allowed
# throughout the super state.
FMI3_AFTER_ERROR = T
FMI3_ALLOWED = {
    "fmi3SetDebugLogging": {I, N, S, T},
    "fmi3EnterInitializationMode": {I},
    "fmi3ExitInitializationMode": {N},
    "fmi3Terminate": {S},
    "fmi3Reset": {I, N, S, T},
    "fmi3GetFloat64": {N, S, T},
    "fmi3GetInt32": {N, S, T},
    "fmi3GetInt64": {N, S, T},
    "fmi3GetBoolean": {N, S, T},
    "fmi3GetString": {N, S, T},
    "fmi3GetBinary": {N, S, T},
    "fmi3GetFloat32": {N, S, T},
    "fmi3GetInt8": {N, S, T},
    "fmi3GetUInt8": {N, S, T},
    "fmi3GetInt16": {N, S, T},
    "fmi3GetUInt16": {N, S, T},
    "fmi3GetUInt32": {N, S, T},
    "fmi3GetUInt64": {N, S, T},
    "fmi3SetFloat64": {I, N, S},
    "fmi3SetInt32": {I, N, S},
    "fmi3SetInt64": {I, N, S},
    "fmi3SetBoolean": {I, N, S},
    "fmi3SetString": {I, N, S},
    "fmi3SetBinary": {I, N, S},
    "fmi3SetFloat32": {I, N, S},
    "fmi3SetInt8": {I, N, S},
    "fmi3SetUInt8": {I, N, S},
    "fmi3SetInt16": {I, N, S},
    "fmi3SetUInt16": {I, N, S},
    "fmi3SetUInt32": {I, N, S},
    "fmi3SetUInt64": {I, N, S},
    "fmi3GetFMUState": {I, N, S, T},
    "fmi3SetFMUState": {I, N, S, T},
    "fmi3FreeFMUState": {I, N, S, T},
    "fmi3SerializedFMUStateSize": {I, N, S, T},
    "fmi3SerializeFMUState": {I, N, S, T},
    "fmi3DeserializeFMUState": {I, N, S, T},
    "fmi3DoStep": {S},
}

# FMI 3.0, Model Exchange: the common states (section 2.3: Instantiated, Initialization Mode, the super
# state Initialized, Event Mode, Terminated) and Continuous-Time Mode (section 3.2), where
# fmi3Set{VariableType} is for continuous-time inputs only (this FMU's are discrete: BEYOND_THE_TABLE).
FMI3_ME_ALLOWED = {
    **{
        name: (
            {I, N, EV, C, T}
            if states == {I, N, S, T}
            else {I, N, EV}
            if states == {I, N, S}
            else {N, EV, C, T}
            if states == {N, S, T}
            else {EV, C}
            if name == "fmi3Terminate"
            else states
        )
        for name, states in FMI3_ALLOWED.items()
        if name != "fmi3DoStep"
    },
    "fmi3EnterEventMode": {C},
    "fmi3UpdateDiscreteStates": {EV},
    "fmi3EnterContinuousTimeMode": {EV},
    "fmi3CompletedIntegratorStep": {C},
    "fmi3SetTime": {C},
    "fmi3SetContinuousStates": {C},
    "fmi3GetContinuousStateDerivatives": {N, EV, C, T},
    "fmi3GetEventIndicators": {N, EV, C, T},
    "fmi3GetContinuousStates": {N, EV, C, T},
    "fmi3GetNominalsOfContinuousStates": {N, EV, C, T},
    "fmi3GetNumberOfEventIndicators": {I, EV, C},
    "fmi3GetNumberOfContinuousStates": {I, EV, C},
}

# FMI 3.0, Scheduled Execution (section 5.2, State: Clock Activation Mode): the common states of 2.3 with
# Clock Activation Mode where Co-Simulation has Step Mode: fmi3Set{VariableType} of inputs and tunable
# parameters, fmi3Get{VariableType}, fmi3ActivateModelPartition, fmi3GetInterval, the FMU-state functions
# (between activations) and fmi3Terminate there. The interval of a fixed periodic Clock without
# intervalDecimal is asked in Initialization Mode and may be in Clock Activation Mode, its shift in
# Initialization Mode (2.2.9.3, the table of Clock types).
FMI3_SE_ALLOWED = {
    **{name: {CA if s == S else s for s in states} for name, states in FMI3_ALLOWED.items() if name != "fmi3DoStep"},
    "fmi3ActivateModelPartition": {CA},
    "fmi3GetIntervalDecimal": {N, CA},
    "fmi3GetShiftDecimal": {N},
}

# Calls this FMU takes where the standard's table has none (docs/fmi.md, Model Exchange): the sets of
# Event Mode in Continuous-Time Mode too, as OMSimulator makes them at each integrator step (the next
# cycle takes the values the instant before it is left with). Every other cell is the standard's.
BEYOND_THE_TABLE = {(2, f"fmi2Set{kind}", C) for kind in ("Integer", "Boolean", "String")} | {
    (3, name, C) for name in FMI3_ALLOWED if name.startswith("fmi3Set") and "FMUState" not in name
}

# Functions of capabilities this FMU does not have, by the standards' chapters, and the reason each
# refusal gives. FMI 2: Model Exchange (chapter 3); directional derivatives, input derivatives and output
# derivatives (providesDirectionalDerivative, canInterpolateInputs and maxOutputDerivativeOrder are
# false or 0). FMI 3: derivatives and dependencies (providesDirectionalDerivatives,
# providesAdjointDerivatives, providesPerElementDependencies false; maxOutputDerivativeOrder 0);
# Co-Simulation's Event Mode (hasEventMode false); Configuration Mode (no structural parameters); and of
# the Clock functions those its one Clock has no use for: it is an input Clock (no fmi3GetClock), ticks in
# Scheduled Execution only (no fmi3SetClock, no clocked partition in Event Mode), decimal only
# (supportsFraction false), with the interval and shift the FMU gives (no fmi3SetInterval, fmi3SetShift).
FMI2_NO_DERIVATIVES = "this FMU provides no derivatives (see the model description)"
FMI3_NO_DERIVATIVES = "this FMU provides no derivatives or dependencies (see the model description)"
FMI3_NO_CONFIGURATION = "this FMU has no Configuration Mode (no structural parameters)"
FMI3_NO_EVENT_CLOCKS = "this FMU's Clock ticks in Scheduled Execution only: no clocked partition in Event Mode"
FMI3_NO_FRACTION = "the Clock's timing is decimal only (supportsFraction = false): use fmi3GetIntervalDecimal"
FMI3_CLOCK_FOLLOWS_CYCLE = (
    "the Clock's interval and shift are cycleTime's (a fixed periodic Clock without intervalDecimal): set cycleTime"
)
FMI3_NO_CS_EVENT_MODE = "this FMU has no Event Mode in Co-Simulation (hasEventMode = false)"
UNSUPPORTED = {
    **{
        f"fmi2{name}": FMI2_NO_DERIVATIVES
        for name in ("GetDirectionalDerivative", "SetRealInputDerivatives", "GetRealOutputDerivatives")
    },
    "fmi3EnterStepMode": FMI3_NO_CS_EVENT_MODE,
    **{
        f"fmi3{name}": FMI3_NO_DERIVATIVES
        for name in (
            "GetNumberOfVariableDependencies",
            "GetVariableDependencies",
            "GetDirectionalDerivative",
            "GetAdjointDerivative",
            "GetOutputDerivatives",
        )
    },
    "fmi3EnterConfigurationMode": FMI3_NO_CONFIGURATION,
    "fmi3ExitConfigurationMode": FMI3_NO_CONFIGURATION,
    "fmi3EvaluateDiscreteStates": FMI3_NO_EVENT_CLOCKS,
    "fmi3GetClock": "the Clock is an input Clock; fmi3GetClock reads output Clocks, and this FMU has none",
    "fmi3SetClock": "the Clock ticks in Scheduled Execution only (fmi3ActivateModelPartition); in Co-Simulation the "
    "communication step and in Model Exchange the time events run the cycles",
    "fmi3GetIntervalFraction": FMI3_NO_FRACTION,
    "fmi3GetShiftFraction": FMI3_NO_FRACTION,
    **{
        f"fmi3{name}": FMI3_CLOCK_FOLLOWS_CYCLE
        for name in ("SetIntervalDecimal", "SetIntervalFraction", "SetShiftDecimal", "SetShiftFraction")
    },
}


# The refusal of a function of another interface (the interface whose table has it): its own text, or
# (fmi2DoStep, fmi3DoStep: Step Mode is Co-Simulation's alone; fmi3ActivateModelPartition: Clock
# Activation Mode is Scheduled Execution's) the state's
def other_interface_text(version, interface, owner):
    if version == 2 and interface == ME_:
        return "a Co-Simulation function, and this instance was instantiated for Model Exchange"
    return f"a {owner} function, and this instance was instantiated for {interface}"


# not called on an instance, or ending it
NOT_INSTANCE_CALLS = {
    "fmi2GetTypesPlatform",
    "fmi2GetVersion",
    "fmi2Instantiate",
    "fmi2FreeInstance",
    "fmi3GetVersion",
    "fmi3InstantiateCoSimulation",
    "fmi3InstantiateModelExchange",
    "fmi3InstantiateScheduledExecution",
    "fmi3FreeInstance",
}


def exported_functions(version):
    """Every function of the FMI API, from the function types header that
    the pinned fmpy ships."""
    header = Path(fmpy_file).parent / "c-code" / f"fmi{version}FunctionTypes.h"
    text = re.sub(r"/\*.*?\*/", "", header.read_text(), flags=re.S)
    found = re.findall(r"typedef\s+[\w\s\*]+?\b(fmi%d\w+)TYPE\s*\((.*?)\)\s*;" % version, text, flags=re.S)
    return {
        name: (0 if params.strip() in ("", "void") else params.count(",") + 1)
        for name, params in found
        if not name.startswith(f"fmi{version}Callback")
    }


def raw(fmu, name, argtypes, *args):
    function = getattr(fmu.fmu.dll, name)
    function.argtypes, function.restype = argtypes, c_int
    return function(*args)


def valid_call(fmu, name):
    """The function called with valid arguments; returns its status."""
    c, v = fmu.fmu.component, fmu.version
    vr = (c_uint * 1)(fmu.vr("u"))
    out = (c_uint * 1)(fmu.vr("y"))
    boolean_vr = (c_uint * 1)(fmu.vr("bypass"))
    integer_vr = (c_uint * 1)(fmu.vr("status"))
    real = (c_double * 1)(1.0)
    integer = (ctypes.c_int32 * 1)(0)
    int64 = (ctypes.c_int64 * 1)(0)
    flag = (c_int * 1)(0) if v == 2 else (c_bool * 1)(False)
    state = c_void_p()
    take_state = "fmi2GetFMUstate" if v == 2 else "fmi3GetFMUState"

    def with_state(call):
        # a state taken in Initialization Mode on a second instance of the
        # same FMU: valid whatever state this instance is in
        helper = Instance("RateLimiter", v, name="helper", model_exchange=fmu.model_exchange, scheduled=fmu.scheduled)
        try:
            helper.start()
            assert (
                raw(helper, take_state, [c_void_p, POINTER(c_void_p)], helper.fmu.component, ctypes.byref(state)) == 0
            )
            return call()
        finally:
            helper.release()

    size = c_size_t()
    buffer = ctypes.create_string_buffer(4096)
    # Model Exchange: no continuous states, no event indicators (n = 0)
    me_calls = {
        f"fmi{v}{kind}": (lambda k=f"fmi{v}{kind}": raw(fmu, k, [c_void_p, c_void_p, c_size_t], c, buffer, 0))
        for kind in (
            "SetContinuousStates",
            "GetContinuousStates",
            "GetDerivatives",
            "GetNominalsOfContinuousStates",
            "GetEventIndicators",
            "GetContinuousStateDerivatives",
        )
    }
    me_calls[f"fmi{v}EnterEventMode"] = lambda: raw(fmu, f"fmi{v}EnterEventMode", [c_void_p], c)
    me_calls[f"fmi{v}EnterContinuousTimeMode"] = lambda: raw(fmu, f"fmi{v}EnterContinuousTimeMode", [c_void_p], c)
    me_calls[f"fmi{v}SetTime"] = lambda: raw(fmu, f"fmi{v}SetTime", [c_void_p, c_double], c, fmu.t)
    me_calls[f"fmi{v}CompletedIntegratorStep"] = lambda: raw(
        fmu,
        f"fmi{v}CompletedIntegratorStep",
        [c_void_p, c_int if v == 2 else c_bool, c_void_p, c_void_p],
        c,
        1,
        flag,
        flag,
    )
    if v == 2:
        me_calls["fmi2NewDiscreteStates"] = lambda: raw(
            fmu, "fmi2NewDiscreteStates", [c_void_p, c_void_p], c, ctypes.byref(fmi2EventInfo())
        )
    else:
        me_calls["fmi3UpdateDiscreteStates"] = lambda: raw(
            fmu, "fmi3UpdateDiscreteStates", [c_void_p] * 7, c, flag, flag, flag, flag, flag, real
        )
        for kind in ("EventIndicators", "ContinuousStates"):
            me_calls[f"fmi3GetNumberOf{kind}"] = lambda k=f"fmi3GetNumberOf{kind}": raw(
                fmu, k, [c_void_p, POINTER(c_size_t)], c, ctypes.byref(size)
            )
    if name in me_calls:
        return me_calls[name]()
    if v == 2:
        calls = {
            "fmi2SetDebugLogging": lambda: raw(fmu, name, [c_void_p, c_int, c_size_t, c_void_p], c, 1, 0, None),
            "fmi2SetupExperiment": lambda: raw(
                fmu, name, [c_void_p, c_int, c_double, c_double, c_int, c_double], c, 0, 0.0, 0.0, 0, 0.0
            ),
            "fmi2EnterInitializationMode": lambda: raw(fmu, name, [c_void_p], c),
            "fmi2ExitInitializationMode": lambda: raw(fmu, name, [c_void_p], c),
            "fmi2Terminate": lambda: raw(fmu, name, [c_void_p], c),
            "fmi2Reset": lambda: raw(fmu, name, [c_void_p], c),
            "fmi2GetReal": lambda: raw(fmu, name, [c_void_p, c_void_p, c_size_t, c_void_p], c, out, 1, real),
            "fmi2GetInteger": lambda: raw(
                fmu, name, [c_void_p, c_void_p, c_size_t, c_void_p], c, integer_vr, 1, integer
            ),
            "fmi2GetBoolean": lambda: raw(fmu, name, [c_void_p, c_void_p, c_size_t, c_void_p], c, boolean_vr, 1, flag),
            "fmi2GetString": lambda: raw(fmu, name, [c_void_p, c_void_p, c_size_t, c_void_p], c, vr, 0, buffer),
            "fmi2SetReal": lambda: raw(fmu, name, [c_void_p, c_void_p, c_size_t, c_void_p], c, vr, 1, real),
            "fmi2SetInteger": lambda: raw(fmu, name, [c_void_p, c_void_p, c_size_t, c_void_p], c, vr, 0, integer),
            "fmi2SetBoolean": lambda: raw(fmu, name, [c_void_p, c_void_p, c_size_t, c_void_p], c, boolean_vr, 1, flag),
            "fmi2SetString": lambda: raw(fmu, name, [c_void_p, c_void_p, c_size_t, c_void_p], c, vr, 0, buffer),
            "fmi2GetFMUstate": lambda: raw(fmu, name, [c_void_p, POINTER(c_void_p)], c, ctypes.byref(c_void_p())),
            "fmi2DoStep": lambda: raw(fmu, name, [c_void_p, c_double, c_double, c_int], c, fmu.t, 0.1, 1),
            "fmi2GetStatus": lambda: raw(fmu, name, [c_void_p, c_int, c_void_p], c, 0, integer),
            "fmi2GetRealStatus": lambda: raw(fmu, name, [c_void_p, c_int, c_void_p], c, 2, real),
            "fmi2GetIntegerStatus": lambda: raw(fmu, name, [c_void_p, c_int, c_void_p], c, 0, integer),
            "fmi2GetBooleanStatus": lambda: raw(fmu, name, [c_void_p, c_int, c_void_p], c, 4, flag),
            "fmi2GetStringStatus": lambda: raw(fmu, name, [c_void_p, c_int, c_void_p], c, 1, buffer),
        }
    else:
        # the Clock of the binary (declared by the Scheduled Execution FMU alone): refused in CS and ME
        clock = (c_uint * 1)(clock_vr("RateLimiter"))
        calls = {
            "fmi3SetDebugLogging": lambda: raw(fmu, name, [c_void_p, c_bool, c_size_t, c_void_p], c, True, 0, None),
            "fmi3EnterInitializationMode": lambda: raw(
                fmu, name, [c_void_p, c_bool, c_double, c_double, c_bool, c_double], c, False, 0.0, 0.0, False, 0.0
            ),
            "fmi3ExitInitializationMode": lambda: raw(fmu, name, [c_void_p], c),
            "fmi3Terminate": lambda: raw(fmu, name, [c_void_p], c),
            "fmi3Reset": lambda: raw(fmu, name, [c_void_p], c),
            "fmi3GetFloat64": lambda: raw(
                fmu, name, [c_void_p, c_void_p, c_size_t, c_void_p, c_size_t], c, out, 1, real, 1
            ),
            "fmi3GetInt32": lambda: raw(
                fmu, name, [c_void_p, c_void_p, c_size_t, c_void_p, c_size_t], c, integer_vr, 1, integer, 1
            ),
            "fmi3GetInt64": lambda: raw(
                fmu,
                name,
                [c_void_p, c_void_p, c_size_t, c_void_p, c_size_t],
                c,
                (c_uint * 1)(fmu.vr("zeroRate")),
                1,
                int64,
                1,
            ),
            "fmi3GetBoolean": lambda: raw(
                fmu, name, [c_void_p, c_void_p, c_size_t, c_void_p, c_size_t], c, boolean_vr, 1, flag, 1
            ),
            "fmi3SetFloat64": lambda: raw(
                fmu, name, [c_void_p, c_void_p, c_size_t, c_void_p, c_size_t], c, vr, 1, real, 1
            ),
            "fmi3SetInt64": lambda: raw(
                fmu,
                name,
                [c_void_p, c_void_p, c_size_t, c_void_p, c_size_t],
                c,
                (c_uint * 1)(fmu.vr("zeroRate")),
                1,
                (ctypes.c_int64 * 1)(1),
                1,
            ),
            "fmi3SetBoolean": lambda: raw(
                fmu, name, [c_void_p, c_void_p, c_size_t, c_void_p, c_size_t], c, boolean_vr, 1, flag, 1
            ),
            "fmi3GetFMUState": lambda: raw(fmu, name, [c_void_p, POINTER(c_void_p)], c, ctypes.byref(c_void_p())),
            # the Clock of Scheduled Execution
            "fmi3ActivateModelPartition": lambda: raw(
                fmu, name, [c_void_p, c_uint, c_double], c, clock[0], fmu.t + 0.1
            ),
            "fmi3GetIntervalDecimal": lambda: raw(
                fmu, name, [c_void_p, c_void_p, c_size_t, c_void_p, c_void_p], c, clock, 1, real, integer
            ),
            "fmi3GetShiftDecimal": lambda: raw(fmu, name, [c_void_p, c_void_p, c_size_t, c_void_p], c, clock, 1, real),
            "fmi3DoStep": lambda: raw(
                fmu,
                name,
                [c_void_p, c_double, c_double, c_bool] + [c_void_p] * 4,
                c,
                fmu.t,
                0.1,
                True,
                flag,
                flag,
                flag,
                real,
            ),
            "fmi3GetBinary": lambda: raw(
                fmu, name, [c_void_p, c_void_p, c_size_t, c_void_p, c_void_p, c_size_t], c, vr, 0, buffer, buffer, 0
            ),
            "fmi3SetBinary": lambda: raw(
                fmu, name, [c_void_p, c_void_p, c_size_t, c_void_p, c_void_p, c_size_t], c, vr, 0, buffer, buffer, 0
            ),
        }
        for kind in ("Float32", "Int8", "UInt8", "Int16", "UInt16", "Int32", "UInt32", "UInt64", "String"):
            # no variables of these types (Int32: status is one, read above): none asked for
            for access in ("Get", "Set"):
                key = f"fmi3{access}{kind}"
                if key not in calls:
                    calls[key] = lambda k=key: raw(
                        fmu, k, [c_void_p, c_void_p, c_size_t, c_void_p, c_size_t], c, vr, 0, buffer, 0
                    )
    prefix = "fmi2" if v == 2 else "fmi3"
    calls[f"{prefix}SetFMUstate" if v == 2 else "fmi3SetFMUState"] = lambda: with_state(
        lambda: raw(fmu, f"{prefix}SetFMUstate" if v == 2 else "fmi3SetFMUState", [c_void_p, c_void_p], c, state)
    )
    free_name = "fmi2FreeFMUstate" if v == 2 else "fmi3FreeFMUState"
    calls[free_name] = lambda: raw(fmu, free_name, [c_void_p, POINTER(c_void_p)], c, ctypes.byref(c_void_p()))
    size_name = "fmi2SerializedFMUstateSize" if v == 2 else "fmi3SerializedFMUStateSize"
    calls[size_name] = lambda: with_state(
        lambda: raw(fmu, size_name, [c_void_p, c_void_p, POINTER(c_size_t)], c, state, ctypes.byref(size))
    )
    ser_name = "fmi2SerializeFMUstate" if v == 2 else "fmi3SerializeFMUState"
    calls[ser_name] = lambda: with_state(
        lambda: raw(fmu, ser_name, [c_void_p, c_void_p, c_void_p, c_size_t], c, state, buffer, 4096)
    )

    def deserialize():
        des_name = "fmi2DeSerializeFMUstate" if v == 2 else "fmi3DeserializeFMUState"

        def serialize_then_deserialize():
            assert raw(fmu, ser_name, [c_void_p, c_void_p, c_void_p, c_size_t], c, state, buffer, 4096) in (0, 3)
            helper = Instance(
                "RateLimiter", v, name="serializer", model_exchange=fmu.model_exchange, scheduled=fmu.scheduled
            )
            try:  # serialized by a healthy instance of the same FMU
                helper.start()
                h = helper.fmu.component
                assert (
                    raw(helper, size_name, [c_void_p, c_void_p, POINTER(c_size_t)], h, state, ctypes.byref(size)) == 0
                )
                assert (
                    raw(helper, ser_name, [c_void_p, c_void_p, c_void_p, c_size_t], h, state, buffer, size.value) == 0
                )
            finally:
                helper.release()
            return raw(
                fmu,
                des_name,
                [c_void_p, c_void_p, c_size_t, POINTER(c_void_p)],
                c,
                buffer,
                size.value,
                ctypes.byref(c_void_p()),
            )

        return with_state(serialize_then_deserialize)

    calls["fmi2DeSerializeFMUstate" if v == 2 else "fmi3DeserializeFMUState"] = deserialize
    if name in calls:
        return calls[name]()
    # a function of a capability this FMU lacks: every argument but the instance NULL or 0
    n = exported_functions(v)[name]
    return raw(fmu, name, [c_void_p] * n, c, *([None] * (n - 1)))


def enter(fmu, state):
    if fmu.model_exchange:
        return enter_model_exchange(fmu, state)
    if fmu.scheduled:
        return enter_scheduled_execution(fmu, state)
    if state in (N, S, T):
        if fmu.version == 2:
            fmu.fmu.setupExperiment(startTime=0.0)
            fmu.fmu.enterInitializationMode()
        else:
            fmu.fmu.enterInitializationMode(startTime=0.0)
    if state in (S, T):
        fmu.fmu.exitInitializationMode()
    if state == T:
        fmu.fmu.terminate()
    if state == E:
        fmu.start()
        assert call_status(fmu.fmu.doStep, fmu.t, 0.0) == 3  # h = 0: error


def enter_model_exchange(fmu, state):
    fmu.set(cycleTime=0.1)
    if state == N:
        fmu.enter_initialization()
    elif state != I:
        fmu.start()  # Event Mode
    if state == C:
        fmu.fmu.enterContinuousTimeMode()
    if state == T:
        fmu.fmu.terminate()
    if state == E:
        set_time = getattr(fmu.fmu.dll, f"fmi{fmu.version}SetTime")
        set_time.argtypes, set_time.restype = [c_void_p, c_double], c_int
        assert set_time(fmu.fmu.component, -1.0) == 3  # before the start: error


def enter_scheduled_execution(fmu, state):
    fmu.set(cycleTime=0.1)
    if state == N:
        fmu.enter_initialization()
    elif state != I:
        fmu.start()  # Clock Activation Mode
    if state == T:
        fmu.fmu.terminate()
    if state == E:
        assert fmu.raw_activate(-1.0) == 3  # before the start: error


# the states as the refusals name them (FMI 2's Error state: after a failed call)
STATE_TEXT = {
    **{(v, state): state for v in (2, 3) for state in STATES + ME_STATES + SE_STATES},
    (2, E): "Error (after a failed call)",
}

INTERFACE_STATES = {CS_: STATES, ME_: ME_STATES, SE_: SE_STATES}
INTERFACES = {2: (CS_, ME_), 3: (CS_, ME_, SE_)}
CASES = [
    (v, name, state, interface)
    for v in (2, 3)
    for interface in INTERFACES[v]
    for name in sorted(exported_functions(v))
    if name not in NOT_INSTANCE_CALLS
    for state in INTERFACE_STATES[interface]
]


def allowed_table(version, interface):
    return {
        (2, CS_): FMI2_ALLOWED,
        (3, CS_): FMI3_ALLOWED,
        (2, ME_): FMI2_ME_ALLOWED,
        (3, ME_): FMI3_ME_ALLOWED,
        (3, SE_): FMI3_SE_ALLOWED,
    }[version, interface]


@pytest.mark.parametrize("version", [2, 3])
def test_every_function_is_allowed_somewhere_or_unsupported_for_a_reason(version):
    """The tables above cover the whole API: each exported function is in the state table, refused as a
    capability this FMU lacks, or (fmi2CancelStep: nothing to cancel) allowed in no state."""
    tables = set().union(*(allowed_table(version, interface) for interface in INTERFACES[version]))
    rest = set(exported_functions(version)) - NOT_INSTANCE_CALLS - tables - set(UNSUPPORTED)
    assert rest == ({"fmi2CancelStep"} if version == 2 else set())
    assert not tables & set(UNSUPPORTED)


@pytest.mark.parametrize(
    "version,function,state,interface",
    CASES,
    ids=lambda x: {CS_: "CS", ME_: "ME", SE_: "SE"}.get(x) if x in (CS_, ME_, SE_) else None,
)
def test_every_function_in_every_state(version, function, state, interface):
    table = allowed_table(version, interface)
    allowed = table.get(function, set()) | {
        s for v, f, s in BEYOND_THE_TABLE if (v, f) == (version, function) and interface == ME_
    }
    owners = [
        other for other in INTERFACES[version] if other != interface and function in allowed_table(version, other)
    ]
    row = FMI3_AFTER_ERROR if version == 3 and state == E else state
    fmu = Instance("RateLimiter", version, model_exchange=interface == ME_, scheduled=interface == SE_)
    try:
        enter(fmu, state)
        before = len(fmu.errors())
        status = valid_call(fmu, function)
        new_errors = fmu.errors()[before:]
        if row in allowed:
            assert status in (0, 1, 2), (function, state, status, fmu.messages)  # OK, Warning or Discard
            assert not new_errors, (function, state, new_errors)
        else:
            assert status == 3, (function, state, status)
            assert len(new_errors) == 1, (function, state, fmu.messages)
            assert new_errors[0][2].startswith(f"{function}: "), new_errors  # it names the function first
            if function in UNSUPPORTED:  # a capability this FMU does not have: says which
                assert new_errors[0][2] == f"{function}: {UNSUPPORTED[function]}", new_errors
            elif function not in table and owners:  # another interface's: says so, or the state
                assert new_errors[0][2] in (
                    f"{function}: {other_interface_text(version, interface, owners[0])}",
                    f"{function}: not allowed in {STATE_TEXT[version, row]}",
                ), new_errors
            else:  # refused for the state: says which
                assert new_errors[0][2] == f"{function}: not allowed in {STATE_TEXT[version, row]}", new_errors
    finally:
        fmu.free()


@pytest.mark.parametrize("version", [2, 3])
def test_calls_after_an_error_are_refused_until_reset(version):
    fmu = Instance("RateLimiter", version)
    try:
        enter(fmu, E)
        assert call_status(fmu.fmu.doStep, fmu.t, 0.1) == 3
        assert call_status(fmu.set, u=1.0) == 3
        fmu.fmu.reset()
        fmu.start()
        fmu.set(u=1.0)
        fmu.step(0.1)
        assert fmu.get("y") == pytest.approx(0.1)
    finally:
        fmu.free()


@pytest.mark.parametrize("cycle_time", [0.0, 0.1])
def test_fmi3_a_step_reports_no_event_no_stop_no_early_return_and_its_end(cycle_time):
    """fmi3DoStep's outputs (FMI 3.0 section 4.2.3): this FMU has no events,
    never asks to stop and never returns early, so the three flags are
    false and lastSuccessfulTime is the end of the step; on the first step,
    a repeated step size (with cycleTime 0 the common step's fast path) and
    a new one. Then a step from a point that is not the FMU's time is
    refused, even one whose size is the FMU's time and whose point is the
    last step size."""
    fmu = Instance("RateLimiter", 3)
    try:
        fmu.start(rateUpPar=2.0, cycleTime=cycle_time)
        do_step = fmu.fmu.dll.fmi3DoStep
        do_step.argtypes, do_step.restype = [c_void_p, c_double, c_double, c_bool] + [c_void_p] * 4, c_int
        t = 0.0
        for h in (0.5, 0.5, 0.5, 0.25, 1.0):
            flags, when = (c_bool * 3)(True, True, True), c_double(-1.0)
            assert (
                do_step(
                    fmu.fmu.component,
                    t,
                    h,
                    True,
                    ctypes.byref(flags, 0),
                    ctypes.byref(flags, 1),
                    ctypes.byref(flags, 2),
                    ctypes.byref(when),
                )
                == 0
            )
            t += h
            assert list(flags) == [False, False, False] and when.value == t, (h, list(flags), when.value)
        assert (
            do_step(
                fmu.fmu.component,
                1.0,
                t,
                True,
                ctypes.byref(flags, 0),
                ctypes.byref(flags, 1),
                ctypes.byref(flags, 2),
                ctypes.byref(when),
            )
            == 3
        )
        assert "currentCommunicationPoint" in fmu.errors()[-1][2] and fmu.get("time") == t
    finally:
        fmu.free()
