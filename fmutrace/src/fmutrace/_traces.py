"""Trace CSV files as people have them, read into NumPy structured arrays.

A trace is a header line of column names and one line of numbers per
sample. Accepted, without options:

- separator ``,`` or ``;`` (the one in the header line); with ``;`` a
  decimal comma (``1,5``) is read as a decimal point, as spreadsheet
  exports in many locales write it;
- the time column named ``time``, ``t`` or ``Time`` (any position; it is
  called ``time`` in the result);
- names in double quotes (``"time","u"``), spaces around cells;
- Booleans as ``0``/``1`` or ``true``/``false`` in any case;
- a repeated time is an event: the row before gives the value up to that
  instant, the row after it from that instant on;
- blank lines, lines starting with ``#``, a missing or extra trailing
  newline.

Anything else raises a TraceError, which names the file, the line and
the column.
"""

import codecs
import io
import os
import math
import re
import warnings
from collections.abc import Callable, Iterator
from os import PathLike
from typing import NamedTuple, TextIO

import cffi
import numpy as np
import pyarrow as pa
import pyarrow.csv as pcsv

from ._errors import TraceError
from ._native import native_function
from ._reading import MAX_LINE, open_regular, quoted, read_bytes

TIME_NAMES = ("time", "t", "Time")
UNUSUAL_LINE_BREAKS = "\x0b\x0c\x1c\x1d\x1e\x85\u2028\u2029"
_LINE_BREAK = re.compile("\r\n|[\n\r" + UNUSUAL_LINE_BREAKS + "]")  # where str.splitlines() splits
BOOLEAN_WORDS = {"true": 1.0, "false": 0.0}


def read_text(path):
    """A file's text, within the read bound (_reading); a TraceError if it
    cannot be read, is no regular file, is larger, or is not UTF-8."""
    data = read_bytes(path)
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        raise TraceError(path, 0, 0, f"not UTF-8 text ({error.reason} at byte {error.start})") from None


def shown(text) -> str:
    """Text from users' files and names as it can be shown and written:
    bytes of a file name that are not UTF-8 (Python's surrogate escapes)
    as U+FFFD."""
    text = str(text)
    try:
        return text.encode("utf-8", "surrogateescape").decode("utf-8", "replace")
    except UnicodeEncodeError:  # a surrogate that escapes no byte
        return text.encode("utf-8", "replace").decode("utf-8")


def data_lines(text, path=""):
    """(line number, text) of the lines that hold data or the header, split
    as str.splitlines() splits them, one at a time (a reader that needs only
    the header does not split the rest); a line longer than MAX_LINE is a
    TraceError of path's."""
    number, position, end = 0, 0, len(text)
    while position < end:
        reach = min(end, position + MAX_LINE + 2)  # (a search that never looks past a line's bound)
        cut = _LINE_BREAK.search(text, position, reach)
        number += 1
        if cut is None and reach < end or (cut and cut.start() - position > MAX_LINE):
            raise TraceError(path, number, 0, line_too_long())
        line, position = (text[position : cut.start()], cut.end()) if cut else (text[position:], end)
        if line.strip() and not line.lstrip().startswith("#"):
            yield number, line


def line_too_long(length: int | None = None) -> str:
    """Why a line is refused: longer than MAX_LINE (its length, where it is known)."""
    what = f"a line of {length:,} characters: more than" if length else "a line longer than"
    return f"{what} the bound of {MAX_LINE:,} characters (so many columns, or no line ends?)"


def counts_outside_quotes(line, characters):
    """{character: how often it occurs in line outside double quotes}."""
    counts = dict.fromkeys(characters, 0)
    quoted = False
    for char in line:
        if char == '"':
            quoted = not quoted
        elif not quoted and char in counts:
            counts[char] += 1
    return counts


def _separator(header):
    """',' or ';': the one that occurs outside quotes in the header."""
    counts = counts_outside_quotes(header, ",;")
    return ";" if counts[";"] > counts[","] else ","


def split_cells(line, separator):
    """The cells of a line, stripped. A cell quoted as a whole loses its
    quotes ("a;b" -> a;b, doubled quotes inside become one); quotes inside a
    name stay ("DB_Ramp".value is a TIA Portal name as written). A space
    separator means any run of blanks (as space-aligned exports have them).
    The one rule for traces, case files and recorders' exports."""
    if '"' not in line:
        if separator == " ":
            return line.split()
        return [cell.strip() for cell in line.split(separator)]
    cells: list[str] = []
    current: list[str] = []
    quoted = False
    for char in line:
        if char == '"':
            quoted = not quoted
        if char == separator and not quoted:
            cells.append("".join(current))
            current = []
        else:
            current.append(char)
    cells.append("".join(current))
    if separator == " ":
        cells = [c for c in cells if c.strip()]
    return [_unquote_cell(c.strip()) for c in cells]


def _unquote_cell(cell):
    if len(cell) >= 2 and cell[0] == cell[-1] == '"' and '"' not in cell[1:-1].replace('""', ""):
        return cell[1:-1].replace('""', '"')
    return cell


def parse_number(text, decimal_comma=False):
    """A cell's value as a float: a number (with a decimal comma if
    decimal_comma, where the cell has no point), or a Boolean word; None
    if it is neither. The one rule for numbers (recordings add IEC
    literals to it: recordings._text.cell_value)."""
    word = text.strip().lower()
    if word in BOOLEAN_WORDS:
        return BOOLEAN_WORDS[word]
    if decimal_comma and "," in text and "." not in text:
        text = text.replace(",", ".")
    try:
        return plain_float(text)
    except ValueError:
        return None


def plain_float(text) -> float:
    """float(text) without Python's own literal forms: '_' between digits
    (1_0 is not 10 in a CSV file; recordings read IEC's 1_000 themselves);
    ValueError if it is not a number."""
    if "_" in text:
        raise ValueError(f"{text!r} is not a number")
    return float(text)


def read_trace(
    path: str | PathLike, known: Callable[[str], str | None] | None = None, text: str | None = None
) -> np.ndarray:
    """The trace in path (or its text, given) as a structured array with
    'time' first.

    known: if given, a function of a column's name (time aside) that
    returns why the column is not allowed, or None if it is; a column
    that is not allowed is a TraceError at its place in the header.
    """
    text = read_text(path) if text is None else text.removeprefix("\ufeff")
    lines = data_lines(text, path)
    try:
        header_line, header = next(lines)
    except StopIteration:
        raise TraceError(path, 0, 0, "empty file: no header line and no samples") from None
    separator = _separator(header)
    names = split_cells(header, separator)
    time_columns = [i for i, n in enumerate(names) if n in TIME_NAMES]
    if not time_columns:
        raise TraceError(
            path,
            header_line,
            1,
            f"no time column: one of the columns must be named "
            f"{', '.join(TIME_NAMES[:-1])} or {TIME_NAMES[-1]} (found {quoted(names[0])})",
        )
    if len(time_columns) > 1:
        raise TraceError(
            path, header_line, time_columns[1] + 1, f"a second time column {quoted(names[time_columns[1]])}"
        )
    time_index = time_columns[0]
    seen: dict[str, int] = {}
    for i, name in enumerate(names):
        if not name:
            raise TraceError(path, header_line, i + 1, "a column without a name")
        if name in seen:
            raise TraceError(
                path, header_line, i + 1, f"column {quoted(name)} again (first in column {seen[name] + 1})"
            )
        seen[name] = i
        if i != time_index and known is not None:
            problem = known(name)
            if problem:
                raise TraceError(path, header_line, i + 1, problem)
    order = [time_index] + [i for i in range(len(names)) if i != time_index]
    dtype = [("time", np.float64)] + [(names[i], np.float64) for i in order[1:]]
    table = _plain_body(text, header_line, separator, len(names))
    if table is not None:
        table = table[:, order]
        times = table[:, 0]
        if np.isfinite(times).all() and (np.diff(times) >= 0).all():
            trace = np.empty(len(table), dtype=dtype)
            for j, (name, _) in enumerate(dtype):
                trace[name] = table[:, j]
            return trace
    return _read_rows(path, lines, _Header(names, order, time_index, dtype, header_line), separator)


def _plain_body(text, header_line, separator, columns):
    """The samples of a plain body (',' separated numbers, nothing else
    the general reader would have to interpret) as an (n, columns) array
    read by NumPy's C parser; None for any other body, which the general
    reader then reads or explains. Both read a number with a correctly
    rounded conversion, so they give the same bits (a test checks it)."""
    if (
        separator != ","
        or any(c in text for c in UNUSUAL_LINE_BREAKS)
        or ("\r" in text and "\r" in text.replace("\r\n", ""))
    ):
        return None  # splitlines() would count the lines otherwise
    body = text.split("\n", header_line)[-1]
    if '"' in body or "#" in body:
        return None
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # an empty body warns: the general reader says what is wrong
            table = np.loadtxt(io.StringIO(body), delimiter=",", comments=None, dtype=np.float64, ndmin=2)
    except (ValueError, UserWarning):
        return None
    if table.shape[1] != columns or not len(table):
        return None
    return table


class _Header(NamedTuple):
    """A trace's header: its names, the order of the columns read (time
    first), the time's column, the array's dtype, its line."""

    names: list
    order: list
    time_index: int
    dtype: list
    line: int


def _read_rows(path, lines, header: _Header, separator):
    """The general reader: every cell by itself, every problem placed."""
    names, order, time_index, dtype, header_line = header
    decimal_comma = separator == ";"
    rows = []
    previous_time = -math.inf
    for number, line in lines:
        cells = split_cells(line, separator)
        if len(cells) != len(names):
            raise TraceError(
                path,
                number,
                min(len(cells), len(names)) + 1,
                f"{len(cells)} cells, the header has {len(names)} columns",
            )
        row = []
        for i in order:
            value = parse_number(cells[i], decimal_comma)
            if value is None:
                raise TraceError(
                    path,
                    number,
                    i + 1,
                    f"{quoted(cells[i])} in column {quoted(names[i])} is not a number"
                    if cells[i]
                    else f"an empty cell in column {quoted(names[i])}",
                )
            row.append(value)
        if not math.isfinite(row[0]):
            raise TraceError(path, number, time_index + 1, f"time {quoted(cells[time_index])} is not a finite number")
        if row[0] < previous_time:
            raise TraceError(
                path, number, time_index + 1, f"time goes backwards: {cells[time_index]} after {previous_time!r}"
            )
        previous_time = row[0]
        rows.append(tuple(row))
    if not rows:
        raise TraceError(path, header_line, 0, "no samples: the file has a header line only")
    return np.array(rows, dtype=dtype)


CHUNK_BYTES = 1 << 22  # of CSV text per chunk of trace_chunks
MAX_STEPS = 200_000_000  # more steps than this (23 days of 10 ms cycles) is a misread unit: refused


def steps_problem(start, stop, step) -> str | None:
    """Why a run from start to stop in steps of step is refused (None if it is not): the one bound on
    the work a case, a recording or a run may ask for, checked before anything runs."""
    steps = (stop - start) / step
    if steps > MAX_STEPS:
        return (
            f"{steps:.3g} steps of {step!r} s from {start!r} to {stop!r} s: more than the bound of "
            f"{MAX_STEPS:,} steps (a step size or time in another unit?)"
        )
    return None


def samples_problem(samples) -> str | None:
    """Why a channel of so many samples is refused (None if it is not): each sample is a cycle of its
    own, so it asks for at least as many steps, under steps_problem's bound; checked before they are read."""
    if samples > MAX_STEPS:
        return f"{samples:,} samples, each a cycle of its own: more than the bound of {MAX_STEPS:,} steps"
    return None


def trace_chunks(
    path: str | PathLike, known: Callable[[str], str | None] | None = None, chunk_bytes: int = CHUNK_BYTES
) -> Iterator[np.ndarray]:
    """The trace in path as consecutive structured arrays ('time' first) of
    about chunk_bytes of text each, read by pyarrow's CSV reader: memory
    stays flat in the file's length. For the plain dialect (',' separated
    numbers, a header of names); any other file, or one whose values or
    times read_trace would refuse, raises NotPlain at the chunk where that
    shows, and read_trace reads or explains it. Both readers convert a
    number correctly rounded: the same bits (a test checks it)."""
    try:
        file = open_regular(path)  # (closed below, however the chunks end)
    except TraceError as error:
        raise NotPlain(str(error)) from None
    with file:
        yield from _plain_chunks(file, known, chunk_bytes)


def _plain_chunks(file, known, chunk_bytes) -> Iterator[np.ndarray]:
    """trace_chunks' work on the open file (one opening for the header and the blocks)."""
    try:
        header = file.readline(MAX_LINE + 1).decode("utf-8-sig")
    except (OSError, UnicodeDecodeError) as error:
        raise NotPlain(str(error)) from None
    if len(header) > MAX_LINE or _separator(header) != "," or header.lstrip().startswith("#"):
        raise NotPlain("not the plain dialect")
    names = split_cells(header, ",")
    times = [i for i, n in enumerate(names) if n in TIME_NAMES]
    if (
        len(times) != 1
        or len(set(names)) != len(names)
        or not all(names)
        or (known is not None and any(known(n) for i, n in enumerate(names) if i != times[0]))
    ):
        raise NotPlain("the header needs read_trace's explanation")
    order = [names[times[0]]] + [n for i, n in enumerate(names) if i != times[0]]
    dtype = [("time", np.float64)] + [(n, np.float64) for n in order[1:]]
    read_block = _BlockReader(names, order, dtype)
    previous = -math.inf
    rows = 0
    # blocks of whole lines cut here, each parsed by itself: pyarrow's own streaming reader holds on to
    # memory that grows with the file (measured: 80 MB at 360,000 rows, 240 MB at 17,280,000)
    for block in _line_blocks(file, chunk_bytes):
        chunk = read_block(block)
        t = chunk["time"]
        if len(t) and not (np.isfinite(t).all() and t[0] >= previous and (np.diff(t) >= 0).all()):
            raise NotPlain("a time read_trace would refuse")
        if len(t):
            previous = t[-1]
        rows += len(t)
        yield chunk
    if not rows:
        raise NotPlain("no samples")


_ROWS_FFI = cffi.FFI()
_ROWS_FFI.cdef("size_t fmutrace_plain_rows(const char *, size_t, size_t, const size_t *, double *, size_t, size_t *);")
C_ROWS = native_function("_rows", _ROWS_FFI, "fmutrace_plain_rows")  # (None: not built, pyarrow then)


class _BlockReader:
    """A block of a plain file's data lines as a structured array (time
    first): the lines _rows.c reads (the common form of numbers), pyarrow
    from the first line it does not (or every line, where _rows.c is not
    built). Both convert a number correctly rounded (a test holds them
    equal to read_trace)."""

    def __init__(self, names, order, dtype):
        self.names, self.order, self.dtype = names, order, dtype
        self.field_of = _ROWS_FFI.new("size_t[]", [order.index(n) for n in names]) if C_ROWS else None
        self.convert = pcsv.ConvertOptions(
            column_types={n: pa.float64() for n in names}, null_values=[], strings_can_be_null=False
        )
        self.parse = pcsv.ParseOptions(delimiter=",", quote_char=False)

    def __call__(self, block: bytes) -> np.ndarray:
        read = 0
        if C_ROWS is not None:
            chunk = np.empty(block.count(b"\n") + 1, dtype=self.dtype)
            stopped = _ROWS_FFI.new("size_t *")
            values = _ROWS_FFI.cast("double *", chunk.ctypes.data)
            read = C_ROWS(block, len(block), len(self.names), self.field_of, values, len(chunk), stopped)
            if stopped[0] == len(block):
                return chunk[:read]
            block = block[stopped[0] :]
            if block.startswith(codecs.BOM_UTF8):  # (pyarrow skips one at the start of what it is given)
                raise NotPlain("a byte-order mark inside the file")
        rest = self._arrow(block)
        return np.concatenate([chunk[:read], rest]) if read else rest

    def _arrow(self, block: bytes) -> np.ndarray:
        try:
            table = pcsv.read_csv(
                io.BytesIO(block),
                read_options=pcsv.ReadOptions(column_names=self.names, use_threads=True),
                parse_options=self.parse,
                convert_options=self.convert,
            )
        except pa.ArrowInvalid as error:
            raise NotPlain(str(error)) from None
        chunk = np.empty(table.num_rows, dtype=self.dtype)
        for (field, _), name in zip(self.dtype, self.order, strict=True):
            chunk[field] = float64_values(table.column(name))
        return chunk


def float64_values(column) -> np.ndarray:
    """A float64 column without nulls (null_values=[]: none) as one array,
    from its buffers: pyarrow's to_numpy imports pandas where it is
    installed, a third of a second of a short campaign."""
    assert column.null_count == 0
    parts = [np.frombuffer(c.buffers()[1], dtype=np.float64, count=len(c), offset=c.offset * 8) for c in column.chunks]
    return parts[0] if len(parts) == 1 else np.concatenate(parts) if parts else np.empty(0)


def _float64_array(values) -> pa.Array:
    """values as a float64 arrow array, made from their buffer: pa.array and
    pa.table import pandas where it is installed (a third of a second)."""
    data = np.ascontiguousarray(values, dtype=np.float64)
    return pa.Array.from_buffers(pa.float64(), len(data), [None, pa.py_buffer(data)])


def last_time(path):
    """The time in the last data line of a plain CSV file (its first cell),
    however long that line is."""
    with open(path, "rb") as file:
        end = file.seek(0, os.SEEK_END)
        size = 4096
        while True:
            if size > 4 * MAX_LINE:
                raise ValueError(line_too_long(size))
            begin = max(0, end - size)
            file.seek(begin)
            text = file.read(end - begin).rstrip()
            start = max(text.rfind(b"\n"), text.rfind(b"\r")) + 1
            if start or begin == 0:  # a line break before the last line: it is whole
                return float(text[start:].split(b",")[0])
            size *= 4


def _line_blocks(file, size):
    """The open file's bytes from here on in blocks of about size, each ending at a line's end."""
    rest = b""
    while True:
        data = file.read(size)
        if not data:
            break
        data = rest + data
        cut = data.rfind(b"\n") + 1
        if cut == 0:
            if len(data) > max(size, 4 * MAX_LINE):
                raise NotPlain(line_too_long(len(data)))
            rest = data
            continue
        block, rest = data[:cut], data[cut:]
        if block.strip():
            yield block
    if rest.strip():
        yield rest


class NotPlain(Exception):
    """trace_chunks cannot read the file: read_trace reads or explains it."""


def format_number(value):
    """The shortest text that reads back as the same double (so a trace
    written and read again is bit for bit the same)."""
    value = float(value)
    if math.isnan(value):
        return "nan"
    if math.isinf(value):
        return "inf" if value > 0 else "-inf"
    if value.is_integer() and abs(value) < 1e16:
        return str(int(value)) if value or math.copysign(1.0, value) > 0 else "-0"
    return repr(value)


WRITE_ROWS = 1 << 16  # rows formatted at a time by write_trace


def write_trace(path: str | PathLike | TextIO, trace: np.ndarray) -> None:
    """The structured array as CSV into a file name or a text stream:
    'time' first, names quoted, numbers that read back bit for bit,
    Booleans as 0/1. Formatted a block of rows at a time by pyarrow's
    writer (the shortest text that reads back as the same double)."""
    if isinstance(path, (str, PathLike)):
        with open(path, "w", newline="\n") as out:
            return write_trace(out, trace)
    writer = TraceWriter(path, trace.dtype.names)
    writer.write(trace)


class TraceWriter:
    """A trace written block by block (a long result as it is made), in
    write_trace's format."""

    def __init__(self, out: TextIO, names):
        self.out, self.names = out, list(names)
        out.write(",".join(f'"{name}"' for name in self.names) + "\n")

    def write(self, trace: np.ndarray):
        for begin in range(0, len(trace), WRITE_ROWS):
            block = trace[begin : begin + WRITE_ROWS]
            table = pa.Table.from_arrays([_float64_array(block[name]) for name in self.names], names=self.names)
            data = io.BytesIO()
            pcsv.write_csv(table, data, write_options=pcsv.WriteOptions(include_header=False, quoting_style="none"))
            self.out.write(data.getvalue().decode("ascii"))
