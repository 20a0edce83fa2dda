"""ASAM MDF4 (.mf4) through asammdf: every channel with the time base of
its channel group, as recorded (nothing is resampled onto a common time
base, so no value is invented). Master (time) channels are the stamps,
in seconds; channels of text or byte arrays are listed as ignored."""

import sys
import tempfile
from typing import Any, cast

import numpy as np

from .._errors import TraceError
from ._model import Channel, Recording

MAGIC = b"MDF     "


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
    return None if head.startswith(MAGIC) else "not MDF (no 'MDF' identification block)"


def read(path):
    """The recording of an MDF file. asammdf copies a file that was not
    finalized into a temporary folder: here one of this read's own,
    removed however the read ends."""
    with tempfile.TemporaryDirectory(prefix="fmutrace-mdf-", ignore_cleanup_errors=True) as scratch:
        return _read(path, scratch)


def _read(path, scratch):
    from asammdf import MDF  # loaded on first use: it brings pandas, seconds of import for every other command

    _quiet_asammdf_finalizers()
    problem = None
    try:
        mdf = MDF(str(path), temporary_folder=scratch)
    except Exception as error:  # asammdf raises many kinds for a damaged file
        problem = f"not a readable MDF file ({error})"
    if problem is not None:  # raised out here: the half-made MDF goes with the error above, not with this one
        raise TraceError(path, 0, 0, problem)
    channels, notes = [], []
    try:
        for group_index, group in enumerate(cast(list[Any], mdf.groups)):
            master = mdf.masters_db.get(group_index)
            for channel_index in range(len(group.channels)):
                if channel_index == master:
                    continue
                signal = mdf.get(group=group_index, index=channel_index)
                samples = np.asarray(signal.samples)
                if samples.dtype.kind not in "biuf" or samples.ndim != 1:
                    notes.append(f"channel {signal.name!r} (group {group_index}) holds {samples.dtype} values: ignored")
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
        format="ASAM MDF4",
        channels=channels,
        time_unit="s",
        time_source="MDF's time channels are in seconds",
        notes=notes,
    )
