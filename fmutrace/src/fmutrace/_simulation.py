"""Simulations as fmpy.simulate_fmu makes them (simulate: through the
Runner's own loop where it gives fmpy's result, else fmpy's).

fmpy's co-simulation loop applies the inputs at t (a row holds from its
time on for discrete inputs, continuous ones are interpolated; at a
repeated time the row after the event), calls doStep(t, h) and records
the outputs at t + h.
"""

import math
from dataclasses import dataclass
from os import PathLike
from pathlib import Path

import numpy as np

from ._errors import InputError
from ._fmpy import Experiment, Signals
from ._fmu import Fmu
from ._runner import Runner
from ._traces import read_trace
from .recordings._timebase import MAX_STEPS


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
    fmu = fmu if isinstance(fmu, Fmu) else Fmu(fmu)
    if isinstance(input, (str, Path)):
        inputs = read_trace(input, fmu.input_problem)
    elif input is not None:
        inputs = np.asarray(input)
        if inputs.dtype.names is None or "time" not in inputs.dtype.names:
            raise InputError("the input must be a structured array with a 'time' field")
        for name in inputs.dtype.names:
            problem = name != "time" and fmu.input_problem(name)
            if problem:
                raise InputError(problem)
    else:
        inputs = None
    options = SimulationOptions(start_values, start_time, stop_time, step_size, output_interval, outputs)
    times = inputs["time"] if inputs is not None and len(inputs) else None
    experiment, signals = resolved(fmu, options, (times[0], times[-1]) if times is not None else None)
    runner = Runner(fmu.path.read_bytes())  # its own loop where it gives fmpy's result, else fmpy's
    try:
        result = runner.run(experiment, Signals(inputs, signals.start_values, signals.outputs))
    finally:
        runner.close()
    return every_nth(result, experiment.start, experiment.step, output_interval)


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
    steps = (stop - start) / step
    if steps > MAX_STEPS:  # refused before anything is allocated: the result would not fit in memory
        raise InputError(
            f"{steps:.3g} steps of {step!r} s from {start!r} to {stop!r} s: more than the bound of "
            f"{MAX_STEPS:,} steps (a step size or time in another unit?)"
        )
    return Experiment(start, stop, step), Signals(None, values, names)
