"""A recording as a case of a campaign: read, matched to the FMU, laid on
its steps (recordings._align), and compared signal by signal, each on its
own samples; a failing comparison names the recording's file and line of
its first deviation and, where the inputs were sampled coarser than the
step, what that means."""

import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ._cases import Case
from ._errors import InputError
from ._fmpy import Replay
from ._names import shortest
from .recordings import read_recording
from .recordings._align import align
from .recordings._matching import plan
from .recordings._options import RecordingOptions
from .recordings._timebase import UNIT_NAMES, nominal, normalise


@dataclass
class RecordedCase(Case):
    references: list = field(default_factory=list)  # structured arrays, one per time base of the compared channels
    channels: dict = field(default_factory=dict)  # compared variable -> its Channel
    notes: list = field(default_factory=list)  # what was assumed, ignored or found
    coarse: str = ""  # why an exact comparison cannot hold
    shift: int = 1  # steps from a row's time to its output's (timing)
    cycles: dict = field(default_factory=dict)  # compared variable -> the cycle of each of its samples
    clock: dict = field(default_factory=dict)  # the cycle fit's figures (results.json's "clock")
    replay: Replay | None = None  # cycle_lengths "recorded"

    def explain(self, deviations) -> list:
        """What a failing comparison's reader needs beside the deviations:
        where in the recording the first ones are, and the notes."""
        messages = []
        step = self.options["StepSize"]
        for deviation in deviations:
            channel = self.channels.get(deviation.name)
            if deviation.passed or channel is None or deviation.time is None:
                continue
            cycle = int(round(deviation.time / step)) - self.shift
            at = np.flatnonzero(self.cycles[deviation.name] == cycle)
            if len(at):
                i = int(at[0])
                messages.append(
                    first_differs(
                        deviation,
                        cycle,
                        channel.where(i),
                        nominal(float(channel.times[i]), cycle, step),
                        float(channel.values[i]),
                    )
                )
        if self.coarse:
            messages.append(self.coarse)
        return messages + self.notes


def first_differs(deviation, cycle, where, time, recorded):
    """Where a failing signal's first deviation is in the recording."""
    return (
        f"{deviation.name} first differs at the recording's sample of cycle {cycle} ({where}, t={shortest(time)} s "
        f"from its first sample): recorded {recorded!r}, the FMU gives {deviation.value!r}"
    )


def recorded_case(path, fmu, name, options: RecordingOptions) -> RecordedCase:
    """The RecordedCase of the recording at path (recording_paths' form)
    for fmu; InputError (TraceError with file, line, column) for bad input."""
    found = read_recording(path.split(os.pathsep) if os.pathsep in path and not os.path.exists(path) else path)
    if len(found) != 1:
        raise InputError(f"{path}: holds {len(found)} recordings: give them one by one (or their files)")
    recording = found[0]
    matched = plan(recording, fmu.variables, fmu.label, options.maps, options.names)
    used = [c for _, c in matched.drives + matched.compares]  # the time base: what is compared, nothing else
    normalise(recording, options.timebase_unit, options.step_size, fmu.default_step, options.names, used or None)
    aligned = align(recording, matched, options.timing, fmu.label, options.names, options.cycle_lengths)
    start_values = {n: fmu.start_value(n, v) for n, v in options.start_values}
    names = [v for reference in aligned.references for v in reference.dtype.names[1:]]
    unit = UNIT_NAMES.get(recording.time_unit, recording.time_unit)
    samples = max(len(c.values) for c in used or recording.channels)  # of the channels compared or driven
    description = (
        f"{recording.format}: {samples} samples, time as {unit} ({recording.time_source}), "
        f"step {shortest(recording.step_size)} s ({recording.step_source}), {aligned.description}"
        + (", cycle lengths as recorded" if aligned.replay is not None else "")
    )
    return RecordedCase(
        name=name,
        model=fmu.model,
        folder=Path(recording.paths[0]),
        options={
            "StartTime": aligned.start_time,
            "StopTime": aligned.stop_time,
            "StepSize": aligned.step_size,
            "RelTol": 1e-6,
        },
        start_values=start_values,
        inputs=aligned.inputs,
        reference=_union(aligned.references, names),
        description=description,
        references=aligned.references,
        channels={v: c for v, c in matched.compares},
        notes=aligned.notes + matched.describe(),
        coarse=aligned.coarse,
        shift=1 if options.timing == "cycle" else 0,
        cycles={v: aligned.cycles[id(c)] for v, c in matched.compares},
        clock=aligned.clock,
        replay=None if aligned.replay is None else Replay(*aligned.replay),
    )


def _union(references, names):
    """One table of every compared signal on the union of their instants,
    NaN where a signal has no sample (for the plot and the outputs)."""
    if len(references) == 1:
        return references[0]
    times = np.unique(np.concatenate([r["time"] for r in references]))
    union = np.full(len(times), np.nan, dtype=[("time", np.float64)] + [(n, np.float64) for n in names])
    union["time"] = times
    for reference in references:
        at = np.searchsorted(times, reference["time"])
        for name in reference.dtype.names[1:]:
            union[name][at] = reference[name]
    return union
