"""Simulations as fmpy.simulate_fmu makes them (simulate: through the
Runner's own loop where it gives fmpy's result, else fmpy's).

fmpy's co-simulation loop applies the inputs at t (a row holds from its
time on for discrete inputs, continuous ones are interpolated; at a
repeated time the row after the event), calls doStep(t, h) and records
the outputs at t + h.
"""

import math
from collections.abc import Iterator
from dataclasses import dataclass
from os import PathLike

import numpy as np

from ._errors import InputError
from ._fmpy import Experiment, Signals
from ._fmu import Fmu
from ._progress import SampleProgress
from ._reading import read_bytes
from ._runner import STEPS_PER_CHUNK, Runner
from ._traces import CHUNK_BYTES, NotPlain, last_time, read_trace, steps_problem, trace_chunks


def every_nth(result, start_time, step_size, output_interval):
    """The samples of result at multiples of output_interval from start_time."""
    if output_interval is None or output_interval == step_size:
        return result
    ratio = output_interval / step_size
    n = round(ratio)
    if n < 1 or not math.isclose(ratio, n, rel_tol=1e-9):
        raise InputError(
            f"the output interval {output_interval:g} s must be a whole multiple of the step size {step_size:g} s"
        )
    steps = np.rint((result["time"] - start_time) / step_size).astype(np.int64)
    return result[steps % n == 0]


@dataclass(frozen=True)
class SimulationOptions:
    """A simulation's settings, as simulate takes them (None: its default)."""

    start_values: dict | None = None
    start_time: float | None = None
    stop_time: float | None = None
    step_size: float | None = None
    output_interval: float | None = None
    outputs: list[str] | None = None


def simulate(
    fmu: str | PathLike | Fmu,
    input: str | PathLike | np.ndarray | None = None,
    *,
    start_values: dict | None = None,
    start_time: float | None = None,
    stop_time: float | None = None,
    step_size: float | None = None,
    output_interval: float | None = None,
    outputs: list[str] | None = None,
) -> np.ndarray:
    """Simulate an FMI 2 or FMI 3 co-simulation FMU on input signals.

    fmu              path of the .fmu file
    input            a CSV file (any dialect fmutrace reads) or a structured
                     array with a 'time' field, or None
    start_values     {name: value}; values may be text ("2.5", "true")
    start_time       default: the input's first time, else the FMU's default
                     experiment, else 0
    stop_time        default: the input's last time, else the FMU's default
    step_size        the communication step (a PLC cycle for these FMUs);
                     default: the FMU's default step size
    output_interval  a whole multiple of step_size (default: step_size)
    outputs          names to record (default: the FMU's outputs)

    Returns a NumPy structured array, 'time' first. Raises InputError for
    bad input (nothing is run) and SimulationError if the FMU fails.
    """
    options = SimulationOptions(start_values, start_time, stop_time, step_size, output_interval, outputs)
    chunks = list(simulate_chunks(fmu, input, options))
    return chunks[0] if len(chunks) == 1 else np.concatenate(chunks)


def simulate_chunks(
    fmu: str | PathLike | Fmu,
    input: str | PathLike | np.ndarray | None = None,
    options: SimulationOptions = SimulationOptions(),
    chunk_bytes: int = CHUNK_BYTES,
    steps_per_chunk: int = STEPS_PER_CHUNK,
    progress: bool = False,
) -> Iterator[np.ndarray]:
    """simulate's result as consecutive structured arrays, made as they are
    asked for: an input file of the plain dialect is read chunk by chunk
    (chunk_bytes of text each), so memory does not grow with its length;
    any other is read whole by read_trace. InputError for bad input before
    the FMU runs (a value further into a long file than the first chunk
    as the run reaches it), SimulationError if the FMU fails. progress: a
    progress bar on standard error (on a terminal only)."""
    fmu = fmu if isinstance(fmu, Fmu) else Fmu(fmu)
    table, names, span = _input_table(fmu, input, chunk_bytes)
    experiment, signals = resolved(fmu, options, span)
    interval = options.output_interval
    every_nth(np.empty(0, dtype=[("time", np.float64)]), experiment.start, experiment.step, interval)  # checked now
    runner = Runner(read_bytes(fmu.path))  # its own loop where it gives fmpy's result, else fmpy's
    bar = SampleProgress(round((experiment.stop - experiment.start) / experiment.step) + 1) if progress else None
    made = 0
    try:
        results = runner.run_chunks(
            experiment, Signals(table, signals.start_values, signals.outputs), names, steps_per_chunk
        )
        try:
            for chunk in results:
                made += len(chunk)
                if bar is not None:
                    bar.update(made)
                yield every_nth(chunk, experiment.start, experiment.step, interval)
        except NotPlain as error:  # a later chunk of an input file: read_trace says where
            if isinstance(input, (str, PathLike)):
                read_trace(input, fmu.input_problem)
            raise InputError(f"{input}: {error}") from None
    finally:
        if bar is not None:
            bar.close()
        runner.close()


def _input_table(fmu: Fmu, input, chunk_bytes) -> tuple:
    """(a function that gives the input table's chunks from its first row,
    or None; its columns; its first and last time, or None)."""
    if input is None:
        return None, (), None
    if isinstance(input, (str, PathLike)):
        try:
            first = next(trace_chunks(input, fmu.input_problem, chunk_bytes=1 << 16))
            span = (float(first["time"][0]), last_time(input))
        except (NotPlain, OSError, ValueError, StopIteration):
            whole = read_trace(input, fmu.input_problem)  # it reads the file, or says what is wrong where
            return (lambda: iter([whole])), tuple(whole.dtype.names or ())[1:], _span(whole)
        names = tuple(first.dtype.names or ())[1:]
        return (lambda: trace_chunks(input, fmu.input_problem, chunk_bytes=chunk_bytes)), names, span
    inputs = np.asarray(input)
    if inputs.dtype.names is None or "time" not in inputs.dtype.names:
        raise InputError("the input must be a structured array with a 'time' field")
    for name in inputs.dtype.names:
        problem = name != "time" and fmu.input_problem(name)
        if problem:
            raise InputError(problem)
    return (lambda: iter([inputs])), inputs.dtype.names[1:], _span(inputs)


def _span(inputs):
    return (float(inputs["time"][0]), float(inputs["time"][-1])) if len(inputs) else None


def resolved(fmu: Fmu, options: SimulationOptions, input_span: tuple | None) -> tuple[Experiment, Signals]:
    """A simulation's experiment and signals (its inputs left None) with
    every default resolved, for simulate and `fmutrace run` alike: the
    times given, else the input's first and last time (input_span), else
    the FMU's default experiment (else a start at 0); the FMU's default
    step; its outputs. InputError for what cannot be run."""
    values = {name: fmu.start_value(name, value) for name, value in (options.start_values or {}).items()}
    names = list(options.outputs) if options.outputs else fmu.outputs
    for name in names:
        problem = fmu.variable_problem(name)
        if problem:
            raise InputError(f"output {problem.removeprefix('column ')}")

    def first(*candidates):
        return next((float(c) for c in candidates if c is not None), None)

    first_time, last_time = input_span if input_span is not None else (None, None)
    start = first(options.start_time, first_time, fmu.default_start, 0.0)
    stop = first(options.stop_time, last_time, fmu.default_stop)
    step = first(options.step_size, fmu.default_step)
    if step is None:
        raise InputError(f"{fmu.label} gives no default step size: give step_size")
    if not (step > 0 and math.isfinite(step)):
        raise InputError(f"the step size must be a finite number greater than 0, not {step!r}")
    if stop is None or not stop > start or not math.isfinite(stop - start):
        raise InputError(f"the stop time ({stop!r}) must be after the start time ({start!r}), both finite")
    problem = steps_problem(start, stop, step)
    if problem:
        raise InputError(problem)
    return Experiment(start, stop, step), Signals(None, values, names)
