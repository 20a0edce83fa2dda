"""Scheduled Execution (docs/fmi.md, Scheduled Execution): every model's
Scheduled Execution FMU (build/fmi3-se/, the FMI 3 binary with only that
interface declared) runs the PLC's cyclic interrupt (OB) as an input Clock,
one PLC cycle per activation. Driven by the scheduler of support.scheduled_execution,
written from the standard's text, and compared with Co-Simulation stepping
one cycle per step: the same outputs after each activation as after each
step, bit for bit, for every reference scenario in both LREAL and REAL. Then
what differs on purpose (a tick activated late or early runs its cycle at
the time it is given), the Clock's timing, the state machine with its
misuse, the preemption locks and FMU states."""

import ctypes
import math
import struct
import zipfile
from ctypes import POINTER, c_bool, c_double, c_size_t, c_uint32, c_void_p

import pytest

from support.fmu_driver import fmu_file
from support.importers import input_values
from support.scenarios import discover
from support.scheduled_execution import CHANGED, ERROR, OK, UNCHANGED, WARNING, Fmi3, Scheduler, library

SCENARIOS = discover()
# a scenario of more ticks than this runs in the slow lane (a recording of hours at 10 ms)
FAST_TICKS = 20000


def clock_of(fmu):
    (clock,) = fmu.clocks
    return clock.valueReference


def plc_cycle(scenario):
    """The scenario's PLC cycle: its cycleTime, or where that is 0 (one
    cycle per step) its step size, which Co-Simulation's step stands for."""
    cycle = float(dict(scenario.start_values).get("cycleTime", 0.0))
    return scenario.options["StepSize"] if cycle == 0 else cycle


def arithmetic_types(model):
    """LREAL and REAL where the model has the parameter arithmetic, else its own."""
    _, md, _ = library(model)
    return [1, 2] if any(v.name == "arithmetic" for v in md.modelVariables) else [None]


CASES = [
    pytest.param(
        scenario,
        arithmetic,
        id=f"{scenario.name}-{ {None: 'own', 1: 'LREAL', 2: 'REAL'}[arithmetic] }",
        marks=[pytest.mark.slow]
        if (scenario.options["StopTime"] - scenario.options["StartTime"]) / plc_cycle(scenario) > FAST_TICKS
        else [],
    )
    for scenario in SCENARIOS
    if plc_cycle(scenario) > 0
    for arithmetic in arithmetic_types(scenario.model)
]


def differences(se, cs, names, t):
    """Each output that differs, bit for bit, as a line."""
    return [
        f"{name} at {t!r}: Scheduled Execution {se.get(name)!r}, Co-Simulation {cs.get(name)!r}"
        for name in names
        if struct.pack("d", float(se.get(name))) != struct.pack("d", float(cs.get(name)))
    ]


@pytest.mark.parametrize("scenario,arithmetic", CASES)
def test_every_activation_gives_co_simulations_outputs(scenario, arithmetic):
    """The scenario's inputs, held over each cycle, through both interfaces
    of the same FMU: Co-Simulation steps one PLC cycle per doStep from each
    tick to the next, the scheduler activates the Clock at each tick; every
    output after each activation is the step's, bit for bit. The scenarios
    of a million cycles (10 ms over hours) run in the slow lane."""
    o = scenario.options
    start = dict(scenario.start_values)
    start["cycleTime"] = plc_cycle(scenario)
    if arithmetic is not None:
        start["arithmetic"] = arithmetic
    se = Fmi3(scenario.model, "ScheduledExecution")
    cs = Fmi3(scenario.model, "CoSimulation", name="co-simulation")
    try:
        t0 = o["StartTime"]
        for fmu in (se, cs):
            for name, value in {**start, **input_values(scenario, t0)}.items():
                assert fmu.set(name, value) == OK, fmu.messages
        scheduler = Scheduler(se)
        assert scheduler.initialize(t0) == OK, se.messages
        assert cs.enter_initialization(t0) == OK and cs.exit_initialization() == OK, cs.messages
        interval, shift = scheduler.timing[clock_of(se)]
        assert interval == shift == start["cycleTime"]
        outputs = [v.name for v in se.md.modelVariables if v.causality == "output"]
        # every output and the time, one call per type (a run of a million cycles takes a minute)
        read_se, read_cs = se.reader(outputs + ["time"]), cs.reader(outputs + ["time"])
        assert read_se() == read_cs(), differences(se, cs, outputs, t0)
        previous, ticks, held = [t0], [], {}

        def before(t):
            for name, value in input_values(scenario, previous[0]).items():
                if held.get(name) != value:  # a held input is set once
                    assert se.set(name, value) == OK and cs.set(name, value) == OK
                    held[name] = value
            # one cycle: from the last tick to this one (t - previous is exact, so the step ends at t)
            assert cs.do_step(previous[0], t - previous[0]) in (OK, WARNING), cs.messages[-1:]

        def after(t):
            assert read_se() == read_cs(), differences(se, cs, outputs, t)
            previous[0] = t
            ticks.append(t)

        scheduler.run(o["StopTime"], before, after)
        assert len(ticks) == round((o["StopTime"] - t0) / interval)
        assert se.get("time") == cs.get("time") == ticks[-1]
        assert se.errors() == cs.errors() == []
    finally:
        se.free()
        cs.free()


def scheduled(model="RateLimiter", locks=True, **start):
    """An instance in Clock Activation Mode, started at 0 with these start values."""
    fmu = Fmi3(model, "ScheduledExecution", locks=locks)
    for name, value in start.items():
        assert fmu.set(name, value) == OK
    assert fmu.enter_initialization(0.0) == OK and fmu.exit_initialization() == OK, fmu.messages
    return fmu


def test_a_tick_late_or_early_runs_its_cycle_at_the_time_it_is_given():
    """Worked by hand from docs/rules.md, rule 3; and docs/rules.md, rule 6.
    cycleTime 0.5, initMode inputValueDelayed with initDelay 1 s, rateUpPar 1 per s: the
    cycles that end by 1 s pass u, later ones ramp 0.5 per cycle (the
    configured cycle, not the time since the last tick). On time, the tick
    of 1 s still passes u = 6; activated late at 1.2 s, the same cycle ends
    after the delay and ramps from 4 to 4.5, and the next, at its own 1.5 s
    after only 0.3 s, ramps a full 0.5 to 5; early at 0.9 s it passes u."""
    runs = {}
    for second_tick in (1.0, 1.2, 0.9):
        fmu = scheduled(cycleTime=0.5, initMode=3, initDelay=1.0, rateUpPar=1.0, u=4.0)
        try:
            clock, ys = clock_of(fmu), []
            for t, u in ((0.5, 4.0), (second_tick, 6.0), (1.5, 10.0)):
                assert fmu.set("u", u) == OK
                assert fmu.activate(clock, t) == OK, fmu.messages
                ys.append(fmu.get("y"))
                assert fmu.get("time") == t
            runs[second_tick] = ys
        finally:
            fmu.free()
    assert runs == {1.0: [4.0, 6.0, 6.5], 1.2: [4.0, 4.5, 5.0], 0.9: [4.0, 6.0, 6.5]}


def test_the_clock_interval_and_shift_are_cycle_time():
    """A fixed periodic Clock without intervalDecimal (2.2.9.3): interval
    and shift asked in Initialization Mode, qualified Changed when new and
    Unchanged after (2.2.9.6); in Clock Activation Mode Unchanged; a reset
    forgets what was reported."""
    fmu = Fmi3("RateLimiter")
    try:
        clock = clock_of(fmu)
        for _ in range(2):
            assert fmu.set("cycleTime", 0.1) == OK
            assert fmu.enter_initialization(0.0) == OK
            assert fmu.interval(clock) == (OK, 0.1, CHANGED)
            assert fmu.interval(clock) == (OK, 0.1, UNCHANGED)
            assert fmu.set("cycleTime", 0.02) == OK
            assert fmu.interval(clock) == (OK, 0.02, CHANGED)
            assert fmu.shift(clock) == (OK, 0.02)
            assert fmu.exit_initialization() == OK
            assert fmu.interval(clock) == (OK, 0.02, UNCHANGED)
            assert fmu.activate(clock, 0.02) == OK
            assert fmu.call("fmi3Reset", []) == OK
        assert fmu.errors() == []
    finally:
        fmu.free()


def test_the_model_description_declares_the_clock():
    """Every Scheduled Execution FMU: that interface alone (a Co-Simulation
    FMU with Clocks must have Event Mode, FMI 3.0 4.4), the binary of the
    FMI 3 Co-Simulation FMU, and one input Clock, periodic with a fixed
    interval given by the FMU (no intervalDecimal), the priority Scheduled
    Execution requires, a value reference no variable has."""
    for model in {s.model for s in SCENARIOS}:
        _, md, clocks = library(model)
        assert md.scheduledExecution is not None
        assert (md.coSimulation, md.modelExchange) == (None, None)
        assert md.scheduledExecution.modelIdentifier == model
        binary = f"binaries/x86_64-linux/{model}.so"
        with zipfile.ZipFile(fmu_file(model, 3)) as cs, zipfile.ZipFile(fmu_file(model, 3, scheduled=True)) as se:
            assert se.read(binary) == cs.read(binary)
        (clock,) = clocks
        assert (clock.name, clock.causality, clock.intervalVariability) == ("cyclicInterrupt", "input", "fixed")
        assert (clock.priority, clock.intervalDecimal) == (0, None)
        others = [v.valueReference for v in md.modelVariables if v.type != "Clock"]
        assert clock.valueReference not in others


@pytest.mark.parametrize("cycle_time", [0.0, -0.1])
def test_without_a_plc_cycle_the_clock_has_no_interval(cycle_time):
    """cycleTime 0 (Co-Simulation's one cycle per step) or invalid: the
    Clock has no interval to give, and says what to set; activated anyway,
    the block reports no valid cycle once, in Scheduled Execution's words,
    and holds its output."""
    fmu = Fmi3("RateLimiter")
    try:
        clock = clock_of(fmu)
        assert fmu.set("cycleTime", cycle_time) == OK
        assert fmu.enter_initialization(0.0) == OK
        assert fmu.interval(clock)[0] == ERROR
        assert fmu.errors() == [
            "fmi3GetIntervalDecimal: cyclicInterrupt has no interval: cycleTime is not a PLC cycle (finite, > 0); "
            "set it to the interval of the cyclic interrupt OB or task"
        ]
        assert fmu.call("fmi3Reset", []) == OK
        fmu.messages.clear()
        assert fmu.set("cycleTime", cycle_time) == OK and fmu.set("u", 5.0) == OK
        assert fmu.enter_initialization(0.0) == OK and fmu.exit_initialization() == OK
        assert fmu.set("u", 7.0) == OK
        for t in (0.1, 0.2):
            assert fmu.activate(clock, t) == OK
            assert (fmu.get("y"), fmu.get("error"), fmu.get("time")) == (5.0, True, t)
        warnings = [m for s, m in fmu.messages if s == WARNING]
        assert len(warnings) == 1 and "Scheduled Execution's clock ticks once per PLC cycle" in warnings[0]
    finally:
        fmu.free()


# ---- the state machine and its misuse -----------------------------------------


def raw(fmu, name, argtypes, *args):
    return fmu.call(name, argtypes, *args)


def vr_array(*vrs):
    return (c_uint32 * len(vrs))(*vrs)


# misuse in Clock Activation Mode, after one activation at 0.1: (call, the one error message)
MISUSES = {
    "time going backwards": (lambda f, c: f.activate(c, 0.05), "activationTime 0.050000000000000003 is not finite"),
    "the same time again": (lambda f, c: f.activate(c, 0.1), "activationTime 0.10000000000000001 is not finite"),
    "a NaN time": (lambda f, c: f.activate(c, math.nan), "activationTime nan is not finite"),
    "an unknown clock reference": (
        lambda f, c: f.activate(9999, 0.2),
        "unknown Clock reference 9999; the Clock is cyclicInterrupt",
    ),
    "a variable, not a clock": (
        lambda f, c: f.activate(f.variables["u"].valueReference, 0.2),
        "u (value reference 1) is not a Clock; the Clock is cyclicInterrupt",
    ),
    "a Co-Simulation step": (lambda f, c: f.do_step(0.1, 0.1), "fmi3DoStep: not allowed in Clock Activation Mode"),
    "a fixed parameter": (
        lambda f, c: f.set("cycleTime", 0.2),
        "cycleTime is a fixed parameter and cannot be set after initialization",
    ),
    "the shift after initialization": (
        lambda f, c: f.shift(c)[0],
        "fmi3GetShiftDecimal: not allowed in Clock Activation Mode",
    ),
    "the interval of a variable": (
        lambda f, c: raw(
            f,
            "fmi3GetIntervalDecimal",
            [POINTER(c_uint32), c_size_t, c_void_p, c_void_p],
            vr_array(f.variables["y"].valueReference),
            1,
            ctypes.byref(c_double()),
            ctypes.byref(ctypes.c_int()),
        ),
        "y (value reference 17) is not a Clock",
    ),
    "an interval set": (
        lambda f, c: raw(
            f, "fmi3SetIntervalDecimal", [POINTER(c_uint32), c_size_t, c_void_p], vr_array(c), 1, (c_double * 1)(0.2)
        ),
        "the Clock's interval and shift are cycleTime's",
    ),
    "a fraction": (
        lambda f, c: raw(
            f,
            "fmi3GetIntervalFraction",
            [POINTER(c_uint32), c_size_t, c_void_p, c_void_p, c_void_p],
            vr_array(c),
            1,
            (ctypes.c_uint64 * 1)(),
            (ctypes.c_uint64 * 1)(),
            (ctypes.c_int * 1)(),
        ),
        "supportsFraction = false",
    ),
    "an input clock read": (
        lambda f, c: raw(f, "fmi3GetClock", [POINTER(c_uint32), c_size_t, c_void_p], vr_array(c), 1, (c_bool * 1)()),
        "fmi3GetClock reads output Clocks",
    ),
    "a clock set": (
        lambda f, c: raw(f, "fmi3SetClock", [POINTER(c_uint32), c_size_t, c_void_p], vr_array(c), 1, (c_bool * 1)(1)),
        "the Clock ticks in Scheduled Execution only (fmi3ActivateModelPartition)",
    ),
    "a Model Exchange function": (
        lambda f, c: raw(f, "fmi3EnterEventMode", []),
        "fmi3EnterEventMode: not allowed in Clock Activation Mode",
    ),
}


@pytest.mark.parametrize("misuse", MISUSES)
def test_misuse_is_an_error_and_the_instance_recovers(misuse):
    """One error status and one log message naming the function and why;
    the instance is Terminated (FMI 3 has no Error state: 2.3), where the
    values can still be read and activations are refused; a reset and a
    new initialization run it again as new."""
    call, message = MISUSES[misuse]
    fmu = scheduled(cycleTime=0.1, u=1.0)
    try:
        clock = clock_of(fmu)
        assert fmu.activate(clock, 0.1) == OK
        y = fmu.get("y")
        assert call(fmu, clock) == ERROR
        (error,) = fmu.errors()
        assert message in error and error.startswith("fmi3"), error
        assert fmu.get("y") == y
        assert fmu.activate(clock, 0.2) == ERROR
        assert fmu.errors()[-1] == "fmi3ActivateModelPartition: not allowed in Terminated"
        assert fmu.call("fmi3Reset", []) == OK
        assert fmu.set("cycleTime", 0.1) == OK and fmu.set("u", 1.0) == OK
        assert fmu.enter_initialization(0.0) == OK and fmu.exit_initialization() == OK
        assert fmu.activate(clock, 0.1) == OK and fmu.get("y") == y
    finally:
        fmu.free()


@pytest.mark.parametrize("state", ["Instantiated", "Initialization Mode", "Terminated"])
def test_an_activation_out_of_clock_activation_mode_is_refused(state):
    fmu = Fmi3("RateLimiter")
    try:
        assert fmu.set("cycleTime", 0.1) == OK
        if state != "Instantiated":
            assert fmu.enter_initialization(0.0) == OK
        if state == "Terminated":
            assert fmu.exit_initialization() == OK and fmu.call("fmi3Terminate", []) == OK
        assert fmu.activate(clock_of(fmu), 0.1) == ERROR
        assert fmu.errors() == [f"fmi3ActivateModelPartition: not allowed in {state}"]
    finally:
        fmu.free()


def test_the_functions_of_other_interfaces_say_so():
    """Instantiated (where the state allows them): a Model Exchange function
    refuses a Scheduled Execution instance, and the Clock's functions a
    Co-Simulation one."""
    se, cs = Fmi3("RateLimiter"), Fmi3("RateLimiter", "CoSimulation", name="cs")
    try:
        n = c_size_t()
        assert raw(se, "fmi3GetNumberOfContinuousStates", [POINTER(c_size_t)], ctypes.byref(n)) == ERROR
        assert se.errors() == [
            "fmi3GetNumberOfContinuousStates: a Model Exchange function, and this instance was instantiated for "
            "Scheduled Execution"
        ]
        assert cs.set("cycleTime", 0.1) == OK and cs.enter_initialization(0.0) == OK
        assert cs.interval(clock_of(cs))[0] == ERROR
        assert cs.errors() == [
            "fmi3GetIntervalDecimal: a Scheduled Execution function, and this instance was instantiated for "
            "Co-Simulation"
        ]
    finally:
        se.free()
        cs.free()


def test_the_preemption_callbacks_are_both_or_neither():
    dll, md, _ = library("RateLimiter")
    from support.scheduled_execution import CLOCK_UPDATE, LOG_MESSAGE, PREEMPTION

    messages = []
    log = LOG_MESSAGE(lambda env, status, category, message: messages.append(message.decode()))
    lock = PREEMPTION(lambda: None)
    instantiate = dll.fmi3InstantiateScheduledExecution
    instantiate.argtypes = [ctypes.c_char_p] * 3 + [c_bool, c_bool, c_void_p, LOG_MESSAGE, CLOCK_UPDATE]
    instantiate.argtypes += [PREEMPTION, PREEMPTION]
    instantiate.restype = c_void_p
    token = md.guid.encode()
    assert instantiate(b"a", token, None, False, True, None, log, CLOCK_UPDATE(), lock, PREEMPTION()) is None
    assert messages == ["lockPreemption and unlockPreemption must both be given, or neither"]
    without = instantiate(b"a", token, None, False, True, None, log, CLOCK_UPDATE(), PREEMPTION(), PREEMPTION())
    assert without is not None  # an importer that does not preempt
    free = dll.fmi3FreeInstance
    free.argtypes, free.restype = [c_void_p], None
    free(without)


def test_activations_gets_and_sets_are_critical_sections():
    """5.1.2: the FMU secures the state an activation and the gets and sets
    of other tasks share. Each of them in Clock Activation Mode is one
    lockPreemption ... unlockPreemption pair, a refused one too; in
    Initialization Mode, where no partition runs, none."""
    fmu = Fmi3("RateLimiter")
    try:
        clock = clock_of(fmu)
        assert fmu.set("cycleTime", 0.1) == OK and fmu.enter_initialization(0.0) == OK
        assert fmu.set("u", 1.0) == OK and fmu.get("y") == 1.0 and fmu.interval(clock)[0] == OK
        assert fmu.exit_initialization() == OK
        assert fmu.locks == []
        assert fmu.set("u", 2.0) == OK
        assert fmu.activate(clock, 0.1) == OK
        assert fmu.get("y") == 1.0 + 0.1  # rateUpPar 1 per s, one cycle of 0.1 s
        assert fmu.interval(clock)[0] == OK
        assert fmu.locks == ["lock", "unlock"] * 4
        fmu.locks.clear()
        assert fmu.set("cycleTime", 1.0) == ERROR  # refused inside the section: it is left still
        assert fmu.locks == ["lock", "unlock"]
    finally:
        fmu.free()


# ---- FMU states, as in Co-Simulation --------------------------------------------


def state_call(fmu, name, *args):
    types = {
        "fmi3GetFMUState": [POINTER(c_void_p)],
        "fmi3SetFMUState": [c_void_p],
        "fmi3FreeFMUState": [POINTER(c_void_p)],
        "fmi3SerializedFMUStateSize": [c_void_p, POINTER(c_size_t)],
        "fmi3SerializeFMUState": [c_void_p, c_void_p, c_size_t],
        "fmi3DeserializeFMUState": [c_void_p, c_size_t, POINTER(c_void_p)],
    }[name]
    return fmu.call(name, types, *args)


def activations(fmu, times, names=("y", "runningTime", "rampActive", "status", "time")):
    rows = []
    for t in times:
        assert fmu.set("u", 10.0 * t) == OK and fmu.activate(clock_of(fmu), t) == OK, fmu.messages
        rows.append(tuple(fmu.get(n) for n in names))
    return rows


def test_fmu_states_take_the_partition_back():
    """Taken between activations (5.2.1: no partition active), a state set
    again, or serialized and deserialized into another instance, runs the
    same activations to the same outputs, bit for bit; a Co-Simulation
    state is refused, naming the two interfaces."""
    fmu = scheduled(cycleTime=0.1, rateUpPar=0.5)
    other = scheduled(cycleTime=0.1)
    cs = Fmi3("RateLimiter", "CoSimulation", name="cs")
    state, copy, foreign = c_void_p(), c_void_p(), c_void_p()
    try:
        activations(fmu, [0.1, 0.2, 0.3])
        assert state_call(fmu, "fmi3GetFMUState", ctypes.byref(state)) == OK
        later = [0.4, 0.55, 0.6]
        first = activations(fmu, later)
        assert state_call(fmu, "fmi3SetFMUState", state) == OK
        assert activations(fmu, later) == first
        size = c_size_t()
        assert state_call(fmu, "fmi3SerializedFMUStateSize", state, ctypes.byref(size)) == OK
        data = ctypes.create_string_buffer(size.value)
        assert state_call(fmu, "fmi3SerializeFMUState", state, data, size.value) == OK
        assert state_call(other, "fmi3DeserializeFMUState", data, size.value, ctypes.byref(copy)) == OK
        assert state_call(other, "fmi3SetFMUState", copy) == OK
        assert activations(other, later) == first
        assert cs.enter_initialization(0.0) == OK and cs.exit_initialization() == OK
        assert state_call(cs, "fmi3GetFMUState", ctypes.byref(foreign)) == OK
        assert state_call(fmu, "fmi3SetFMUState", foreign) == ERROR
        assert fmu.errors() == [
            "fmi3SetFMUState: an FMU state of Step Mode, which this Scheduled Execution instance cannot be in"
        ]
    finally:
        for owner, s in ((fmu, state), (other, copy), (cs, foreign)):
            if s:
                state_call(owner, "fmi3FreeFMUState", ctypes.byref(s))
        for f in (fmu, other, cs):
            f.free()
