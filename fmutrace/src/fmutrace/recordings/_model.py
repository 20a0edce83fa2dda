"""The normalised recording every reader produces: channels, each with its
own time stamps and values as NumPy arrays (columnar: a reader that reads
in chunks can append to them), and how its time is to be read."""

from dataclasses import dataclass, field

import numpy as np


@dataclass
class Channel:
    name: str  # as the recorder wrote it, e.g. "DB_Ramp".value; made unique where its file has it twice (written)
    stamps: np.ndarray  # as recorded: float64, int64 (FILETIME ticks) or datetime64[ns]
    values: np.ndarray  # float64
    file: str
    column: int = 0  # 1-based column of its values in a text file, 0 in MDF4
    lines: np.ndarray | None = None  # line of each sample in a text file (int64), else None
    symbol: str = ""  # a fuller name the recorder gives too (TwinCAT's SymbolName)
    times: np.ndarray | None = None  # seconds from the recording's first sample (normalise())
    sample_time: float | None = None  # its sample interval in seconds, when the file declares it (TwinCAT)
    written: str = ""  # its name as written where other channels of its file share it: name is then NAME#POSITION

    def where(self, index):
        """'file, line L' of sample index (or the file and channel)."""
        if self.lines is not None and len(self.lines) > index:
            return f"{self.file}, line {int(self.lines[index])}"
        return f"{self.file}, channel {self.name!r}"


@dataclass
class Recording:
    paths: list  # the files it was read from
    format: str  # the recorder's export, as users call it
    channels: list
    time_unit: str  # "s", "ms", "us", "ns", "cycles", "FILETIME", "date", "OLE days"
    time_source: str  # why that unit: the header says so, or what was assumed
    sample_time: float | None = None  # the recorder's sample interval in seconds, when the file declares it
    encoding: str = ""
    notes: list = field(default_factory=list)
    step_size: float | None = None  # set by normalise()
    step_source: str = ""
    unit_given: bool = False  # the caller gave the time unit (set by normalise())
    origin: object = None  # the stamp that is time 0 (set by normalise())

    @property
    def label(self):
        return self.paths[0] if len(self.paths) == 1 else f"{self.paths[0]} (+{len(self.paths) - 1} files)"

    def channel(self, name):
        return next(c for c in self.channels if c.name == name)

    def __len__(self):
        return max((len(c.values) for c in self.channels), default=0)


TIME_FACTORS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9, "FILETIME": 1e-7, "OLE days": 86400e-6}
# units that are a whole fraction of a second: divided by it (one rounding: 4.2 ms is 0.0042 s, not
# 0.004200000000000001 as 4.2 * 1e-3 gives); dates are in ns
TIME_DIVISORS = {"ms": 1e3, "us": 1e6, "ns": 1e9, "FILETIME": 1e7, "date": 1e9}
