"""A long one-file recording (a table export: CSV/TSV, TIA Portal, CODESYS
V3) read in blocks of lines (_recording runs it through _pipeline.run_chunked_case),
in memory that does not grow with its length.

The file's head (its first HEAD_BYTES) is read as the in-memory path reads
the whole (format, header, columns, time unit, the channels matched to the
FMU); every block of lines after it is cut into cells and converted by the
same functions (grid.uniform_table, grid.numeric_stamps, text.values), so
each sample has the in-memory path's bits. Each row is a cycle: its inputs
drive the step from its cycle, its outputs are compared as align.py lays
them. Before anything runs, one pass over the time column alone applies
the whole file's rules (time_column_pass): the step is the head's finest
interval and must be the whole file's (timebase.Intervals, the rule
normalise applies in memory), the length one normalise takes, every row
the cycle after the one before; notes and the failing signals' recorded
samples are the in-memory path's, word for word (a test runs both on the
same recordings).

What it takes: one file of a table export in UTF-8 or Windows-1252, a
separator other than blanks, a time column of numbers (not dates or
FILETIME integers), every cell filled, lines ending in LF or CR LF, no
blank line before the end, one row per cycle (no repeated or skipped
cycle). Anything else raises NotPlain before the outcome is made, and the
in-memory path reads the file (or explains it): what the head or the time
column shows before the FMU runs, a bad cell of another column when its
block is read, after the FMU ran the cycles before it.
"""

import io
from dataclasses import dataclass

import numpy as np
import pyarrow as pa
import pyarrow.csv as pcsv

from .._errors import TraceError
from .._reading import MAX_LINE, open_regular
from .._traces import UNUSUAL_LINE_BREAKS, NotPlain, float64_values, line_too_long
from . import TEXT_FORMATS, _mdf as mdf, _tables as tables
from . import _grid as grids
from . import _text as texts
from . import _clock as clock
from . import _timebase as timebase

HEAD_BYTES = 1 << 20  # read as the in-memory path reads a whole file
BLOCK_BYTES = 1 << 22  # of text per block of lines after the head
MAX_INTERVALS = 1 << 16  # distinct intervals between stamps counted for the step (more: the in-memory path)
_CODECS = {"UTF-8": "utf-8", "UTF-8 (with BOM)": "utf-8", "Windows-1252": "cp1252"}


class Table:
    """A table export's layout from its head, and its body in blocks of rows."""

    def __init__(self, path, fmu, options):
        self.path = str(path)
        with open_regular(path) as file:
            head = file.read(HEAD_BYTES)
            at_end = not file.read(1)
        if mdf.sniff(head[:64]) is None:
            raise NotPlain("MDF")
        if not at_end:
            head = head[: head.rfind(b"\n") + 1]
        decoded, self.encoding = texts.decode(self.path, head)
        if self.encoding not in _CODECS or _unusual_breaks(decoded):
            raise NotPlain("an encoding or line breaks the blocks cannot follow")
        text = texts.Text(self.path, decoded, self.encoding)
        fits = next((name for name, sniff, _ in TEXT_FORMATS if sniff(text) is None), None)
        if fits != TEXT_FORMATS[-1][0]:
            raise NotPlain("not a table export")
        recording = tables.read(text)
        index, self.separator, names, time_columns, index_columns = tables.layout(text)
        if self.separator == " " or recording.time_unit == "date":
            raise NotPlain("blanks as the separator, or dates")
        self.width, self.decimal_comma = len(names), self.separator != ","
        self.time_column = time_columns[0] if time_columns else index_columns[0]
        self.time_name = names[self.time_column]
        rows = len(text.lines) - index - 1
        if any(c.stamps.dtype != np.float64 or len(c.values) != rows for c in recording.channels) or rows < 2:
            raise NotPlain("integer stamps, an empty cell or too few rows in the head")
        timebase.normalise(recording, options.timebase_unit, options.step_size, fmu.default_step, options.names)
        self.recording = recording
        self.origin = float(recording.channels[0].stamps[0])
        self.step_given = recording.time_unit == "cycles" or recording.step_source != timebase.FINEST
        # the body starts after the header's line (index: 0-based), counted in bytes of the head
        start = 0
        for _ in range(index + 1):
            start = head.index(b"\n", start) + 1
        self.body_start, self.first_line = start, index + 2
        self.columns = {c.name: c.column - 1 for c in recording.channels}

    def blocks(self, block_bytes=None, time_only=False):
        """(first line number, cells, line numbers, times) of each block of
        rows; cells: a channel's values by table.values(cells, line numbers,
        name). time_only: pyarrow converts the time cells alone (the other
        columns are only split), for the pass over the time column."""
        codec = _CODECS[self.encoding]
        number = self.first_line
        with open_regular(self.path) as file:
            file.seek(self.body_start)
            rest, data = b"", b"x"
            while data:
                data = file.read(block_bytes or BLOCK_BYTES)
                block = rest + data
                cut = block.rfind(b"\n") + 1 if data else len(block)
                if cut == 0 and len(block) > 4 * MAX_LINE:
                    raise TraceError(self.path, number, 0, line_too_long(len(block)))
                block, rest = block[:cut], block[cut:]
                if not data:  # the file's end: blank lines there end the table as in memory
                    lines = block.split(b"\n")
                    while lines and not lines[-1].strip():
                        lines.pop()
                    block = b"\n".join(lines)
                if not block.strip():
                    continue
                fast = self._numbers(block, time_only)
                if fast is not None:
                    cells, stamps = fast
                    line_numbers = np.arange(number, number + len(stamps), dtype=np.int64)
                else:
                    cells, line_numbers, stamps = self._cells(block, codec, number)
                yield (
                    number,
                    cells,
                    line_numbers,
                    timebase.seconds(
                        timebase._minus(stamps, self.origin), self.recording.time_unit, self.recording.step_size
                    ),
                )
                number += len(stamps)

    def _numbers(self, block, time_only=False):
        """(values by column, stamps) of a block whose every cell (with
        time_only: every time cell, the only column converted) is a plain
        number, read by pyarrow; None for any other (the cells are then
        read as the in-memory path reads them). pyarrow converts a decimal
        number correctly rounded, as NumPy's conversion of the cells does:
        the same bits. Left to the cells: NaN (its sign and payload), time
        stamps beyond 1e15 (grid.numeric_stamps may read those as
        integers), a line of other cells, blanks, quotes, an empty line."""
        if b"\r" in block and block.count(b"\r") != block.count(b"\r\n"):
            return None
        names = [f"c{j}" for j in range(self.width)]
        read = [self.time_column] if time_only else range(self.width)
        try:
            table = pcsv.read_csv(
                io.BytesIO(block),
                read_options=pcsv.ReadOptions(column_names=names, use_threads=True),
                parse_options=pcsv.ParseOptions(delimiter=self.separator, quote_char=False, ignore_empty_lines=False),
                convert_options=pcsv.ConvertOptions(
                    include_columns=[names[j] for j in read],
                    column_types={names[j]: pa.float64() for j in read},
                    null_values=[],
                    strings_can_be_null=False,
                    decimal_point="," if self.decimal_comma else ".",
                ),
            )
        except pa.ArrowInvalid:
            return None
        columns = {j: float64_values(table.column(names[j])) for j in read}
        stamps = columns[self.time_column]
        if any(np.isnan(c).any() for c in columns.values()) or (np.abs(stamps) >= 1e15).any():
            return None
        return columns, stamps

    def _cells(self, block, codec, number):
        """(cells, line numbers, stamps) of a block as the in-memory path cuts and reads them."""
        try:
            decoded = block.decode(codec)
        except UnicodeDecodeError:
            raise NotPlain("bytes of another encoding") from None
        if _unusual_breaks(decoded):
            raise NotPlain("line breaks the blocks cannot follow")
        text = texts.Text(self.path, decoded, self.encoding)
        lines = text.lines
        if any(not line.strip() or line.strip() == "EOF" for line in lines):
            raise NotPlain("a blank line or an end marker inside the table")
        table = grids.uniform_table(text, 0, self.separator, self.width, stop_words=())
        if table is None or len(table[0]) != len(lines):
            raise NotPlain("a line of other cells than the header's")
        cells, line_numbers = table
        line_numbers = line_numbers + (number - 1)
        try:
            if not grids.present(cells).all():
                raise NotPlain("an empty cell")
            stamps = grids.numeric_stamps(
                text, cells[:, self.time_column], line_numbers, self.time_column + 1, self.time_name, self.decimal_comma
            )
        except TraceError:
            raise NotPlain("a time cell the in-memory path explains") from None
        if stamps.dtype != np.float64:
            raise NotPlain("integer stamps")
        return cells, line_numbers, stamps

    def values(self, cells, line_numbers, name):
        """A channel's values in a block (text.values, as the in-memory path converts them)."""
        j = self.columns[name]
        if isinstance(cells, dict):
            return cells[j]
        try:
            return texts.values(
                cells[:, j],
                self.decimal_comma,
                texts.Text(self.path, "", self.encoding),
                lambda i: int(line_numbers[i]),
                j + 1,
                name,
            )
        except TraceError:
            raise NotPlain("a cell the in-memory path explains") from None


def _unusual_breaks(text):
    return any(c in text for c in UNUSUAL_LINE_BREAKS) or "\r" in text.replace("\r\n", "")


@dataclass
class Cycles:
    """What the pre-pass over a streamed recording's time column found."""

    rows: int
    last: int  # the last row's cycle
    grid: clock.Grid  # the cycles the rows sit on (the recorder's clock): cycle 0 is the first row's
    digits: int | None = None  # decimals of a second that make every stamp whole (asked for: resolution=True)
    ends: tuple = ()  # (the first two rows' times, the last's), seconds (resolution=True)


def time_column_pass(table, step, block_bytes=None, resolution=False):
    """The whole file's time column read once, before anything runs (only
    its cells converted), by the rules normalise applies to a whole
    recording: the step its intervals give (unless one was given) is the
    head's, its length is no misread unit; and by the stream's own: the
    rows fitted to a grid of cycles as the in-memory path fits them (the
    first SEARCH_WINDOW rows numbered by clock.fit, each later block by the
    line of the rows before it, clock.Line), each row on a cycle after the
    one before, a cycle now and then skipped (the OB did not run it) but
    not every other one (a recorder sampling every k-th cycle: read whole).
    The run numbers each row again on the whole file's line. resolution:
    the recorder's too (Cycles.digits, Cycles.ends), for recorded cycle
    lengths. NotPlain otherwise."""
    recording = table.recording
    intervals = timebase.Intervals()
    line = clock.Line()
    rows, span, last = 0, 0.0, -1
    skipped = 0  # rows after a skipped cycle
    first: list[np.ndarray] | None = []  # the first SEARCH_WINDOW rows' times: numbered once they are in
    digits, head = 0, np.zeros(0)

    def number(times, grid):
        nonlocal last, skipped
        index = grid.index(times)
        gaps = np.diff(np.concatenate([[last], index]))
        if (gaps < 1).any():
            raise NotPlain("two rows on one cycle, or time going back (the in-memory path says)")
        skipped += int(np.count_nonzero(gaps > 1))
        line.add(index, times)
        last = int(index[-1])

    for _, _, _, times in table.blocks(block_bytes, time_only=True):
        if resolution:
            found = timebase.decimal_resolution(times)
            if found is None:
                raise NotPlain("stamps of no decimal resolution (the in-memory path says)")
            digits = max(digits, found)
        head = np.concatenate([head, times[: 2 - len(head)]])
        if first is None:
            number(times, line.grid(step))
        else:
            first.append(times)
            if sum(map(len, first)) >= clock.SEARCH_WINDOW:
                window = np.concatenate(first)
                number(window, clock.fit(window, step))
                first = None
        rows, span = rows + len(times), float(times[-1])
        if not table.step_given:
            intervals.add(times)
            if len(intervals.values) > MAX_INTERVALS:
                raise NotPlain("too many distinct intervals between stamps")
    if first:
        window = np.concatenate(first)
        number(window, clock.fit(window, step))
    if not rows:
        raise NotPlain("no rows")
    if 2 * skipped > rows:
        raise NotPlain("samples every few cycles (the in-memory path reads them so)")
    if not table.step_given and timebase.snapped_interval(intervals.median() or step) != step:
        raise NotPlain("the whole file's interval is another step than its head's")
    if timebase.too_long(span) or timebase.too_many_steps(span / step, rows, recording.unit_given):
        raise NotPlain("the in-memory path refuses the length")
    grid = line.grid(step)
    zero = int(grid.index(head[:1])[0])  # cycle 0 is the first row's (as clock.fit makes it)
    grid = clock.Grid(grid.period, grid.phase + zero * grid.period)
    if clock.restep(grid, step) != step:
        raise NotPlain("the rows fit another step than their finest interval (the in-memory path says)")
    last = int(grid.index(np.array([span]))[0])
    if resolution:
        return Cycles(rows, last, grid, digits, (*head.tolist(), span))
    return Cycles(rows, last, grid)
