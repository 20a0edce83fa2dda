"""The other recorders' exports: CODESYS 2.3's "Trace in ASCII file",
WinCC's data-log CSV and Niagara's history exports.

CODESYS 2.3 (online help, 'Trace in ASCII-File'): a title line, the
project's path, the names separated by blanks, then one line per sample,
values separated by blanks. The first column is the cycle number when
the trace sampled every cycle ('Cycle'/'Zyklus'), else the time in ms
since the trace started.

WinCC data log (WinCC flexible / WinCC Advanced / Unified Comfort CSV
logs): header VarName, TimeString, VarValue, Validity, Time_ms; one row
per tag and time stamp. Time_ms is the time as OLE days (since 30 Dec
1899) times 1e6, good to a few microseconds; TimeString the same to the
second, the time where Time_ms is damaged (a PC whose locale wrote a tab
for its decimal mark). Rows whose VarName is a marker ($RT_OFF$ runtime
stopped, $RT_DIS$ logging disabled, $RT_COUNT$ with fewer cells) and
rows of Validity 0 are no samples. Separator ',' or ';' (then a decimal comma).

Niagara (history table 'Export', CSV): one history (point) per file,
columns Timestamp, Trend Flags, Status, Value (the value column may carry
its unit: 'Value (°C)'). A sample whose status is not ok ({null},
{fault}, {stale}, {down}...) or whose value is not a number is none. The
point's name is the file's name, unless a line before the table names
the history ('History: /Station/delayedValue', 'HistoryId,...'): then its
last component."""

import os

import numpy as np

from .._errors import TraceError
from .._traces import split_cells
from . import _grid as grids
from . import _text as texts
from . import _timebase as timebase
from ._model import Channel, Recording
from ._tables import CYCLE_WORDS, bare_name


# -- CODESYS 2.3 -----------------------------------------------------------------------
def _codesys23_header(text):
    lines = list(text.lines[:3])
    if len(lines) < 3 or len(text.lines) < 4:
        return None, "fewer than four lines (title, project, names, samples)"
    if not lines[1].strip().lower().endswith(".pro"):
        return None, "its second line is no CODESYS 2.3 project path (*.pro)"
    names = lines[2].split()
    if len(names) < 2:
        return None, "its third line holds no names"
    return names, None


def sniff_codesys23(text):
    return _codesys23_header(text)[1]


def read_codesys23(text):
    names, why = _codesys23_header(text)
    if names is None:
        raise text.error(0, 0, why)
    rows, lines = grids.body(text, 3, " ")
    if not rows:
        raise text.error(3, 0, "no samples after the names")
    for row, line in zip(rows, lines, strict=True):
        if len(row) != len(names):
            raise text.error(
                int(line), min(len(row), len(names)) + 1, f"{len(row)} values, the names line has {len(names)}"
            )
    table = grids.grid(rows, len(names))
    stamps = grids.numeric_stamps(text, table[:, 0], lines, 1, names[0], True)
    grids.check_increasing(text, stamps, lines, 1, names[0])
    cycles = bare_name(names[0]) in CYCLE_WORDS
    everywhere = np.ones(len(rows), dtype=bool)
    channels = grids.unique_names(
        [
            grids.channel_from(text, table[:, j], grids.Rows(lines, stamps, everywhere), j + 1, names[j], True)
            for j in range(1, len(names))
        ]
    )
    return Recording(
        paths=[text.path],
        format="CODESYS 2.3 trace (ASCII file)",
        channels=channels,
        time_unit="cycles" if cycles else "ms",
        time_source=f"its first column is {names[0]!r}" + ("" if cycles else ": CODESYS 2.3 writes ms since the start"),
        encoding=text.encoding,
    )


# -- WinCC ---------------------------------------------------------------------------
WINCC_COLUMNS = ("VarName", "TimeString", "VarValue")


def _wincc_header(text):
    for i, line in enumerate(text.lines[:20]):
        if "VarName" in line and "VarValue" in line:
            separator = texts.sniff_separator(line)
            names = [n.strip('"') for n in split_cells(line, separator)]
            if all(c in names for c in WINCC_COLUMNS):
                return i, separator, names
    return None, None, "no header VarName, TimeString, VarValue, Validity, Time_ms"


def sniff_wincc(text):
    found = _wincc_header(text)
    return found[2] if found[0] is None else None


def read_wincc(text):
    index, separator, names = _wincc_header(text)
    if index is None:
        raise text.error(0, 0, names)
    rows, lines = grids.body(text, index + 1, separator)
    if not rows:
        raise text.error(index + 1, 0, "no samples: the log has a header line only")
    table = grids.grid(rows, len(names))
    column = {n: j for j, n in enumerate(names)}
    tags = np.char.strip(table[:, column["VarName"]])
    keep = ~(np.char.startswith(tags, "$") & np.char.endswith(tags, "$"))
    notes = []
    markers = int((~keep).sum())
    if markers:
        notes.append(f"{markers} marker rows ($RT_OFF$, $RT_DIS$, ...) are no samples")
    if "Validity" in column:
        validity = np.char.strip(table[:, column["Validity"]])
        invalid = keep & (validity == "0")
        if invalid.any():
            first = int(np.flatnonzero(invalid)[0])
            notes.append(f"{int(invalid.sum())} samples of Validity 0 skipped (the first at line {int(lines[first])})")
        keep &= ~invalid
    decimal_comma = separator != ","
    samples = np.flatnonzero(keep)
    j, stamps, unit, source = _wincc_stamps(text, table[samples], lines[samples], column, notes)
    value_column = column["VarValue"]
    channels = []
    order = dict.fromkeys(tags[keep].tolist())
    for tag in order:
        rows_of = np.flatnonzero(keep & (tags == tag))
        tag_stamps = stamps[np.searchsorted(samples, rows_of)]
        grids.check_increasing(text, tag_stamps, lines[rows_of], j + 1, f"time of {tag}")
        values = texts.values(
            table[rows_of, value_column],
            decimal_comma,
            text,
            lambda i, rows_of=rows_of: int(lines[rows_of[i]]),
            value_column + 1,
            "VarValue",
        )
        channels.append(
            Channel(
                name=tag,
                stamps=tag_stamps,
                values=values,
                file=text.path,
                column=value_column + 1,
                lines=lines[rows_of],
            )
        )
    return Recording(
        paths=[text.path],
        format="WinCC data log CSV",
        channels=channels,
        time_unit=unit,
        time_source=source,
        encoding=text.encoding,
        notes=notes,
    )


def _wincc_stamps(text, table, lines, column, notes):
    """(column, stamps, unit, source) of a WinCC log's sample rows: Time_ms,
    else TimeString (to the second) where Time_ms is missing or damaged (a
    PC whose locale wrote a tab for its decimal mark), with a note naming
    the first damaged cell."""
    if "Time_ms" in column:
        j = column["Time_ms"]
        try:
            stamps = texts.values(table[:, j], True, text, lambda i: int(lines[i]), j + 1, "Time_ms")
            return j, stamps, "OLE days", "WinCC's Time_ms"
        except TraceError as error:
            damaged = error
    j = column["TimeString"]
    try:
        stamps = timebase.dates(table[:, j], text, lambda i: int(lines[i]), j + 1, "TimeString")
    except TraceError:
        if "Time_ms" in column:
            raise damaged from None
        raise
    if "Time_ms" in column:
        notes.append(f"{damaged}: the time is TimeString's instead")
        return j, stamps, "date", "WinCC's TimeString: its Time_ms is damaged"
    return j, stamps, "date", "WinCC's TimeString"


# -- Niagara -------------------------------------------------------------------------
NIAGARA_COLUMNS = ("timestamp", "trend flags", "status", "value")
HISTORY_KEYS = ("history", "history id", "historyid", "history name", "point", "name")


def _niagara_header(text):
    for i, line in enumerate(text.lines[:20]):
        separator = texts.sniff_separator(line)
        names = [bare_name(n) for n in split_cells(line, separator)]
        if len(names) >= 4 and tuple(names[:4]) == NIAGARA_COLUMNS:
            return i, separator
    return None, "no header Timestamp, Trend Flags, Status, Value (one Niagara history per file)"


def sniff_niagara(text):
    found = _niagara_header(text)
    return found[1] if found[0] is None else None


def _point_name(text, header_index):
    for line in text.lines[:header_index]:
        separator = ":" if ":" in line and texts.sniff_separator(line) == " " else texts.sniff_separator(line)
        cells = [c for c in split_cells(line, separator) if c]
        if len(cells) >= 2 and cells[0].strip().lower() in HISTORY_KEYS:
            return cells[1].strip().rstrip("/").split("/")[-1]
    return os.path.splitext(os.path.basename(text.path))[0]


def read_niagara(text):
    index, separator = _niagara_header(text)
    if index is None:
        raise text.error(0, 0, separator)
    name = _point_name(text, index)
    rows, lines = grids.body(text, index + 1, separator)
    if not rows:
        raise text.error(index + 1, 0, "no samples: the history has a header line only")
    for row, line in zip(rows, lines, strict=True):
        if len(row) < 4:
            raise text.error(
                int(line), len(row) + 1, f"{len(row)} cells: a row holds Timestamp, Trend Flags, Status and Value"
            )
    # the Status cell may hold separators itself ({fault,stale}): the value is the last cell
    table = grids.grid([[r[0], " ".join(r[2:-1]), r[-1]] for r in rows], 3)
    status = np.char.lower(np.char.strip(table[:, 1]))
    value_cells = np.char.strip(table[:, 2])
    valueless = np.isin(np.char.lower(value_cells), ("", "null", "-", "nan", "--"))
    good = (np.isin(status, ("{ok}", "ok", "{}", "")) | np.char.startswith(status, "{ok")) & ~valueless
    notes = []
    if not good.all():
        first = int(np.flatnonzero(~good)[0])
        notes.append(
            f"{name}: {int((~good).sum())} samples whose status is not ok or that hold no value skipped "
            f"(the first at {text.path}, line {int(lines[first])}: {table[first, 1] or table[first, 2]!r})"
        )
    rows_of = np.flatnonzero(good)
    stamps = timebase.dates(table[rows_of, 0], text, lambda i: int(lines[rows_of[i]]), 1, "Timestamp")
    grids.check_increasing(text, stamps, lines[rows_of], 1, "Timestamp")
    values = texts.values(
        value_cells[rows_of], separator != ",", text, lambda i: int(lines[rows_of[i]]), len(rows[0]), "Value"
    )
    channel = Channel(
        name=name, stamps=stamps, values=values, file=text.path, column=len(rows[0]), lines=lines[rows_of]
    )
    return Recording(
        paths=[text.path],
        format="Niagara history export",
        channels=[channel],
        time_unit="date",
        time_source="Niagara's Timestamp",
        encoding=text.encoding,
        notes=notes,
    )


def merge(recordings):
    """One recording of several single-history files (Niagara)."""
    names: dict[str, int] = {}
    for recording in recordings:
        for channel in recording.channels:
            if channel.name in names:
                raise texts.TraceError(
                    channel.file, 0, 0, f"the point {channel.name!r} again (also in {names[channel.name]})"
                )
            names[channel.name] = channel.file
    first = recordings[0]
    return Recording(
        paths=[p for r in recordings for p in r.paths],
        format=first.format,
        channels=[c for r in recordings for c in r.channels],
        time_unit=first.time_unit,
        time_source=first.time_source,
        encoding=first.encoding,
        notes=[n for r in recordings for n in r.notes],
    )
