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
from . import _clock as clock
from ._model import TIME_DIVISORS, TIME_FACTORS
from ._timebase import FINEST, OFF_CYCLE, _minus, as_read, cycle_times, decimal_resolution, finest_interval

TIMINGS = ("cycle", "fmi")
CYCLE_LENGTHS = ("nominal", "recorded")
MOST_NAMED = 100  # missing cycles named in a note and in results.json (the rest counted)


@dataclass
class Aligned:
    inputs: np.ndarray | None  # structured: time, then the driven variables (None if none)
    references: list  # structured arrays: time, then compared variables sharing those instants
    start_time: float
    stop_time: float
    step_size: float
    notes: list = field(default_factory=list)  # what was assumed, skipped or found
    coarse: str = ""  # why an exact comparison cannot hold (inputs sampled coarser than the step)
    grid: clock.Grid | None = None  # the cycles the samples were laid on (recorder's clock)
    clock: dict = field(default_factory=dict)  # the figures of the fit: results.json's "clock"
    description: str = ""  # the fit in words: jitter, missing cycles
    replay: tuple | None = None  # cycle_lengths "recorded": (points, sizes) of every step (size 0: no doStep)
    cycles: dict = field(default_factory=dict)  # id(channel) -> the cycle of each of its samples


def fitted_grid(recording, channels, names: Names = ()):
    """The clock.Grid that the samples of channels (those compared or
    driven) sit on, near the recording's step; InputError where they fit
    none (the best cycle found, and how far the samples are from it)."""
    step = recording.step_size
    times = np.unique(np.concatenate([c.times for c in channels]))
    grid = clock.fit(times, step)
    if recording.step_source == FINEST and clock.restep(grid, step) != step:
        # jitter and skipped cycles pulled the median interval off the cycle the samples sit on
        recording.step_size, recording.step_source = clock.restep(grid, step), "the cycle its time stamps fit"
    distance = grid.distance(times, grid.index(times))
    if clock.fits(distance):
        return grid
    jitter = clock.Jitter()
    jitter.add(distance)
    own = finest_interval(channels)
    best = f"a cycle of {grid.period:.6g} s leaves them {jitter.describe()} off"
    if own is not None and own != step:
        nearer = clock.fit(times, own)
        found = clock.Jitter()
        found.add(nearer.distance(times, nearer.index(times)))
        if found.typical < jitter.typical and found.largest < 0.5:
            best = f"their own intervals give a cycle of {nearer.period:.6g} s, {found.describe()} off it"
    raise InputError(
        f"{recording.label}: the samples of {', '.join(c.name for c in channels)} fit no grid of cycles of "
        f"{shortest(step)} s ({recording.step_source}): {best} (jitter is less than half a cycle); give the "
        f"recorder's cycle with {name_of(names, 'step_size')}"
    )


def _cycles_of(channel, grid, step, names):
    """(the cycle of each sample of channel on grid, the samples put apart):
    each sample's nearest cycle, or the one _apart puts it on; InputError
    for two samples on one cycle."""
    nearest = grid.index(channel.times)
    index, moved = _apart(nearest, grid.distance(channel.times, nearest))
    repeated = np.flatnonzero(np.diff(index) == 0)
    if len(repeated):
        i = int(repeated[0])
        raise InputError(
            f"{channel.where(i + 1)}: samples of {channel.name} at t={shortest(as_read(channel.times[i]))} s and "
            f"t={shortest(as_read(channel.times[i + 1]))} s fall on the same cycle of {shortest(step)} s, jitter of "
            f"up to half a cycle allowed: the step is coarser than the recording (give the recorder's cycle with "
            f"{name_of(names, 'step_size')})"
        )
    return index, moved


def _apart(index, distance):
    """(index, the samples moved): index (each sample's nearest cycle, its
    distance from it) with two samples that share a cycle put apart where
    the stamps allow it: the one farther from that cycle, on its side, goes
    to the neighbouring cycle if no sample has it (a message sent or
    stamped more than half a cycle late or early, as a CAN sender starting
    up does). Where the neighbour is taken too, or where more than
    clock.FAR_SHARE of the samples would move (a step coarser than the
    recording, not a sample out of turn), nothing moves (the caller
    refuses the two)."""
    repeated = np.flatnonzero(np.diff(index) == 0)
    if not len(repeated) or len(repeated) > clock.FAR_SHARE * len(index):
        return index, []
    apart = index.copy()
    moved = []
    for i in repeated.tolist():
        if apart[i] != apart[i + 1]:  # (a move before put these apart)
            continue
        cycle = int(apart[i])
        early, late = float(distance[i]), float(distance[i + 1])
        earlier_free = early < 0 and (i == 0 or apart[i - 1] < cycle - 1)
        later_free = late > 0 and (i + 2 == len(apart) or apart[i + 2] > cycle + 1)
        if earlier_free and (-early >= late or not later_free):
            apart[i] = cycle - 1
            moved.append(i)
        elif later_free:
            apart[i + 1] = cycle + 1
            moved.append(i + 1)
        else:
            return index, []
    return apart, moved


def _cycle_notes(channel, grid, index, moved, step, names):
    """The notes on channel's samples on their cycles: those more than
    OFF_CYCLE off their nearest cycle, and those put apart from it (moved)."""
    distance = grid.distance(channel.times, index)
    notes = []
    far = np.abs(distance) > OFF_CYCLE
    far[moved] = False
    off = np.flatnonzero(far)
    if len(off):
        i = int(off[0])
        note = off_cycle_note(
            channel.name, len(off), len(index), (channel.where(i), float(channel.times[i]), int(index[i])), grid
        )
        own = finest_interval([channel])
        if own is not None and own != step:
            own_grid = clock.fit(channel.times, own)
            if not (np.abs(own_grid.distance(channel.times, own_grid.index(channel.times))) > OFF_CYCLE).any():
                note += f". Its own stamps fit a step of {shortest(own)} s ({name_of(names, step_size=own)})."
        notes.append(note)
    if moved:
        i, first, largest = moved[0], float(distance[moved[0]]), float(np.abs(distance[moved]).max())
        notes.append(
            f"{channel.name}: {len(moved)} of its {len(index)} samples are more than half a cycle from their "
            "cycle, each put on the neighbouring cycle no other sample has (its nearest holds a nearer sample); "
            f"the first at {channel.where(i)}: t={shortest(as_read(channel.times[i]))} s, {abs(first):.3f} of a "
            f"cycle {'after' if first > 0 else 'before'} its cycle (the largest {largest:.3f})"
        )
    return notes


def off_cycle_note(name, off, samples, first, grid):
    """What a channel with stamps off their cycles gets: how many of its
    samples, the first (first: where, its file and line; its time,
    seconds; its cycle on grid)."""
    where, time, cycle = first
    return (
        f"{name}: {off} of its {samples} time stamps are more than {OFF_CYCLE:g} of a cycle "
        f"({OFF_CYCLE * grid.period:.6g} s) off their cycle, each on its nearest; the first at {where}: "
        f"t={shortest(as_read(time))} s, {float(grid.distance(time, cycle)):+.3f} cycles from cycle {int(cycle)}"
    )


def align(recording, plan, timing="cycle", label="the FMU", names: Names = (), cycle_lengths="nominal"):
    """The Aligned of a normalised recording and its Plan; names: the
    caller's words for the settings (RecordingOptions.names);
    cycle_lengths: 'nominal' (every step the step size) or 'recorded'
    (every step the recorded interval between its cycle's execution and
    the one before, Aligned.replay)."""
    if timing not in TIMINGS:
        raise InputError(f"timing must be one of {', '.join(TIMINGS)}, not {timing!r}")
    if cycle_lengths not in CYCLE_LENGTHS:
        raise InputError(f"cycle_lengths must be one of {', '.join(CYCLE_LENGTHS)}, not {cycle_lengths!r}")
    if not plan.compares:
        raise InputError(
            f"{recording.label}: no channel is an output of {label}: nothing to compare (channels: "
            f"{', '.join(c.name for c in recording.channels)}; map one with "
            f"{name_of(names, maps=('VARIABLE', 'CHANNEL'))})"
        )
    step = recording.step_size
    notes = list(recording.notes)
    shift = 1 if timing == "cycle" else 0
    used = list({id(c): c for _, c in plan.drives + plan.compares}.values())  # (a channel may drive and be compared)
    grid = fitted_grid(recording, [c for c in used if len(c.times)], names)
    step = recording.step_size  # (the fit may have found the cycle the median interval missed)
    numbered = {id(c): _cycles_of(c, grid, step, names) for c in used}
    index_of = {key: index for key, (index, _) in numbered.items()}
    put_apart = {key: moved for key, (_, moved) in numbered.items() if moved}  # from their nearest cycle
    if put_apart:
        # samples put apart from their nearest cycle: the grid's line through every sample on its cycle
        grid = clock.line(
            np.concatenate([index_of[id(c)] for c in used]), np.concatenate([c.times for c in used]), grid
        )
        first = min(int(index[0]) for index in index_of.values() if len(index))
        grid = clock.Grid(grid.period, grid.phase + first * grid.period)  # cycle 0 the first sample's
        index_of = {key: index - first for key, index in index_of.items()}
    for channel in used:
        for note in _cycle_notes(channel, grid, index_of[id(channel)], put_apart.get(id(channel), []), step, names):
            if note not in notes:  # a channel that drives and is compared is said once
                notes.append(note)
    # inputs: every driven channel held on the union of their sample cycles
    inputs = None
    coarse = []
    if plan.drives:
        indices = [index_of[id(channel)] for _, channel in plan.drives]
        cycles = np.unique(np.concatenate(indices))
        inputs = np.empty(len(cycles), dtype=[("time", np.float64)] + [(v, np.float64) for v, _ in plan.drives])
        inputs["time"] = cycle_times(cycles, step)
        for (variable, channel), index in zip(plan.drives, indices, strict=True):
            where = np.searchsorted(index, cycles, side="right") - 1
            inputs[variable] = channel.values[np.maximum(where, 0)]
            every = _interval(index)
            if every > 1:
                coarse.append((variable, every))
    references = []
    last = 0
    groups: dict[bytes, tuple[np.ndarray, list]] = {}  # the cycles' bytes -> (cycles, [(variable, channel)])
    for variable, channel in plan.compares:
        index = index_of[id(channel)]
        last = max(last, int(index[-1]) if len(index) else 0)
        groups.setdefault(index.tobytes(), (index, []))[1].append((variable, channel))
    for index, members in groups.values():
        reference = np.empty(len(index), dtype=[("time", np.float64)] + [(v, np.float64) for v, _ in members])
        reference["time"] = cycle_times(index + shift, step)
        for variable, channel in members:
            reference[variable] = channel.values
        references.append(reference)
    if inputs is not None:
        last = max(last, int(cycles[-1]))
    stop = float(cycle_times(np.array([max(last + shift, 1)]), step)[0])
    aligned = Aligned(inputs=inputs, references=references, start_time=0.0, stop_time=stop, step_size=step, notes=notes)
    aligned.cycles = index_of
    if coarse:
        aligned.coarse = _coarse_note(coarse, plan, index_of, step, names)
    executed = np.unique(np.concatenate([index_of[id(c)] for c in used]))
    _describe_clock(aligned, recording, used, index_of, grid, executed)
    if cycle_lengths == "recorded":
        aligned.replay = _replay(recording, used, index_of, np.arange(round(stop / step)) + 1 - shift, names)
    return aligned


def _describe_clock(aligned, recording, used, index_of, grid, executed):
    """The fit's figures (Aligned.clock) and words (Aligned.description, a
    note naming the missing cycles of a recording that samples every cycle)."""
    jitter = clock.Jitter()
    for channel in used:
        jitter.add(grid.distance(channel.times, index_of[id(channel)]))
    every = _interval(executed)
    count, first = clock.missing(executed, MOST_NAMED) if every == 1 else (0, [])
    aligned.grid = grid
    aligned.clock = clock_figures(grid, jitter, every, count, first)
    aligned.description = f"jitter {jitter.describe()}"
    if count:
        aligned.notes.append(missing_note(count, int(executed[-1] - executed[0]) + 1, first))


def missing_note(count, cycles, first):
    """The note on a recording that samples every cycle and has count of
    its cycles without a sample (the first of them: first)."""
    named = ", ".join(str(c) for c in first) + (f" and {count - len(first)} more" if count > len(first) else "")
    return (
        f"{count} of {cycles} cycles have no sample (cycles {named} from the first sample's): the OB did not run "
        "them (an overrun), or the recorder missed them"
    )


def clock_figures(grid, jitter, every, missing, first_missing):
    """results.json's "clock" of a recording: the cycle in the recorder's clock and the time of cycle 0
    (seconds from the first sample), the jitter, the cycles
    between samples, the missing cycles' count and the first of them."""
    return {
        "cycle_s": grid.period,
        "phase_s": grid.phase,
        **jitter.settings(),
        "sampled_every": every,
        "missing_cycles": missing,
        "first_missing": first_missing,
    }


def _replay(recording, used, index_of, cycles, names):
    """(points, sizes) of every step for cycle_lengths 'recorded': step k runs
    the execution of cycles[k] (k + 1 - shift) for the recorded interval since the
    execution before it, at the recorder's resolution (whole ticks of its
    time stamps, each interval one rounding: a TIME in ms is whole ms); the
    first execution runs a nominal step (nothing before it is recorded); a
    cycle without a sample gets no doStep (size 0)."""
    executed = np.unique(np.concatenate([index_of[id(c)] for c in used]))
    if _interval(executed) > 1:
        raise InputError(
            f"{recording.label}: {name_of(names, cycle_lengths='recorded')} replays every execution of the OB, but "
            f"the recording samples only every {_interval(executed)} cycles: compare with the nominal cycle lengths"
        )
    ticks, per_second = _ticks(recording, used)
    none = np.iinfo(np.int64).max
    execution = np.full(int(executed[-1]) + 1, none, dtype=np.int64)  # cycle -> its earliest sample's tick
    for channel in used:
        np.minimum.at(execution, index_of[id(channel)], ticks[id(channel)])
    ran = np.flatnonzero((cycles <= executed[-1]) & (execution[np.minimum(cycles, len(execution) - 1)] != none))
    stamps = execution[cycles[ran]]
    if (np.diff(stamps) < 0).any():
        raise InputError(f"{recording.label}: the recorded executions go back in time")
    if not len(ran):
        return np.zeros(len(cycles)), np.zeros(len(cycles))
    # each step's start counted in whole ticks after the first execution's nominal step: no sum of floats
    ticks = np.zeros(len(cycles), dtype=np.int64)
    ticks[ran[1:]] = np.diff(stamps)
    before = np.concatenate([[0], np.cumsum(ticks)[:-1]])
    sizes = ticks / per_second
    sizes[ran[0]] = recording.step_size
    points = before / per_second + np.where(np.arange(len(cycles)) > ran[0], recording.step_size, 0.0)
    return points, sizes


def _ticks(recording, channels):
    """({id(channel): its stamps from the recording's origin as whole ticks}, ticks per second): the
    recorder's resolution, the coarsest power of ten of its unit that makes every stamp whole."""
    unit = recording.time_unit
    if unit == "OLE days":  # WinCC stamps in whole ms; OLE days to four decimals of 1e-6 are within 9 us of them
        return {id(c): np.rint(c.times * 1000).astype(np.int64) for c in channels}, 1000.0
    elapsed = {id(c): _minus(c.stamps, recording.origin) for c in channels}
    if unit == "cycles":
        return {k: np.rint(v).astype(np.int64) for k, v in elapsed.items()}, 1 / recording.step_size
    per_unit = 1.0 if unit == "s" else TIME_DIVISORS.get(unit) or 1 / TIME_FACTORS[unit]
    digits = decimal_resolution(np.concatenate(list(elapsed.values())))
    if digits is not None:
        return {k: np.rint(v * 10.0**digits).astype(np.int64) for k, v in elapsed.items()}, per_unit * 10**digits
    raise InputError(
        f"{recording.label}: its time stamps have no resolution of a whole power of ten of their unit: the recorded "
        "cycle lengths cannot be read from them"
    )


def _interval(index):
    """The cycles between a channel's samples (its typical interval)."""
    if len(index) < 2:
        return 1
    return int(np.median(np.diff(index)))


def _coarse_note(coarse, plan, index_of, step, names):
    """What inputs sampled every N cycles mean, and a tolerance that is."""
    every = max(n for _, n in coarse)
    sampled = ", ".join(f"{v} every {n} cycles" for v, n in coarse)
    lag = float(cycle_times(np.array([every - 1]), step)[0])
    spans = []
    for variable, channel in plan.compares:
        gaps = np.diff(index_of[id(channel)])
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
