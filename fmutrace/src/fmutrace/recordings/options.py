"""How the recordings of a campaign are read: one RecordingOptions for all."""
from dataclasses import dataclass

from .._errors import InputError
from .align import TIMINGS

TIME_UNITS = ("s", "ms", "us", "ns", "cycles", "filetime")


@dataclass(frozen=True)
class RecordingOptions:
    """How the recordings of a command are read (the same for all)."""
    step_size: float = None
    time_unit: str = None           # one of TIME_UNITS, None: the recording's own
    timing: str = "cycle"           # align.TIMINGS
    maps: tuple = ()                # (VARIABLE, CHANNEL) pairs
    start_values: tuple = ()        # (NAME, VALUE) pairs

    def __post_init__(self):
        if self.time_unit is not None and self.time_unit not in TIME_UNITS:
            raise InputError(f"--time-unit must be one of {', '.join(TIME_UNITS)}, not {self.time_unit!r}")
        if self.timing not in TIMINGS:
            raise InputError(f"--timing must be one of {', '.join(TIMINGS)}, not {self.timing!r}")
        if self.step_size is not None and not self.step_size > 0:
            raise InputError(f"--step-size must be greater than 0, not {self.step_size!r}")

    def settings(self) -> dict:
        return {"step_size": self.step_size, "time_unit": self.time_unit, "timing": self.timing,
                "maps": [list(m) for m in self.maps], "start_values": [list(s) for s in self.start_values]}
