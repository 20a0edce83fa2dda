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
import csv
import io
import math
import re
import warnings
from collections.abc import Callable
from os import PathLike
from typing import TextIO

import numpy as np

from .errors import TraceError

TIME_NAMES = ("time", "t", "Time")
UNUSUAL_LINE_BREAKS = "\x0b\x0c\x1c\x1d\x1e\x85\u2028\u2029"
_LINE_BREAK = re.compile("\r\n|[\n\r" + UNUSUAL_LINE_BREAKS + "]")  # where str.splitlines() splits
BOOLEAN_WORDS = {"true": 1.0, "false": 0.0}


def read_text(path):
    """A file's text; a TraceError if it cannot be read or is not UTF-8."""
    try:
        with open(path, encoding="utf-8-sig") as file:
            return file.read()
    except UnicodeDecodeError as error:
        raise TraceError(path, 0, 0, f"not UTF-8 text ({error.reason} at byte {error.start})") from None
    except OSError as error:
        raise TraceError(path, 0, 0, error.strerror or str(error)) from None


def data_lines(text):
    """(line number, text) of the lines that hold data or the header, split
    as str.splitlines() splits them, one at a time (a reader that needs only
    the header does not split the rest)."""
    number, position, end = 0, 0, len(text)
    while position < end:
        cut = _LINE_BREAK.search(text, position)
        line, position = (text[position:cut.start()], cut.end()) if cut else (text[position:], end)
        number += 1
        if line.strip() and not line.lstrip().startswith("#"):
            yield number, line


def _separator(header):
    """',' or ';': the one that occurs outside quotes in the header."""
    counts = {",": 0, ";": 0}
    quoted = False
    for char in header:
        if char == '"':
            quoted = not quoted
        elif not quoted and char in counts:
            counts[char] += 1
    return ";" if counts[";"] > counts[","] else ","


def split_cells(line, separator):
    """The cells of a line, unquoted and stripped."""
    return [cell.strip() for cell in next(csv.reader([line], delimiter=separator, skipinitialspace=True))]


def parse_number(text, decimal_comma=False):
    """A cell's value as a float: a number, or a Boolean word; None if it
    is neither."""
    word = text.strip().lower()
    if word in BOOLEAN_WORDS:
        return BOOLEAN_WORDS[word]
    if decimal_comma and "," in text and "." not in text:
        text = text.replace(",", ".")
    try:
        return float(text)
    except ValueError:
        return None


def read_trace(path: str | PathLike, known: Callable[[str], str | None] | None = None,
               text: str | None = None) -> np.ndarray:
    """The trace in path (or its text, given) as a structured array with
    'time' first.

    known: if given, a function of a column's name (time aside) that
    returns why the column is not allowed, or None if it is; a column
    that is not allowed is a TraceError at its place in the header.
    """
    text = read_text(path) if text is None else text.removeprefix("\ufeff")
    lines = data_lines(text)
    try:
        header_line, header = next(lines)
    except StopIteration:
        raise TraceError(path, 0, 0, "empty file: no header line and no samples") from None
    separator = _separator(header)
    names = split_cells(header, separator)
    time_columns = [i for i, n in enumerate(names) if n in TIME_NAMES]
    if not time_columns:
        raise TraceError(path, header_line, 1, f"no time column: one of the columns must be named "
                                               f"{', '.join(TIME_NAMES[:-1])} or {TIME_NAMES[-1]} (found {names[0]!r})")
    if len(time_columns) > 1:
        raise TraceError(path, header_line, time_columns[1] + 1, f"a second time column {names[time_columns[1]]!r}")
    time_index = time_columns[0]
    seen = {}
    for i, name in enumerate(names):
        if not name:
            raise TraceError(path, header_line, i + 1, "a column without a name")
        if name in seen:
            raise TraceError(path, header_line, i + 1, f"column {name!r} again (first in column {seen[name] + 1})")
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
    return _read_rows(path, lines, names, order, time_index, separator, dtype, header_line)


def _plain_body(text, header_line, separator, columns):
    """The samples of a plain body (',' separated numbers, nothing else
    the general reader would have to interpret) as an (n, columns) array
    read by NumPy's C parser; None for any other body, which the general
    reader then reads or explains. Both read a number with a correctly
    rounded conversion, so they give the same bits (a test checks it)."""
    if separator != "," or any(c in text for c in UNUSUAL_LINE_BREAKS) or \
            ("\r" in text and "\r" in text.replace("\r\n", "")):
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


def _read_rows(path, lines, names, order, time_index, separator, dtype, header_line):
    """The general reader: every cell by itself, every problem placed."""
    decimal_comma = separator == ";"
    rows = []
    previous_time = -math.inf
    for number, line in lines:
        cells = split_cells(line, separator)
        if len(cells) != len(names):
            raise TraceError(path, number, min(len(cells), len(names)) + 1,
                             f"{len(cells)} cells, the header has {len(names)} columns")
        row = []
        for i in order:
            value = parse_number(cells[i], decimal_comma)
            if value is None:
                raise TraceError(path, number, i + 1, f"{cells[i]!r} in column {names[i]!r} is not a number"
                                 if cells[i] else f"an empty cell in column {names[i]!r}")
            row.append(value)
        if not math.isfinite(row[0]):
            raise TraceError(path, number, time_index + 1, f"time {cells[time_index]!r} is not a finite number")
        if row[0] < previous_time:
            raise TraceError(path, number, time_index + 1,
                             f"time goes backwards: {cells[time_index]} after {previous_time!r}")
        previous_time = row[0]
        rows.append(tuple(row))
    if not rows:
        raise TraceError(path, header_line, 0, "no samples: the file has a header line only")
    return np.array(rows, dtype=dtype)


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


def write_trace(path: str | PathLike | TextIO, trace: np.ndarray) -> None:
    """The structured array as CSV into a file name or a text stream:
    'time' first, names quoted, numbers that read back bit for bit,
    Booleans as 0/1."""
    if not hasattr(path, "write"):
        with open(path, "w", newline="\n") as out:
            return write_trace(out, trace)
    names = trace.dtype.names
    path.write(",".join(f'"{name}"' for name in names) + "\n")
    columns = [trace[name].astype(np.float64) for name in names]
    for i in range(len(trace)):
        path.write(",".join(format_number(column[i]) for column in columns) + "\n")
