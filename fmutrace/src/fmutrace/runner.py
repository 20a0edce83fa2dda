"""Many traces through one FMU instance, at close to the cost of the FMU's
own calls, with results bit for bit equal to fmpy.simulate_fmu's.

A Runner unpacks the FMU and reads its model description once, makes one
instance with fmpy and reuses it across traces through the standard reset
(fmi2Reset / fmi3Reset). A trace starts as fmpy starts it (fmpy's own
start-value function and calls, in its order); its steps then run from
arrays: the input values of every step are computed at once with fmpy's
rule (`discrete_rows`), the outputs are read with the FMI functions
straight from the library into arrays kept from trace to trace, one call
per variable type as fmpy's recorder makes them.

The fast loop gives fmpy's result when (checked by `fast_path_problem`
before a trace starts):
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
import math
from ctypes import c_void_p

import cffi
import numpy as np
from fmpy.simulation import apply_start_values, instantiate_fmu, settable_in_initialization_mode, \
    settable_in_instantiated

from .fmu import REAL_TYPES, unpacked
from .simulation import held_to, run_fmpy

# per FMI type: the C type's dtype (fmpy's Input tables and getters) and the
# recorded column's dtype (fmpy's Recorder)
FMI2_TYPES = {"Real": (np.float64, np.float64), "Integer": (np.int32, np.int32), "Boolean": (np.int32, np.bool_)}
FMI3_TYPES = {t: (d, d) for t, d in (("Float32", np.float32), ("Float64", np.float64), ("Int8", np.int8),
                                     ("UInt8", np.uint8), ("Int16", np.int16), ("UInt16", np.uint16),
                                     ("Int32", np.int32), ("UInt32", np.uint32), ("Int64", np.int64),
                                     ("UInt64", np.uint64), ("Boolean", np.bool_))}


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
    return np.unique(np.concatenate(events))


# The hot loop calls the library through cffi: a call costs about half what
# a ctypes call does. The values are passed as byte pointers into NumPy arrays.
FFI = cffi.FFI()
FFI.cdef("\n".join(
    [f"int fmi2{verb}{kind}(void *, const unsigned int *, size_t, char *);"
     for kind in FMI2_TYPES for verb in ("Set", "Get")]
    + [f"int fmi3{verb}{kind}(void *, const unsigned int *, size_t, char *, size_t);"
       for kind in FMI3_TYPES for verb in ("Set", "Get")]
    + ["int fmi2DoStep(void *, double, double, int);",
       "int fmi3DoStep(void *, double, double, bool, bool *, bool *, bool *, double *);"]))

KEPT_SHAPES = 8  # grids and output arrays kept for traces of so many shapes (memory stays flat)


def _forget_oldest(kept):
    if len(kept) >= KEPT_SHAPES:
        del kept[next(iter(kept))]


def _row_pointers(values):
    """A char pointer to each row of a 2-D array."""
    base = FFI.cast("char *", values.ctypes.data)
    return [base + k * values.strides[0] for k in range(len(values))]


def _value_references(variables):
    return FFI.new("unsigned int[]", [v.valueReference for v in variables])


def _close(a, b):
    """math.isclose elementwise (relative 1e-9)."""
    return np.abs(a - b) <= 1e-9 * np.maximum(np.abs(a), np.abs(b))


_LOOPS = {}


def _step_loop(fmi3, outputs):
    """The step loop for an FMI version and a number of output types: per
    step the inputs where they change, doStep and one get per type, into
    the next row; False as soon as a call fails or an FMI 3 step asks to
    stop. Written out per shape
    (Python source made here once per shape): an inner loop over the
    getters would cost as much as a call."""
    key = (fmi3, outputs)
    if key not in _LOOPS:
        names = [f"g{i}" for i in range(outputs)]
        unpack = "".join(f"    ({name}, {name}_vrs, {name}_n), = getters[{i}:{i + 1}]\n" for i, name in enumerate(names))
        rows = "".join(f", {name}_row" for name in names)
        row_lists = "".join(f", rows[{i}]" for i in range(outputs))
        if fmi3:
            calls = "".join(f" | {name}(component, {name}_vrs, {name}_n, {name}_row, {name}_n)" for name in names)
            step = "do_step(component, t, h, True, event, terminate, early, last)"
            check = "status > 1 or stop[0]"
            unpack += "    event, terminate, early, stop, last = flags\n"
        else:
            calls = "".join(f" | {name}(component, {name}_vrs, {name}_n, {name}_row)" for name in names)
            step = "do_step(component, t, h, 1)"
            check = "status > 1"
        source = (f"def loop(do_step, component, times, sizes, set_at, set_inputs, getters, rows, flags):\n"
                  f"{unpack}"
                  f"    for t, h, row{rows} in zip(times, sizes, set_at{row_lists}):\n"
                  f"        if row is not None and set_inputs(row) > 1:\n"
                  f"            return False\n"
                  f"        status = {step}{calls}\n"
                  f"        if {check}:\n"
                  f"            return False\n"
                  f"    return True\n")
        namespace = {}
        exec(compile(source, f"<fmutrace step loop {key}>", "exec"), namespace)
        _LOOPS[key] = namespace["loop"]
    return _LOOPS[key]


class Runner:
    """One FMU instance in this process, reused for trace after trace."""

    def __init__(self, fmu_bytes):
        self.folder, self.md = unpacked(fmu_bytes)
        self.fmi3 = self.md.fmiVersion.startswith("3")
        self.types = FMI3_TYPES if self.fmi3 else FMI2_TYPES
        self.variables = {v.name: v for v in self.md.modelVariables}
        self.order = {v.name: i for i, v in enumerate(self.md.modelVariables)}
        self.variable_step = bool(self.md.coSimulation.canHandleVariableCommunicationStepSize)
        self.fmu = self._lib = None
        self.fast_runs = self.fmpy_runs = 0
        self._grids = {}    # (start, step, n) -> the communication points and step sizes as C doubles
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
            if self.fmi3:
                self._flags = FFI.new("bool[4]")  # eventHandlingNeeded, terminateSimulation, earlyReturn, (pad)
                self._stop_flags = FFI.cast("uint16_t *", self._flags + 1)  # terminate or early return: one read
                self._last_time = FFI.new("double *")
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

    def fast_path_problem(self, start, stop, step, inputs, outputs):
        """Why the fast loop would not give fmpy's result for this trace
        (None if it would); see the module's docstring."""
        n = round((stop - start) / step)
        if n < 1 or not math.isclose(start + n * step, stop):
            return "the stop time is not a whole number of steps from the start"
        if any(self.variables[name].shape for name in outputs):
            return "an array variable"
        if inputs is None:
            return None
        for name in inputs.dtype.names[1:]:
            v = self.variables[name]
            if v.shape or (v.type in REAL_TYPES and v.variability not in ("discrete", "tunable")):
                return f"{name} is a continuous input (fmpy interpolates it)"
        if self.variable_step:
            events = input_events(inputs)
            events = events[(events > start) & (events < stop) & ~_close(events, start) & ~_close(events, stop)]
            grid = start + np.rint((events - start) / step) * step  # Python's round() also rounds half to even
            off = ~_close(grid, events)
            if off.any():
                return f"an input event at t={events[off][0]!r} between communication points"
        return None

    def run(self, start, stop, step, inputs, start_values, outputs, relative_tolerance=None):
        """The trace's result, as fmpy.simulate_fmu(..., output_interval=step)
        returns it (a structured array). SimulationError if the FMU fails."""
        inputs = held_to(inputs, stop)  # as run_fmpy gives them to fmpy
        if self.fast_path_problem(start, stop, step, inputs, outputs) is None:
            with contextlib.redirect_stdout(io.StringIO()):  # what fmpy's default logger prints
                result = self._fast(start, stop, step, inputs, start_values, outputs, relative_tolerance)
            if result is not None:
                self.fast_runs += 1
                return result
            self._drop_instance()  # a call failed: fmpy tells the story on an instance of its own
        self.fmpy_runs += 1
        return run_fmpy(self.folder, self.md, start_time=start, stop_time=stop, step_size=step, inputs=inputs,
                        start_values=start_values, outputs=outputs, relative_tolerance=relative_tolerance)

    def _grid(self, start, step, n):
        """fmpy's communication points, start + (n_steps + 1) * output_interval,
        and the step sizes it passes (next point - time)."""
        key = (start, step, n)
        if key not in self._grids:
            _forget_oldest(self._grids)
            times = np.concatenate(([start], start + np.arange(1, n + 1, dtype=np.float64) * step))
            self._grids[key] = times, times[:-1].tolist(), (times[1:] - times[:-1]).tolist()
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
        groups = {}
        for name in sorted(names, key=self.order.get):
            v = self.variables[name]
            groups.setdefault(self._kind(v), []).append(v)
        return groups

    def _fast(self, start, stop, step, inputs, start_values, outputs, tolerance):
        fmu = self._instance()
        n = round((stop - start) / step)
        times, step_times, step_sizes = self._grid(start, step, n)
        component = self._component

        # inputs: per FMI type (fmpy's grouping, by the variable's type) the values at the steps where a row changes
        setters = []
        changes = np.array([0])
        if inputs is not None:
            t = inputs["time"]
            rows = discrete_rows(t, times[:-1], after_event=True)
            first = discrete_rows(t, times[:1], after_event=False)
            changes = np.concatenate(([0], np.flatnonzero(rows[1:] != rows[:-1]) + 1))
            groups = {}
            for name in sorted(inputs.dtype.names[1:], key=self.order.get):
                v = self.variables[name]
                groups.setdefault(v.type, []).append(v)
            for variables in groups.values():
                kind = self._kind(variables[0])
                table = np.asarray(np.stack([inputs[v.name] for v in variables]),
                                   dtype=self.types[kind][0])  # fmpy's conversion
                values = np.ascontiguousarray(np.concatenate([table[:, first], table[:, rows[changes]]], axis=1).T)
                setters.append((self._set[kind], _value_references(variables), len(variables), values,
                                _row_pointers(values)))

        # outputs: per FMI type in the recorder's order, into the kept arrays
        getters, columns = [], [("time", np.float64)]
        groups = self._groups([name for name in outputs if name != "time"])
        for kind in self.types:
            if kind in groups:
                variables = groups[kind]
                values, pointers = self._buffer(kind, len(variables), n)
                getters.append((self._get[kind], _value_references(variables), len(variables), pointers, values,
                                variables, kind))
                columns += [(v.name, self.types[kind][1]) for v in variables]
        fmi3 = self.fmi3

        def set_inputs(row):
            status = 0
            for function, vrs, count, _, pointers in setters:
                status |= function(component, vrs, count, pointers[row], count) if fmi3 else \
                    function(component, vrs, count, pointers[row])
            return status

        try:
            if fmi3:
                remaining = apply_start_values(fmu, self.md, start_values, settable=settable_in_instantiated)
                fmu.enterInitializationMode(tolerance=tolerance, startTime=start, stopTime=stop)
            else:
                fmu.setupExperiment(tolerance=tolerance, startTime=start, stopTime=stop)
                remaining = apply_start_values(fmu, self.md, start_values, settable=settable_in_instantiated)
                fmu.enterInitializationMode()
            remaining = apply_start_values(fmu, self.md, remaining, settable=settable_in_initialization_mode)
            if remaining or set_inputs(0) > 1:
                return None
            fmu.exitInitializationMode()
        except Exception:  # fmpy's calls raise on an error status
            return None

        status = 0
        for function, vrs, count, pointers, _, _, _ in getters:
            status |= function(component, vrs, count, pointers[0], count) if fmi3 else \
                function(component, vrs, count, pointers[0])
        if status > 1:
            return None
        set_at = [None] * n  # the row of the setters' values to set before step k (None: no change)
        if setters:
            for row, k in enumerate(changes.tolist(), start=1):
                set_at[k] = row
        loop = _step_loop(fmi3, len(getters))
        getter_arguments = [(function, vrs, count) for function, vrs, count, _, _, _, _ in getters]
        rows = [pointers[1:] for _, _, _, pointers, _, _, _ in getters]
        flags = (self._flags, self._flags + 1, self._flags + 2, self._stop_flags, self._last_time) if fmi3 else ()
        if not loop(self._do_step, component, step_times, step_sizes, set_at, set_inputs, getter_arguments, rows,
                    flags):
            return None
        try:
            fmu.terminate()
        except Exception:
            return None

        result = np.empty(n + 1, dtype=columns)
        result["time"] = times
        for _, _, _, _, values, variables, kind in getters:
            for i, v in enumerate(variables):
                result[v.name] = values[:, i] != 0 if kind == "Boolean" and not self.fmi3 else values[:, i]
        return result
