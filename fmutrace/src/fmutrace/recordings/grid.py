"""A table body as a grid of cells (a NumPy array of str, one row per data
line, short rows padded with empty cells), and its columns as channels:
an empty cell is no sample of that channel (recorders leave cells empty
where a channel sampled less often)."""
import numpy as np

from . import text as texts
from .model import Channel


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
        rows.append(texts.split(line, separator))
        numbers.append(index + 1)
    return rows, np.asarray(numbers, dtype=np.int64)


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
    """Time must not go backwards within a channel's time column."""
    if len(stamps) > 1:
        back = np.flatnonzero(stamps[1:] < stamps[:-1])
        if len(back):
            i = int(back[0]) + 1
            raise text.error(int(lines[i]), column, f"time goes backwards in column {name!r}: "
                                                   f"{stamps[i]!r} after {stamps[i - 1]!r}")


def channel_from(text, cells, lines, stamps, stamp_present, column, name, decimal_comma, symbol=""):
    """The channel of one value column: its samples are the rows where both
    its cell and its time cell hold something."""
    has = present(cells) & stamp_present
    rows = np.flatnonzero(has)
    values = texts.values(cells[rows], decimal_comma, text, lambda i: int(lines[rows[i]]), column, name)
    return Channel(name=name, stamps=stamps[rows], values=values, file=text.path, column=column,
                   lines=lines[rows], symbol=symbol)
