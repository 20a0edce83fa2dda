"""ASAM MDF4 (.mf4) through asammdf: every channel with the time base of
its channel group, as recorded (nothing is resampled onto a common time
base, so no value is invented). Master (time) channels are the stamps,
in seconds; channels of text or byte arrays are listed as ignored."""

from typing import Any, cast

import numpy as np

from .._errors import TraceError
from ._model import Channel, Recording

MAGIC = b"MDF     "


def sniff(head):
    return None if head.startswith(MAGIC) else "not MDF (no 'MDF' identification block)"


def read(path):
    from asammdf import MDF  # loaded on first use: it brings pandas, seconds of import for every other command

    try:
        mdf = MDF(str(path))
    except Exception as error:  # asammdf raises many kinds for a damaged file
        raise TraceError(path, 0, 0, f"not a readable MDF file ({error})") from None
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
