"""The one way a case is read, run and compared: chunk by chunk, in memory
that does not grow with its length (a short case is one chunk).

The reference and the inputs are read in chunks (traces.trace_chunks, by
pyarrow) where they are the plain CSV dialect, else whole by read_trace
(which reads any dialect fmutrace reads, or explains what is wrong with
file, line and column); the FMU runs chunk after chunk on one instance
(Runner.run_chunks, which hands a trace the fast loop cannot give to fmpy
itself); each reference chunk is compared as soon as the result reaches
it, by the comparison module's rules (its samples matched by
comparison.aligned, the verdict accumulated by comparison.Verdict), and
the figure's lines are envelopes filled as they go (plot.Envelope). A
tube compares each result sample with the reference around it: the
reference is kept from the row before that window to a row after it
(Tube.band on that window gives the whole reference's bounds); its second
side, each reference row with the result around it, keeps the result the
same way. The
verdict does not depend on where the chunks end (a test runs every
reference scenario in chunks of one step and one row).
"""

import contextlib
import itertools
import math
import time
from collections.abc import Callable, Iterator
import os
import tempfile
from typing import TextIO
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ._cases import load_case, read_criteria, read_options, read_start_values, recorded_steps
from ._comparison import Band, Criteria, Mode, Pointwise, Tube, Verdict, aligned, criteria_for, time_slack
from ._errors import InputError, SimulationError
from ._fmpy import Experiment, ReplaySteps, Signals
from ._outcome import CaseOutcome, Status
from ._plot import DETAIL, ZOOM_SAMPLES, Envelope, Figure, as_script, draw, needs_tiles, page_data, page_tile
from ._progress import SampleProgress
from ._reading import absent
from ._runner import STEPS_PER_CHUNK
from ._traces import CHUNK_BYTES, NotPlain, TraceWriter, last_time, read_text, trace_chunks


def _signal_names(trace: np.ndarray) -> tuple[str, ...]:
    """The names of a trace's columns after its time."""
    return tuple(trace.dtype.names or ())[1:]


@dataclass(frozen=True)
class Streaming:
    """How a long case streams: where its result goes, the size of its
    pieces (tests make them small), its progress bar."""

    keep_result: bool = False  # the result of a case that gets its plot kept in a file (result_path)
    steps_per_chunk: int = STEPS_PER_CHUNK  # steps run between two result chunks
    chunk_bytes: int = CHUNK_BYTES  # CSV text per chunk of a case's files
    block_bytes: int | None = None  # text per block of a recording's lines (None: recordings._stream's)
    progress: SampleProgress | None = None  # (None: one on standard error)


@dataclass
class ChunkedCase:
    """A case given as chunks: inputs (None: no inputs) a function that
    gives the input table's consecutive structured arrays, time first,
    from its first row each time it is called; references: the reference
    tables, each as consecutive structured arrays (one, or one per time
    base of a recording's signals, each signal in one of them)."""

    name: str
    title: str  # the figure's
    options: dict  # StartTime, StopTime, StepSize, RelTol
    start_values: dict
    input_names: tuple
    inputs: Callable[[], Iterator] | None
    references: list[Iterator]
    outputs: list
    t_end: float  # the figure's last time
    # what the outcome's messages add after the comparison's: more_messages(passed, deviations)
    more_messages: Callable | None = None
    started: float = field(default_factory=time.perf_counter)
    criteria: tuple = ()  # the case's own per-signal criteria: ((pattern, Mode), ...)
    replay: ReplaySteps | None = None  # recorded cycle lengths: Experiment.replay
    clock: dict = field(default_factory=dict)  # a recording's cycle fit: CaseOutcome.clock


@dataclass(frozen=True)
class CaseFiles:
    """A case folder as a campaign names it: its folder, its name, and its
    files' texts (None: read from the folder)."""

    folder: str | Path
    name: str
    texts: dict | None = None


def run_folder_case(files: CaseFiles, target, settings, streaming: Streaming = Streaming()) -> CaseOutcome:
    """The CaseOutcome of the case in files.folder on target (a _worker.Target)."""
    started = time.perf_counter()

    def run(whole):
        case = _read_folder_case(files, target, streaming, whole)
        case.started = started
        return run_chunked_case(case, target, settings, streaming)

    if files.texts is None:  # (texts travelled: read them whole)
        try:
            return run(whole=False)
        except (NotPlain, InputError):
            pass  # a file the chunk reader does not take: read_trace reads or explains it, whole
    try:
        return run(whole=True)
    except (NotPlain, InputError) as error:
        outcome = CaseOutcome(files.name, **target.labels, status=Status.INVALID, messages=[str(error)])
        outcome.seconds = time.perf_counter() - started
        return outcome


def _read_folder_case(files: CaseFiles, target, streaming: Streaming, whole: bool) -> ChunkedCase:
    """The case's files as chunks (whole: each file one chunk, read by
    read_trace); NotPlain where a file needs read_trace, InputError for
    what is wrong in a file."""
    fmu, folder, name = target.fmu, Path(files.folder), files.name
    model = fmu.model
    replay = None
    if whole:
        read = load_case(folder, fmu, name, files.texts)
        inputs, reference = read.inputs, read.reference
        options, start_values, description = read.options, read.start_values, read.description
        criteria = read.criteria
        input_names = _signal_names(inputs) if inputs is not None else ()
        table = None if inputs is None else (lambda: iter([inputs]))
        ref_chunks: Iterator = iter([reference])  # (one table)
        outputs, last = read.outputs, float(reference["time"][-1])
        if options.get("CycleLengths") == "recorded":
            replay = recorded_steps(folder / f"{model}_ref.csv", reference, options)
    else:
        ref_path, in_path = folder / f"{model}_ref.csv", folder / f"{model}_in.csv"
        try:
            listed = set(os.listdir(folder))  # (one look at the folder, not one per file)
        except OSError:
            listed = None

        def present(file_name):  # (a name listed is there, read or not: a dangling link, a FIFO)
            if listed is None or os.path.basename(file_name) != file_name:  # (a model's name may hold a '/')
                return not absent(folder / file_name)
            return file_name in listed

        texts = {}  # the small files' texts (the reference and the inputs are read in chunks)
        for file_name in (f"{model}_ref.opt", f"{model}_start.csv", f"{model}_criteria.csv", "README.md"):
            if present(file_name):
                texts[file_name] = read_text(folder / file_name)
        ref_chunks = trace_chunks(ref_path, fmu.variable_problem, chunk_bytes=streaming.chunk_bytes)
        try:
            if os.path.getsize(ref_path) <= streaming.chunk_bytes:  # a chunk or two: read now, its end known
                ref_chunks = iter(ref_read := list(ref_chunks))
                first_ref, last = ref_read[0], float(ref_read[-1]["time"][-1])
            else:
                first_ref = next(ref_chunks)
                last = last_time(ref_path)
                ref_chunks = itertools.chain([first_ref], ref_chunks)  # (each file read once)
        except (OSError, ValueError, StopIteration, IndexError) as error:
            raise NotPlain(str(error)) from None
        bounds = np.zeros(2, dtype=[("time", np.float64)])
        bounds["time"] = [first_ref["time"][0], last]
        options = read_options(folder / f"{model}_ref.opt", texts.get(f"{model}_ref.opt"), bounds, fmu)
        if options.get("CycleLengths") == "recorded":
            raise NotPlain("the recorded cycle lengths are read from the whole reference")
        start_values = read_start_values(folder / f"{model}_start.csv", texts.get(f"{model}_start.csv"), fmu)
        criteria = read_criteria(folder / f"{model}_criteria.csv", texts.get(f"{model}_criteria.csv"), fmu)
        input_names, table = (), None
        if present(f"{model}_in.csv"):
            in_chunks = trace_chunks(in_path, fmu.input_problem, chunk_bytes=streaming.chunk_bytes)
            first_in = next(in_chunks, None)
            if first_in is None:
                raise NotPlain("no samples")
            input_names = _signal_names(first_in)
            read_once = [itertools.chain([first_in], in_chunks)]  # the first reading goes on from there

            def table():
                return (
                    read_once.pop()
                    if read_once
                    else trace_chunks(in_path, fmu.input_problem, chunk_bytes=streaming.chunk_bytes)
                )

        outputs = list(_signal_names(first_ref))
        readme = (texts.get("README.md") or "").strip().splitlines()
        description = readme[0].lstrip("# ").strip() if readme else ""
    title = f"{name} on {target.labels['fmu']}" + (f": {description}" if description else "")
    return ChunkedCase(
        name,
        title,
        options,
        start_values,
        input_names,
        table,
        [ref_chunks],
        outputs,
        max(options["StopTime"], last),
        criteria=criteria,
        replay=replay,
    )


def run_chunked_case(case: ChunkedCase, target, settings, streaming: Streaming = Streaming()) -> CaseOutcome:
    """The CaseOutcome of a case given as chunks on target (a
    _worker.Target): an FMU that fails makes it an error. NotPlain from a
    chunk that needs read_trace (the caller reads the file whole)."""
    options, outputs, input_names = case.options, case.outputs, case.input_names
    start, stop, step = options["StartTime"], options["StopTime"], options["StepSize"]
    n = round((stop - start) / step) if case.replay is None or case.replay.times is None else len(case.replay.times) - 1
    bar = streaming.progress or SampleProgress(n + 1)
    mode = criteria_for(settings.mode, case.criteria, target.fmu.discrete_names())
    state = _Comparer(case, mode, bar)
    # each table compared from the run's start (several tables, per-signal criteria): the run kept whole
    state.keep_all = len(case.references) > 1 or isinstance(mode, Criteria)
    seen = False  # the input envelopes are filled on the first reading of the table only

    def inputs():
        nonlocal seen
        assert case.inputs is not None
        chunks, first = case.inputs(), not seen
        seen = True
        last = None
        for chunk in chunks:
            if first:
                for s in input_names:
                    state.envelopes[("input", s)].add(chunk["time"], chunk[s])
                last = chunk[-1:] if len(chunk) else last
            yield chunk
        if last is not None and last["time"][0] < case.t_end:  # a row holds to the end: drawn so
            for s in input_names:
                state.envelopes[("input", s)].add(np.array([case.t_end]), last[s])

    results = target.runner.run_chunks(
        Experiment(start, stop, step, options["RelTol"], case.replay),
        Signals(inputs if case.inputs is not None else None, case.start_values, outputs),
        input_names,
        streaming.steps_per_chunk,
    )
    with contextlib.ExitStack() as stack:
        stack.callback(bar.close)
        stack.callback(results.close)  # given up or done: the run's chunks and pointers go now, not with the frame
        state.result = _Result(streaming.keep_result)
        stack.callback(state.result.close)  # (a result not kept by then is removed)
        state.results = results
        try:
            for reference in case.references:
                if isinstance(mode, Criteria):
                    state.whole_rows([chunk for chunk in reference if len(chunk)])
                elif isinstance(mode, Tube):
                    for chunk in reference:
                        state.tube_rows(chunk)
                    state.tube_rows(None)
                else:
                    # each chunk with the next one's first time (a repeated time spans chunks), the last with NaN
                    chunks = (c for c in reference if len(c))
                    chunk = next(chunks, None)
                    while chunk is not None:
                        following = next(chunks, None)
                        state.compare_rows(chunk, np.nan if following is None else following["time"][0])
                        chunk = following
                state.next_reference()
            state.result_until(math.inf)  # the rest of the run: an FMU failing there fails the case
        except SimulationError as error:
            outcome = CaseOutcome(case.name, **target.labels, status=Status.ERROR, messages=[str(error)])
            if case.more_messages is not None:
                outcome.messages += case.more_messages(False, [])
            outcome.seconds = time.perf_counter() - case.started
            return outcome
        return state.outcome(case, target.labels, settings)  # (its result file kept before the stack closes)


class _Comparer:
    """A chunked case's comparison as it goes: the result's window, each
    signal's verdict, the figure's envelopes and its zoom."""

    def __init__(self, case: ChunkedCase, mode: Mode, bar: SampleProgress):
        options, outputs = case.options, case.outputs
        self.mode, self.outputs, self.start, self.step = mode, outputs, options["StartTime"], options["StepSize"]
        self.t_end = case.t_end
        self.signals = {name: Verdict(name) for name in outputs}
        self.envelopes = {
            key: Envelope(self.start, case.t_end)
            for key in [("ref", s) for s in outputs]
            + [("result", s) for s in outputs]
            + [("deviation", s) for s in outputs]
            + ([("back", s) for s in outputs] if isinstance(mode, Tube) and mode.sides == 2 else [])
            + ([(edge, s) for s in outputs for edge in ("lower", "upper")] if mode.fills_band else [])
            + [("input", s) for s in case.input_names]
        }
        self.zoom_at: float | None = None  # the first failing sample's time, the zoom's lines around it
        self.zoom_lines: list | None = None
        self.expected: dict[str, np.ndarray] = {}  # name -> the reference at the samples of its band being added
        self.recent: dict[str, tuple] = {}  # name -> the last ZOOM_SAMPLES compared samples (times, values, lower,
        # upper, deviation)
        # reference times without a result sample: their count and the first's time, of the first table with any
        self.absent = 0
        self.first_absent: float | None = None
        self.absent_here = 0  # of the table being compared
        self.first_absent_here: float | None = None
        self.keep_all = False  # the run's chunks kept from its start (several reference tables)
        self.window: list[tuple[int, np.ndarray]] = []  # result chunks not yet compared: (first index, chunk)
        self.reached = 0  # result samples made
        self.results: Iterator[np.ndarray] = iter(())  # the run's chunks
        self.result = _Result(False)  # the result kept for its file
        self.bar = bar
        self.reference: np.ndarray | None = None  # a tube's: the reference rows its next samples look around
        self.t_first: float | None = None  # the reference's first time
        self.compared = 0  # a tube's: the result samples compared
        # a two-sided tube's second side: each signal's verdict on the reference's rows in the tube around the
        # result, the rows not yet judged, and the result from the sample before their window on
        two_sided = isinstance(mode, Tube) and mode.sides == 2
        self.back = {name: Verdict(name) for name in outputs} if two_sided else None
        self.back_rows: np.ndarray | None = None
        self.back_result: list[np.ndarray] = []
        self.result_first: float | None = None  # the run's first time

    def next_reference(self):
        """The table compared is done: the next one starts at the run's start."""
        if self.absent_here and not self.absent:
            self.absent, self.first_absent = self.absent_here, self.first_absent_here
        self.absent_here, self.first_absent_here = 0, None
        self.back_rows, self.back_result = None, [c for _, c in self.window] if self.keep_all else []
        self.reference, self.t_first, self.compared = None, None, 0

    def result_until(self, k):
        """The result window through sample k (or the end)."""
        while self.reached <= k:
            chunk = next(self.results, None)
            if chunk is None:
                return
            self.window.append((self.reached, chunk))
            self.reached += len(chunk)
            if self.back is not None and len(chunk):
                self.back_result.append(chunk)
                self.result_first = float(chunk["time"][0]) if self.result_first is None else self.result_first
            for s in self.outputs:
                self.envelopes[("result", s)].add(chunk["time"], chunk[s])
            self.result.add(chunk)
            self.bar.update(self.reached)

    def compare_rows(self, rows, next_time):
        """Compares reference rows (next_time: the time of the row after the
        last, NaN if none) with the result, as Pointwise.bands does on the
        whole: comparison.aligned on the result samples around the rows' times."""
        if not len(rows):
            return
        step, window, names = self.step, self.window, rows.dtype.names[1:]
        times = rows["time"]
        for s in names:
            self.envelopes[("ref", s)].add(times, rows[s])
        # the result's samples from two steps before the first time to two after the last (by their times:
        # fmpy's loop adds a sample at an input event between communication points)
        low, high = times[0] - 2 * step, times[-1] + 2 * step
        while not window or float(window[-1][1]["time"][-1]) < high:
            before = self.reached
            self.result_until(self.reached)
            if self.reached == before:
                break  # the run has no more samples
        while not self.keep_all and len(window) > 1 and float(window[1][1]["time"][0]) <= low:
            window.pop(0)  # chunks before the first sample needed
        result = (window[0][1] if len(window) == 1 else np.concatenate([c for _, c in window])) if window else None
        if result is not None:
            result = result[np.searchsorted(result["time"], low) : np.searchsorted(result["time"], high, "right")]
        if result is None or not len(result):
            result, index = None, np.full(len(times), -1)  # the run ended before these rows
        else:
            index = aligned(result["time"], np.append(times, next_time))[:-1]  # (the next row tells a repeated time)
        missing = np.flatnonzero(index == -1)
        if len(missing):
            if self.first_absent_here is None:
                self.first_absent_here = float(times[missing[0]])
            self.absent_here += len(missing)
        use = index >= 0
        if result is None or not use.any():
            return
        assert isinstance(self.mode, Pointwise)  # (stream_case gives a tube's rows to tube_rows)
        picked, compared_times, bands = result[index[use]], times[use], {}
        for s in names:
            expected = self.expected[s] = rows[s][use].astype(np.float64)
            values = picked[s].astype(np.float64)
            lower, upper, ok = self.mode.bounds(values, expected)
            with np.errstate(invalid="ignore", over="ignore"):
                bands[s] = Band(compared_times, values, lower, upper, ok, values - expected)
        self._add(bands)

    def whole_rows(self, chunks):
        """Per-signal criteria: the reference's chunks compared at once with
        the whole run (Criteria.judge; a discrete signal's changes and a
        tube's time used need the whole trace)."""
        if not chunks:
            return
        rows = np.concatenate(chunks)
        times, names = rows["time"], _signal_names(rows)
        for s in names:
            self.envelopes[("ref", s)].add(times, rows[s])
        self.result_until(math.inf)
        if not self.window:
            self.absent_here, self.first_absent_here = len(rows), float(times[0])
            return
        result = np.concatenate([c for _, c in self.window])
        assert isinstance(self.mode, Criteria)
        deviations, bands, problem = self.mode.judge(result, rows, names)
        if problem:  # the pointwise signals' reference times without a result sample
            index = aligned(result["time"], times)
            missing = np.flatnonzero(index == -1)
            self.absent_here, self.first_absent_here = len(missing), float(times[missing[0]])
        self._add(bands)
        for s, deviation in deviations.items():
            self.signals[s].deviation = deviation

    def tube_rows(self, rows):
        """A tube's comparison as Tube.judge makes it on the whole: adds
        reference rows (None: there are no more) and compares the result
        samples whose look-around window they cover, each against the
        reference from its time - the tube's time to its time + the tube's
        time (the window: from the row before that on, to a row after it);
        on a two-sided tube the reference's rows the other way round."""
        if self.back is not None and rows is not None and len(rows):
            self.back_rows = rows if self.back_rows is None else np.concatenate([self.back_rows, rows])
        self._tube_forth(rows)
        if self.back is not None:
            self._tube_back(done=rows is None)

    def _tube_forth(self, rows):
        """The result's samples in the tube around the reference."""
        mode = self.mode
        assert isinstance(mode, Tube)
        if rows is not None and len(rows):
            for s in rows.dtype.names[1:]:
                self.envelopes[("ref", s)].add(rows["time"], rows[s])
            self.t_first = float(rows["time"][0]) if self.t_first is None else self.t_first
            self.reference = rows if self.reference is None else np.concatenate([self.reference, rows])
        if self.reference is None or self.t_first is None:
            return
        reference = self.reference
        last = float(reference["time"][-1])
        # the samples whose window ends before the last row (or all of them once the reference is whole)
        covered = np.inf if rows is None else last - mode.time - 2 * float(time_slack(last))
        while True:
            if self.compared >= self.reached:
                before = self.reached
                self.result_until(self.reached)
                if self.reached == before:
                    return  # the run has no more samples
            window = self.window
            while not self.keep_all and len(window) > 1 and window[1][0] <= self.compared:
                window.pop(0)  # chunks compared already
            base = window[0][0]
            result = window[0][1] if len(window) == 1 else np.concatenate([c for _, c in window])
            result = result[self.compared - base :]
            take = int(np.searchsorted(result["time"], covered, side="left"))
            if take:
                span = (self.t_first, last if rows is None else np.inf)
                self._add(
                    {s: mode.band(result[:take], reference, s, span) for s in tuple(reference.dtype.names or ())[1:]}
                )
                self.compared += take
            if take < len(result):
                break
        # the rows the next sample's window needs: from the one before its time - the tube's time on
        at = float(result["time"][take])
        keep = int(np.searchsorted(reference["time"], at - mode.time - float(time_slack(at)), side="left")) - 1
        self.reference = reference[max(keep, 0) :]

    def _tube_back(self, done):
        """The reference's rows in the tube around the result: those whose
        window the result made so far covers (all once done: the reference
        and the run are whole), each against the result from its time - the
        tube's time to its time + the tube's time."""
        mode, rows, back = self.mode, self.back_rows, self.back
        assert isinstance(mode, Tube) and back is not None
        if rows is None or not len(rows) or not self.back_result:
            return
        result = self.back_result[0] if len(self.back_result) == 1 else np.concatenate(self.back_result)
        last = float(result["time"][-1])
        covered = np.inf if done else last - mode.time - 2 * float(time_slack(last))
        take = int(np.searchsorted(rows["time"], covered, side="left"))
        if not done:
            take = min(take, len(rows) - 1)  # (the last row waits for the next: a repeated time may span chunks)
        if take:
            span = (self.result_first, last if done else np.inf)
            following = float(rows["time"][take]) if take < len(rows) else math.nan
            for s in _signal_names(rows):
                band = mode.back_band(rows[:take], result, s, span, following)
                back[s].add(band)
                self.envelopes[("back", s)].add(band.times, band.deviation)
        # the result the next rows' windows need: from the sample before the earliest's time - the tube's time on
        at = float(rows["time"][min(take, len(rows) - 1)])
        keep = int(np.searchsorted(result["time"], at - mode.time - float(time_slack(at)), side="left")) - 1
        self.back_result, self.back_rows = [result[max(keep, 0) :]], rows[take:]

    def _add(self, bands):
        """Each signal's band on the compared samples; the zoom at the first failing one."""
        failing_now = []
        for s, band in bands.items():
            if not len(band.times):
                continue
            verdict = self.signals[s].deviation
            before = verdict.failed
            self.signals[s].add(band)
            self.envelopes[("deviation", s)].add(band.times, band.deviation)
            if band.back is not None:  # (per-signal criteria: a two-sided tube's signals have one)
                self.envelopes.setdefault(("back", s), Envelope(self.start, self.t_end)).add(
                    band.back.times, band.back.deviation
                )
            if self.mode.fills_band:  # (the same samples: both edges' envelopes have the same times)
                self.envelopes[("lower", s)].add(band.times, band.lower)
                self.envelopes[("upper", s)].add(band.times, band.upper)
            if self.zoom_lines is None and verdict.failed > before and verdict.time is not None:
                failing_now.append(verdict.time)
            expected = self.expected.pop(s, None)  # (known on a pointwise comparison's rows)
            self.recent[s] = (band.times, band.values, band.lower, band.upper, band.deviation, expected)
        if failing_now and self.zoom_lines is None:
            at = min(failing_now)
            self.zoom_at, self.zoom_lines = at, []
            for s in self.outputs:
                if s not in self.recent:
                    continue
                t, v, lo, up, dev, ref = self.recent[s]
                k = int(np.searchsorted(t, at))
                w = slice(max(k - ZOOM_SAMPLES, 0), k + ZOOM_SAMPLES + 1)
                self.zoom_lines.append((s, t[w], v[w], lo[w], up[w], dev[w], None if ref is None else ref[w]))

    def band(self, name):
        """The band's edges to draw, (times, lower, upper), or None."""
        if not self.mode.fills_band:
            return None
        (times, lower), (_, upper) = self.envelopes[("lower", name)].line(), self.envelopes[("upper", name)].line()
        return (times, lower, upper) if len(times) else None

    def page_scripts(self, case: ChunkedCase, figure: Figure, label, criteria):
        """The case page's plot data as a script, and a long case's finer level as DETAIL scripts (or none)."""
        envelopes, outputs = self.envelopes, self.outputs
        data = page_data(figure, label, criteria, self.mode.deviation_label)
        tiles = []
        if needs_tiles(envelopes.values()):
            any_line = next(iter(envelopes.values()))
            data["tiles"], data["span"] = DETAIL, [any_line.t0, any_line.t0 + any_line.span]
            inputs = [(s, envelopes[("input", s)]) for s in case.input_names]
            signals = [
                (s, *(envelopes.get((line, s)) for line in ("ref", "result", "lower", "upper", "deviation", "back")))
                for s in outputs
            ]
            tiles = [as_script("fmutraceTile(", page_tile(k, inputs, signals), ");") for k in range(DETAIL)]
        return as_script("window.fmutracePlot = ", data, ";"), tiles

    def outcome(self, case: ChunkedCase, labels, settings):
        """The case's CaseOutcome once every reference row was compared."""
        outputs, envelopes = self.outputs, self.envelopes
        deviations = [self.signals[s].deviation for s in outputs]
        if isinstance(self.mode, Tube):
            back = self.back
            deviations = [self.mode.verdict(d, back[d.name].deviation if back else None) for d in deviations]
        outcome = CaseOutcome(case.name, **labels)
        outcome.clock = case.clock
        problem = ""
        if self.absent:
            problem = f"the result has no sample at t={self.first_absent!r} ({self.absent} reference times without one)"
        passed = not problem and all(d.passed for d in deviations)
        outcome.status = Status.PASS if passed else Status.FAIL
        outcome.deviations = [d for d in deviations if not d.passed]
        outcome.messages = [problem] if problem else [d.describe() for d in deviations if not d.passed]
        outcome.messages += [d.describe() for d in deviations if d.passed and d.allowance]  # (per-signal criteria)
        if case.more_messages is not None:
            outcome.messages += case.more_messages(passed, outcome.deviations)
        outcome.criteria = self.mode.describe()
        if settings.plots == "all" or (settings.plots == "failed" and not passed):
            figure = Figure(
                case.title,
                [(s, *envelopes[("input", s)].line()) for s in case.input_names],
                [(s, envelopes[("ref", s)].line(), envelopes[("result", s)].line(), self.band(s)) for s in outputs],
                [(s, *envelopes[("deviation", s)].line()) for s in outputs],
                (self.zoom_at, self.zoom_lines) if self.zoom_lines else None,
                {s: envelopes[("back", s)].line() for s in outputs if ("back", s) in envelopes},
            )
            criteria = {s: d.criterion or outcome.criteria for s, d in zip(outputs, deviations, strict=True)}
            try:
                outcome.plot_js, outcome.plot_tiles = self.page_scripts(case, figure, labels["fmu"], criteria)
            except Exception as error:  # a page's plots lost, not the verdict (as a figure below)
                outcome.messages.append(f"no plot: its data failed ({type(error).__name__}: {error})")
            outcome.result_path = self.result.keep() or ""
            if settings.png:
                try:
                    outcome.png = draw(figure, self.mode, labels["fmu"])
                except Exception as error:  # (matplotlib's errors are many) a figure lost, not the verdict
                    outcome.messages.append(f"no plot: drawing it failed ({type(error).__name__}: {error})")
        outcome.seconds = time.perf_counter() - case.started
        return outcome


SPILL_BYTES = 1 << 22  # a result kept for its file goes there as it is made once it is larger than this


class _Result:
    """A run's result kept for the case's result file (the report moves it
    in): in memory while it is small, in a file of its own (made then)
    once larger, so that memory stays flat; keep() gives the file, close()
    removes one not kept."""

    def __init__(self, wanted: bool):
        self.wanted = wanted
        self.chunks: list[np.ndarray] = []
        self.size = 0
        self.path: str | None = None
        self.file: TextIO | None = None
        self.writer: TraceWriter | None = None
        self.kept = False

    def add(self, chunk):
        if not self.wanted:
            return
        if self.writer is None:
            self.chunks.append(chunk)
            self.size += chunk.nbytes
            if self.size <= SPILL_BYTES:
                return
            self._open()
        else:
            self.writer.write(chunk)

    def _open(self):
        handle, self.path = tempfile.mkstemp(prefix="fmutrace-", suffix="_out.csv")
        os.chmod(self.path, 0o644)  # as the report's other files (mkstemp makes it private)
        self.file = file = os.fdopen(handle, "w", newline="\n")
        names = self.chunks[0].dtype.names if self.chunks else ("time",)
        self.writer = TraceWriter(file, names)
        for chunk in self.chunks:
            self.writer.write(chunk)
        self.chunks = []

    def keep(self) -> str | None:
        """The result's file, written whole (None if no result was wanted or made)."""
        if not self.wanted or (self.writer is None and not self.chunks):
            return None
        if self.writer is None:
            self._open()
        assert self.file is not None
        self.file.close()
        self.kept = True
        return self.path

    def close(self):
        if self.file is not None and not self.file.closed:
            self.file.close()
        if self.path is not None and not self.kept:
            os.unlink(self.path)
        self.chunks = []
