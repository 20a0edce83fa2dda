"""A recording laid on the FMU's steps: the input table fmpy's loop is fed
and the references the results are compared with.

The recorder's convention (the default, timing="cycle"): a row holds the
input a cycle read and the output that same cycle produced. In fmpy's
loop the inputs applied at t drive doStep(t, h), whose output is recorded
at t + h; so the sample of cycle k (stamped k*h from the first sample)
drives the step from k*h, and its output is compared with the result at
(k + 1)*h. With timing="fmi" a row is read as fmpy and the FMI
cross-check files write it: the output at the row's time, which is the
output of the cycle before (the first row's is the initial output).

    recorder row k:  | input u_k | output y_k |      (one cycle, k)
    fmpy:      set u_k at t=k*h -> doStep(k*h, h) -> y recorded at t=(k+1)*h
    timing=cycle:  y_k compared with the result at (k+1)*h
    timing=fmi:    y_k compared with the result at k*h

Inputs hold from their sample on (sample and hold, as the PLC's process
image does); before a channel's first sample its first value holds.
Channels sampled on other instants keep their own time bases: no value
is invented for a reference.
"""

from dataclasses import dataclass, field

import numpy as np

from .._errors import InputError
from .._names import Names, name_of, shortest
from ._timebase import OFF_CYCLE, as_read, cycle_times, cycles, finest_interval

TIMINGS = ("cycle", "fmi")


@dataclass
class Aligned:
    inputs: np.ndarray | None  # structured: time, then the driven variables (None if none)
    references: list  # structured arrays: time, then compared variables sharing those instants
    start_time: float
    stop_time: float
    step_size: float
    notes: list = field(default_factory=list)  # what was assumed, skipped or found
    coarse: str = ""  # why an exact comparison cannot hold (inputs sampled coarser than the step)


def _cycles_of(channel, step, notes, names):
    index, off = cycles(channel.times, step)
    if len(off):
        i = int(off[0])
        note = off_cycle_note(channel.name, len(off), len(index), channel.where(i), float(channel.times[i]), step)
        own = finest_interval([channel])
        if own is not None and cycles(channel.times, own)[1].size == 0 and own != step:
            note += f" Its own stamps fit a step of {shortest(own)} s ({name_of(names, step_size=own)})."
        if note not in notes:  # a channel that drives and is compared is said once
            notes.append(note)
    repeated = np.flatnonzero(np.diff(index) == 0)
    if len(repeated):
        i = int(repeated[0])
        raise InputError(
            f"{channel.where(i + 1)}: samples of {channel.name} at t={shortest(as_read(channel.times[i]))} s and "
            f"t={shortest(as_read(channel.times[i + 1]))} s fall on the same cycle of {shortest(step)} s: the step is "
            f"coarser than the recording (give the recorder's cycle with {name_of(names, 'step_size')})"
        )
    return index


def off_cycle_note(name, off, samples, where, time, step):
    """What a channel with off time stamps gets: how many of its samples,
    the first (where: its file and line, time: seconds)."""
    return (
        f"{name}: {off} of its {samples} time stamps are more than {OFF_CYCLE:g} of a cycle "
        f"({shortest(OFF_CYCLE * step)} s) off a cycle end, matched to the nearest one; the first at {where}: "
        f"t={shortest(as_read(time))} s, {time / step:.3f} cycles: is the step size the recorder's cycle?"
    )


def _interval(index):
    """The cycles between a channel's samples (its typical interval)."""
    if len(index) < 2:
        return 1
    return int(np.median(np.diff(index)))


def align(recording, plan, timing="cycle", label="the FMU", names: Names = ()):
    """The Aligned of a normalised recording and its Plan; names: the
    caller's words for the settings (RecordingOptions.names)."""
    if timing not in TIMINGS:
        raise InputError(f"timing must be one of {', '.join(TIMINGS)}, not {timing!r}")
    if not plan.compares:
        raise InputError(
            f"{recording.label}: no channel is an output of {label}: nothing to compare (channels: "
            f"{', '.join(c.name for c in recording.channels)}; map one with "
            f"{name_of(names, maps=('VARIABLE', 'CHANNEL'))})"
        )
    step = recording.step_size
    notes = list(recording.notes)
    shift = 1 if timing == "cycle" else 0
    # inputs: every driven channel held on the union of their sample cycles
    inputs = None
    coarse = []
    if plan.drives:
        indices = [_cycles_of(channel, step, notes, names) for _, channel in plan.drives]
        grid = np.unique(np.concatenate(indices))
        inputs = np.empty(len(grid), dtype=[("time", np.float64)] + [(v, np.float64) for v, _ in plan.drives])
        inputs["time"] = cycle_times(grid, step)
        for (variable, channel), index in zip(plan.drives, indices, strict=True):
            where = np.searchsorted(index, grid, side="right") - 1
            inputs[variable] = channel.values[np.maximum(where, 0)]
            every = _interval(index)
            if every > 1:
                coarse.append((variable, every))
    references = []
    last = 0
    groups: dict[bytes, tuple[np.ndarray, list]] = {}  # the cycles' bytes -> (cycles, [(variable, channel)])
    for variable, channel in plan.compares:
        index = _cycles_of(channel, step, notes, names)
        last = max(last, int(index[-1]) if len(index) else 0)
        groups.setdefault(index.tobytes(), (index, []))[1].append((variable, channel))
    for index, members in groups.values():
        reference = np.empty(len(index), dtype=[("time", np.float64)] + [(v, np.float64) for v, _ in members])
        reference["time"] = cycle_times(index + shift, step)
        for variable, channel in members:
            reference[variable] = channel.values
        references.append(reference)
    if inputs is not None:
        last = max(last, int(np.rint(inputs["time"][-1] / step)))
    stop = float(cycle_times(np.array([max(last + shift, 1)]), step)[0])
    aligned = Aligned(inputs=inputs, references=references, start_time=0.0, stop_time=stop, step_size=step, notes=notes)
    if coarse:
        aligned.coarse = _coarse_note(coarse, plan, step, names)
    return aligned


def _coarse_note(coarse, plan, step, names):
    """What inputs sampled every N cycles mean, and a tolerance that is."""
    every = max(n for _, n in coarse)
    sampled = ", ".join(f"{v} every {n} cycles" for v, n in coarse)
    lag = float(cycle_times(np.array([every - 1]), step)[0])
    spans = []
    for variable, channel in plan.compares:
        index = np.rint(channel.times / step)
        gaps = np.diff(index)
        moves = np.abs(np.diff(channel.values))
        ok = (gaps > 0) & np.isfinite(moves)
        if ok.any():
            rate = float(np.max(moves[ok] / gaps[ok]))
            spans.append((variable, rate * (every - 1)))
    tolerance = max((s for _, s in spans), default=0.0)
    return (
        f"the recording's inputs were sampled coarser than the step ({sampled}; step {shortest(step)} s): between two "
        "samples the FMU holds the last recorded value while the controller saw values the recording does not "
        f"hold, so its output may lead or lag the recorded one by up to {every - 1} cycles and an exact "
        "comparison cannot hold. A meaningful comparison allows that lag: "
        f"{name_of(names, tube_time=lag, tube_value=0.0)}, or {name_of(names, abs_tol=tolerance)} "
        "(the largest change of "
        f"{', '.join(v for v, _ in spans) or 'the outputs'} over {every - 1} cycles, as recorded)"
    )
