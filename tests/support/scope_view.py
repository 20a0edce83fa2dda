"""An independent reader of TwinCAT Scope View CSV exports, for the tests:
written from the export's documented structure (Beckhoff's Scope View
manual, "Export to csv"), sharing nothing with fmutrace's reader. It is
told the separator and the decimal mark (the export's settings) instead
of guessing them, and reads what the structure says, no more:

- a title block, blank lines, then the header block: one row per channel
  property; in each row the property's key stands above a time column,
  the channels' values above theirs (a row may stop before its trailing
  empty cells);
- a blank line, then the samples, up to the end or a line 'EOF'; each
  channel's time is the time column nearest to its left; a channel with
  no sample in a row has an empty cell there, or the row ends before it.

Channels: {Name: Channel(symbol, sample_time_ms, times_ms, values)}, in
the order of the columns."""

from dataclasses import dataclass

import numpy as np


@dataclass
class Channel:
    symbol: str
    sample_time_ms: float | None
    times_ms: np.ndarray
    values: np.ndarray


def _number(cell, decimal):
    return float(cell.strip().replace(decimal, ".") if decimal != "." else cell.strip())


def read(path, separator, decimal):
    """The channels of the export at path (UTF-8 text)."""
    lines = open(path, encoding="utf-8-sig").read().splitlines()
    start = next(i for i in range(1, len(lines)) if lines[i].startswith("Name" + separator) and not lines[i - 1])
    end = next(i for i in range(start, len(lines)) if not lines[i].strip())
    header = {line.split(separator)[0]: line.split(separator) for line in lines[start:end]}
    names = header["Name"]
    keys = [j for j, cell in enumerate(names) if cell == "Name"]
    rows = []
    for line in lines[end + 1 :]:
        if line.strip() == "EOF":
            break
        if line.strip():
            rows.append(line.split(separator))
    channels = {}
    for j, name in enumerate(names):
        if j in keys or not name:
            continue
        time_column = max(k for k in keys if k < j)
        times, values = [], []
        for row in rows:
            if len(row) > j and row[j].strip():
                times.append(_number(row[time_column], decimal))
                values.append(_number(row[j], decimal))

        def prop(key, j=j):
            cells = header.get(key, [])
            return cells[j] if j < len(cells) else ""

        sample_time = prop("SampleTime[ms]")
        channels[name] = Channel(
            prop("SymbolName"),
            float(sample_time.replace(",", ".")) if sample_time and separator != "," else None,
            np.array(times),
            np.array(values),
        )
    return channels
