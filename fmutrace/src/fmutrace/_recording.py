"""A recording as a case of the pipeline (_pipeline.run_chunked_case): a
one-file table export read in blocks of lines as it is compared
(recordings._stream reads it), in memory that does not grow with its
length; any other recording, or one the blocks cannot follow, read whole
(_recorded.recorded_case). Its notes and messages are the same either
way, word for word."""

import os
import time

import numpy as np

from ._errors import InputError
from ._names import shortest
from ._pipeline import ChunkedCase, Streaming, run_chunked_case
from ._outcome import CaseOutcome, Status
from ._recorded import first_differs, recorded_case
from ._traces import NotPlain
from .recordings import _clock as clock, _stream as stream, _timebase as timebase
from .recordings._align import MOST_NAMED, clock_figures, missing_note, off_cycle_note
from .recordings._timebase import OFF_CYCLE
from .recordings._matching import plan


SECONDS_OF_DECIMALS = ("s", "ms", "us", "ns", "FILETIME", "date")  # stamps whose resolution is a decimal of a second


class _StreamedReplay:
    """A Replay (recorded cycle lengths) of a streamed recording, its steps
    made from the rows' stamps as the blocks are read (read: reads the next
    block, which add()s its rows; False at the end), as recordings._align's
    replay makes them from a recording read whole: step k executes cycle
    k + 1 - shift; a cycle with a row runs for the interval since the row
    before at the recorder's resolution (the first one step size), a cycle
    without one gets no doStep (size 0). Each step's start is counted in
    whole ticks: no sum of floats."""

    times = None  # (the results stand at the grid's times)

    def __init__(self, cycles, step, shift, read):
        self.step, self.read = step, read
        self.scale = 10.0**cycles.digits  # ticks per second
        first, *second, last = cycles.ends
        self.origin = self._ticks(second[0] if shift == 0 and second else first)  # the first step's row's tick
        self.end = step + (self._ticks(last) - self.origin) / self.scale
        self.next_cycle = 1 - shift  # the cycle of the next step to make
        self.tick = None  # the tick of the last row read
        self.started = False  # a step with a row made (the first runs one step size)
        self.points: list[np.ndarray] = []  # steps made and not yet asked for
        self.sizes: list[np.ndarray] = []
        self.made = 0

    def _ticks(self, seconds):
        return np.rint(np.asarray(seconds, dtype=np.float64) * self.scale).astype(np.int64)

    def add(self, times, index):
        """The steps through the cycle of the last of these rows (times, their cycles index)."""
        ticks = self._ticks(times)
        before = np.concatenate([[ticks[0] if self.tick is None else self.tick], ticks[:-1]])
        self.tick = int(ticks[-1])
        rows = index >= self.next_cycle
        ticks, before, index = ticks[rows], before[rows], index[rows]
        if not len(index):
            return
        if (ticks < before).any():
            raise NotPlain("recorded executions that go back in time (the in-memory path says)")
        cycles = np.arange(self.next_cycle, int(index[-1]) + 1)
        at = index - self.next_cycle  # each row's step among these
        sizes = np.zeros(len(cycles))
        sizes[at] = (ticks - before) / self.scale
        points = np.zeros(len(cycles))
        # each step starts at the row before it: the last row of a cycle before the step's
        last_row = np.searchsorted(index, cycles, side="left") - 1  # (-1: the row before these)
        start_tick = np.where(last_row >= 0, ticks[np.maximum(last_row, 0)], before[0])
        if not self.started:
            sizes[at[0]] = self.step
            ran = cycles > index[0]  # (up to the first step with a row: from 0, its size one step)
            points[ran] = self.step + (start_tick[ran] - self.origin) / self.scale
            self.started = True
        else:
            points[:] = self.step + (start_tick - self.origin) / self.scale
        self.sizes.append(sizes)
        self.points.append(points)
        self.made += len(cycles)
        self.next_cycle = int(index[-1]) + 1

    def steps(self, k, m):
        """(points, sizes) of steps k to k + m - 1, k the first not yet given."""
        while self.made < k + m and self.read():
            pass
        points, sizes = np.concatenate(self.points), np.concatenate(self.sizes)
        given = self.made - len(sizes)  # the index of the first step kept
        self.points, self.sizes = [points[k + m - given :]], [sizes[k + m - given :]]
        return points[k - given : k + m - given], sizes[k - given : k + m - given]


def _once(chunks):
    """The input table's function for ChunkedCase: the stream's blocks can
    be read once; a second reading (fmpy's, for a trace the fast loop
    cannot give) is NotPlain: the in-memory path reads the recording."""
    given = False

    def table():
        nonlocal given
        if given:
            raise NotPlain("the recording is read once")
        given = True
        return chunks

    return table


def streamable(path) -> bool:
    """Whether the recording at path is one file (the blocks may follow it)."""
    return os.path.isfile(path)


def run_recording(path, name, target, settings, streaming: Streaming = Streaming()) -> CaseOutcome:
    """The CaseOutcome of the recording at path (recording_paths' form) on
    target (a _worker.Target), read with settings.recording: a one-file
    table export read in blocks of lines as it is compared, any
    other recording (or one the blocks cannot follow) read whole; either
    way run and compared by the pipeline."""
    if streamable(path):
        outcome = run_streamed_recording(path, name, target, settings, streaming)
        if outcome is not None:
            return outcome
    started = time.perf_counter()
    try:
        recorded = recorded_case(str(path), target.fmu, name, settings.recording)
    except InputError as error:
        outcome = CaseOutcome(name, **target.labels, status=Status.INVALID, messages=[str(error)])
        outcome.seconds = time.perf_counter() - started
        return outcome
    inputs = recorded.inputs

    def more_messages(passed, deviations):
        return [recorded.description] + (recorded.notes if passed else recorded.explain(deviations))

    case = ChunkedCase(
        name,
        f"{name} on {target.labels['fmu']}: {recorded.description}",
        recorded.options,
        recorded.start_values,
        tuple(inputs.dtype.names or ())[1:] if inputs is not None else (),
        (lambda: iter([inputs])) if inputs is not None else None,
        [iter([reference]) for reference in recorded.references],
        recorded.outputs,
        max(recorded.options["StopTime"], float(recorded.reference["time"][-1])),
        more_messages,
        started,
        replay=recorded.replay,
        clock=recorded.clock,
    )
    return run_chunked_case(case, target, settings, streaming)


def run_streamed_recording(path, name, target, settings, streaming: Streaming = Streaming()):
    """The CaseOutcome of the one-file recording at path on target (a
    _worker.Target), read with settings.recording, streamed; None if this
    path cannot take it (the in-memory path then reads it)."""
    fmu, options, block_bytes = target.fmu, settings.recording, streaming.block_bytes
    try:
        table = stream.Table(path, fmu, options)
        recording = table.recording
        matched = plan(recording, fmu.variables, fmu.label, options.maps, options.names)
        if not matched.compares:
            return None
        step = recording.step_size
        shift = 1 if options.timing == "cycle" else 0
        recorded = options.cycle_lengths == "recorded"
        if recorded and recording.time_unit not in SECONDS_OF_DECIMALS:
            return None  # (the in-memory path takes the resolution of other clocks)
        cycles = stream.time_column_pass(table, step, block_bytes, resolution=recorded)
        start_values = {n: fmu.start_value(n, v) for n, v in options.start_values}
    except (NotPlain, InputError, OSError, ValueError):
        return None
    drives, compares = matched.drives, matched.compares
    stop = float(timebase.cycle_times(np.array([max(cycles.last + shift, 1)]), step)[0])
    pending: dict[str, list[np.ndarray]] = {"inputs": [], "refs": []}
    replay = _StreamedReplay(cycles, step, shift, lambda: parse()) if recorded else None
    before = -1  # the cycle of the row before the next block's
    jitter = clock.Jitter()  # of every row on the grid, as the blocks are read
    off: list = [0, None]  # rows more than OFF_CYCLE off their cycle, and (line, seconds, cycle) of the first
    missing: list = [0, []]  # the cycles without a row: their count, and the first MOST_NAMED

    def parse():
        """Reads the next block into the queues; False at the end."""
        nonlocal before
        block = next(blocks, None)
        if block is None:
            if not jitter.fits():
                raise NotPlain("rows on no grid of cycles (the in-memory path says)")
            return False
        _, cells, line_numbers, times = block
        index = cycles.grid.index(times)
        gaps = np.diff(np.concatenate([[before], index]))
        if (gaps < 1).any():
            raise NotPlain("two rows on one cycle on the whole file's grid (the in-memory path says)")
        if (gaps > 1).any():
            count, named = clock.missing(np.concatenate([[before], index]), MOST_NAMED - len(missing[1]))
            missing[0] += count
            missing[1] += named
        before = int(index[-1])
        far = np.abs(cycles.grid.distance(times, index))
        largest = float(far.max())
        jitter.add_far(far, largest)
        if largest > OFF_CYCLE:
            late = np.flatnonzero(far > OFF_CYCLE)
            if off[1] is None:
                off[1] = (int(line_numbers[late[0]]), float(times[late[0]]), int(index[late[0]]))
            off[0] += len(late)
        if drives:
            chunk = np.empty(len(index), dtype=[("time", np.float64)] + [(v, np.float64) for v, _ in drives])
            chunk["time"] = timebase.cycle_times(index, step)
            for variable, channel in drives:
                chunk[variable] = table.values(cells, line_numbers, channel.name)
            pending["inputs"].append(chunk)
        chunk = np.empty(len(index), dtype=[("time", np.float64)] + [(v, np.float64) for v, _ in compares])
        chunk["time"] = timebase.cycle_times(index + shift, step)
        for variable, channel in compares:
            chunk[variable] = table.values(cells, line_numbers, channel.name)
        pending["refs"].append(chunk)
        if replay is not None:
            replay.add(times, index)
        return True

    def queue(kind):
        while True:
            if pending[kind]:
                yield pending[kind].pop(0)
            elif not parse():
                while pending[kind]:
                    yield pending[kind].pop(0)
                return

    blocks = table.blocks(block_bytes)
    figures: dict = {}  # the clock's figures, made with the last messages (the outcome takes the dict)

    def more_messages(passed, deviations):
        notes = []
        if off[0]:
            line, time, cycle = off[1]
            notes = list(
                dict.fromkeys(  # a channel that drives and is compared is said once, as read whole
                    off_cycle_note(
                        channel.name, off[0], cycles.rows, (f"{table.path}, line {line}", time, cycle), cycles.grid
                    )
                    for _, channel in drives + compares
                )
            )
        if missing[0]:
            notes.append(missing_note(missing[0], before + 1, missing[1]))
        notes += matched.describe()
        unit = timebase.UNIT_NAMES.get(recording.time_unit, recording.time_unit)
        description = (
            f"{recording.format}: {cycles.rows} samples, time as {unit} ({recording.time_source}), "
            f"step {shortest(step)} s ({recording.step_source}), jitter {jitter.describe()}"
            + (", cycle lengths as recorded" if recorded else "")
        )
        figures.update(clock_figures(cycles.grid, jitter, 1, missing[0], missing[1]))
        if passed:
            return [description] + notes
        explained = _explain(table, deviations, dict((v, c) for v, c in compares), step, shift, cycles.grid)
        return [description] + explained + notes

    inputs = queue("inputs") if drives else None
    case = ChunkedCase(
        name,
        f"{name} on {target.labels['fmu']}: {recording.format}",
        {"StartTime": 0.0, "StopTime": stop, "StepSize": step, "RelTol": 1e-6},
        start_values,
        tuple(v for v, _ in drives),
        _once(inputs) if inputs is not None else None,
        [queue("refs")],
        [v for v, _ in compares],
        stop,
        more_messages,
        clock=figures,
        replay=replay,
    )
    try:
        outcome = run_chunked_case(case, target, settings, streaming)
    except NotPlain:
        return None
    outcome.streamed = True
    return outcome


def _explain(table, deviations, channels, step, shift, grid):
    """RecordedCase.explain's messages: each failing signal's recorded sample at its first deviation
    (the row of its cycle on grid)."""
    wanted = {}
    for deviation in deviations:
        if deviation.name in channels and deviation.time is not None:
            wanted[deviation.name] = int(round(deviation.time / step)) - shift
    found = {}
    if wanted:
        for _, cells, line_numbers, times in table.blocks():
            index = grid.index(times)
            for name, cycle in wanted.items():
                at = int(np.searchsorted(index, cycle))
                if name not in found and at < len(index) and index[at] == cycle:
                    value = table.values(cells, line_numbers, channels[name].name)[at]
                    found[name] = (int(line_numbers[at]), float(times[at]), float(value))
            if len(found) == len(wanted) or index[-1] >= max(wanted.values()):
                break
    messages = []
    for deviation in deviations:
        if deviation.name in found:
            line, time, value = found[deviation.name]
            cycle = wanted[deviation.name]
            shown = timebase.nominal(time, cycle, step)
            messages.append(first_differs(deviation, cycle, f"{table.path}, line {line}", shown, value))
    return messages
