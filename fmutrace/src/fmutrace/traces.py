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

Anything else raises :class:`TraceError`, which names the file, the line
and the column.
"""
import csv
import math
from pathlib import Path

import numpy as np

TIME_NAMES = ("time", "t", "Time")
BOOLEAN_WORDS = {"true": 1.0, "false": 0.0}


class InputError(ValueError):
    """Bad input that no simulation can mend (exit code 2)."""


class TraceError(InputError):
    """Bad input: the file, the line and column (1-based, 0 if none) and
    what is wrong. str() is the message users see."""

    def __init__(self, path, line, column, message):
        self.path, self.line, self.column, self.message = str(path), line, column, message
        where = str(path)
        if line:
            where += f", line {line}"
        if column:
            where += f", column {column}"
        super().__init__(f"{where}: {message}")


def _lines(path):
    """(line number, text) of the lines that hold data or the header."""
    try:
        text = Path(path).read_text(encoding="utf-8-sig")
    except UnicodeDecodeError as error:
        raise TraceError(path, 0, 0, f"not UTF-8 text ({error.reason} at byte {error.start})") from None
    except OSError as error:
        raise TraceError(path, 0, 0, error.strerror or str(error)) from None
    for number, line in enumerate(text.splitlines(), start=1):
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


def _split(line, separator):
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


def read_trace(path, known=None):
    """The trace in path as a structured array with 'time' first.

    known: if given, a function of a column's name (time aside) that
    returns why the column is not allowed, or None if it is; a column
    that is not allowed is a TraceError at its place in the header.
    """
    lines = _lines(path)
    try:
        header_line, header = next(lines)
    except StopIteration:
        raise TraceError(path, 0, 0, "empty file: no header line and no samples") from None
    separator = _separator(header)
    names = _split(header, separator)
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
    decimal_comma = separator == ";"
    rows = []
    previous_time = -math.inf
    for number, line in lines:
        cells = _split(line, separator)
        if len(cells) != len(names):
            raise TraceError(path, number, min(len(cells), len(names)) + 1,
                             f"{len(cells)} cells, the header has {len(names)} columns")
        row = []
        for i in order:
            value = parse_number(cells[i], decimal_comma)
            if value is None:
                shown = cells[i] if cells[i] else "an empty cell"
                raise TraceError(path, number, i + 1, f"{shown!r} in column {names[i]!r} is not a number"
                                 if cells[i] else f"{shown} in column {names[i]!r}")
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
    dtype = [("time", np.float64)] + [(names[i], np.float64) for i in order[1:]]
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


def write_trace(path, trace):
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
