"""Many traces through one FMU instance, at close to the cost of the FMU's
own calls, with results bit for bit equal to fmpy.simulate_fmu's.

A Runner unpacks the FMU and reads its model description once, makes one
instance with fmpy and reuses it across traces through the standard reset
(fmi2Reset / fmi3Reset). A trace starts as fmpy starts it (fmpy's own
start-value function and calls, in its order); its steps then run from
arrays: the input values of every step are computed at once with fmpy's
rule (`discrete_rows`), the outputs are read with the FMI functions
straight from the library into arrays kept from trace to trace, one call
per variable type as fmpy's recorder makes them. The step loop runs in C
(_steps.c, a chunk of steps per call, the FMU's own FMI functions), or in
Python where that module was not built: the same calls in the same order.

The fast loop gives fmpy's result when (`fast_path_problem`; a trace
checks the names and the grid before it starts, and each window of its
input table as it is read, before the FMU sees a row of it):
- the communication points are the regular grid start + k * h and the
  last one is the stop time: no input event falls between grid points
  (fmpy would add a communication point there) and (stop - start) / h is
  whole;
- every input column is a discrete input or a tunable parameter (fmpy
  interpolates continuous ones) and every recorded variable is a scalar;
- every call returns OK or Warning, and no FMI 3 step asks to terminate
  or returns early.
Any other trace, or one whose call fails, runs through fmpy.simulate_fmu
itself on a new instance (the same result or error as fmpy gives).

One call fmpy makes is left out: fmpy sets every input before every step;
the fast loop sets them at the steps where an input row changes. An FMU
keeps a set input until it is set again (FMI 2.0 section 4.2.1, FMI 3.0
section 4.2.1: inputs are set, not consumed), so the FMU sees the same
values; the tests check the results against fmpy's on every reference
scenario and on random traces.
"""

import contextlib
import io
import itertools
import math
from ctypes import c_void_p
from typing import Any, NamedTuple

import cffi
import numpy as np
from fmpy.simulation import (
    apply_start_values,
    instantiate_fmu,
    settable_in_initialization_mode,
    settable_in_instantiated,
)

from ._errors import InputError, SimulationError
from ._fmu import REAL_TYPES, unpacked
from ._fmpy import Experiment, Signals, held_to, run_fmpy
from ._native import native_function

# per FMI type: the C type's dtype (fmpy's Input tables and getters) and the
# recorded column's dtype (fmpy's Recorder)
FMI2_TYPES = {"Real": (np.float64, np.float64), "Integer": (np.int32, np.int32), "Boolean": (np.int32, np.bool_)}
FMI3_TYPES = {
    t: (d, d)
    for t, d in (
        ("Float32", np.float32),
        ("Float64", np.float64),
        ("Int8", np.int8),
        ("UInt8", np.uint8),
        ("Int16", np.int16),
        ("UInt16", np.uint16),
        ("Int32", np.int32),
        ("UInt32", np.uint32),
        ("Int64", np.int64),
        ("UInt64", np.uint64),
        ("Boolean", np.bool_),
    )
}


def discrete_rows(t, times, after_event):
    """For each of times the row of the input table (times t) that fmpy's
    Input.interpolate applies to a discrete variable: the first row up to
    t[0], the last after t[-1], else the row before the first t[i] >= time,
    and with after_event also every later row at or close to time."""
    n = len(t)
    if n < 2:
        return np.zeros(len(times), dtype=np.intp)
    i0 = np.searchsorted(t, times)
    rows = i0 - 1
    if after_event:
        # advance while t[i + 1] < time or isclose(time, t[i + 1]) (math.isclose: relative 1e-9)
        while True:
            nxt = np.clip(rows + 1, 0, n - 1)
            step = (rows + 1 < n) & ((t[nxt] < times) | _close(times, t[nxt]))
            if not step.any():
                break
            rows = np.where(step, rows + 1, rows)
    rows = np.where(i0 == 0, 0, rows)
    return np.where(i0 == n, n - 1, rows)


def input_events(inputs):
    """The time events fmpy's Input.findEvents finds in a table of discrete
    columns: repeated times and the times where a column changes (NaN
    counts as a change, as np.diff makes it)."""
    t = inputs["time"]
    if len(t) < 2:
        return t[:0]
    changed = np.diff(t) == 0
    events = [t[:-1][changed]]
    with np.errstate(invalid="ignore"):
        for name in inputs.dtype.names[1:]:
            events.append(t[1:][np.diff(inputs[name]) != 0])
    return _sorted_unique(np.concatenate(events))


def _sorted_unique(values):
    """np.unique of finite values, without its import of numpy.ma (16 ms
    of every worker's first case)."""
    values = np.sort(values)
    return values[np.concatenate(([True], values[1:] != values[:-1]))] if len(values) else values


# The hot loop calls the library through cffi: a call costs about half what
# a ctypes call does. The values are passed as byte pointers into NumPy arrays.
FFI = cffi.FFI()
FFI.cdef(
    "\n".join(
        [
            f"int fmi2{verb}{kind}(void *, const unsigned int *, size_t, char *);"
            for kind in FMI2_TYPES
            for verb in ("Set", "Get")
        ]
        + [
            f"int fmi3{verb}{kind}(void *, const unsigned int *, size_t, char *, size_t);"
            for kind in FMI3_TYPES
            for verb in ("Set", "Get")
        ]
        + [
            "int fmi2DoStep(void *, double, double, int);",
            "int fmi3DoStep(void *, double, double, bool, bool *, bool *, bool *, double *);",
            # _steps.c: a chunk of steps in C, the same calls as _steps_python
            "typedef struct { void (*function)(void); const unsigned int *vrs; size_t count; char *rows;"
            " ptrdiff_t row_bytes; } fmutrace_calls;",
            "size_t fmutrace_steps(int, void (*)(void), void *, const double *, const double *, size_t,"
            " const long long *, const fmutrace_calls *, size_t, const fmutrace_calls *, size_t);",
        ]
    )
)


C_STEPS = native_function("_steps", FFI, "fmutrace_steps")  # (None: not built, the Python loop then)

STEPS_PER_CHUNK = 1 << 17  # steps run between two result chunks (a long run's memory: its pointers, its rows)
KEPT_SHAPES = 8  # grids and output arrays kept for traces of so many shapes (memory stays flat)


def _forget_oldest(kept):
    if len(kept) >= KEPT_SHAPES:
        del kept[next(iter(kept))]


def _row_pointers(values):
    """A char pointer to each row of a 2-D array."""
    base = FFI.cast("char *", values.ctypes.data)
    return [base + k * values.strides[0] for k in range(len(values))]


def _held_to(chunks, stop_time):
    """The chunks of an input table, a table of a single row held until
    stop_time as held_to holds it for fmpy."""
    first = next(chunks, None)
    if first is None:
        return
    if len(first) == 1:
        second = next(chunks, None)
        if second is None:
            yield held_to(first, stop_time)
            return
        yield first
        first = second
    yield first
    yield from chunks


def _value_references(variables):
    return FFI.new("unsigned int[]", [v.valueReference for v in variables])


def _close(a, b):
    """math.isclose elementwise (relative 1e-9)."""
    return np.abs(a - b) <= 1e-9 * np.maximum(np.abs(a), np.abs(b))


class FastLoopFailed(Exception):
    """The fast loop cannot give fmpy's result (a call failed, or the inputs need fmpy)."""


class InputsNeedFmpy(FastLoopFailed):
    """An input event falls between communication points: fmpy's loop adds
    a point there. Raised as the input table is read; for a whole table
    (Runner.run) before the FMU is called, so the instance stays usable."""


@contextlib.contextmanager
def _quiet():
    """What fmpy's default logger prints (the FMU's messages) goes nowhere."""
    with contextlib.redirect_stdout(io.StringIO()):
        yield


class _InputRows:
    """The rows of an input table that fmpy applies at consecutive steps,
    the table read chunk by chunk. discrete_rows gives a step's row from
    a window of the table when the window starts before the step (or at
    the table's first row) and reaches past it, not only close to it (or to
    the table's last row): the window keeps the rows from the one before
    the last step's on, and grows by chunks until it reaches the next
    steps. Per FMI type the values of the rows that change, as fmpy
    converts them."""

    def __init__(self, chunks, runner, experiment: Experiment):
        self.chunks, self.runner, self.experiment = chunks, runner, experiment
        self.table: np.ndarray = np.empty(0)  # the window (offset: its first row in the table)
        self.offset, self.done = 0, False
        self.last_row = None  # the row set at the last step
        self.setters: list | None = None  # (FMI type, value references, count, dtype, names) per FMI type

    def _read(self):
        chunk = next(self.chunks, None)
        if chunk is None:
            self.done = True
            return
        if self.setters is None:
            r = self.runner
            self.setters = [
                (kind, _value_references(variables), len(variables), r.types[kind][0], [v.name for v in variables])
                for kind, variables in r._groups(chunk.dtype.names[1:]).items()
            ]
        self.table = np.concatenate([self.table, chunk]) if len(self.table) else chunk
        problem = self.runner.event_problem(self.experiment, self.table)
        if problem:
            raise InputsNeedFmpy(problem)

    def reach(self, time):
        """Reads the table until its window reaches past time (each window's events checked as it is read)."""
        while not self.done and (
            not len(self.table) or not (self.table["time"][-1] > time and not _close(time, self.table["time"][-1]))
        ):
            self._read()
        if not len(self.table):
            raise FastLoopFailed("no input rows")

    def _setter(self, rows):
        """The calls that set the table's rows (global indices): per FMI type
        (function, value references, count, the rows' values)."""
        calls = []
        for kind, vrs, count, dtype, names in self.setters or ():
            table = np.asarray(np.stack([self.table[name] for name in names]), dtype=dtype)  # fmpy's conversion
            values = np.ascontiguousarray(table[:, rows - self.offset].T)
            calls.append((self.runner._set[kind], vrs, count, values))
        return calls

    def first(self, start):
        """The setter calls for the initialization (their row 0): the row before the first event at start."""
        self.reach(start)
        row = discrete_rows(self.table["time"], np.array([start]), after_event=False) + self.offset
        return self._setter(row)

    def steps(self, times):
        """(set_at, setters) of steps at times: set_at[k] the row of the
        setter calls set before step k, -1 where the row stays the one set."""
        self.reach(times[-1])
        t = self.table["time"]
        rows = discrete_rows(t, times, after_event=True) + self.offset
        changed = np.empty(len(rows), dtype=bool)
        changed[0] = self.last_row is None or rows[0] != self.last_row
        changed[1:] = rows[1:] != rows[:-1]
        at = np.flatnonzero(changed)
        set_at = np.full(len(times), -1, dtype=np.int64)
        set_at[at] = np.arange(len(at))
        setters = self._setter(rows[at])
        self.last_row = rows[-1]
        keep = max(int(np.searchsorted(t, times[-1])) - 1, 0)
        self.table, self.offset = self.table[keep:], self.offset + keep
        return set_at, setters


class _Fmi2Calls:
    """How the step loop calls an FMI 2 FMU (a Runner picks its version's once)."""

    fmi_version = 2  # fmutrace_steps' first argument: its loop for this version

    @staticmethod
    def values(component, function, vrs, count):
        """call(pointer) -> status: function, an FMI Set or Get, on count values at pointer."""
        return lambda pointer: function(component, vrs, count, pointer)

    @staticmethod
    def step(do_step, component, flags):
        """step(t, h) -> status of doStep."""
        return lambda t, h: do_step(component, t, h, 1)


class _Fmi3Calls:
    """How the step loop calls an FMI 3 FMU: Set and Get take the number
    of values too (count: scalars); a step that asks to terminate or
    returns early counts as an Error (the loop stops after its getters)."""

    fmi_version = 3

    @staticmethod
    def values(component, function, vrs, count):
        return lambda pointer: function(component, vrs, count, pointer, count)

    @staticmethod
    def step(do_step, component, flags):
        event, terminate, early, last = flags

        def step(t, h):
            status = do_step(component, t, h, True, event, terminate, early, last)
            return 3 if terminate[0] or early[0] else status

        return step


def _setter_calls(calls, component, setters):
    """(call, a pointer to each row) of every setter (function, value references, count, rows)."""
    return [
        (calls.values(component, function, vrs, count), _row_pointers(values))
        for function, vrs, count, values in setters
    ]


def _set_row(calls, row):
    """Sets row of every _setter_calls call; the statuses OR-ed."""
    status = 0
    for call, pointers in calls:
        status |= call(pointers[row])
    return status


class _Instance(NamedTuple):
    """What the step loop calls an instance through: its version's
    _Fmi2Calls or _Fmi3Calls, its doStep, the instance pointer, and FMI 3's
    step flags (None for FMI 2)."""

    calls: type[_Fmi2Calls] | type[_Fmi3Calls]
    do_step: object
    component: object
    flags: tuple | None


def _steps_python(instance: _Instance, times, sizes, set_at, setters, getters):
    """Per step: the inputs where they change, doStep, one get per output
    type into the step's row; False as soon as a call fails (or an FMI 3
    step asks to terminate or returns early). getters: (function, value
    references, count, a pointer to each step's row)."""
    calls, do_step, component, flags = instance
    set_calls = _setter_calls(calls, component, setters)
    get_calls = [(calls.values(component, function, vrs, count), rows) for function, vrs, count, rows in getters]
    step = calls.step(do_step, component, flags)
    for t, h, row, k in zip(times.tolist(), sizes.tolist(), set_at.tolist(), itertools.count()):
        if row >= 0 and _set_row(set_calls, row) > 1:
            return False
        status = step(t, h) if h != 0 else 0  # (a size of 0: a cycle that did not run, Experiment.replay)
        for get, rows in get_calls:
            status |= get(rows[k])
        if status > 1:
            return False
    return True


def _call_table(calls):
    """fmutrace_calls of (function, value references, count, rows array, first row's pointer)."""
    table = FFI.new("fmutrace_calls[]", max(len(calls), 1))
    # (no calls get a table of one entry)
    for entry, (function, vrs, count, values, first) in zip(table, calls, strict=False):
        entry.function, entry.vrs, entry.count = FFI.cast("void (*)(void)", function), vrs, count
        entry.rows, entry.row_bytes = first, values.strides[0]
    return table


def _steps_c(instance: _Instance, times, sizes, set_at, setters, getters):
    """_steps_python's loop in C (_steps.c): the same calls in the same order."""
    calls, do_step, component, _ = instance
    setter_table = _call_table(
        [(f, vrs, n, values, FFI.cast("char *", values.ctypes.data)) for f, vrs, n, values in setters]
    )
    getter_table = _call_table(getters)
    times = np.ascontiguousarray(times, dtype=np.float64)
    sizes = np.ascontiguousarray(sizes, dtype=np.float64)
    set_at = np.ascontiguousarray(set_at, dtype=np.int64)
    done = C_STEPS(
        calls.fmi_version,
        FFI.cast("void (*)(void)", do_step),
        component,
        FFI.cast("double *", times.ctypes.data),
        FFI.cast("double *", sizes.ctypes.data),
        len(times),
        FFI.cast("long long *", set_at.ctypes.data),
        setter_table,
        len(setters),
        getter_table,
        len(getters),
    )
    return done == len(times)


class Runner:
    """One FMU instance in this process, reused for trace after trace."""

    def __init__(self, fmu_bytes):
        self.folder, self.md = unpacked(fmu_bytes)
        self.fmi3 = self.md.fmiVersion.startswith("3")
        self.types = FMI3_TYPES if self.fmi3 else FMI2_TYPES
        self.calls = _Fmi3Calls if self.fmi3 else _Fmi2Calls
        self.variables = {v.name: v for v in self.md.modelVariables}
        self.order = {v.name: i for i, v in enumerate(self.md.modelVariables)}
        self.variable_step = bool(self.md.coSimulation.canHandleVariableCommunicationStepSize)
        self.fmu = self._lib = None
        self.fast_runs = self.fmpy_runs = 0
        self.c_loop = C_STEPS is not None  # the steps in C (_steps.c), else in Python: the same calls
        self._grids = {}  # (start, step, n) -> the communication points and step sizes as C doubles
        self._buffers = {}  # (kind, count, n) -> output array kept from trace to trace, and its rows as C pointers

    # ---- the instance ----------------------------------------------------

    def _instance(self):
        if self.fmu is None:
            with contextlib.redirect_stdout(io.StringIO()):
                self.fmu = instantiate_fmu(self.folder, self.md, fmi_type="CoSimulation")
            # the library fmpy loaded (the same handle: dlopen counts), its functions through cffi
            self._lib = FFI.dlopen(self.fmu.dll._name)
            prefix = "fmi3" if self.fmi3 else "fmi2"
            self._set = {kind: getattr(self._lib, f"{prefix}Set{kind}") for kind in self.types}
            self._get = {kind: getattr(self._lib, f"{prefix}Get{kind}") for kind in self.types}
            self._do_step = getattr(self._lib, f"{prefix}DoStep")
            component = self.fmu.component
            self._component = FFI.cast("void *", component.value if isinstance(component, c_void_p) else component)
            self._step_flags = None  # FMI 3's doStep returns these beside its status
            if self.fmi3:
                flags = FFI.new("bool[3]")  # eventHandlingNeeded, terminateSimulation, earlyReturn
                self._step_flags = flags, flags + 1, flags + 2, FFI.new("double *")  # and lastSuccessfulTime
            self.fresh = True
        elif not self.fresh:
            try:
                self.fmu.reset()
            except Exception:  # an FMU without a working reset gets a new instance per trace
                self._drop_instance()
                return self._instance()
        self.fresh = False
        return self.fmu

    def _drop_instance(self):
        if self.fmu is not None:
            with contextlib.suppress(Exception):
                self.fmu.freeInstance()
        self.fmu = self._lib = None

    def close(self):
        self._drop_instance()

    # ---- a trace -----------------------------------------------------------

    def _kind(self, variable):
        """The FMI type of the functions that set and get variable."""
        if variable.type == "Enumeration":
            return "Int64" if self.fmi3 else "Integer"
        return variable.type

    def fast_path_problem(self, experiment: Experiment, inputs, outputs):
        """Why the fast loop would not give fmpy's result for this trace
        (None if it would); see the module's docstring."""
        names = inputs.dtype.names[1:] if inputs is not None else ()
        return self.static_problem(experiment, names, outputs) or (
            self.event_problem(experiment, inputs) if inputs is not None else None
        )

    def static_problem(self, experiment: Experiment, input_names, outputs):
        """fast_path_problem's reasons that the names and the grid alone give."""
        start, stop, step = experiment.start, experiment.stop, experiment.step
        n = round((stop - start) / step)
        if experiment.replay is not None and experiment.replay.times is not None:
            pass  # (the steps are the replay's, from its first time to its last)
        elif n < 1 or not math.isclose(start + n * step, stop):
            return "the stop time is not a whole number of steps from the start"
        if any(self.variables[name].shape for name in outputs):
            return "an array variable"
        for name in input_names:
            v = self.variables[name]
            if v.shape or (v.type in REAL_TYPES and v.variability not in ("discrete", "tunable")):
                return f"{name} is a continuous input (fmpy interpolates it)"
        return None

    def event_problem(self, experiment: Experiment, inputs):
        """fast_path_problem's reason that an input table (or a run of its
        consecutive rows) gives: an input event between communication points."""
        start, stop, step = experiment.start, experiment.stop, experiment.step
        if self.variable_step:
            events = input_events(inputs)
            events = events[(events > start) & (events < stop) & ~_close(events, start) & ~_close(events, stop)]
            points = experiment.replay.times if experiment.replay is not None else None
            if points is not None:  # the recorded communication points: an event at one of them
                at = np.searchsorted(points, events)
                off = ~_close(points[np.minimum(at, len(points) - 1)], events) & ~_close(points[at - 1], events)
            else:
                grid = start + np.rint((events - start) / step) * step  # Python's round() also rounds half to even
                off = ~_close(grid, events)
            if off.any():
                return f"an input event at t={events[off][0]!r} between communication points"
        return None

    def run(self, experiment: Experiment, signals: Signals):
        """The trace's result, as fmpy.simulate_fmu(..., output_interval=step)
        returns it (a structured array): run_chunks' chunks joined, the
        input table given whole. SimulationError if the FMU fails."""
        inputs: Any = signals.inputs  # a structured array, or None
        names = inputs.dtype.names[1:] if inputs is not None else ()
        table = None if inputs is None else (lambda: iter([inputs]))
        chunks = list(self.run_chunks(experiment, Signals(table, signals.start_values, signals.outputs), names))
        return chunks[0] if len(chunks) == 1 else np.concatenate(chunks)

    def run_chunks(self, experiment: Experiment, signals: Signals, input_names, steps_per_chunk=STEPS_PER_CHUNK):
        """The trace's result as fmpy.simulate_fmu(..., output_interval=step)
        gives it, in consecutive structured arrays (the first holds the
        start time's row too), in memory that does not grow with the length
        on the fast loop. signals.inputs: None, or a function that gives the
        input table as consecutive structured arrays from its first row
        each time it is called (an iterator of them is read once and kept);
        input_names: their columns. Where the fast loop cannot give fmpy's
        result (the names or the grid say so before it starts; an input
        event between communication points or a failing call as it runs),
        fmpy runs the trace on an instance of its own, the table read whole,
        and its rows after those given already follow (the fast loop's are
        fmpy's bits: a test checks it). SimulationError if the FMU fails."""
        inputs: Any = signals.inputs
        if inputs is not None and not callable(inputs):
            kept = list(inputs)
            inputs = lambda: iter(kept)  # noqa: E731 (a table given as an iterator: read once)
        given = -math.inf  # the time of the last row given
        problem = self.static_problem(experiment, input_names, signals.outputs)
        if problem is not None and experiment.replay is not None:
            raise InputError(
                f"recorded cycle lengths run on fmutrace's own step loop, which cannot take this: {problem}"
            )
        if problem is None:
            table = None if inputs is None else _held_to(inputs(), experiment.stop)
            try:
                for chunk in self._fast(
                    experiment, Signals(table, signals.start_values, signals.outputs), steps_per_chunk
                ):
                    given = float(chunk["time"][-1])
                    yield chunk
                self.fast_runs += 1
                return
            except InputsNeedFmpy as error:
                if experiment.replay is not None:
                    raise InputError(
                        f"recorded cycle lengths run on fmutrace's own step loop, which cannot take this: {error}"
                    ) from None
            except FastLoopFailed as error:
                self._drop_instance()  # a call failed: fmpy tells the story on an instance of its own
                if experiment.replay is not None:  # (fmpy steps on a grid: not the recorded steps)
                    raise SimulationError(f"the FMU failed on the recorded cycle lengths: {error}") from None
        self.fmpy_runs += 1
        table = None if inputs is None else np.concatenate(list(inputs()))
        result = run_fmpy(self.folder, self.md, experiment, Signals(table, signals.start_values, signals.outputs))
        result = result[result["time"] > given]
        for k in range(0, len(result), steps_per_chunk):
            yield result[k : k + steps_per_chunk]

    def _grid(self, start, step, k, m):
        """fmpy's communication points from step k on for m steps,
        start + (n_steps + 1) * output_interval, as an array, and the step
        times and sizes it passes (next point - time) as lists."""
        key = (start, step, m)
        if k or key not in self._grids:
            times = start + np.arange(k, k + m + 1, dtype=np.float64) * step
            if k == 0:
                times[0] = start
            grid = times, times[:-1], times[1:] - times[:-1]
            if k:
                return grid  # a long run's later chunks: not kept
            _forget_oldest(self._grids)
            self._grids[key] = grid
        return self._grids[key]

    def _buffer(self, kind, count, n):
        """An output array of n + 1 rows kept for traces of this shape, and
        a pointer to each row."""
        key = (kind, count, n)
        if key not in self._buffers:
            _forget_oldest(self._buffers)
            values = np.zeros((n + 1, count), dtype=self.types[kind][0])
            self._buffers[key] = values, _row_pointers(values)
        return self._buffers[key]

    def _groups(self, names):
        """{kind: [variables]} of names, each list in model description order."""
        groups: dict[str, list] = {}
        for name in sorted(names, key=lambda name: self.order[name]):
            v = self.variables[name]
            groups.setdefault(self._kind(v), []).append(v)
        return groups

    def _fast(self, experiment: Experiment, signals: Signals, steps_per_chunk):
        """The fast loop's result chunk by chunk (see run_chunks);
        FastLoopFailed as soon as a call fails or the inputs need fmpy."""
        start, stop, step, tolerance = experiment.start, experiment.stop, experiment.step, experiment.relative_tolerance
        start_values, outputs = signals.start_values, signals.outputs
        inputs = _InputRows(signals.inputs, self, experiment) if signals.inputs is not None else None
        if inputs is not None:
            inputs.reach(start)  # the first window read (and its events checked) before the FMU is called
        with _quiet():
            fmu = self._instance()
        replay = experiment.replay
        n = round((stop - start) / step) if replay is None or replay.times is None else len(replay.times) - 1
        size = min(n, steps_per_chunk)
        component, calls = self._component, self.calls
        end = stop if replay is None else max(stop, replay.end)  # the FMU's last time

        # outputs: per FMI type in the recorder's order, into arrays kept for chunks of this size
        getters: list[tuple] = []
        columns: list[tuple[str, type]] = [("time", np.float64)]
        groups = self._groups([name for name in outputs if name != "time"])
        for kind in self.types:
            if kind in groups:
                variables = groups[kind]
                values, pointers = self._buffer(kind, len(variables), size)
                getters.append(
                    (self._get[kind], _value_references(variables), len(variables), pointers, values, variables, kind)
                )
                columns += [(v.name, self.types[kind][1]) for v in variables]

        def result(rows, times):
            chunk = np.empty(len(times), dtype=columns)
            chunk["time"] = times
            for _, _, _, _, values, variables, kind in getters:
                for i, v in enumerate(variables):
                    chunk[v.name] = values[rows, i] != 0 if kind == "Boolean" and not self.fmi3 else values[rows, i]
            return chunk

        with _quiet():
            first = inputs.first(start) if inputs is not None else None
            try:
                if self.fmi3:
                    remaining = apply_start_values(fmu, self.md, start_values, settable=settable_in_instantiated)
                    fmu.enterInitializationMode(tolerance=tolerance, startTime=start, stopTime=end)
                else:
                    fmu.setupExperiment(tolerance=tolerance, startTime=start, stopTime=end)
                    remaining = apply_start_values(fmu, self.md, start_values, settable=settable_in_instantiated)
                    fmu.enterInitializationMode()
                remaining = apply_start_values(fmu, self.md, remaining, settable=settable_in_initialization_mode)
                if remaining or (first is not None and _set_row(_setter_calls(calls, component, first), 0) > 1):
                    raise FastLoopFailed("a start value or an input was refused")
                fmu.exitInitializationMode()
            except FastLoopFailed:
                raise
            except Exception as error:  # fmpy's calls raise on an error status
                raise FastLoopFailed(str(error)) from None
            status = 0
            for function, vrs, count, pointers, _, _, _ in getters:
                status |= calls.values(component, function, vrs, count)(pointers[0])
            if status > 1:
                raise FastLoopFailed("a getter failed")
        pending = result(slice(0, 1), [start])  # the start's row goes out with the first chunk

        for k in range(0, n, size):
            m = min(size, n - k)
            if replay is not None and replay.times is not None:  # the steps and their times as recorded
                times, (step_times, step_sizes) = replay.times[k : k + m + 1], replay.steps(k, m)
            else:
                times, step_times, step_sizes = self._grid(start, step, k, m)
            if replay is not None and replay.times is None:  # the steps as recorded, their results at the grid's
                step_times, step_sizes = replay.steps(k, m)
            with _quiet():
                if inputs is not None:
                    set_at, setters = inputs.steps(times[:-1])
                else:
                    set_at, setters = np.full(m, -1, dtype=np.int64), []
                instance = _Instance(calls, self._do_step, component, self._step_flags)
                if self.c_loop:
                    done = _steps_c(
                        instance,
                        step_times,
                        step_sizes,
                        set_at,
                        setters,
                        [
                            (function, vrs, count, values, pointers[1])
                            for function, vrs, count, pointers, values, _, _ in getters
                        ],
                    )
                else:
                    done = _steps_python(
                        instance,
                        step_times,
                        step_sizes,
                        set_at,
                        setters,
                        [
                            (function, vrs, count, pointers[1 : m + 1])
                            for function, vrs, count, pointers, _, _, _ in getters
                        ],
                    )
                if not done:
                    raise FastLoopFailed("a step failed")
            chunk = result(slice(1, m + 1), times[1:])
            if pending is not None:
                chunk, pending = np.concatenate([pending, chunk]), None
            yield chunk
        with _quiet():
            try:
                fmu.terminate()
            except Exception as error:
                raise FastLoopFailed(str(error)) from None
