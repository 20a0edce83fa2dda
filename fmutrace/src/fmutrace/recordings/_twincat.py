"""Beckhoff TwinCAT Scope View's CSV export (TE13xx, "Export to csv").

Its structure, as Beckhoff documents it and as open readers (pytcs) read
it: a title block (Name, File, 'Starttime of export' as FILETIME and as
text, 'Endtime of export'), blank lines, then one header row per channel
property (Name, SymbolComment, Data-Type, SampleTime[ms], VariableSize,
SymbolBased, IndexGroup, IndexOffset, SymbolName, NetID, Port, Offset,
ScaleFactor, BitMask, Unit, ...), a blank line, and the samples.

In the header rows the property's key stands in the cell above a time
column and the channels' values in the cells above theirs: with the
timelines option 'All' every channel has its own time column (Name, a,
Name, b), with 'For each sampletime' consecutive channels of one sample
time share one (Name, a, b, Name, c), with 'None' there is none (the
sample time and the row give the time). The separator is the export's
(tab by default, or ';', ',', ':' or blanks), the decimal mark '.' or ','.
Times are milliseconds from the export's first point or, with 'Full
Timestamp', FILETIME. A group that sampled less often ends earlier:
its cells are blank (or the row is shorter). An 'EOF' line may close the
file."""

import numpy as np

from .._traces import split_cells
from . import _grid as grids
from . import _text as texts
from ._model import Recording

KEYS = (
    "SampleTime[ms]",
    "SampleTime",
    "SymbolName",
    "Data-Type",
    "SymbolComment",
    "VariableSize",
    "NetID",
    "IndexGroup",
    "SymbolBased",
    "Unit",
)
TITLE_SCAN = 40


def _find(text):
    """(index of the Name header row, separator) or (None, why not)."""
    lines = text.lines
    for i in range(min(len(lines), TITLE_SCAN)):
        line = lines[i]
        if line.startswith("Name") and len(line) > 4 and not line[4].isalnum():
            separator = line[4]
            following = split_cells(lines[i + 1], separator)[0] if i + 1 < len(lines) else ""
            if following in KEYS:  # a channel property (the title block's Name is followed by File)
                return i, separator
    return None, "no channel header block (rows 'Name', 'SampleTime[ms]', 'SymbolName' ... as Scope View writes)"


def sniff(text):
    found, why = _find(text)
    return why if found is None else None


def _padded(key, cells, name_cells, key_columns):
    """A property row that leaves out its trailing empty cells (Scope View
    does with 'For each sampletime': 'SymbolComment', then nothing for the
    last channels) filled up to the Name row, when its keys stand where
    the Name row's do; any other row as it is."""
    keys = [j for j, c in enumerate(cells) if c == key]
    if len(cells) >= len(name_cells) or keys != key_columns[: len(keys)]:
        return cells
    filled = cells + [""] * (len(name_cells) - len(cells))
    for j in key_columns:
        filled[j] = key
    return filled


def _realigned(text, line, key, cells, name_row, separator):
    """A property row with more cells than the Name row: Scope View writes
    a decimal comma in SampleTime[ms] even with ',' as the separator
    ('SampleTime[ms],0,2,SampleTime[ms],1'). Where a group of one channel
    got more cells than it has channels, they are one number; any other
    misfit cannot be told apart and is an error at the row. name_row:
    (the Name row's cells, the columns of its 'Name' keys)."""
    name_cells, key_columns = name_row
    starts = [j for j, c in enumerate(cells) if c == key]
    if len(starts) != len(key_columns):
        raise text.error(line, 0, f"the row {key!r} has {len(starts)} groups, the Name row {len(key_columns)}")
    fixed = []
    bounds = key_columns + [len(name_cells)]
    for g, start in enumerate(starts):
        slots = bounds[g + 1] - bounds[g] - 1
        end = starts[g + 1] if g + 1 < len(starts) else len(cells)
        values = cells[start + 1 : end]
        if len(values) != slots:
            if slots != 1 or not all(v.strip().lstrip("-").isdigit() for v in values):
                why = (
                    "a name with blanks, blanks separating"
                    if separator == " "
                    else "a decimal comma, ',' separating"
                    if separator == ","
                    else "a separator inside a name"
                )
                raise text.error(
                    line,
                    start + 1,
                    f"the row {key!r} has {len(values)} cells for {slots} channels "
                    f"({why}?): export with another separator",
                )
            values = [",".join(values)]
        fixed += [key] + values
    return fixed


def read(text):
    start, separator = _find(text)
    if start is None:
        raise text.error(0, 0, separator)
    header = {}
    index = start
    while index < len(text.lines) and text.lines[index].strip():
        cells = split_cells(text.lines[index], separator) if separator != " " else text.lines[index].split(" ")
        header[cells[0]] = (index + 1, cells)
        index += 1
    name_line, name_cells = header["Name"]
    key_columns = [j for j, c in enumerate(name_cells) if c == "Name"]
    for key, (line, cells) in list(header.items()):
        if len(cells) != len(name_cells):
            cells = _padded(key, cells, name_cells, key_columns)
            header[key] = (line, _realigned(text, line, key, cells, (name_cells, key_columns), separator))
    rows, lines = grids.body(text, index, separator if separator != " " else " ")
    if not rows:
        raise text.error(name_line, 0, "no samples: the export has its header only")
    width = max(len(name_cells), max(len(r) for r in rows))
    table = grids.grid(rows, width)
    decimal_comma = separator != ","
    channel_count = len(name_cells) - len(key_columns)
    no_time = max(len(r) for r in rows) <= channel_count and key_columns == [0]
    groups: list[tuple[int | None, list[int]]] = []  # (time column or None, [channel columns])
    for j in range(len(name_cells)):
        if j in key_columns and not no_time:
            groups.append((j, []))
        elif j not in key_columns:
            if not groups:
                groups.append((None, []))
            groups[-1][1].append(j)

    def prop(key, j):
        cells = header.get(key, (0, []))[1]
        return cells[j].strip() if j < len(cells) else ""

    sample_times = []
    for _, columns in groups:
        for j in columns:
            literal = prop("SampleTime[ms]", j) or prop("SampleTime", j)
            if literal:
                value = texts.cell_value(literal)
                if value is None or not value > 0:
                    raise text.error(
                        header.get("SampleTime[ms]", (0,))[0],
                        j + 1,
                        f"SampleTime[ms] {literal!r} is not a positive number",
                    )
                sample_times.append(value)
    if no_time:
        rows_columns = [j - 1 for j in range(len(name_cells)) if j not in key_columns]
        table = grids.grid(rows, channel_count)
    channels = []
    filetime = False
    for time_column, columns in groups:
        if no_time or time_column is None:
            if not sample_times:
                raise text.error(name_line, 1, "no time columns and no SampleTime[ms]: the time is unknown")
            row_stamps = np.arange(len(rows), dtype=np.float64)
            for j in columns:
                k = rows_columns[columns.index(j)] if no_time else j
                ms = texts.cell_value(prop("SampleTime[ms]", j))
                channel = grids.channel_from(
                    text,
                    table[:, k],
                    grids.Rows(lines, row_stamps * ms, np.ones(len(rows), bool)),
                    k + 1,
                    prop("Name", j),
                    decimal_comma,
                )
                channel.symbol = prop("SymbolName", j)
                channel.sample_time = ms * 1e-3
                channels.append(channel)
            continue
        cells = table[:, time_column]
        stamp_present = grids.present(cells)
        rows_with = np.flatnonzero(stamp_present)
        stamps_present = grids.numeric_stamps(
            text,
            cells[rows_with],
            lines[rows_with],
            time_column + 1,
            f"time of {prop('Name', columns[0]) if columns else 'a group'}",
            decimal_comma,
        )
        filetime = filetime or stamps_present.dtype.kind == "i"
        stamps = np.zeros(len(rows), dtype=stamps_present.dtype)
        stamps[rows_with] = stamps_present
        grids.check_increasing(text, stamps_present, lines[rows_with], time_column + 1, "time")
        for j in columns:
            channel = grids.channel_from(
                text, table[:, j], grids.Rows(lines, stamps, stamp_present), j + 1, prop("Name", j), decimal_comma
            )
            channel.symbol = prop("SymbolName", j)
            declared = texts.cell_value(prop("SampleTime[ms]", j) or prop("SampleTime", j))
            channel.sample_time = declared * 1e-3 if declared else None
            channels.append(channel)
    unit = "FILETIME" if filetime else "ms"
    source = (
        "its stamps are FILETIME ('Full Timestamp')"
        if filetime
        else "Scope View writes milliseconds from the first point"
    )
    return Recording(
        paths=[text.path],
        format="Beckhoff TwinCAT Scope View CSV export",
        channels=grids.unique_names(channels),
        time_unit=unit,
        time_source=source,
        encoding=text.encoding,
        sample_time=min(sample_times) * 1e-3 if sample_times else None,
    )
