"""fmi.md, FMI behaviour: every misuse gets an error status and one log message
naming the function; the instance keeps its last good state, refuses
further calls until recovered (FMU state or reset), then runs on."""

import ctypes
import math

import pytest
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave

from support.fmu_driver import STATE_FUNCTIONS, Instance, call_status, state_api, unzipped


def set_raw(fmu, vr, value, kind="Real"):
    f = fmu.fmu
    if fmu.version == 2:
        setter = {"Real": f.setReal, "Integer": f.setInteger, "Boolean": f.setBoolean}[kind]
    else:
        setter = {"Real": f.setFloat64, "Integer": f.setInt64, "Boolean": f.setBoolean}[kind]
    return call_status(setter, [vr], [value])


def get_raw(fmu, vr, kind):
    f = fmu.fmu
    names = {
        2: {"Real": "getReal", "Integer": "getInteger", "Boolean": "getBoolean"},
        3: {"Real": "getFloat64", "Integer": "getInt32", "Boolean": "getBoolean"},
    }
    getter = getattr(f, names[fmu.version][kind])
    return call_status(getter, [vr])


def null_arrays(fmu):
    f = fmu.fmu
    if fmu.version == 2:
        return call_status(f.fmi2SetReal, f.component, None, 1, None)
    return call_status(f.fmi3SetFloat64, f.component, None, 1, None, 1)


def foreign_state(fmu):
    junk = ctypes.create_string_buffer(256)
    return call_status(state_api(fmu)["set"], ctypes.cast(junk, ctypes.c_void_p))


def null_in_state_call(fmu, case):
    """An FMU-state function given NULL where a pointer belongs; every other argument good."""
    api = state_api(fmu)
    state = api["get"]()
    data = bytes(api["serialize"](state))
    size = ctypes.c_size_t()
    p, n = ctypes.c_void_p, ctypes.c_size_t
    calls = {
        "get": ("get", [p, p], (None,)),
        "set": ("set", [p, p], (None,)),
        "size of NULL": ("size", [p, p, p], (None, ctypes.byref(size))),
        "size pointer": ("size", [p, p, p], (state, None)),
        "byte array": ("serialize", [p, p, p, n], (state, None, len(data))),
        "deserialize": ("deserialize", [p, ctypes.c_char_p, n, p], (data, len(data), None)),
    }
    which, argtypes, args = calls[case]
    function = getattr(fmu.fmu.dll, STATE_FUNCTIONS[fmu.version][which])
    function.argtypes, function.restype = argtypes, ctypes.c_int
    status = function(fmu.fmu.component, *args)
    api["free"](state)
    return status


# name: (misuse, words the log message must contain)
MISUSES = {
    "step size zero": (
        lambda f: call_status(f.fmu.doStep, f.t, 0.0),
        "DoStep: communicationStepSize must be finite and > 0, not 0",
    ),
    "step size negative": (
        lambda f: call_status(f.fmu.doStep, f.t, -0.5),
        "DoStep: communicationStepSize must be finite and > 0, not -0.5",
    ),
    "step size NaN": (
        lambda f: call_status(f.fmu.doStep, f.t, math.nan),
        "DoStep: communicationStepSize must be finite and > 0, not nan",
    ),
    "step size infinite": (
        lambda f: call_status(f.fmu.doStep, f.t, math.inf),
        "DoStep: communicationStepSize must be finite and > 0, not inf",
    ),
    "communication point not the FMU's time": (
        lambda f: call_status(f.fmu.doStep, f.t + 0.1, 0.5),
        "currentCommunicationPoint",
    ),
    "communication point NaN": (lambda f: call_status(f.fmu.doStep, math.nan, 0.5), "currentCommunicationPoint"),
    "unknown value reference": (lambda f: set_raw(f, 999, 1.0), "unknown value reference 999"),
    "wrong type (get)": (lambda f: get_raw(f, f.vr("y"), "Integer"), "Real variable"),
    "wrong type (set)": (lambda f: set_raw(f, f.vr("u"), True, "Boolean"), "Real variable"),
    "setting an output": (lambda f: set_raw(f, f.vr("y"), 1.0), "output"),
    "fixed parameter after initialisation": (
        lambda f: set_raw(f, f.vr("cycleTime"), 0.1),
        ": cycleTime is a fixed parameter and cannot be set after initialization",
    ),
    # the ZeroRate items are hold = 1 and noLimit = 2
    "enumeration out of range": (
        lambda f: set_raw(f, f.vr("zeroRate"), 7, "Integer"),
        ": zeroRate = 7 is outside its range [1, 2]",
    ),
    "null arrays": (null_arrays, "NULL"),
    "call in the wrong state": (lambda f: call_status(f.fmu.exitInitializationMode), "not allowed in Step Mode"),
    "foreign FMU state": (foreign_state, "not an FMU state"),
    "FMU state pointer NULL (get)": (lambda f: null_in_state_call(f, "get"), ": the FMU state pointer is NULL"),
    "FMU state pointer NULL (deserialize)": (
        lambda f: null_in_state_call(f, "deserialize"),
        ": the FMU state pointer is NULL",
    ),
    "FMU state NULL (set)": (lambda f: null_in_state_call(f, "set"), ": the FMU state is NULL"),
    "FMU state NULL (serialized size)": (lambda f: null_in_state_call(f, "size of NULL"), ": the FMU state is NULL"),
    "size pointer NULL": (lambda f: null_in_state_call(f, "size pointer"), ": the size pointer is NULL"),
    "byte array NULL": (lambda f: null_in_state_call(f, "byte array"), ": the byte array is NULL"),
}


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("misuse", sorted(MISUSES))
def test_misuse_is_an_error_and_the_instance_recovers(version, misuse):
    fmu = Instance("RateLimiter", version)
    fmu.start(rateUpPar=2.0)
    fmu.set(u=5.0)
    fmu.step(0.5)  # y = 1
    api = state_api(fmu)
    good, t = api["get"](), fmu.t
    action, words = MISUSES[misuse]

    assert action(fmu) == 3
    errors = fmu.errors()
    assert len(errors) == 1, errors
    assert words in errors[0][2] and f"fmi{version}" in errors[0][2], errors[0]

    # FMI 2's Error state, FMI 3's Terminated: no further stepping until
    # recovered; both allow reading the last good values
    assert call_status(fmu.step, 0.5) == 3
    assert f"not allowed in {'Error' if version == 2 else 'Terminated'}" in fmu.errors()[-1][2]
    assert fmu.get("y") == 1.0 and fmu.get("cycleTime") == 0.0 and fmu.get("zeroRate") == 1
    fmu.restore(good, t)
    fmu.step(0.5)
    assert fmu.get("y") == 2.0
    api["free"](good)
    fmu.free()


def assert_runs_again_after_reset(fmu):
    """Reset, start anew and ramp: 4 per s for 0.5 s."""
    fmu.fmu.reset()
    fmu.start(rateUpPar=4.0)
    fmu.set(u=5.0)
    fmu.step(0.5)
    assert fmu.get("y") == 2.0


@pytest.mark.parametrize("version", [2, 3])
def test_reset_recovers_from_error(version):
    fmu = Instance("RateLimiter", version)
    fmu.start(rateUpPar=2.0)
    assert call_status(fmu.fmu.doStep, 0.0, -1.0) == 3
    assert_runs_again_after_reset(fmu)
    fmu.free()


@pytest.mark.parametrize("version", [2, 3])
def test_reset_is_as_good_as_a_new_instance(version):
    """After fmi*Reset the instance is as after instantiation, whatever ran
    before: FMI 2 without fmi2SetupExperiment starts at time 0 (the default
    start time), and a valid configuration logs no status line (no status
    was reported in the new run)."""
    fmu = Instance("RateLimiter", version)
    fmu.start(start_time=1.0, rateUpPar=-1.0)
    fmu.step(0.5)
    assert [m[2] for m in fmu.messages if "status" in m[2]] == [
        "status 16#8200: a rate is negative (rateUpPar = -1); the output holds"
    ]
    fmu.fmu.reset()
    fmu.messages.clear()
    if version == 2:
        fmu.fmu.enterInitializationMode()
    else:
        fmu.fmu.enterInitializationMode(startTime=0.0)
    fmu.fmu.exitInitializationMode()
    fmu.t = 0.0
    fmu.set(u=1.0)
    fmu.step(0.5)
    assert fmu.get("y") == 0.5 and fmu.get("time") == 0.5
    assert fmu.messages == []
    fmu.free()


@pytest.mark.parametrize("version", [2, 3])
def test_nan_values_in_a_set_of_several_are_all_or_nothing(version):
    fmu = Instance("RateLimiter", version)
    fmu.start()
    f = fmu.fmu
    setter = f.setReal if version == 2 else f.setFloat64
    assert call_status(setter, [fmu.vr("rateUpPar"), 999], [5.0, 1.0]) == 3
    if version == 2:
        assert fmu.get("rateUpPar") == 1.0  # the valid first value was not applied either
    fmu.free()


@pytest.mark.parametrize("version", [2, 3])
def test_status_change_is_a_warning_logged_once(version):
    """A block status is the PLC's business, not an FMI error: every call
    returns OK (an importer that stops on any other status, as OMSimulator
    does, runs on) and the step that sees the change logs one message of
    status Warning in logStatusWarning."""
    fmu = Instance("RateLimiter", version)
    fmu.start()
    fmu.set(rateUpPar=-1.0)
    assert [fmu.raw_step(0.5) for _ in range(3)] == [0, 0, 0]
    warnings = [m for m in fmu.messages if m[0] == 1]
    assert len(warnings) == 1 and "16#8200" in warnings[0][2] and "rateUpPar" in warnings[0][2]
    assert warnings[0][1] == "logStatusWarning"
    assert fmu.get("status") == 0x8200 and fmu.get("error") is True
    fmu.set(rateUpPar=1.0)
    fmu.step(0.5)
    assert fmu.get("status") == 0 and len([m for m in fmu.messages if m[0] == 1]) == 1
    fmu.free()


def test_wrong_guid_is_refused_with_a_message():
    unzipdir = unzipped("RateLimiter", 2)
    messages = []
    fmu = FMU2Slave(
        guid="{00000000-0000-0000-0000-000000000000}",
        unzipDirectory=unzipdir,
        modelIdentifier="RateLimiter",
        instanceName="wrong",
    )
    from fmpy import calloc, free
    from fmpy.fmi2 import (
        fmi2CallbackAllocateMemoryTYPE,
        fmi2CallbackFreeMemoryTYPE,
        fmi2CallbackFunctions,
        fmi2CallbackLoggerTYPE,
    )

    callbacks = fmi2CallbackFunctions()
    callbacks.logger = fmi2CallbackLoggerTYPE(lambda e, n, s, c, m: messages.append(m.decode()))
    callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
    callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
    with pytest.raises(Exception, match="Failed to instantiate model"):  # fmpy's words for a NULL instance
        fmu.instantiate(callbacks=callbacks)
    assert messages and "GUID" in messages[0]
    fmu.freeLibrary()


@pytest.mark.parametrize("version", [2, 3])
def test_many_instances_are_independent(version):
    unzipdir = unzipped("RateLimiter", version)
    instances = [Instance("RateLimiter", version, name=f"i{k}", unzipdir=unzipdir) for k in range(50)]
    for k, fmu in enumerate(instances):
        fmu.start(rateUpPar=float(k + 1))
        fmu.set(u=1000.0)
    for fmu in instances:
        fmu.step(1.0)
    assert [fmu.get("y") for fmu in instances] == [float(k + 1) for k in range(50)]
    for fmu in instances:
        fmu.fmu.terminate()
        fmu.release()


def test_fmi3_error_leaves_terminated_with_values_states_and_reset():
    """FMI 3.0 section 2.3: "If any function called in super state FMU State
    Settable returns fmi3Error, the FMU enters state Terminated", where
    fmi3Get{VariableType} and the FMU-state functions are allowed."""
    fmu = Instance("RateLimiter", 3)
    fmu.start(rateUpPar=2.0)
    fmu.set(u=5.0)
    fmu.step(0.5)  # y = 1, ramping
    last_good = {n: fmu.get(n) for n in ("y", "rampActive", "runningTime", "status", "time")}
    assert call_status(fmu.fmu.doStep, fmu.t, -1.0) == 3
    assert {n: fmu.get(n) for n in last_good} == last_good
    api = state_api(fmu)
    state = api["get"]()  # allowed in Terminated
    data = bytes(api["serialize"](state))
    assert data[:4] == b"RLFS"
    assert call_status(fmu.fmu.doStep, fmu.t, 0.5) == 3
    assert "fmi3DoStep: not allowed in Terminated" in fmu.errors()[-1][2]
    api["free"](state)
    assert_runs_again_after_reset(fmu)
    fmu.free()


@pytest.mark.parametrize("version", [2, 3])
def test_communication_point_within_a_relative_1e_9_of_the_time(version):
    """Whatever the step size: a huge h does not widen the tolerance."""
    fmu = Instance("RateLimiter", version)
    fmu.start(rateUpPar=1.0)
    fmu.set(u=1e15)
    fmu.step(0.1)  # the FMU's time is 0.1
    assert call_status(fmu.fmu.doStep, 1000.0, 1e12) == 3
    assert "currentCommunicationPoint 1000 is not the FMU's time 0.10000000000000001" in fmu.errors()[-1][2]
    fmu.fmu.reset()
    fmu.start(rateUpPar=1.0)
    fmu.set(u=1e15)
    fmu.step(0.1)
    inside = 0.1 * (1 + 0.9e-9)  # the step runs from there
    assert fmu.raw_step_at(inside, 0.1) == 0
    assert fmu.get("time") == inside + 0.1
    outside = fmu.get("time") * (1 + 1.1e-9)
    assert fmu.raw_step_at(outside, 0.1) == 3
    assert "is not the FMU's time" in fmu.errors()[-1][2]
    # relative to the FMU's time, not to the communication point: a start
    # time and a point just beyond 1e-9 of it, though within 1e-9 of itself
    start, t = next((s, t) for s in (1 + i / 1024 for i in range(4096)) if (t := just_outside(s)))
    fmu.fmu.reset()
    fmu.start(start_time=start)
    assert fmu.raw_step_at(t, 0.1) == 3
    assert f"currentCommunicationPoint {t:.17g} is not the FMU's time {start:.17g}" in fmu.errors()[-1][2]
    fmu.free()


@pytest.mark.parametrize("version", [2, 3])
def test_the_common_step_judges_the_communication_point_alike(version):
    """Steps of 1e-12 s with nothing changed but u take the common step; a
    point 5e-10 s from the FMU's time (2e-12) is far beyond a relative 1e-9
    of it there too."""
    fmu = Instance("RateLimiter", version)
    fmu.start()
    fmu.set(u=1.0)
    fmu.step(1e-12)
    fmu.step(1e-12)
    assert fmu.raw_step_at(fmu.t + 5e-10, 1e-12) == 3
    assert "is not the FMU's time" in fmu.errors()[-1][2]
    # before time 0 times must match exactly: a point 0.05 s off is refused
    fmu.fmu.reset()
    fmu.start(start_time=-1.0)
    fmu.set(u=1.0)
    fmu.step(0.1)
    fmu.step(0.1)
    assert fmu.raw_step_at(fmu.t + 0.05, 0.1) == 3
    assert "is not the FMU's time" in fmu.errors()[-1][2]
    fmu.free()


def just_outside(time):
    """A point more than a relative 1e-9 from time but within 1e-9 of itself (the doubles near the edge,
    checked as the FMU does), or None."""
    ulp = math.ulp(time)
    edge = math.floor(1e-9 * time / ulp)
    for k in range(edge - 2, edge + 3):
        t = time + k * ulp
        if abs(t - time) > 1e-9 * abs(time) and abs(t - time) <= 1e-9 * abs(t):
            return t
    return None


@pytest.mark.parametrize("version", [2, 3])
def test_status_messages_say_what_the_status_means(version):
    fmu = Instance("RateLimiter", version)
    fmu.start()
    for settings, code, text in (
        ({"rateUpPar": -1.0}, "16#8200", "a rate is negative (rateUpPar = -1)"),
        ({"rateUpPar": 1.0, "yMin": 3.0, "yMax": 2.0}, "16#8204", "yMin is above yMax (yMin = 3)"),
        ({"yMin": math.nan, "ratePeriod": -1.0}, "16#8202", "ratePeriod is negative or not finite (ratePeriod = -1)"),
    ):
        fmu.set(**settings)
        fmu.step(0.5)
        warning = [m for m in fmu.messages if m[0] == 1][-1]
        assert warning[1] == "logStatusWarning"
        assert warning[2] == f"status {code}: {text}; the output holds", warning
    fmu.set(ratePeriod=1.0, yMax=math.nan)
    fmu.step(0.5)  # cleared: an event, not a warning
    assert fmu.messages[-1][1:] == ("logEvents", "status 16#0000: no error")
    fmu.free()


@pytest.mark.parametrize("version", [2, 3])
def test_wrong_type_messages_name_the_types(version):
    """Each of the four types, with its article."""
    fmu = Instance("RateLimiter", version)
    fmu.start()
    get_integer = "fmi2GetInteger" if version == 2 else "fmi3GetInt32"
    get_real = "fmi2GetReal" if version == 2 else "fmi3GetFloat64"
    set_boolean = "fmi2SetBoolean" if version == 2 else "fmi3SetBoolean"
    for call, message in (
        (
            lambda: get_raw(fmu, fmu.vr("y"), "Integer"),
            f"y (value reference 17) is a Real variable, which {get_integer} cannot access",
        ),
        (
            lambda: set_raw(fmu, fmu.vr("zeroRate"), True, "Boolean"),
            f"zeroRate (value reference 12) is an Enumeration variable, which {set_boolean} cannot access",
        ),
        (
            lambda: get_raw(fmu, fmu.vr("status"), "Real"),
            f"status (value reference {fmu.vr('status')}) is an Integer variable, which {get_real} cannot access",
        ),
        (
            lambda: get_raw(fmu, fmu.vr("bypass"), "Real"),
            f"bypass (value reference {fmu.vr('bypass')}) is a Boolean variable, which {get_real} cannot access",
        ),
    ):
        assert call() == 3, message
        assert fmu.errors()[-1][2].endswith(": " + message), fmu.errors()[-1]
        fmu.fmu.reset()
        fmu.start()
    fmu.free()


def logged_categories(version, logging_on, categories):
    """The categories of what an instance logs after SetDebugLogging: a
    status warning, the status cleared (an event) and a failed call."""
    fmu = Instance("RateLimiter", version, logging=logging_on)
    fmu.fmu.setDebugLogging(logging_on, categories)
    fmu.start(rateUpPar=-1.0)
    fmu.raw_step(0.5)
    fmu.set(rateUpPar=1.0)
    fmu.raw_step(0.5)
    call_status(fmu.fmu.doStep, fmu.t, -1.0)
    seen = sorted({m[1] for m in fmu.messages})
    fmu.free()
    return seen


@pytest.mark.parametrize("version", [2, 3])
def test_debug_logging_categories_choose_what_is_logged(version):
    every = ["logEvents", "logStatusError", "logStatusWarning"]
    assert logged_categories(version, True, []) == every
    assert logged_categories(version, True, ["logEvents"]) == (
        ["logEvents", "logStatusError", "logStatusWarning"] if version == 2 else ["logEvents"]
    )
    assert logged_categories(version, True, ["logStatusWarning", "logStatusError"]) == [
        "logStatusError",
        "logStatusWarning",
    ]
    # FMI 2 always says why a call failed and warns; FMI 3 follows loggingOn
    assert logged_categories(version, False, []) == (["logStatusError", "logStatusWarning"] if version == 2 else [])
    fmu = Instance("RateLimiter", version)
    with pytest.raises(FMICallException):
        fmu.fmu.setDebugLogging(True, ["logNoSuchCategory"])
    assert 'unknown log category "logNoSuchCategory"' in fmu.errors()[-1][2]
    fmu.free()


def me_update(fmu):
    """The event update of either version: (nextEventTimeDefined, nextEventTime)."""
    result = fmu.fmu.newDiscreteStates() if fmu.version == 2 else fmu.fmu.updateDiscreteStates()
    return result[4], result[5]


def me_raw(fmu, name, argtypes, *args):
    function = getattr(fmu.fmu.dll, f"fmi{fmu.version}{name}")
    function.argtypes, function.restype = [ctypes.c_void_p] + argtypes, ctypes.c_int
    return function(fmu.fmu.component, *args)


def cs_state_into(fmu):
    """An FMU state of a Co-Simulation instance of the same FMU set into this Model Exchange one."""
    other = Instance("RateLimiter", fmu.version, name="co-simulation")
    try:
        other.start()
        state = state_api(other)["get"]()
        return call_status(state_api(fmu)["set"], state)
    finally:
        other.release()


# Model Exchange, in Continuous-Time Mode after the event at 0.5 s: name: (misuse, words of the message)
ME_MISUSES = {
    "time before the last event": (
        lambda f: me_raw(f, "SetTime", [ctypes.c_double], 0.25),
        "SetTime: time 0.25 is not finite or before the last event at 0.5",
    ),
    "time NaN": (lambda f: me_raw(f, "SetTime", [ctypes.c_double], math.nan), "SetTime: time nan is not finite"),
    **{
        f"{function} with n = {n}": (
            lambda f, function=function, n=n: me_raw(
                f,
                function if f.version == 3 or function != "GetContinuousStateDerivatives" else "GetDerivatives",
                [ctypes.c_void_p, ctypes.c_size_t],
                (ctypes.c_double * n)(),
                n,
            ),
            f"this FMU has no {what}; n = {n}, not 0",
        )
        for function, what, n in (
            ("SetContinuousStates", "continuous states", 1),
            ("GetContinuousStates", "continuous states", 1),
            ("GetContinuousStateDerivatives", "continuous states", 2),
            ("GetNominalsOfContinuousStates", "continuous states", 3),
            ("GetEventIndicators", "event indicators", 2),
        )
    },
    "event update in Continuous-Time Mode": (
        lambda f: me_raw(
            f,
            "NewDiscreteStates" if f.version == 2 else "UpdateDiscreteStates",
            [ctypes.c_void_p] * (1 if f.version == 2 else 6),
            *([None] * (1 if f.version == 2 else 6)),
        ),
        "DiscreteStates: not allowed in Continuous-Time Mode",
    ),
    "a Co-Simulation step": (
        lambda f: me_raw(
            f,
            "DoStep",
            [ctypes.c_double, ctypes.c_double]
            + ([ctypes.c_int] if f.version == 2 else [ctypes.c_bool] + [ctypes.c_void_p] * 4),
            0.5,
            0.5,
            1,
            *([] if f.version == 2 else [None] * 4),
        ),
        "DoStep: not allowed in Continuous-Time Mode",
    ),
    "fixed parameter after initialisation": (
        lambda f: set_raw(f, f.vr("cycleTime"), 0.1),
        ": cycleTime is a fixed parameter and cannot be set after initialization",
    ),
    "a Co-Simulation instance's FMU state": (
        cs_state_into,
        "an FMU state of Step Mode, which this Model Exchange instance cannot be in",
    ),
}


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("misuse", sorted(ME_MISUSES))
def test_model_exchange_misuse_is_an_error_and_the_instance_recovers(version, misuse):
    """The same in Model Exchange (fmi.md, Model Exchange): cycles of 0.5 s, 2 per s."""
    fmu = Instance("RateLimiter", version, model_exchange=True)
    fmu.start(cycleTime=0.5, rateUpPar=2.0)
    assert me_update(fmu) == (True, 0.5)
    fmu.set(u=5.0)
    fmu.fmu.enterContinuousTimeMode()
    fmu.fmu.setTime(0.5)
    fmu.fmu.enterEventMode()
    assert me_update(fmu) == (True, 1.0) and fmu.get("y") == 1.0
    fmu.fmu.enterContinuousTimeMode()
    api = state_api(fmu)
    good = api["get"]()
    action, words = ME_MISUSES[misuse]

    assert action(fmu) == 3
    errors = fmu.errors()
    assert len(errors) == 1, errors
    assert words in errors[0][2] and errors[0][2].startswith(f"fmi{version}"), errors[0]

    assert me_raw(fmu, "SetTime", [ctypes.c_double], 1.0) == 3
    assert f"not allowed in {'Error' if version == 2 else 'Terminated'}" in fmu.errors()[-1][2]
    assert fmu.get("y") == 1.0 and fmu.get("cycleTime") == 0.5
    api["set"](good)
    fmu.fmu.setTime(1.0)
    fmu.fmu.enterEventMode()
    assert me_update(fmu) == (True, 1.5) and fmu.get("y") == 2.0
    api["free"](good)
    fmu.free()
