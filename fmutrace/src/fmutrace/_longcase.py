"""A long case (a recorder's hours of cycles as a cross-check case) read,
simulated, compared and plotted chunk by chunk, in memory that does not
grow with its length.

The reference and the inputs are read by pyarrow in chunks
(traces.trace_chunks), the FMU runs chunk after chunk on one instance
(Runner.run_chunks), each reference chunk is compared as soon as the
result reaches it, and the figure's lines are envelopes filled as they
go (plot.Envelope). The verdict is the in-memory path's (worker.run_case
with comparison.compare_traces), bit for bit, from the comparison
module's own rules (its samples matched by comparison.aligned, the
verdict accumulated by comparison.Verdict): every signal's counts, its
first deviation and its largest, and a reference time the result lacks
(a test runs both on the same cases). A case this path cannot take (a
tube, a file that is not the plain CSV dialect, an input the fast loop
cannot replay, a failing FMU) goes to the in-memory path, which reads it
or explains it: `run_long_case` returns None then, before anything is
reported.
"""
import contextlib
import os
import time
from pathlib import Path

import numpy as np

from ._cases import read_options, read_start_values
from ._comparison import Band, Mode, Pointwise, Verdict, aligned
from ._errors import InputError, SimulationError
from ._fmu import Fmu
from ._outcome import CaseOutcome, Status
from ._plot import ZOOM_SAMPLES, Envelope, Figure, draw
from ._progress import SampleProgress
from ._runner import STEPS_PER_CHUNK, FastLoopFailed, Runner
from ._traces import CHUNK_BYTES, LONG_CASE_BYTES, NotPlain, TraceWriter, read_text, trace_chunks


def is_long(folder, model, texts) -> bool:
    """Whether the case in folder is run chunk by chunk (its files are here and large)."""
    if texts is not None:
        return False
    try:
        return os.path.getsize(os.path.join(folder, f"{model}_ref.csv")) >= LONG_CASE_BYTES
    except OSError:
        return False


def _last_time(path):
    """The time in the last data line of a plain CSV file (its first cell),
    however long that line is."""
    with open(path, "rb") as file:
        end = file.seek(0, os.SEEK_END)
        size = 4096
        while True:
            begin = max(0, end - size)
            file.seek(begin)
            lines = [line for line in file.read(end - begin).splitlines() if line.strip()]
            if len(lines) >= 2 or begin == 0:  # a line break before the last line: it is whole
                return float(lines[-1].split(b",")[0])
            size *= 4


def run_long_case(folder, name, runner: Runner, fmu: Fmu, labels: dict, mode: Mode, plots: str, result_file=None,
                  steps_per_chunk: int = STEPS_PER_CHUNK, chunk_bytes: int = CHUNK_BYTES, progress=None):
    """The CaseOutcome of the case in folder, chunk by chunk; None if this
    path cannot take it (the in-memory path then runs it). result_file: a
    path the result is written to as it is made (for the report), or None."""
    if not isinstance(mode, Pointwise):  # (a tube looks around each sample: the in-memory path)
        return None
    started = time.perf_counter()
    folder = Path(folder)
    model = fmu.model
    ref_path, in_path = folder / f"{model}_ref.csv", folder / f"{model}_in.csv"
    try:
        texts = {}  # the small files' texts (the reference and the inputs are read in chunks)
        for file_name in (f"{model}_ref.opt", f"{model}_start.csv", "README.md"):
            if (folder / file_name).exists():
                texts[file_name] = read_text(folder / file_name)
        first_ref = next(trace_chunks(ref_path, fmu.variable_problem, chunk_bytes=1 << 16))
        bounds = np.zeros(2, dtype=[("time", np.float64)])
        bounds["time"] = [first_ref["time"][0], _last_time(ref_path)]
        options = read_options(folder / f"{model}_ref.opt", texts.get(f"{model}_ref.opt"), bounds, fmu)
        start_values = read_start_values(folder / f"{model}_start.csv", texts.get(f"{model}_start.csv"), fmu)
        input_names = ()
        if in_path.exists():
            first_in = next(trace_chunks(in_path, fmu.input_problem, chunk_bytes=1 << 16))
            input_names = first_in.dtype.names[1:]
            if len(first_in) < 2:
                return None
    except (InputError, NotPlain, OSError, ValueError, StopIteration):
        return None
    outputs = list(first_ref.dtype.names[1:])
    stop = options["StopTime"]
    readme = (texts.get("README.md") or "").strip().splitlines()
    description = readme[0].lstrip("# ").strip() if readme else ""

    def inputs():
        yield from trace_chunks(in_path, fmu.input_problem, chunk_bytes=chunk_bytes)

    title = f"{name} on {labels['fmu']}" + (f": {description}" if description else "")
    return stream_case(name, labels, mode, plots, runner, options, start_values, input_names,
                       inputs() if input_names else None,
                       trace_chunks(ref_path, fmu.variable_problem, chunk_bytes=chunk_bytes), outputs,
                       max(stop, bounds["time"][1]), title, result_file, steps_per_chunk, progress, started=started)


def stream_case(name, labels, mode, plots, runner, options, start_values, input_names, input_chunks, ref_chunks,
                outputs, t_end, title, result_file=None, steps_per_chunk=STEPS_PER_CHUNK, progress=None,
                more_messages=None, started=None):
    """The CaseOutcome of a case given as chunks: input_chunks (None: no
    inputs) and ref_chunks are consecutive structured arrays, time first;
    options: StartTime, StopTime, StepSize, RelTol. None if this path
    cannot take it (a chunk raises NotPlain, the fast loop cannot replay
    it), before anything is reported. more_messages(passed, deviations):
    what the outcome's messages add after the comparison's."""
    started = time.perf_counter() if started is None else started
    start, stop, step = options["StartTime"], options["StopTime"], options["StepSize"]
    n = round((stop - start) / step)
    signals = {name: Verdict(name) for name in outputs}
    envelopes = {key: Envelope(start, t_end) for key in
                 [("ref", s) for s in outputs] + [("result", s) for s in outputs] + [("deviation", s) for s in outputs]
                 + [("input", s) for s in input_names]}
    zoom = {"at": None, "lines": None}
    recent = {}  # name -> the last ZOOM_SAMPLES compared samples (times, values, lower, upper, deviation)
    absent = [0, None]  # reference times without a result sample: count, the first

    def inputs():
        for chunk in input_chunks:
            for s in input_names:
                envelopes[("input", s)].add(chunk["time"], chunk[s])
            yield chunk

    results = runner.run_chunks(start, stop, step, inputs() if input_chunks is not None else None, input_names,
                                start_values, outputs, options["RelTol"], steps_per_chunk=steps_per_chunk)
    window = []  # result chunks not yet compared: [(first index, chunk)]
    reached = 0  # result samples made
    bar = progress or SampleProgress(n + 1)
    writer = None
    with contextlib.ExitStack() as stack:
        stack.callback(bar.close)
        stack.callback(results.close)  # given up or done: the run's chunks and pointers go now, not with the frame
        out = stack.enter_context(open(result_file, "w", newline="\n")) if result_file else None

        def result_until(k):
            """The result window through sample k (or the end)."""
            nonlocal reached, writer
            while reached <= k:
                chunk = next(results, None)
                if chunk is None:
                    return
                window.append((reached, chunk))
                reached += len(chunk)
                for s in outputs:
                    envelopes[("result", s)].add(chunk["time"], chunk[s])
                if out is not None:
                    writer = writer or TraceWriter(out, chunk.dtype.names)
                    writer.write(chunk)
                bar.update(reached)

        try:
            held = None  # the reference's last row so far: compared with the next chunk (a repeated time)
            for chunk in ref_chunks:
                if held is not None:
                    chunk = np.concatenate([held, chunk])
                held = chunk[-1:]
                _compare_rows(chunk[:-1], chunk["time"][-1], start, step, n, mode, outputs, signals, envelopes, window,
                         result_until, absent, zoom, recent)
            if held is not None:
                _compare_rows(held, np.nan, start, step, n, mode, outputs, signals, envelopes, window, result_until,
                         absent, zoom, recent)
            result_until(n)  # the rest of the run: an FMU failing there fails the case as in memory
            if reached != n + 1:
                raise FastLoopFailed("the run ended early")
        except (FastLoopFailed, NotPlain):
            return None

    deviations = [signals[s].deviation for s in outputs]
    outcome = CaseOutcome(name, **labels, streamed=True)
    problem = ""
    if absent[0]:
        problem = f"the result has no sample at t={absent[1]!r} ({absent[0]} reference times without one)"
    passed = not problem and all(d.passed for d in deviations)
    outcome.status = Status.PASS if passed else Status.FAIL
    outcome.deviations = [d for d in deviations if not d.passed]
    outcome.messages = [problem] if problem else [d.describe() for d in deviations if not d.passed]
    if more_messages is not None:
        outcome.messages += more_messages(passed, outcome.deviations)
    if plots == "all" or (plots == "failed" and not passed):
        figure = Figure(title, [(s, *envelopes[("input", s)].line()) for s in input_names],
                        [(s, envelopes[("ref", s)].line(), envelopes[("result", s)].line(), None) for s in outputs],
                        [(s, *envelopes[("deviation", s)].line()) for s in outputs],
                        (zoom["at"], zoom["lines"]) if zoom["lines"] else None)
        outcome.png = draw(figure, mode, labels["fmu"])
    outcome.seconds = time.perf_counter() - started
    return outcome


def _compare_rows(rows, next_time, start, step, n, mode, outputs, signals, envelopes, window, result_until, absent, zoom,
             recent):
    """Compares reference rows (next_time: the time of the row after the
    last, NaN if none) with the result, as Pointwise.bands does on the
    whole: comparison.aligned on the result samples around the rows' times."""
    if not len(rows):
        return
    times = rows["time"]
    for s in outputs:
        envelopes[("ref", s)].add(times, rows[s])
    # the communication points start + k * step from two before the first time to two after the last
    first, last = np.clip([np.floor((times[0] - start) / step) - 2, np.ceil((times[-1] - start) / step) + 2], 0, n)
    first, last = int(first), int(last)
    result_until(last)
    while len(window) > 1 and window[1][0] <= first:
        window.pop(0)  # chunks before the first sample needed
    base = window[0][0]
    result = window[0][1] if len(window) == 1 else np.concatenate([c for _, c in window])
    result = result[first - base:last - base + 1]
    if not len(result):
        raise FastLoopFailed("the run ended early")
    index = aligned(result["time"], np.append(times, next_time))[:-1]  # (the next row tells a repeated time)
    missing = np.flatnonzero(index == -1)
    if len(missing):
        if absent[1] is None:
            absent[1] = float(times[missing[0]])
        absent[0] += len(missing)
    use = index >= 0
    if not use.any():
        return
    picked = result[index[use]]
    compared_times = times[use]
    failing_now = []
    for s in outputs:
        expected = rows[s][use].astype(np.float64)
        values = picked[s].astype(np.float64)
        lower, upper, ok = mode.bounds(values, expected)
        with np.errstate(invalid="ignore", over="ignore"):
            deviation = values - expected
        verdict = signals[s].deviation
        before = verdict.failed
        signals[s].add(Band(compared_times, values, lower, upper, ok, deviation))
        envelopes[("deviation", s)].add(compared_times, deviation)
        if zoom["lines"] is None and verdict.failed > before:
            failing_now.append(verdict.time)
        recent[s] = (compared_times, values, lower, upper, deviation)
    if failing_now and zoom["lines"] is None:
        at = min(failing_now)
        zoom["at"], zoom["lines"] = at, []
        for s in outputs:
            t, v, lo, up, dev = recent[s]
            k = int(np.searchsorted(t, at))
            w = slice(max(k - ZOOM_SAMPLES, 0), k + ZOOM_SAMPLES + 1)
            zoom["lines"].append((s, t[w], v[w], lo[w], up[w], dev[w]))


def simulate_long(fmu_path, input_path, out, start_values=None, start_time=None, stop_time=None, step_size=None,
                  outputs=None, steps_per_chunk: int = STEPS_PER_CHUNK, chunk_bytes: int = CHUNK_BYTES,
                  progress=None):
    """fmutrace run on a long input file, chunk by chunk: the result (as
    simulation.simulate gives it, the same bits) written to the text
    stream out as it is made; its samples, or None if this path cannot
    take it (an input it does not read, a trace the fast loop cannot
    replay, a failing FMU): simulate then runs it and explains."""
    try:
        if os.path.getsize(input_path) < LONG_CASE_BYTES:
            return None
        fmu = Fmu(fmu_path)
        first_in = next(trace_chunks(input_path, fmu.input_problem, chunk_bytes=1 << 16))
        values = {name: fmu.start_value(name, value) for name, value in (start_values or {}).items()}
        names = list(outputs) if outputs else fmu.outputs
        if any(fmu.variable_problem(name) for name in names) or len(first_in) < 2:
            return None
        start = float(start_time) if start_time is not None else float(first_in["time"][0])
        stop = float(stop_time) if stop_time is not None else _last_time(input_path)
        step = float(step_size) if step_size is not None else fmu.default_step
        if step is None or not step > 0 or not stop > start:
            return None
    except (InputError, NotPlain, OSError, ValueError, StopIteration):
        return None
    runner = Runner(fmu.path.read_bytes())
    n = round((stop - start) / step)
    bar = progress or SampleProgress(n + 1)
    written, writer = 0, None
    try:
        for chunk in runner.run_chunks(start, stop, step, trace_chunks(input_path, fmu.input_problem,
                                                                       chunk_bytes=chunk_bytes),
                                       first_in.dtype.names[1:], values, names, steps_per_chunk=steps_per_chunk):
            if writer is None:
                writer = TraceWriter(out, chunk.dtype.names)
            writer.write(chunk)
            written += len(chunk)
            bar.update(written)
    except (FastLoopFailed, NotPlain) as error:
        if written:  # too late to leave it to simulate: the result is half written
            raise SimulationError(f"the simulation failed at t={start + (written - 1) * step!r}: {error}") from None
        return None
    finally:
        bar.close()
        runner.close()
    return written
