"""A recording as a case of a campaign: read, matched to the FMU, laid on
its steps (align.py), and compared signal by signal, each on its own
samples; a failing comparison names the recording's file and line of its
first deviation and, where the inputs were sampled coarser than the step,
what that means."""
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..cases import Case
from ..comparison import Comparison, compare_traces
from ..errors import InputError
from . import read_recording, text as texts, vendors
from .align import TIMINGS, align
from .matching import plan
from .timebase import UNIT_NAMES, normalise

TIME_UNITS = ("s", "ms", "us", "ns", "cycles", "filetime")
_UNITS = {"filetime": "FILETIME"}


@dataclass(frozen=True)
class RecordingOptions:
    """How the recordings of a command are read (the same for all)."""
    step_size: float = None
    time_unit: str = None           # one of TIME_UNITS, None: the recording's own
    timing: str = "cycle"           # align.TIMINGS
    maps: tuple = ()                # (VARIABLE, CHANNEL) pairs
    start_values: tuple = ()        # (NAME, VALUE) pairs

    def __post_init__(self):
        if self.time_unit is not None and self.time_unit not in TIME_UNITS:
            raise InputError(f"--time-unit must be one of {', '.join(TIME_UNITS)}, not {self.time_unit!r}")
        if self.timing not in TIMINGS:
            raise InputError(f"--timing must be one of {', '.join(TIMINGS)}, not {self.timing!r}")
        if self.step_size is not None and not self.step_size > 0:
            raise InputError(f"--step-size must be greater than 0, not {self.step_size!r}")

    def settings(self) -> dict:
        return {"step_size": self.step_size, "time_unit": self.time_unit, "timing": self.timing,
                "maps": [list(m) for m in self.maps], "start_values": [list(s) for s in self.start_values]}


@dataclass
class RecordedCase(Case):
    references: list = field(default_factory=list)  # structured arrays, one per time base of the compared channels
    channels: dict = field(default_factory=dict)    # compared variable -> its Channel
    notes: list = field(default_factory=list)       # what was assumed, ignored or found
    coarse: str = ""                                # why an exact comparison cannot hold
    shift: int = 1                                  # steps from a row's time to its output's (timing)

    def compare(self, result, mode) -> Comparison:
        """Every compared signal on its own samples."""
        merged = Comparison()
        for reference in self.references:
            part = compare_traces(result, reference, mode)
            merged.deviations += part.deviations
            merged.bands.update(part.bands)
            merged.problem = merged.problem or part.problem
        return merged

    def explain(self, comparison) -> list:
        """What a failing comparison's reader needs beside the deviations:
        where in the recording the first ones are, and the notes."""
        messages = []
        step = self.options["StepSize"]
        for deviation in comparison.deviations:
            channel = self.channels.get(deviation.name)
            if deviation.passed or channel is None or deviation.time is None:
                continue
            cycle = int(round(deviation.time / step)) - self.shift
            at = np.flatnonzero(np.rint(channel.times / step).astype(np.int64) == cycle)
            if len(at):
                i = int(at[0])
                messages.append(first_differs(deviation, cycle, channel.where(i), float(channel.times[i]),
                                              float(channel.values[i])))
        if self.coarse:
            messages.append(self.coarse)
        return messages + self.notes


def first_differs(deviation, cycle, where, time, recorded):
    """Where a failing signal's first deviation is in the recording."""
    return (f"{deviation.name} first differs at the recording's sample of cycle {cycle} ({where}, t={time:.9g} s "
            f"from its first sample): recorded {recorded!r}, the FMU gives {deviation.value!r}")


def recording_paths(paths):
    """The recordings among paths given to compare: [(path, name)], where
    path is one file or folder, or several single-point files (Niagara)
    joined by os.pathsep: together they make one recording."""
    items, points = [], []
    for path in paths:
        path = os.fspath(path)
        if os.path.isfile(path) and _is_single_point(path):
            points.append(path)
        else:
            items.append((path, Path(path).name))
    if points:
        name = Path(points[0]).parent.name if len(points) > 1 else Path(points[0]).name
        items.append((os.pathsep.join(points), name))
    return items


def _is_single_point(path):
    try:
        with open(path, "rb") as file:
            head = file.read(4096)
    except OSError:
        return False
    try:
        decoded, _ = texts.decode(path, head)
    except InputError:
        return False
    return vendors.sniff_niagara(texts.Text(path, decoded, "")) is None


def recorded_case(path, fmu, name, options: RecordingOptions) -> RecordedCase:
    """The RecordedCase of the recording at path (recording_paths' form)
    for fmu; InputError (TraceError with file, line, column) for bad input."""
    found = read_recording(path.split(os.pathsep) if os.pathsep in path and not os.path.exists(path) else path)
    if len(found) != 1:
        raise InputError(f"{path}: holds {len(found)} recordings: give them one by one (or their files)")
    recording = found[0]
    normalise(recording, _UNITS.get(options.time_unit, options.time_unit), options.step_size, fmu.default_step)
    matched = plan(recording, fmu.variables, fmu.label, options.maps)
    aligned = align(recording, matched, options.timing, fmu.label)
    start_values = {n: fmu.start_value(n, v) for n, v in options.start_values}
    names = [v for reference in aligned.references for v in reference.dtype.names[1:]]
    unit = UNIT_NAMES.get(recording.time_unit, recording.time_unit)
    description = (f"{recording.format}: {len(recording)} samples, time as {unit} ({recording.time_source}), "
                   f"step {recording.step_size:g} s ({recording.step_source})")
    return RecordedCase(name=name, model=fmu.model, folder=Path(recording.paths[0]),
                        options={"StartTime": aligned.start_time, "StopTime": aligned.stop_time,
                                 "StepSize": aligned.step_size, "RelTol": 1e-6},
                        start_values=start_values, inputs=aligned.inputs, reference=_union(aligned.references, names),
                        description=description, references=aligned.references,
                        channels={v: c for v, c in matched.compares}, notes=aligned.notes + matched.describe(),
                        coarse=aligned.coarse,
                        shift=1 if options.timing == "cycle" else 0)


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
