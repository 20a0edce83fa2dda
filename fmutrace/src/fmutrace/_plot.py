"""A case's figure for the report: its inputs, each compared signal
(reference, result, and the band where the mode draws one) and the
deviation, as the data of its page's interactive plots (page_data, and
page_tile for a long case's finer level) and, when asked, as PNG bytes;
for a failing case beside it the same zoomed on the first deviation.

A line of millions of samples is drawn decimated to what the figure can
show: per pixel column the first and last sample and the smallest and
largest value (Envelope), so the picture is the same and its cost does
not grow with the length. A long case fills its envelopes chunk by chunk."""

import importlib
import io
import json
import threading
import warnings

import numpy as np

from ._comparison import Mode
from ._traces import shown

WIDTH_INCHES, DPI = 8.0, 80
COLUMNS = 600  # pixel columns of an axis (the figure is 640 pixels wide)
ZOOM_SAMPLES = 40  # compared samples each side of the first deviation in the zoom


BACK = "the reference outside the tube around the result"  # a two-sided tube's second side, in the plots
DETAIL = 16  # an envelope's columns per figure column: a case page's finer level, sent in tiles of COLUMNS
FOLD_SAMPLES = 1 << 16  # samples an envelope holds before it folds them into its columns


class Envelope:
    """A line over [t0, t1] decimated to COLUMNS pixel columns: per column
    the first and the last sample and the smallest and the largest value
    (NaN ignored), filled from consecutive chunks of (times, values).
    Chunks are held as given (not to be changed after) and folded into
    the columns once FOLD_SAMPLES of them wait, or when the line is drawn:
    a short case that gets no figure never pays for its envelopes."""

    def __init__(self, t0: float, t1: float, columns: int = COLUMNS * DETAIL):
        self.t0, self.span, self.columns = float(t0), max(float(t1) - float(t0), 1e-300), columns
        self.waiting: list[tuple[np.ndarray, np.ndarray]] = []
        self.waiting_samples = 0
        self.samples = 0  # added in all
        self.folded = False  # the columns below hold samples (they are made then)
        self.first_t = self.first_v = self.last_t = self.last_v = self.low = self.high = np.full(0, np.nan)

    def add(self, times, values):
        """Samples in time order, after those added before."""
        if not len(times):
            return
        self.waiting.append((times, values))
        self.waiting_samples += len(times)
        self.samples += len(times)
        if self.waiting_samples >= FOLD_SAMPLES:
            self._fold()

    def _fold(self):
        if not self.waiting:
            return
        if len(self.waiting) == 1:
            times, values = self.waiting[0]
        else:
            times = np.concatenate([t for t, _ in self.waiting])
            values = np.concatenate([np.asarray(v, dtype=np.float64) for _, v in self.waiting])
        self.waiting, self.waiting_samples = [], 0
        if not self.folded:
            self.folded = True
            self.first_t, self.first_v, self.last_t, self.last_v, self.low, self.high = (
                np.full(self.columns, np.nan) for _ in range(6)
            )
        values = np.asarray(values, dtype=np.float64)
        column = np.clip(((times - self.t0) / self.span * self.columns).astype(np.int64), 0, self.columns - 1)
        starts = np.flatnonzero(np.concatenate(([True], column[1:] != column[:-1])))
        ends = np.concatenate((starts[1:], [len(times)])) - 1
        c = column[starts]
        with np.errstate(invalid="ignore"):
            low, high = np.fmin.reduceat(values, starts), np.fmax.reduceat(values, starts)
        new = np.isnan(self.first_t[c])
        self.first_t[c[new]], self.first_v[c[new]] = times[starts[new]], values[starts[new]]
        self.last_t[c], self.last_v[c] = times[ends], values[ends]
        self.low[c], self.high[c] = np.fmin(self.low[c], low), np.fmax(self.high[c], high)

    def line(self, factor: int = DETAIL):
        """(times, values) to draw: per column (of columns / factor, each
        joining factor of the envelope's) its first sample, its range at
        its middle, its last sample."""
        self._fold()
        if not self.folded:
            return np.empty(0), np.empty(0)
        return _line(*_joined(self._arrays(), factor))

    def tile(self, k: int, per: int = COLUMNS):
        """(times, values) of the envelope's own columns k * per .. (k + 1) * per, at its full detail."""
        self._fold()
        if not self.folded:
            return np.empty(0), np.empty(0)
        return _line(*(a[k * per : (k + 1) * per] for a in self._arrays()))

    def _arrays(self):
        return self.first_t, self.first_v, self.last_t, self.last_v, self.low, self.high


def _joined(arrays, factor):
    """An envelope's columns (first_t, first_v, last_t, last_v, low, high) joined factor at a time."""
    if factor == 1:
        return arrays
    first_t, first_v, last_t, last_v, low, high = (a.reshape(-1, factor) for a in arrays)
    filled = ~np.isnan(first_t)
    first = np.argmax(filled, axis=1)  # the first filled column of each group, the last below
    last = factor - 1 - np.argmax(filled[:, ::-1], axis=1)
    rows = np.arange(len(first_t))
    with np.errstate(invalid="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # (a group of empty columns: NaN, as it should)
        lowest, highest = np.nanmin(low, axis=1), np.nanmax(high, axis=1)
    return first_t[rows, first], first_v[rows, first], last_t[rows, last], last_v[rows, last], lowest, highest


def _line(first_t, first_v, last_t, last_v, low, high):
    filled = ~np.isnan(first_t)
    middle = (first_t + last_t) / 2
    times = np.stack([first_t, middle, middle, last_t], axis=1)[filled].ravel()
    values = np.stack([first_v, low, high, last_v], axis=1)[filled].ravel()
    return times, values


class Figure:
    """What a case's figure shows, each line already decimated:
    inputs [(name, times, values)], signals [(name, (ref times, values),
    (result times, values), band or None)], deviations [(name, times,
    values)], and zoom: None, or (its time, [(name, times, values,
    lower, upper, deviation[, reference or None])]) around the first
    deviation (full resolution); back: a two-sided tube's second side,
    {name: (times, the reference outside the tube around the result)}."""

    def __init__(self, title, inputs, signals, deviations, zoom=None, back=None):
        self.title, self.inputs, self.signals, self.deviations, self.zoom = title, inputs, signals, deviations, zoom
        self.back = back or {}


_reused = threading.local()  # a figure is drawn by one thread at a time


def _layouts() -> dict:
    """(rows, columns, has_inputs) -> (figure, axes grid) of this thread."""
    if not hasattr(_reused, "layouts"):
        _reused.layouts = {}
    return _reused.layouts


def draw(figure: Figure, mode: Mode, label: str, reuse: bool = True) -> bytes:
    """The figure as PNG bytes. A layout (number of panels, zoom or not)
    is built once per process (and thread) and then only cleared and
    refilled: making the axes and their ticks is about 40 % of a
    figure's cost, and the picture is a freshly built one's, pixel for
    pixel (test_fmutrace_plot)."""
    has_inputs = bool(figure.inputs)
    rows = len(figure.signals) + 1 + has_inputs
    columns = 2 if figure.zoom else 1
    key, layouts = (rows, columns, has_inputs), _layouts()
    if reuse and key in layouts:
        fig, grid = layouts[key]
        for ax in grid.ravel():
            _clear(ax)
    else:
        fig, grid = _layout(*key)
        if reuse:
            layouts[key] = fig, grid
    axes = list(grid[:, 0])
    if has_inputs:
        ax = axes.pop(0)
        for name, times, values in figure.inputs:
            ax.step(times, values, where="post", label=_plain(f"input {name}"))
        ax.legend(loc="best", fontsize=7)
    deviation_axis = axes.pop()
    many = max((len(r[0]) for _, _, r, _ in figure.signals), default=0) > COLUMNS
    for ax, (name, (ref_t, ref_v), (res_t, res_v), band) in zip(axes, figure.signals, strict=False):
        if band is not None and mode.fills_band:
            ax.fill_between(band[0], band[1], band[2], color="0.85", label=_plain(mode.name))
        ax.plot(ref_t, ref_v, **_held(mode.reference_line), label=_plain(f"{name} reference"))
        ax.step(
            res_t,
            res_v,
            where="post",
            color="C1",
            linewidth=1.2,
            marker="" if many else ".",
            markersize=3,
            label=_plain(f"{name} {label}"),
        )
        ax.legend(loc="best", fontsize=7)
    for name, times, values in figure.deviations:
        deviation_axis.plot(times, values, drawstyle="steps-post", label=_plain(name))
        if name in figure.back:
            deviation_axis.plot(*figure.back[name], drawstyle="steps-post", label=_plain(f"{name}, {BACK}"))
    deviation_axis.set_ylabel(mode.deviation_label, fontsize=7)
    deviation_axis.legend(loc="best", fontsize=7)
    if figure.zoom:
        at, lines = figure.zoom
        zoom_axes = list(grid[has_inputs:, 1])
        zoom_deviation = zoom_axes.pop()
        for ax, (name, times, values, lower, upper, deviation, *_) in zip(zoom_axes, lines, strict=False):
            if mode.fills_band:
                ax.fill_between(times, lower, upper, step="post", color="0.8", label=_plain(mode.name))
            else:  # (lower = upper: the expected values)
                ax.plot(times, lower, **_held(mode.reference_line), label="reference")
            ax.step(times, values, where="post", color="C1", marker=".", markersize=3, label=_plain(name))
            ax.axvline(at, color="C3", linewidth=0.8)
            zoom_deviation.plot(times, deviation, drawstyle="steps-post", marker=".", markersize=3, label=_plain(name))
        zoom_axes and zoom_axes[0].set_title(f"zoom: first deviation at t={at!r}", fontsize=8)
        zoom_deviation.axvline(at, color="C3", linewidth=0.8)
    title = shown(figure.title)
    fig.suptitle(_plain(title if len(title) < 110 else title[:107] + "..."), fontsize=9)
    stream = io.BytesIO()
    fig.savefig(stream, dpi=DPI, format="png", metadata={"Software": None})
    return stream.getvalue()


def _held(line: dict) -> dict:
    """The mode's reference line drawn as the result is: each value held until the next sample."""
    return {**line, "drawstyle": "steps-post"}


def _plain(text):
    """Text from users' files drawn as it is written: every $ escaped, so
    that matplotlib finds no mathtext in it (a broken formula would abort
    the figure), and bytes that are not UTF-8 as U+FFFD."""
    return shown(text).replace("$", r"\$")


def load_plotting():
    """Imports what drawing a figure needs (matplotlib, its Agg canvas): a
    second or more on a loaded machine, paid once by a process."""
    for module in ("matplotlib.figure", "matplotlib.backends.backend_agg"):  # the Agg canvas: savefig's
        importlib.import_module(module)


def _layout(rows: int, columns: int, has_inputs: bool):
    """A new empty figure of the layout and its axes grid (rows, columns)."""
    from matplotlib.figure import Figure as MplFigure
    from matplotlib.ticker import MaxNLocator

    height = 1.6 * rows + 0.6
    # no pyplot: a figure kept for reuse must not stay in pyplot's list of open figures
    fig = MplFigure(figsize=(WIDTH_INCHES * (1 + 0.45 * (columns - 1)), height))
    grid = fig.subplots(rows, columns, sharex="col", squeeze=False, width_ratios=[1, 0.45][:columns])
    for ax in grid.ravel():
        ax.tick_params(labelsize=7)
        # few ticks: matplotlib makes every tick as artists of its own, most of a figure's cost
        ax.xaxis.set_major_locator(MaxNLocator(6))
        ax.yaxis.set_major_locator(MaxNLocator(4))
    for ax in grid[-1]:
        ax.set_xlabel("time [s]")
    if columns == 2 and has_inputs:
        grid[0, 1].set_axis_off()
    # fixed margins: tight_layout would cost more than the rest of the plot
    fig.subplots_adjust(
        left=0.1 / (1 + 0.45 * (columns - 1)),
        right=0.98,
        top=1 - 0.45 / height,
        bottom=0.45 / height,
        hspace=0.12,
        wspace=0.18,
    )
    return fig, grid


def _clear(ax):
    """An axis of a reused layout back to how _layout left it, its ticks
    kept: no line, band or legend, no data limits, the colour
    cycle from its start."""
    for artist in (*ax.lines, *ax.collections):
        artist.remove()
    if ax.get_legend():
        ax.get_legend().remove()
    ax.set_prop_cycle(None)
    ax.relim()
    # the limits of a new axis: an axis left empty shows 0..1, a drawn one autoscales when it is drawn
    ax.set_xlim(0, 1, auto=True)
    ax.set_ylim(0, 1, auto=True)


def _points(times, values, window=None) -> list:
    """[times, values] of a line as lists for a page; window (times,
    values at full resolution) replaces the line's points in its span."""
    times, values = np.asarray(times, dtype=np.float64), np.asarray(values, dtype=np.float64)
    if window is not None and len(window[0]):
        w_t, w_v = np.asarray(window[0], dtype=np.float64), np.asarray(window[1], dtype=np.float64)
        outside = (times < w_t[0]) | (times > w_t[-1])
        k = int(np.searchsorted(times[outside], w_t[0]))
        times = np.concatenate((times[outside][:k], w_t, times[outside][k:]))
        values = np.concatenate((values[outside][:k], w_v, values[outside][k:]))
    return [times.tolist(), values.tolist()]


def _window(zoom_line, k):
    """(times, line k) of a signal's zoom line at full resolution, to replace the decimated line there; or None."""
    return None if zoom_line is None or zoom_line[k] is None else (zoom_line[0], zoom_line[k])


def page_data(figure: Figure, label: str, criteria: dict, deviation_label: str = "result - ref") -> dict:
    """What a case page's interactive plots show (plain lists, NaN kept:
    the page reads them as JavaScript): per signal its reference, result,
    band and deviation, decimated as the figure's, with the samples around
    the first deviation at full resolution; the inputs; where the first
    deviation is and the span to frame on open. criteria: signal -> the
    criterion it is judged by; deviation_label: what the deviation is (the
    mode's, its plots' scale's label)."""
    zoom = {}
    frame = None
    if figure.zoom:
        at, lines = figure.zoom
        for name, times, values, lower, upper, deviation, *reference in lines:
            zoom[name] = (times, values, lower, upper, deviation, reference[0] if reference else None)
            if len(times):
                low, high = float(times[0]), float(times[-1])
                frame = [min(frame[0], low), max(frame[1], high)] if frame else [low, high]
    signals = []
    for (name, ref, result, band), (_, dev_t, dev_v) in zip(figure.signals, figure.deviations, strict=True):
        z = zoom.get(name)
        signals.append(
            {
                "name": shown(name),
                "criterion": shown(criteria.get(name, "")),
                "reference": _points(ref[0], ref[1], window=_window(z, 5)),
                "reference_framed": _window(z, 5) is not None,
                "result": _points(result[0], result[1], window=_window(z, 1)),
                "lower": _points(band[0], band[1], window=_window(z, 2)) if band is not None else None,
                "upper": _points(band[0], band[2], window=_window(z, 3)) if band is not None else None,
                "deviation": _points(dev_t, dev_v, window=_window(z, 4)),
                "back": _points(*figure.back[name]) if name in figure.back else None,
            }
        )
    return {
        "title": shown(figure.title),
        "label": shown(label),
        "deviation_label": deviation_label,
        "back_label": BACK,
        "inputs": [{"name": shown(name), "line": _points(t, v)} for name, t, v in figure.inputs],
        "signals": signals,
        "first_deviation": figure.zoom[0] if figure.zoom else None,
        "frame": frame,
    }


def needs_tiles(envelopes) -> bool:
    """Whether a page gains by the finer level: a line has more samples than the figure's columns show."""
    return any(e.samples > 2 * COLUMNS for e in envelopes)


def page_tile(k: int, inputs, signals) -> dict:
    """Tile k of DETAIL of a case page's finer level: the lines' own
    envelope columns over the k-th part of the time span. inputs: [(name,
    Envelope)]; signals: [(name, reference, result, lower or None, upper
    or None, deviation, back or None)], Envelopes."""
    first = next(e for _, *lines in signals for e in lines if e is not None) if signals else inputs[0][1]
    part = first.span / DETAIL

    def points(envelope):
        return None if envelope is None else [a.tolist() for a in envelope.tile(k)]

    return {
        "k": k,
        "from": first.t0 + k * part,
        "to": first.t0 + (k + 1) * part,
        "inputs": [points(e) for _, e in inputs],
        "signals": [
            {
                "reference": points(ref),
                "result": points(result),
                "lower": points(lower),
                "upper": points(upper),
                "deviation": points(deviation),
                "back": points(back),
            }
            for _, ref, result, lower, upper, deviation, back in signals
        ],
    }


def as_script(head: str, data, tail: str) -> str:
    """head + data as JSON + tail: a script line; NaN and infinities as
    JavaScript's, and no '<' (names from users' files as text even where
    a page would hold the script inline)."""
    return head + json.dumps(data).replace("<", "\\u003c") + tail + "\n"
