"""fmpy's own co-simulation loop (fmpy.simulate_fmu), for the traces the
Runner's fast loop cannot replay: its result as a structured array, a
failure as a SimulationError that quotes what the FMU said."""

import contextlib
import io
from dataclasses import dataclass
from typing import NamedTuple, Protocol

import numpy as np
from fmpy import simulate_fmu

from ._errors import SimulationError


class ReplaySteps(Protocol):
    """What the Runner's loop asks of recorded cycle lengths (a Replay, or one made as a recording is read)."""

    @property
    def times(self) -> np.ndarray | None:
        """The communication points, or None: the grid's."""

    def steps(self, k: int, m: int) -> tuple: ...

    @property
    def end(self) -> float: ...


class Replay(NamedTuple):
    """Recorded cycle lengths: doStep(points[k], sizes[k]) for each step k
    instead of the grid's (a size of 0: no doStep, the outputs held). The
    inputs are set and the results stand at the grid's times, or at times
    (the communication points, one more than the steps) where given."""

    points: np.ndarray
    sizes: np.ndarray
    times: np.ndarray | None = None

    def steps(self, k, m):
        """(points, sizes) of steps k to k + m - 1 (asked for in order: a streamed replay reads them so)."""
        return self.points[k : k + m], self.sizes[k : k + m]

    @property
    def end(self):
        """The last step's end: the FMU's stop time."""
        return float(self.points[-1] + self.sizes[-1]) if len(self.sizes) else 0.0


@dataclass(frozen=True)
class Experiment:
    """A simulation's time frame, as an FMU's DefaultExperiment gives it:
    from start to stop in communication steps of step."""

    start: float
    stop: float
    step: float
    relative_tolerance: float | None = None
    # recorded cycle lengths, one Replay step for each of the (stop - start) / step steps (or for each of its
    # times but the first). Only the Runner's own loop takes it (fmpy steps on a grid).
    replay: ReplaySteps | None = None


@dataclass(frozen=True)
class Signals:
    """What a simulation is fed and records: inputs (a structured array,
    time first, or None; or consecutive such arrays where a run takes
    chunks), start values {name: value} and the outputs' names."""

    inputs: object
    start_values: dict
    outputs: list


def held_to(inputs, stop_time):
    """fmpy needs two input samples: a single row is held until stop_time
    by a copy there (the same signal)."""
    if inputs is None or len(inputs) != 1:
        return inputs
    last = inputs.copy()
    last["time"] = max(stop_time, float(inputs["time"][0]))
    return np.concatenate([inputs, last])


def run_fmpy(
    fmu_location,
    model_description,
    experiment: Experiment,
    signals: Signals,
    fmi_type="CoSimulation",
    debug_logging=False,
):
    """One simulation: the result as a structured array ('time' first). A
    failure is a SimulationError that quotes the FMU's warnings and errors:
    an FMI 3 FMU logs nothing unless logging is on, so a failed run that
    said nothing is repeated once with logging on to hear why."""
    # fmpy prints the FMU's messages ("[ERROR] ...") with its default logger.
    # A logger of our own is no option for FMI 2: fmpy's native proxy for
    # FMI 2 loggers keeps the last one registered for the whole process,
    # and the callback simulate_fmu makes of it dies when simulate_fmu returns.
    printed = io.StringIO()
    start_time, stop_time, step_size = experiment.start, experiment.stop, experiment.step
    try:
        with contextlib.redirect_stdout(printed), np.errstate(invalid="ignore"):  # fmpy's notes; inf - inf in
            # fmpy's search for input events
            return simulate_fmu(
                fmu_location,
                model_description=model_description,
                start_time=start_time,
                stop_time=stop_time,
                output_interval=step_size,
                relative_tolerance=experiment.relative_tolerance,
                input=held_to(signals.inputs, stop_time),
                start_values=dict(signals.start_values),
                output=list(signals.outputs),
                fmi_type=fmi_type,
                debug_logging=debug_logging,
                # Model Exchange: no continuous states, so the solver only
                # carries the time from event to event; a row per output
                # point, as Co-Simulation records, not one per event too
                **(
                    {"solver": "Euler", "step_size": step_size, "record_events": False}
                    if fmi_type == "ModelExchange"
                    else {}
                ),
            )
    except Exception as error:  # fmpy raises FMICallException and plain Exceptions
        said = fmu_messages(printed.getvalue())
        if not said and not debug_logging:
            try:
                run_fmpy(fmu_location, model_description, experiment, signals, fmi_type, debug_logging=True)
            except SimulationError as again:
                raise again from error
        told = f"; the FMU said: {' | '.join(said[-3:])}" if said else ""
        raise SimulationError(f"the simulation failed: {str(error).rstrip('.')}{told}") from error


def fmu_messages(printed):
    """The FMU's warnings and errors among the lines fmpy printed."""
    marks = ("[WARNING] ", "[DISCARD] ", "[ERROR] ", "[FATAL] ")
    return [line.split("] ", 1)[1] for line in printed.splitlines() if line.startswith(marks)]
