"""Text as recorders write it: the encoding, the lines, the separator, and
cells turned into numbers a column at a time.

Encodings: UTF-8 with or without a byte order mark, UTF-16 (with a BOM, or
without one when every other byte is zero, as Windows tools write it) and
Windows-1252 (what a German or English Windows writes when it is not
told otherwise; tried when the bytes are not UTF-8).

Values: numbers with a decimal point, or a decimal comma where the
separator is not a comma (and in cells a comma-separated file quotes);
TRUE/FALSE in any case (1/0); IEC literals 16#..., 8#..., 2#... (WORDs
and the like; '_' between digits allowed); a type prefix (REAL#1.5,
BOOL#TRUE, WORD#16#00FF). A column is converted at once with NumPy; only
when that fails are its cells looked at one by one, to name the first
bad one.
"""

import re

import numpy as np

from .._errors import TraceError
from .._reading import MAX_LINE, read_bytes
from .._traces import counts_outside_quotes, parse_number

SEPARATORS = ("\t", ";", ",", " ")
_IEC_BASED = re.compile(r"^(?:[A-Za-z_]+#)?([+-]?)(2|8|16)#([0-9A-Fa-f_]+)$")
_TYPED = re.compile(r"^[A-Za-z_]+#(.+)$")


class Text:
    """A file's text, how it was decoded, and its lines (without their
    ends) numbered from 1. A line longer than MAX_LINE is a TraceError:
    millions of columns (or a file without line ends) would take minutes
    and all the memory before anything could be said about them."""

    def __init__(self, path, text, encoding):
        self.path, self.text, self.encoding = str(path), text, encoding
        self.lines = text.splitlines()
        if max(map(len, self.lines), default=0) > MAX_LINE:
            number = next(n for n, line in enumerate(self.lines, 1) if len(line) > MAX_LINE)
            raise self.error(
                number,
                0,
                f"a line of {len(self.lines[number - 1]):,} characters: more than the {MAX_LINE:,} a recorder's "
                "export is read with (so many columns, or no line ends?)",
            )

    def error(self, line, column, message):
        return TraceError(self.path, line, column, message)


def decode(path, data):
    """(text, encoding) of a file's bytes; a TraceError if they are none
    of the encodings recorders write."""
    if data.startswith(b"\xef\xbb\xbf"):
        return _strict(path, data[3:], "utf-8", "UTF-8 (with BOM)")
    if data.startswith((b"\xff\xfe", b"\xfe\xff")):
        return _strict(path, data, "utf-16", "UTF-16")
    head = data[:4096]
    if len(head) >= 4:
        zeros_even, zeros_odd = head[0::2].count(0), head[1::2].count(0)
        if zeros_odd > len(head) * 0.4 and zeros_even == 0:
            return _strict(path, data, "utf-16-le", "UTF-16 LE")
        if zeros_even > len(head) * 0.4 and zeros_odd == 0:
            return _strict(path, data, "utf-16-be", "UTF-16 BE")
    if b"\x00" in head:
        raise TraceError(path, 0, 0, "a binary file, not text (and not MDF)")
    try:
        return data.decode("utf-8"), "UTF-8"
    except UnicodeDecodeError:
        pass
    return _strict(path, data, "cp1252", "Windows-1252")


def _strict(path, data, codec, label):
    try:
        return data.decode(codec), label
    except UnicodeDecodeError as error:
        line = data[: error.start].count(b"\n" if "16" not in codec else "\n".encode(codec)) + 1
        raise TraceError(path, line, 0, f"not {label} text ({error.reason} at byte {error.start})") from None


def read(path):
    """The Text of a file; TraceError if it cannot be read (_reading's bounds)."""
    data = read_bytes(path)
    text, encoding = decode(path, data)
    return Text(path, text, encoding)


def sniff_separator(line):
    """The separator of a header line: tab, ';' or ',' (the most frequent
    one outside quotes), else blanks."""
    counts = counts_outside_quotes(line, SEPARATORS[:3])
    best = max(counts, key=counts.get)
    return best if counts[best] else " "


def unquote(name):
    """A name without the quotes around it as a whole (csv leaves the inner
    ones of "DB_Ramp".value alone)."""
    name = name.strip()
    if len(name) >= 2 and name[0] == name[-1] == "'":
        return name[1:-1]
    return name


def cell_value(text):
    """One cell as a float, or None: traces.parse_number's rule (with a
    decimal comma: a comma-separated file has one only in a quoted cell),
    and IEC literals (16#FF, 2#1010_0101) with or without a type prefix
    (WORD#16#00FF, REAL#1.5), '_' between digits."""
    cell = text.strip()
    if not cell:
        return None
    based = _IEC_BASED.match(cell)
    if based:
        sign, base, digits = based.groups()
        try:
            value = float(int(digits.replace("_", ""), int(base)))
        except ValueError:
            return None
        return -value if sign == "-" else value
    typed = _TYPED.match(cell)
    if typed and "#" not in typed.group(1):
        return cell_value(typed.group(1))
    return parse_number(cell.replace("_", "") if "_" in cell else cell, decimal_comma=True)


def numbers(cells, decimal_comma, where):
    """A column of cells (a sequence of str) as float64. where(i) gives
    (line, column, name) of cell i for the error: the first cell that is
    no value is a TraceError naming it."""
    array = np.asarray(cells, dtype=object) if not isinstance(cells, np.ndarray) else cells
    strings = array if array.dtype.kind == "U" else array.astype(str)
    try:
        if decimal_comma:
            return np.char.replace(strings, ",", ".").astype(np.float64)
        return strings.astype(np.float64)
    except ValueError:
        pass
    out = np.empty(len(array), dtype=np.float64)
    for i, cell in enumerate(array):
        value = cell_value(str(cell))
        if value is None:
            error = where(i)
            raise error(repr(str(cell).strip()))
        out[i] = value
    return out


def values(cells, decimal_comma, text, line_of, column, name):
    """numbers() with the usual message: "'x' in column 'name' is not a
    value" at the cell's line and column."""

    def where(i):
        def make(shown):
            message = (
                f"{shown} in column {name!r} is not a number, TRUE/FALSE or an IEC literal (16#...)"
                if shown != "''"
                else f"an empty cell in column {name!r}"
            )
            return text.error(line_of(i), column, message)

        return make

    return numbers(cells, decimal_comma, where)
