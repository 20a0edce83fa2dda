"""A table body as a grid of cells (a NumPy array of str, one row per data
line, short rows padded with empty cells), and its columns as channels:
an empty cell is no sample of that channel (recorders leave cells empty
where a channel sampled less often)."""

import operator
from collections import Counter
from typing import NamedTuple

import numpy as np

from .._traces import split_cells
from . import _text as texts
from ._model import Channel


def grid(rows, width=None):
    """rows: lists of cells. An (n, width) str array, short rows padded
    with ''."""
    width = width or max((len(r) for r in rows), default=0)
    padded = [r + [""] * (width - len(r)) if len(r) < width else r[:width] for r in rows]
    return np.array(padded, dtype=str).reshape(len(rows), width)


def body(text, first, separator, stop_words=("EOF",)):
    """(rows of cells, their line numbers) of the data lines from index
    first (0-based) on: blank lines skipped, a stop word alone on a line
    ends the table (TwinCAT's EOF)."""
    rows, numbers = [], []
    for index in range(first, len(text.lines)):
        line = text.lines[index]
        if not line.strip():
            continue
        if line.strip() in stop_words:
            break
        rows.append(split_cells(line, separator))
        numbers.append(index + 1)
    return rows, np.asarray(numbers, dtype=np.int64)


def uniform_table(text, first, separator, width, stop_words=("EOF",)):
    """The cells (an (n, width) str array, stripped) and line numbers of
    the data lines from index first on, split at once in C for a plain
    body; None where body() and grid() must read it line by line: blanks
    as the separator, quotes, blank lines, a line with another number of
    cells. Invariant that makes the one split equal body()'s: no quote and
    exactly width - 1 separators on every line, so the joined lines split
    at every separator give each line's cells in turn (a test checks it)."""
    if separator == " ":
        return None
    lines = text.lines
    end = len(lines)
    while end > first and (not lines[end - 1].strip() or lines[end - 1].strip() in stop_words):
        end -= 1
    body = lines[first:end]
    if not body:
        return None
    joined = "\n".join(body)
    if '"' in joined or "\n\n" in joined:
        return None
    counts = np.fromiter(map(operator.methodcaller("count", separator), body), dtype=np.int64, count=len(body))
    if (counts != width - 1).any():
        return None
    cells = np.array(joined.replace("\n", separator).split(separator), dtype=str).reshape(len(body), width)
    if " " in joined or ("\t" in joined and separator != "\t"):
        cells = np.char.strip(cells)
    return cells, np.arange(first + 1, end + 1, dtype=np.int64)


def present(column):
    """Which cells of a grid column hold something."""
    return np.char.str_len(np.char.strip(column)) > 0


def numeric_stamps(text, column_cells, lines, column, name, decimal_comma):
    """A time column as stamps: int64 where every cell is an integer of
    more than 15 digits (FILETIME: float64 would round it), else float64."""
    stripped = np.char.strip(column_cells)
    if len(stripped) and np.all(np.char.isdigit(stripped)) and np.char.str_len(stripped).max() > 15:
        return stripped.astype(np.int64)
    return texts.values(stripped, decimal_comma, text, lambda i: int(lines[i]), column, name)


def check_increasing(text, stamps, lines, column, name):
    """Time must be finite and not go backwards within a channel's time column."""
    if stamps.dtype.kind == "f" and not np.isfinite(stamps).all():
        i = int(np.flatnonzero(~np.isfinite(stamps))[0])
        raise text.error(int(lines[i]), column, f"time {float(stamps[i])!r} in column {name!r} is not a finite number")
    if len(stamps) > 1:
        back = np.flatnonzero(stamps[1:] < stamps[:-1])
        if len(back):
            i = int(back[0]) + 1
            raise text.error(
                int(lines[i]),
                column,
                f"time goes backwards in column {name!r}: {_stamp(stamps[i])} after {_stamp(stamps[i - 1])}",
            )


def _stamp(stamp):
    """A time stamp as a message shows it (NumPy's repr names its type)."""
    return str(stamp) if stamp.dtype.kind == "M" else repr(stamp.item())


class Rows(NamedTuple):
    """A table's rows: each one's line number, time stamp, and whether its time cell holds something."""

    lines: np.ndarray
    stamps: np.ndarray
    stamp_present: np.ndarray


def channel_from(text, cells, table_rows: Rows, column, name, decimal_comma):
    """The channel of one value column: its samples are the rows where both
    its cell and its time cell hold something."""
    lines, stamps, stamp_present = table_rows
    has = present(cells) & stamp_present
    rows = np.flatnonzero(has)
    values = texts.values(cells[rows], decimal_comma, text, lambda i: int(lines[rows[i]]), column, name)
    return Channel(name=name, stamps=stamps[rows], values=values, file=text.path, column=column, lines=lines[rows])


def unique_names(channels):
    """The channels of one file, those that share a name each named by its
    position too: NAME#COLUMN in a text file, NAME#K (the K-th of that
    name) where there are no columns (MDF); the name as written is kept
    in written. A recorder writes a name twice where one variable is
    recorded twice (ModbusScope: a register plotted on three axes, each
    with its own expression): every one of them is kept, and a map or a
    report names one alone. A made name that another channel has already
    gets its position again."""
    counts = Counter(c.name for c in channels)
    taken = set(counts)
    seen: Counter = Counter()
    for channel in channels:
        if counts[channel.name] < 2:
            continue
        seen[channel.name] += 1
        position = channel.column or seen[channel.name]
        unique = f"{channel.name}#{position}"
        while unique in taken:
            unique += f"#{position}"
        taken.add(unique)
        channel.written, channel.name = channel.name, unique
    return channels
