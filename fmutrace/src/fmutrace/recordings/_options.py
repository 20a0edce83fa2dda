"""How the recordings of a campaign are read: one RecordingOptions for all."""

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field

from .._errors import InputError
from .._names import Names, name_of
from ._align import CYCLE_LENGTHS, TIMINGS

TIME_UNITS = ("s", "ms", "us", "ns", "cycles", "filetime")


def _pairs(value: Mapping | Iterable, what: str) -> tuple:
    """{name: value} or (name, value) pairs as a tuple of pairs."""
    try:
        return tuple((str(name), value) for name, value in (dict(value) if value is not None else {}).items())
    except (TypeError, ValueError):
        raise InputError(f"{what} must be a dict or (name, value) pairs, not {value!r}") from None


@dataclass(frozen=True)
class RecordingOptions:
    """How recordings (files as a recorder exports them) are read; case
    folders carry their own settings (<Model>_ref.opt, <Model>_start.csv).

    step_size     the PLC's cycle in seconds (None: the recording's sample
                  time, else its finest interval between samples)
    time_unit     s, ms, us, ns, cycles or filetime (None: the recording's own)
    timing        'cycle': a row is the input a cycle read and the output it
                  produced, as recorders write it; 'fmi': a row's output is
                  the output at its time, as fmpy writes it
    cycle_lengths 'nominal': every step is step_size long, whatever the
                  stamps' jitter; 'recorded': each recorded execution of
                  the OB is one step as long as the recorded interval since
                  the one before (blocks that measure elapsed time see the
                  jitter), a cycle without a sample no step
    maps          {VARIABLE: CHANNEL} (or pairs): the channel that is the
                  FMU's variable: its name ('Register 40001#3' where
                  columns share a name: the one in column 3), its
                  symbol, or '#3': the channel in column 3
    start_values  {name: value} (or pairs): start values of the FMU
    names         {setting: how the caller writes it} (or pairs): the
                  words messages name the settings in (default: the
                  API's, RecordingOptions(step_size=...); the command
                  gives its flags, --step-size). Not a setting: equal
                  options with other names are equal
    """

    step_size: float | None = None
    time_unit: str | None = None
    timing: str = "cycle"
    maps: tuple = ()
    start_values: tuple = ()
    cycle_lengths: str = "nominal"
    names: Names = field(default=(), compare=False)  # stored as pairs

    def __post_init__(self):
        object.__setattr__(self, "maps", _pairs(self.maps, "maps"))
        object.__setattr__(self, "start_values", _pairs(self.start_values, "start_values"))
        object.__setattr__(self, "names", _pairs(self.names, "names"))
        if self.time_unit is not None and self.time_unit not in TIME_UNITS:
            raise InputError(
                f"{name_of(self.names, 'time_unit')} must be one of {', '.join(TIME_UNITS)}, not {self.time_unit!r}"
            )
        if self.timing not in TIMINGS:
            raise InputError(
                f"{name_of(self.names, 'timing')} must be one of {', '.join(TIMINGS)}, not {self.timing!r}"
            )
        if self.cycle_lengths not in CYCLE_LENGTHS:
            raise InputError(
                f"{name_of(self.names, 'cycle_lengths')} must be one of {', '.join(CYCLE_LENGTHS)}, "
                f"not {self.cycle_lengths!r}"
            )
        if self.step_size is not None and not self.step_size > 0:
            raise InputError(f"{name_of(self.names, 'step_size')} must be greater than 0, not {self.step_size!r}")

    @property
    def timebase_unit(self) -> str | None:
        """time_unit as recordings._timebase names it."""
        return "FILETIME" if self.time_unit == "filetime" else self.time_unit

    def settings(self) -> dict:
        return {
            "step_size": self.step_size,
            "time_unit": self.time_unit,
            "timing": self.timing,
            "cycle_lengths": self.cycle_lengths,
            "maps": [list(m) for m in self.maps],
            "start_values": [list(s) for s in self.start_values],
        }
