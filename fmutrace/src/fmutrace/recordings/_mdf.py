"""ASAM MDF 4 (.mf4), MDF 3 and MDF 2 (.mdf) through asammdf: every
channel with the time base of its channel group, as recorded (nothing is
resampled onto a common time base, so no value is invented). Master
(time) channels are the stamps, in seconds; channels of text or byte
arrays are listed as ignored; channels of one name in several groups are
each kept (_grid.unique_names). A file its writer has not finalized
(identified 'UnFinMF ', as CAN loggers leave it until it is closed) is
read as asammdf reads it: it finalizes a copy. A channel group that
declares more samples than the step bound allows is refused before its
samples are read (a small compressed file can hold hundreds of
millions)."""

import sys
import tempfile
from typing import Any, cast

import numpy as np

from .._errors import TraceError, require_extra
from .._traces import samples_problem
from ._grid import unique_names
from ._model import Channel, Recording

MAGIC = b"MDF     "
UNFINALIZED = b"UnFinMF "  # the identification of a file its writer has not finalized (MDF 4)


def _quiet_asammdf_finalizers():
    """asammdf's MDF4.__del__ fails on an object its constructor left half
    made (a damaged file), and Python prints that failure with a traceback
    when the object goes: it says nothing the error did not, so it is not
    printed (any other object's still is)."""
    previous = sys.unraisablehook
    if getattr(previous, "quiets_asammdf", False):
        return

    def hook(unraisable):
        if not getattr(unraisable.object, "__module__", "").startswith("asammdf"):
            previous(unraisable)

    hook.quiets_asammdf = True  # type: ignore[attr-defined]
    sys.unraisablehook = hook


def sniff(head):
    if head.startswith((MAGIC, UNFINALIZED)):
        return None
    return "not MDF (no identification block 'MDF' or 'UnFinMF')"


def format_name(version):
    """The format as users call it, from asammdf's version ('2.00', '3.30', '4.10')."""
    major = str(version)[:1]
    return f"ASAM MDF {major}" if major in ("2", "3") else "ASAM MDF4"


def read(path):
    """The recording of an MDF file. asammdf copies a file that was not
    finalized into a temporary folder: here one of this read's own,
    removed however the read ends."""
    with tempfile.TemporaryDirectory(prefix="fmutrace-mdf-", ignore_cleanup_errors=True) as scratch:
        return _read(path, scratch)


def _read(path, scratch):
    require_extra("asammdf", "mdf", f"reading the MDF recording {path}")
    from asammdf import MDF  # loaded on first use: it brings pandas, seconds of import for every other command

    _quiet_asammdf_finalizers()
    with open(path, "rb") as file:
        unfinalized = file.read(len(UNFINALIZED)) == UNFINALIZED
    problem = None
    try:
        mdf = MDF(str(path), temporary_folder=scratch)
    except Exception as error:  # asammdf raises many kinds for a damaged file
        problem = f"not a readable MDF file ({error})"
    if problem is not None:  # raised out here: the half-made MDF goes with the error above, not with this one
        raise TraceError(path, 0, 0, problem)
    channels, notes = [], []
    if unfinalized:
        notes.append("not finalized by its writer ('UnFinMF'): read as asammdf finalizes it")
    try:
        version = mdf.version
        for group_index, group in enumerate(cast(list[Any], mdf.groups)):
            master = mdf.masters_db.get(group_index)
            _check_count(path, mdf, group_index, group)
            for channel_index in range(len(group.channels)):
                if channel_index == master:
                    continue
                signal = mdf.get(group=group_index, index=channel_index)
                samples = np.asarray(signal.samples)
                if samples.dtype.kind not in "biuf" or samples.ndim != 1:
                    notes.append(f"channel {signal.name!r} (group {group_index}) holds {_kind(samples)}: ignored")
                    continue
                channels.append(
                    Channel(
                        name=signal.name,
                        stamps=np.asarray(signal.timestamps, dtype=np.float64),
                        values=samples.astype(np.float64),
                        file=str(path),
                    )
                )
    finally:
        mdf.close()
    return Recording(
        paths=[str(path)],
        format=format_name(version),
        channels=unique_names(channels),
        time_unit="s",
        time_source="MDF's time channels are in seconds",
        notes=notes,
    )


def _check_count(path, mdf, group_index, group):
    """Refuses a channel group whose declared samples are more than the
    step bound allows (before asammdf reads them)."""
    declared = int(getattr(group.channel_group, "cycles_nr", 0) or 0)
    problem = samples_problem(declared)
    if problem is None:
        return
    master = mdf.masters_db.get(group_index)
    names = [c.name for i, c in enumerate(group.channels) if i != master]
    named = f"channel {names[0]!r}" if names else "a channel"
    if len(names) > 1:
        named += f" (and {len(names) - 1} more)"
    raise TraceError(path, 0, 0, f"{named} of channel group {group_index}: {problem}")


def _kind(samples):
    """What a channel that is no number holds, in words."""
    if samples.dtype.names:
        return f"records of {len(samples.dtype.names)} fields (a bus frame?)"
    if samples.ndim != 1:
        return f"arrays of {samples.shape[1:]} values"
    return f"{samples.dtype} values"
