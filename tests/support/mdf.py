"""MDF recordings written by asammdf's own writer (not by fmutrace's
reader), for the tests of what fmutrace reads from them."""

import numpy as np


def mdf_of_groups(path, groups, version="4.10"):
    """An MDF file of the version at path with a channel group per
    (stamps, {name: values}), in the order given; its path as a str."""
    from asammdf import MDF, Signal

    mdf = MDF(version=version)
    for stamps, signals in groups:
        mdf.append([Signal(np.asarray(v, dtype=float), np.asarray(stamps), name=n) for n, v in signals.items()])
    mdf.save(str(path), overwrite=True)
    mdf.close()
    return str(path)
