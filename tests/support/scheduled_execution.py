"""FMI 3 from the importer's side through ctypes alone, and a scheduler for
Scheduled Execution written from the standard's text (FMI 3.0.2: chapter
5, Scheduled Execution; 2.2.9, Clocks), not from this FMU's sources:

- the input Clocks of the model description are the model partitions;
  a periodic Clock without intervalDecimal (intervalVariability fixed or
  tunable) has its interval and shift asked with fmi3GetIntervalDecimal
  and fmi3GetShiftDecimal in Initialization Mode (2.2.9.3, "Fixed periodic
  Clock"), and the first answer is qualified fmi3IntervalChanged;
- the ticks are t_0 = t_start + T_shift, t_i = t_(i-1) + T_interval
  (2.2.9.3, "Periodic Clock"), evaluated as t_start + T_shift + i*T_interval
  from the tick count, so that rounding does not add up over a million
  ticks (as a PLC's operating system counts its interrupts), each an
  fmi3ActivateModelPartition in Clock
  Activation Mode with the tick as activationTime, strictly increasing
  (5.2.1); the inputs set before and the outputs read after it (5.2.1,
  "It is recommended to call fmi3Set, fmi3ActivateModelPartition and
  fmi3Get in a sequence");
- Clocks of one time are activated by priority, the smallest value first
  (5.1.1);
- the lockPreemption and unlockPreemption callbacks given at instantiation
  are recorded, so that a test can check the FMU's critical sections.

The calls bind the FMU's functions once, so that a run of a million ticks
takes seconds."""

import ctypes
import heapq
import sys
import xml.etree.ElementTree as ET
from ctypes import CFUNCTYPE, POINTER, c_bool, c_char_p, c_double, c_int, c_size_t, c_uint32, c_void_p
from pathlib import Path
from typing import NamedTuple

from fmpy import read_model_description

from support.fmu_driver import unzipped

LOG_MESSAGE = CFUNCTYPE(None, c_void_p, c_int, c_char_p, c_char_p)
CLOCK_UPDATE = CFUNCTYPE(None, c_void_p)
PREEMPTION = CFUNCTYPE(None)

OK, WARNING, DISCARD, ERROR = 0, 1, 2, 3
# fmi3IntervalQualifier (fmi3FunctionTypes.h)
NOT_YET_KNOWN, UNCHANGED, CHANGED = 0, 1, 2
PERIODIC = {"constant", "fixed", "tunable"}

# an FMI 3 variable's type -> the fmi3Get/Set suffix and the C type of its values
ACCESS = {
    "Float64": ("Float64", ctypes.c_double),
    "Int32": ("Int32", ctypes.c_int32),
    "Enumeration": ("Int64", ctypes.c_int64),
    "Boolean": ("Boolean", c_bool),
}

_libraries = {}


class Clock(NamedTuple):
    """A <Clock> of the model description, with the attributes a scheduler needs (2.4.7.5)."""

    name: str
    valueReference: int
    causality: str
    intervalVariability: str
    priority: int | None
    intervalDecimal: float | None
    shiftDecimal: float


def read_clocks(model_description):
    """The model partitions: the input Clocks of modelDescription.xml, by priority (5.1.1)."""
    clocks = []
    for element in ET.parse(model_description).getroot().iter("Clock"):
        interval = element.get("intervalDecimal")
        clocks.append(
            Clock(
                element.get("name"),
                int(element.get("valueReference")),
                element.get("causality", "local"),
                element.get("intervalVariability"),
                int(element.get("priority")) if element.get("priority") is not None else None,
                float(interval) if interval is not None else None,
                float(element.get("shiftDecimal", "0")),
            )
        )
    inputs = [c for c in clocks if c.causality == "input"]
    assert all(c.priority is not None for c in inputs), "priority is mandatory for Scheduled Execution (2.4.7.5)"
    return sorted(inputs, key=lambda c: c.priority)


def library(model):
    """The FMU's shared library, its model description and its input Clocks, loaded once per process."""
    if model not in _libraries:
        unzipdir = Path(unzipped(model, 3, scheduled=True))
        md = read_model_description(str(unzipdir))
        platform = {"linux": "x86_64-linux", "win32": "x86_64-windows", "darwin": "aarch64-darwin"}[sys.platform]
        suffix = {"linux": ".so", "win32": ".dll", "darwin": ".dylib"}[sys.platform]
        identifier = md.scheduledExecution.modelIdentifier
        dll = ctypes.CDLL(str(unzipdir / "binaries" / platform / f"{identifier}{suffix}"))
        _libraries[model] = (dll, md, read_clocks(unzipdir / "modelDescription.xml"))
    return _libraries[model]


def function(dll, name, *argtypes):
    f = getattr(dll, name)
    f.argtypes, f.restype = list(argtypes), c_int
    return f


class Fmi3:
    """One instance of a model's FMI 3 FMU, Co-Simulation or Scheduled
    Execution, with every log message and every preemption lock kept.
    Calls return the FMI status; values go by variable name."""

    def __init__(self, model, interface="ScheduledExecution", name="scheduled", locks=True):
        self.dll, self.md, self.clocks = library(model)
        self.variables = {v.name: v for v in self.md.modelVariables}
        self.messages = []
        self.locks = []  # "lock" and "unlock", in the order the FMU called them
        self.log = LOG_MESSAGE(lambda env, status, category, message: self.messages.append((status, message.decode())))
        self.lock = PREEMPTION(lambda: self.locks.append("lock"))
        self.unlock = PREEMPTION(lambda: self.locks.append("unlock"))
        self.clock_update = CLOCK_UPDATE(lambda env: None)
        token = self.md.guid.encode()
        if interface == "ScheduledExecution":
            instantiate = self.dll.fmi3InstantiateScheduledExecution
            instantiate.argtypes = [c_char_p, c_char_p, c_char_p, c_bool, c_bool, c_void_p, LOG_MESSAGE] + [
                CLOCK_UPDATE,
                PREEMPTION,
                PREEMPTION,
            ]
            instantiate.restype = c_void_p
            lock, unlock = (self.lock, self.unlock) if locks else (PREEMPTION(), PREEMPTION())
            self.instance = instantiate(
                name.encode(), token, None, False, True, None, self.log, self.clock_update, lock, unlock
            )
        else:
            instantiate = self.dll.fmi3InstantiateCoSimulation
            instantiate.argtypes = [c_char_p, c_char_p, c_char_p, c_bool, c_bool, c_bool, c_bool, c_void_p]
            instantiate.argtypes += [c_size_t, c_void_p, LOG_MESSAGE, c_void_p]
            instantiate.restype = c_void_p
            self.instance = instantiate(
                name.encode(), token, None, False, True, False, False, None, 0, None, self.log, None
            )
        assert self.instance, self.messages
        d, p, vrs, n = self.dll, c_void_p, POINTER(c_uint32), c_size_t
        self._get = {kind: function(d, f"fmi3Get{s}", p, vrs, n, POINTER(t), n) for kind, (s, t) in ACCESS.items()}
        self._set = {kind: function(d, f"fmi3Set{s}", p, vrs, n, POINTER(t), n) for kind, (s, t) in ACCESS.items()}
        self._activate = function(d, "fmi3ActivateModelPartition", p, c_uint32, c_double)
        flag = POINTER(c_bool)
        self._do_step = function(d, "fmi3DoStep", p, c_double, c_double, c_bool, flag, flag, flag, POINTER(c_double))
        self._vr = {name: (c_uint32 * 1)(v.valueReference) for name, v in self.variables.items()}
        self._values = {kind: (t * 1)() for kind, (_, t) in ACCESS.items()}

    def errors(self):
        return [m for s, m in self.messages if s >= ERROR]

    def call(self, name, argtypes, *args):
        return function(self.dll, name, c_void_p, *argtypes)(self.instance, *args)

    def set(self, name, value):
        kind = self.variables[name].type
        values = self._values[kind]
        values[0] = bool(value) if kind == "Boolean" else int(value) if kind != "Float64" else float(value)
        return self._set[kind](self.instance, self._vr[name], 1, values, 1)

    def get(self, name):
        kind = self.variables[name].type
        values = self._values[kind]
        status = self._get[kind](self.instance, self._vr[name], 1, values, 1)
        assert status == OK, (name, status, self.messages[-1:])
        return values[0]

    def reader(self, names):
        """A function that reads the named variables, one call per type, and returns their values' bytes by type
        (equal bytes: equal bit for bit)."""
        batches = []
        for kind in ACCESS:
            chosen = [n for n in names if self.variables[n].type == kind]
            if chosen:
                vrs = (c_uint32 * len(chosen))(*(self.variables[n].valueReference for n in chosen))
                batches.append((self._get[kind], vrs, (ACCESS[kind][1] * len(chosen))(), len(chosen)))

        def read():
            for get, vrs, values, n in batches:
                assert get(self.instance, vrs, n, values, n) == OK, self.messages[-1:]
            return tuple(bytes(values) for _, _, values, _ in batches)

        return read

    def enter_initialization(self, start_time):
        return self.call(
            "fmi3EnterInitializationMode",
            [c_bool, c_double, c_double, c_bool, c_double],
            False,
            0.0,
            start_time,
            False,
            0.0,
        )

    def exit_initialization(self):
        return self.call("fmi3ExitInitializationMode", [])

    def activate(self, clock, time):
        return self._activate(self.instance, clock, time)

    def do_step(self, t, h):
        flag, last = c_bool(), c_double()
        return self._do_step(
            self.instance, t, h, True, ctypes.byref(flag), ctypes.byref(flag), ctypes.byref(flag), ctypes.byref(last)
        )

    def interval(self, clock):
        """(status, interval, qualifier) of fmi3GetIntervalDecimal."""
        interval, qualifier = (c_double * 1)(), (c_int * 1)()
        status = self.call(
            "fmi3GetIntervalDecimal",
            [POINTER(c_uint32), c_size_t, POINTER(c_double), POINTER(c_int)],
            (c_uint32 * 1)(clock),
            1,
            interval,
            qualifier,
        )
        return status, interval[0], qualifier[0]

    def shift(self, clock):
        shift = (c_double * 1)()
        status = self.call(
            "fmi3GetShiftDecimal", [POINTER(c_uint32), c_size_t, POINTER(c_double)], (c_uint32 * 1)(clock), 1, shift
        )
        return status, shift[0]

    def free(self):
        free_instance = self.dll.fmi3FreeInstance
        free_instance.argtypes, free_instance.restype = [c_void_p], None
        free_instance(self.instance)


class Scheduler:
    """Activates the model partitions of one FMU at the ticks of its
    periodic input Clocks (the module's docstring says from which text)."""

    def __init__(self, fmu):
        self.fmu = fmu
        self.clocks = fmu.clocks
        assert self.clocks, "an FMU for Scheduled Execution exposes its partitions as input Clocks"
        self.timing = {}

    def initialize(self, start_time, before_exit=lambda: None):
        """Initialization Mode: each periodic Clock's interval and shift, then
        Clock Activation Mode. Returns the first failing status, or OK."""
        self.start_time = start_time
        status = self.fmu.enter_initialization(start_time)
        if status != OK:
            return status
        before_exit()
        for clock in self.clocks:
            assert clock.intervalVariability in PERIODIC, "this scheduler runs periodic Clocks"
            if clock.intervalDecimal is not None:
                self.timing[clock.valueReference] = (clock.intervalDecimal, clock.shiftDecimal)
                continue
            status, interval, qualifier = self.fmu.interval(clock.valueReference)
            if status != OK:
                return status
            assert qualifier == CHANGED, "the first interval of Initialization Mode is a new one"
            status, shift = self.fmu.shift(clock.valueReference)
            if status != OK:
                return status
            assert interval > 0 and shift >= 0, (interval, shift)
            self.timing[clock.valueReference] = (interval, shift)
        return self.fmu.exit_initialization()

    def ticks(self, stop_time):
        """Every (time, clock) until stop_time, in the order of activation:
        by time, then by priority (generated: a run of a million ticks
        holds none of them)."""

        def clock_ticks(order, clock):
            interval, shift = self.timing[clock.valueReference]
            i = 0
            while (t := self.start_time + shift + i * interval) <= stop_time * (1 + 1e-12):
                yield t, order, clock.valueReference
                i += 1

        merged = heapq.merge(*(clock_ticks(order, clock) for order, clock in enumerate(self.clocks)))
        return ((t, vr) for t, _, vr in merged)

    def run(self, stop_time, before=lambda t: None, after=lambda t: None):
        """Activate at every tick: before(t), the activation, after(t)."""
        for t, clock in self.ticks(stop_time):
            before(t)
            status = self.fmu.activate(clock, t)
            assert status in (OK, WARNING), (t, status, self.fmu.messages[-1:])
            after(t)
