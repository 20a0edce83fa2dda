"""Tables with a header line: plain CSV/TSV (separator ',' ';' tab or
blanks), the Siemens TIA Portal trace CSV export, the CODESYS V3 trace
text/CSV export and ModbusScope's data file. Metadata lines may come
before the table (TIA Portal and CODESYS write the trace's name, device,
trigger...; ModbusScope its settings and each register's properties as
'//' comments): the table is found by its header, the first line of
names followed by a line of values with as many cells. Columns may share
a name (ModbusScope labels a register plotted twice the same): each is a
channel, named by its column too (_grid.unique_names).

Columns: a time column (time, t, Time, Zeit, Timestamp, Zeitstempel; a
unit in its name: 'Time [ms]', 'Zeit (ms)', 'time_us'; or date strings),
an optional sample index (Index, Sample, Nr, No, #; with no time column
the index counts cycles) and the channels. No public sample of TIA
Portal's export is known, so it is read by these general rules."""

import numpy as np

from .._traces import split_cells
from . import _grid as grids
from . import _text as texts
from . import _timebase as timebase
from ._model import Recording

TIME_WORDS = (
    "time",
    "t",
    "zeit",
    "timestamp",
    "zeitstempel",
    "time stamp",
    "datetime",
    "date/time",
    "datum/zeit",
    "relative time",
    "rel. time",
    "reltime",
)
INDEX_WORDS = (
    "index",
    "sample",
    "sample index",
    "samples",
    "nr",
    "nr.",
    "no",
    "no.",
    "#",
    "id",
    "messpunkt",
    "point",
    "cycle",
    "cycles",
    "zyklus",
    "sample no.",
    "sample number",
    "zeile",
    "row",
)
CYCLE_WORDS = ("cycle", "cycles", "zyklus")
HEADER_SCAN = 200  # lines searched for the header


def bare_name(name):
    """A column name without its unit, in lower case: 'Time [ms]' -> 'time'."""
    name = texts.unquote(name).strip().strip('"').lower()
    for opener in ("[", "("):
        if opener in name:
            name = name[: name.index(opener)]
    for suffix in ("_ms", "_us", "_s", "_ns", "/ms", "/s", "/us"):
        if name.endswith(suffix):
            name = name[: -len(suffix)]
    return name.strip()


def is_time_name(name):
    return bare_name(name) in TIME_WORDS


def is_index_name(name):
    return bare_name(name) in INDEX_WORDS


def _is_value(cell):
    cell = cell.strip()
    return bool(cell) and (texts.cell_value(cell) is not None or timebase.looks_like_date(cell))


def find_header(text):
    """(line index, separator, names) of the table's header line, or
    (None, None, why not)."""
    lines = text.lines
    candidates = 0
    for i in range(min(len(lines), HEADER_SCAN)):
        line = lines[i]
        if not line.strip():
            continue
        separator = texts.sniff_separator(line)
        names = split_cells(line, separator)
        if len(names) < 2 or sum(_is_value(n) for n in names) > len(names) // 2:
            continue
        candidates += 1
        following = next((j for j in range(i + 1, len(lines)) if lines[j].strip()), None)
        if following is None:
            continue
        cells = split_cells(lines[following], separator)
        if len(cells) == len(names) and sum(_is_value(c) for c in cells) >= max(1, len(cells) - 1):
            if any(is_time_name(n) or is_index_name(n) for n in names):
                return i, separator, names
    if not candidates:
        return None, None, "no line of column names"
    return (
        None,
        None,
        (
            "no header line with a time column (time, t, Zeit, Timestamp, 'Time [ms]') or a sample "
            "index followed by a line of values"
        ),
    )


def sniff(text):
    """None if the text is such a table, else why not."""
    return find_header(text)[2] if find_header(text)[0] is None else None


def layout(text):
    """(header's line index, separator, names, time columns, index columns) of a table's text."""
    index, separator, names = find_header(text)
    if index is None:
        raise text.error(0, 0, names)
    names = [texts.unquote(n) for n in names]
    time_columns = [i for i, n in enumerate(names) if is_time_name(n)]
    index_columns = [i for i, n in enumerate(names) if is_index_name(n)]
    return index, separator, names, time_columns, index_columns


def read(text):
    index, separator, names, time_columns, index_columns = layout(text)
    header_line = index + 1
    preamble = [line for line in text.lines[:index] if line.strip()]
    for i, name in enumerate(names):
        if not name:
            raise text.error(header_line, i + 1, "a column without a name")
    fast = grids.uniform_table(text, index + 1, separator, len(names))
    if fast:
        table, lines = fast
    else:
        rows, lines = grids.body(text, index + 1, separator)
        if not rows:
            raise text.error(header_line, 0, "no samples: the table has a header line only")
        for row, line in zip(rows, lines, strict=True):
            if len(row) > len(names):
                raise text.error(int(line), len(names) + 1, f"{len(row)} cells, the header has {len(names)} columns")
        table = grids.grid(rows, len(names))
    decimal_comma = separator != ","
    time_column = time_columns[0] if time_columns else (index_columns[0] if index_columns else None)
    if time_column is None:
        raise text.error(
            header_line,
            1,
            f"no time column: one of the columns must be the time or a sample index (found {names[0]!r})",
        )
    time_name = names[time_column]
    cells = table[:, time_column]
    stamp_present = grids.present(cells)
    if not stamp_present.all():
        row = int(np.argmin(stamp_present))
        raise text.error(int(lines[row]), time_column + 1, f"an empty cell in the time column {time_name!r}")
    if timebase.looks_like_date(cells[0]):
        stamps = timebase.dates(cells, text, lambda i: int(lines[i]), time_column + 1, time_name)
        unit, source = "date", f"column {time_name!r} holds dates"
    else:
        stamps = grids.numeric_stamps(text, cells, lines, time_column + 1, time_name, decimal_comma)
        unit = timebase.unit_in_name(time_name)
        if time_column not in time_columns:
            unit, source = "cycles", f"column {time_name!r} counts samples"
        elif unit:
            source = f"column {time_name!r} says so"
        elif bare_name(time_name) in CYCLE_WORDS:
            unit, source = "cycles", f"column {time_name!r}"
        else:
            unit, source = timebase.unnamed_unit(stamps, time_name)
    grids.check_increasing(text, stamps, lines, time_column + 1, time_name)
    skip = {time_column} | set(index_columns)
    rows = grids.Rows(lines, stamps, stamp_present)
    channels = grids.unique_names(
        [
            grids.channel_from(text, table[:, j], rows, j + 1, names[j], decimal_comma)
            for j in range(len(names))
            if j not in skip
        ]
    )
    return Recording(
        paths=[text.path],
        format=_label(preamble, names, time_name, index_columns),
        channels=channels,
        time_unit=unit,
        time_source=source,
        encoding=text.encoding,
    )


def _label(preamble, names, time_name, index_columns):
    said = " ".join(preamble).lower()
    if said.startswith("//modbusscope"):
        return "ModbusScope data file"
    if "codesys" in said or any(n.startswith("Application.") for n in names):
        return "CODESYS V3 trace export"
    if preamble and (index_columns or "tia" in said or "s7-" in said or any(n.startswith('"') for n in names)):
        return "Siemens TIA Portal trace CSV export"
    return "CSV/TSV table"
