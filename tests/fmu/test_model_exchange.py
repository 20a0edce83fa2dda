"""Model Exchange (docs/fmi.md, Model Exchange): every model's FMI 2 and
FMI 3 FMU runs as Model Exchange too. No continuous states, no event
indicators; the cycle ends t0 + n*cycleTime are time events, each cycle
runs in Event Mode at its end with the values latched when the instant
before it was left, so Model Exchange gives Co-Simulation's outputs at
every cycle end (the reference: the same scenario through the same FMU as
Co-Simulation with the same cycleTime, itself checked against the
hand-worked references by test_reference.py)."""

import math
from ctypes import c_bool, c_double, c_int, c_size_t, c_void_p

import pytest
from fmpy.fmi2 import (
    FMU2Model,
    FMU2Slave,
    fmi2CallbackAllocateMemoryTYPE,
    fmi2CallbackFreeMemoryTYPE,
    fmi2CallbackFunctions,
    fmi2CallbackLoggerTYPE,
)
from fmpy.fmi3 import FMU3Model, FMU3Slave
from fmpy import calloc, free, read_model_description

from support.fmu_driver import MODELS, Instance, fmu_file, unzipped
from support.scenarios import discover, same, simulate

SCENARIOS = discover()


def cycle_ends(result, start, h):
    """The rows of a result at the cycle ends start + n*h (a Co-Simulation
    result also has rows at the input changes between)."""
    return {
        round((t - start) / h): row
        for t, row in zip(result["time"], result, strict=True)
        if math.isclose((t - start) / h, round((t - start) / h), abs_tol=1e-9)
    }


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("scenario", SCENARIOS, ids=lambda s: s.name)
def test_model_exchange_gives_the_co_simulation_outputs_at_every_cycle_end(scenario, version):
    """fmpy's Model Exchange loop (time events from nextEventTime, input
    events, Event Mode) against its Co-Simulation loop, cycleTime = the
    scenario's step, bit for bit."""
    o = scenario.options
    h, start = o["StepSize"], o["StartTime"]
    fmu = fmu_file(scenario.model, version)
    cs = cycle_ends(simulate(scenario, fmu, cycleTime=h), start, h)
    me_result = simulate(scenario, fmu, "ModelExchange", cycleTime=h)
    me = cycle_ends(me_result, start, h)
    assert len(me) == len(me_result)  # Model Exchange records at the cycle ends only
    assert sorted(me) == sorted(cs) == list(range(len(cs)))
    for n in cs:
        for name in scenario.outputs:
            assert same(me[n][name], cs[n][name]), (n, name, me[n][name], cs[n][name])


class Fmi2Logger:
    def __init__(self):
        self.messages = []
        self.callbacks = fmi2CallbackFunctions()
        self.callbacks.logger = fmi2CallbackLoggerTYPE(self._log)
        self.callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        self.callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)

    def _log(self, environment, name, status, category, message):
        self.messages.append((status, category.decode(), message.decode()))


class MeInstance:
    """A Model Exchange instance through fmpy's low-level API, by variable
    name, with the event update of both versions as one call."""

    def __init__(self, model, version):
        self.version = version
        unzipdir = unzipped(model, version)
        md = read_model_description(unzipdir)
        self.vrs = {v.name: v for v in md.modelVariables}
        identifier = md.modelExchange.modelIdentifier
        if version == 2:
            self.fmu = FMU2Model(guid=md.guid, unzipDirectory=unzipdir, modelIdentifier=identifier, instanceName="me")
            self.log = Fmi2Logger()
            self.fmu.instantiate(callbacks=self.log.callbacks, loggingOn=True)
            self.messages = self.log.messages
        else:
            self.messages = []
            self.fmu = FMU3Model(
                guid=md.instantiationToken, unzipDirectory=unzipdir, modelIdentifier=identifier, instanceName="me"
            )
            self.fmu.instantiate(
                loggingOn=True,
                logMessage=lambda env, status, category, message: self.messages.append(
                    (status, category.decode(), message.decode())
                ),
            )

    def set(self, **values):
        for name, value in values.items():
            v = self.vrs[name]
            if v.type == "Boolean":
                self.fmu.setBoolean([v.valueReference], [bool(value)])
            elif v.type in ("Integer", "Int32"):
                self.fmu.setInteger([v.valueReference], [int(value)]) if self.version == 2 else self.fmu.setInt32(
                    [v.valueReference], [int(value)]
                )
            elif v.type == "Enumeration":
                self.fmu.setInteger([v.valueReference], [int(value)]) if self.version == 2 else self.fmu.setInt64(
                    [v.valueReference], [int(value)]
                )
            else:
                (self.fmu.setReal if self.version == 2 else self.fmu.setFloat64)([v.valueReference], [float(value)])

    def get(self, name):
        v = self.vrs[name]
        if v.type in ("Integer", "Int32", "Enumeration"):
            getter = (
                self.fmu.getInteger
                if self.version == 2
                else (self.fmu.getInt64 if v.type == "Enumeration" else self.fmu.getInt32)
            )
        elif v.type == "Boolean":
            getter = self.fmu.getBoolean
        else:
            getter = self.fmu.getReal if self.version == 2 else self.fmu.getFloat64
        return getter([v.valueReference])[0]

    def start(self, start_time=0.0, **values):
        self.set(**values)
        if self.version == 2:
            self.fmu.setupExperiment(startTime=start_time)
            self.fmu.enterInitializationMode()
        else:
            self.fmu.enterInitializationMode(startTime=start_time)
        self.fmu.exitInitializationMode()

    def update(self):
        """The event update: (nextEventTimeDefined, nextEventTime)."""
        if self.version == 2:
            result = self.fmu.newDiscreteStates()
        else:
            result = self.fmu.updateDiscreteStates()
        assert result[:4] == (False, False, False, False)
        return result[4], result[5]

    def to_event(self, t):
        """Continuous-Time Mode from Event Mode, on to time t, Event Mode."""
        self.fmu.enterContinuousTimeMode()
        self.fmu.setTime(t)
        self.fmu.enterEventMode()

    def free(self):
        self.fmu.freeInstance()


@pytest.mark.parametrize("version", [2, 3])
def test_a_cycle_runs_with_the_inputs_latched_at_the_previous_cycle_end(version):
    """u set at t1 before the update of t1 acts in the cycle that ends at t2
    (rate 1 per s, cycles of 0.5 s: y moves 0.5 a cycle)."""
    fmu = MeInstance("RateLimiter", version)
    try:
        fmu.start(cycleTime=0.5, rateUpPar=1.0, rateDownPar=1.0)
        assert fmu.update() == (True, 0.5)
        fmu.to_event(0.5)
        fmu.set(u=10.0)  # the input of instant 0.5
        assert fmu.update() == (True, 1.0)
        assert fmu.get("y") == 0.0  # the cycle ending at 0.5 saw u = 0
        fmu.to_event(1.0)
        assert fmu.get("y") == 0.0  # outputs change only at the update
        assert fmu.update() == (True, 1.5)
        assert fmu.get("y") == 0.5
        fmu.to_event(1.5)
        fmu.set(u=0.0)
        assert fmu.update() == (True, 2.0)
        assert fmu.get("y") == 1.0  # still u = 10, latched at 1.0
        # a second update at the same instant runs nothing
        assert fmu.update() == (True, 2.0) and fmu.get("y") == 1.0
    finally:
        fmu.free()


@pytest.mark.parametrize("version", [2, 3])
def test_a_tunable_rate_changed_at_an_instant_acts_from_the_next_cycle_either_way(version):
    """rateUpPar set at the instant 0.5 from 3 down to 2 (its bytes compare
    below the latched ones) and at 1.5 up to 3 again: each acts from the
    cycle that ends at the next instant on, as Co-Simulation's set before
    the step does (cycles of 0.5 s towards u = 100: 1.5 a cycle at 3 per s,
    1 at 2 per s)."""
    sets = {0: {"u": 100.0}, 1: {"rateUpPar": 2.0}, 3: {"rateUpPar": 3.0}}  # at instant n, time 0.5 n
    me, cs = MeInstance("RateLimiter", version), Instance("RateLimiter", version)
    try:
        me.start(cycleTime=0.5, rateUpPar=3.0)
        cs.start(cycleTime=0.5, rateUpPar=3.0)
        me_y, cs_y = [], [cs.get("y")]
        for n in range(7):
            me.set(**sets.get(n, {}))
            cs.set(**sets.get(n, {}))
            assert me.update() == (True, 0.5 * (n + 1))
            me_y.append(me.get("y"))
            me.to_event(0.5 * (n + 1))
            cs.step(0.5)
            cs_y.append(cs.get("y"))
        assert me_y == cs_y[:7] == [0.0, 1.5, 2.5, 3.5, 5.0, 6.5, 8.0]
    finally:
        me.free()
        cs.free()


@pytest.mark.parametrize("version", [2, 3])
def test_an_input_set_in_continuous_time_mode_is_sampled_when_the_next_instant_is_left(version):
    """As OMSimulator sets inputs at each integrator step: u set between
    the events at 0 and 0.5 is not the cycle ending at 0.5's (which began
    at 0 with u = 0) but the next one's."""
    fmu = MeInstance("RateLimiter", version)
    try:
        fmu.start(cycleTime=0.5, rateUpPar=1.0)
        fmu.update()
        fmu.fmu.enterContinuousTimeMode()
        fmu.fmu.setTime(0.2)
        fmu.set(u=10.0)
        fmu.fmu.setTime(0.5)
        fmu.fmu.enterEventMode()
        assert fmu.update() == (True, 1.0) and fmu.get("y") == 0.0
        fmu.to_event(1.0)
        assert fmu.update() == (True, 1.5) and fmu.get("y") == 0.5
    finally:
        fmu.free()


@pytest.mark.parametrize("version", [2, 3])
def test_next_event_time_is_computed_afresh_from_the_cycle_count(version):
    """48 h of 10 ms cycles: the event after cycle n is start + (n+1)*0.01
    as one product and one sum, not a sum of steps (which drifts)."""
    fmu = MeInstance("RateLimiter", version)
    start = 7.3
    try:
        fmu.start(start_time=start, cycleTime=0.01)
        defined, t = fmu.update()
        n = 0
        while n < 2000:
            n += 1
            assert defined and t == start + n * 0.01, (n, t)
            fmu.to_event(t)
            defined, t = fmu.update()
        # jump to the last cycles of 48 h (the importer may step past events: the update catches up)
        last = 48 * 3600 * 100
        fmu.to_event(start + last * 0.01)
        defined, t = fmu.update()
        assert defined and t == start + (last + 1) * 0.01
    finally:
        fmu.free()


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("model", MODELS)
def test_cycle_time_zero_is_no_valid_cycle_in_model_exchange(model, version):
    """No communication step stands in for the cycle: status 16#8601 (where
    the block has a status output), no time event, the output holds, and a
    warning that asks for the PLC cycle."""
    fmu = MeInstance(model, version)
    try:
        fmu.start(cycleTime=0.0)
        before = [fmu.get(name) for name in fmu.vrs if fmu.vrs[name].causality == "output"]
        assert fmu.update() == (False, 0.0)  # no time event, and its time 0, not left undefined
        fmu.to_event(5.0)
        assert fmu.update() == (False, 0.0)
        after = [fmu.get(name) for name in fmu.vrs if fmu.vrs[name].causality == "output"]
        assert before == after
        if "status" in fmu.vrs:
            assert fmu.get("status") == 0x8601
        warnings = [m for m in fmu.messages if m[0] == 1]
        assert len(warnings) == 1, fmu.messages
        assert warnings[0][2].startswith("status 16#8601: no valid cycle configured (cycleTime = 0)")
        assert "set cycleTime to the PLC cycle" in warnings[0][2]
    finally:
        fmu.free()


@pytest.mark.parametrize("version", [2, 3])
def test_a_state_of_model_exchange_restores_the_latched_inputs_and_the_cycle_count(version):
    """getFMUstate / serialize in Continuous-Time Mode, the run continued,
    then the state deserialized and set: the same run again, bit for bit
    (the latched input of the next cycle travels with the state)."""
    fmu = MeInstance("RateLimiter", version)
    f = fmu.fmu
    get, set_, serialize, deserialize, free_state = (
        (f.getFMUstate, f.setFMUstate, f.serializeFMUstate, f.deSerializeFMUstate, f.freeFMUstate)
        if version == 2
        else (f.getFMUState, f.setFMUState, f.serializeFMUState, f.deserializeFMUState, f.freeFMUState)
    )
    try:
        fmu.start(cycleTime=0.1, rateUpPar=100.0)  # 10 a cycle: y reaches u in one
        fmu.update()
        fmu.to_event(0.1)
        fmu.set(u=1.0)
        fmu.update()
        fmu.fmu.enterContinuousTimeMode()  # latches u = 1
        state = get()
        data = serialize(state)

        def run():
            out = []
            for k in range(2, 6):
                fmu.fmu.setTime(k * 0.1)
                fmu.fmu.enterEventMode()
                fmu.set(u=5.0 * k)
                fmu.update()
                out.append(float(fmu.get("y")).hex())
                fmu.fmu.enterContinuousTimeMode()
            return out

        first = run()
        restored = deserialize(data)
        set_(restored)
        assert run() == first
        # each cycle saw the u of the instant before it: 1 (latched in the state), 10, 15, 20
        assert [float.fromhex(y) for y in first] == [1.0, 10.0, 15.0, 20.0]
        free_state(restored)
        free_state(state)
    finally:
        fmu.free()


def raw(fmu, name, argtypes, *args):
    function = getattr(fmu.fmu.dll, name)
    function.argtypes, function.restype = argtypes, c_int
    return function(*args)


@pytest.mark.parametrize("version", [2, 3])
def test_misuse_in_model_exchange_is_refused_with_a_reason(version):
    """Time before the last event or not finite, continuous states or event
    indicators asked for (there are none), NULL outputs, and a state of a
    Co-Simulation instance: an error naming the function and why."""
    fmu = MeInstance("RateLimiter", version)
    p = f"fmi{version}"
    try:
        for call, text in (
            (lambda c: raw(fmu, f"{p}SetTime", [c_void_p, c_double], c, 0.5), "before the last event"),
            (lambda c: raw(fmu, f"{p}SetTime", [c_void_p, c_double], c, math.nan), "not finite"),
            (
                lambda c: raw(fmu, f"{p}GetContinuousStates", [c_void_p, c_void_p, c_size_t], c, (c_double * 1)(), 1),
                "this FMU has no continuous states; n = 1, not 0",
            ),
            (
                lambda c: raw(fmu, f"{p}GetEventIndicators", [c_void_p, c_void_p, c_size_t], c, (c_double * 2)(), 2),
                "this FMU has no event indicators; n = 2, not 0",
            ),
            (
                lambda c: raw(
                    fmu,
                    f"{p}CompletedIntegratorStep",
                    [c_void_p, c_int if version == 2 else c_bool, c_void_p, c_void_p],
                    c,
                    1,
                    None,
                    None,
                ),
                "an output argument pointer is NULL",
            ),
        ):
            fmu.start(cycleTime=0.1)
            fmu.update()
            fmu.to_event(1.0)
            fmu.update()
            fmu.fmu.enterContinuousTimeMode()
            before = len(fmu.messages)
            assert call(fmu.fmu.component) == 3, text
            errors = [m for m in fmu.messages[before:] if m[0] >= 3]
            assert len(errors) == 1 and text in errors[0][2], (text, fmu.messages[before:])
            fmu.fmu.reset()
        update = f"{p}NewDiscreteStates" if version == 2 else f"{p}UpdateDiscreteStates"
        fmu.start(cycleTime=0.1)
        n = 2 if version == 2 else 7
        assert raw(fmu, update, [c_void_p] * n, fmu.fmu.component, *([None] * (n - 1))) == 3
        assert fmu.messages[-1][2].startswith(f"{update}: ") and "NULL" in fmu.messages[-1][2]
    finally:
        fmu.free()


@pytest.mark.parametrize("version", [2, 3])
def test_a_state_of_a_co_simulation_instance_is_refused_in_model_exchange(version):
    """An FMU state taken in Step Mode by a Co-Simulation instance of the
    same FMU is a mode no Model Exchange instance can be in: setting it is
    an error that says so, and the Model Exchange instance is not changed
    into a Co-Simulation one."""
    fmu = MeInstance("RateLimiter", version)
    unzipdir = unzipped("RateLimiter", version)
    md = read_model_description(unzipdir)
    if version == 2:
        cs = FMU2Slave(
            guid=md.guid, unzipDirectory=unzipdir, modelIdentifier=md.coSimulation.modelIdentifier, instanceName="cs"
        )
        cs.instantiate()
        cs.setupExperiment(startTime=0.0)
    else:
        cs = FMU3Slave(
            guid=md.instantiationToken,
            unzipDirectory=unzipdir,
            modelIdentifier=md.coSimulation.modelIdentifier,
            instanceName="cs",
        )
        cs.instantiate()
    try:
        cs.enterInitializationMode(**({} if version == 2 else {"startTime": 0.0}))
        cs.exitInitializationMode()
        cs.doStep(0.0, 0.1)
        state = cs.getFMUstate() if version == 2 else cs.getFMUState()
        fmu.start(cycleTime=0.1)
        fmu.update()
        fmu.fmu.enterContinuousTimeMode()
        name = "fmi2SetFMUstate" if version == 2 else "fmi3SetFMUState"
        assert raw(fmu, name, [c_void_p, c_void_p], fmu.fmu.component, state) == 3
        errors = [m for m in fmu.messages if m[0] >= 3]
        assert len(errors) == 1, fmu.messages
        assert errors[0][2] == (f"{name}: an FMU state of Step Mode, which this Model Exchange instance cannot be in")
        (cs.freeFMUstate if version == 2 else cs.freeFMUState)(state)
    finally:
        fmu.free()
        cs.freeInstance()
