"""Recordings as controllers' recorders export them, read into one
normalised, columnar Recording (recordings._model) whatever the recorder.

The format is recognised from the content, in this order (the first that
fits reads the file):

  ASAM MDF 4, 3 and 2                    mdf.py
  Beckhoff TwinCAT Scope View CSV        twincat.py
  WinCC data log CSV                     vendors.py
  Niagara history export (one point)     vendors.py
  CODESYS 2.3 trace (ASCII file)         vendors.py
  tables: TIA Portal trace CSV, CODESYS V3 export, ModbusScope data file, plain CSV/TSV   tables.py

A file none of them fits is a TraceError that says, for each, why not.
"""

import os
from collections import Counter
from pathlib import Path

from .._errors import InputError, TraceError
from .._reading import open_regular
from . import _mdf as mdf, _tables as tables, _text as texts, _twincat as twincat, _vendors as vendors
from ._matching import Plan, last_component, plan
from ._model import Channel, Recording
from ._timebase import OFF_CYCLE, normalise

TEXT_FORMATS = (
    ("Beckhoff TwinCAT Scope View CSV", twincat.sniff, twincat.read),
    ("WinCC data log CSV", vendors.sniff_wincc, vendors.read_wincc),
    ("Niagara history export", vendors.sniff_niagara, vendors.read_niagara),
    ("CODESYS 2.3 trace (ASCII file)", vendors.sniff_codesys23, vendors.read_codesys23),
    ("table (TIA Portal trace CSV, CODESYS V3 export, CSV/TSV)", tables.sniff, tables.read),
)
FORMAT_NAMES = ("ASAM MDF (2, 3 or 4)",) + tuple(name for name, _, _ in TEXT_FORMATS)

__all__ = [
    "Channel",
    "FORMAT_NAMES",
    "OFF_CYCLE",
    "Plan",
    "Recording",
    "is_recording",
    "last_component",
    "normalise",
    "plan",
    "read_file",
    "read_recording",
]


def read_file(path):
    """The Recording of one exported file."""
    with open_regular(path) as file:  # (a FIFO or a device refused before a byte is read)
        try:
            head = file.read(64)
        except OSError as error:
            raise TraceError(path, 0, 0, error.strerror or str(error)) from None
    if mdf.sniff(head) is None:
        return mdf.read(path)
    text = texts.read(path)
    if not text.text.strip():
        raise TraceError(path, 0, 0, "empty file")
    reasons = [f"{FORMAT_NAMES[0]}: {mdf.sniff(head)}"]
    for name, sniff, read in TEXT_FORMATS:
        why = sniff(text)
        if why is None:
            return read(text)
        reasons.append(f"{name}: {why}")
    raise TraceError(path, 0, 0, "no known recording format; tried " + "; ".join(reasons))


def _files(paths):
    files = []
    for path in paths:
        path = os.fspath(path)
        if os.path.isdir(path):
            inside = sorted(
                os.path.join(path, n)
                for n in os.listdir(path)
                if not n.startswith(".") and os.path.isfile(os.path.join(path, n))
            )
            if not inside:
                raise InputError(f"{path}: an empty folder")
            files.extend(inside)
        elif os.path.exists(path):
            files.append(path)
        else:
            raise InputError(f"{path}: no such file or folder")
    return files


def read_recording(paths):
    """A list of Recordings of the files and folders given: each file is
    one recording, except single-point histories (Niagara), which together
    make one (given as their files or as their folder)."""
    recordings: list[Recording] = []
    points: list[Recording] = []
    for path in _files([paths] if isinstance(paths, (str, os.PathLike)) else paths):
        recording = read_file(path)
        (points if recording.format == "Niagara history export" else recordings).append(recording)
    if points:
        recordings.append(vendors.merge(points))
    return recordings


def is_recording(path):
    """Whether a path given to compare is a recording (a file, or a folder
    without cases of the cross-check layout: no *_ref.csv in it); a FIFO or
    a device is one too, refused by its kind as it is read."""
    path = os.fspath(path)
    if os.path.exists(path) and not os.path.isdir(path):
        return True
    if os.pathsep in path and all(os.path.isfile(p) for p in path.split(os.pathsep)):
        return True
    if os.path.isdir(path):
        if not os.access(path, os.R_OK | os.X_OK):  # (not searched: a case folder, whose reading says why)
            return False
        seen = set()  # folders by identity: linked folders are searched (as find_cases does), a link loop ends
        for folder, subfolders, names in os.walk(path, followlinks=True):
            status = os.stat(folder)
            if (status.st_dev, status.st_ino) in seen:
                subfolders.clear()
                continue
            seen.add((status.st_dev, status.st_ino))
            if any(n.endswith("_ref.csv") for n in names):
                return False
        return True
    return False


def recording_paths(paths):
    """The recordings among paths given to compare: [(path, name)], where
    path is one file, or several single-point files (Niagara) joined by
    os.pathsep: together they make one recording. A folder is its files:
    each a recording (named folder/file), its single-point files together
    one (named by the folder)."""
    items, points = [], []
    for path in paths:
        path = os.fspath(path)
        if os.path.isdir(path):
            items += _folder_items(path)
        elif os.path.isfile(path) and _is_single_point(path):
            points.append(path)
        else:
            items.append((path, Path(path).name))
    if points:
        name = Path(points[0]).parent.name if len(points) > 1 else Path(points[0]).name
        items.append((os.pathsep.join(points), name))
    return _unique(items)


def _folder_items(folder):
    """recording_paths' items of the files of a folder (an empty folder is one item: reading it says so)."""
    try:
        files = _files([folder])
    except InputError:
        return [(folder, Path(folder).name)]
    points = [f for f in files if _is_single_point(f)]
    name = Path(os.path.abspath(folder)).name
    items = [(f, f"{name}/{Path(f).name}") for f in files if f not in points]
    if points:
        items.append((os.pathsep.join(points) if len(points) > 1 else points[0], name))
    return items


def _unique(items):
    """[(path, name)] with each name once (a case's name names its result
    files): a name given twice gets its folder's name before it, as
    find_cases names cases, then a number."""
    given = Counter(name for _, name in items)
    taken: set[str] = set()
    unique_items = []
    for path, name in items:
        if given[name] > 1:
            name = f"{Path(os.path.abspath(path.split(os.pathsep)[0])).parent.name}/{name}"
        unique, n = name, 2
        while unique in taken:
            unique, n = f"{name} ({n})", n + 1
        taken.add(unique)
        unique_items.append((path, unique))
    return unique_items


def _is_single_point(path):
    try:
        with open_regular(path) as file:
            head = file.read(4096)
    except (OSError, InputError):
        return False
    try:
        decoded, _ = texts.decode(path, head)
    except InputError:
        return False
    return vendors.sniff_niagara(texts.Text(path, decoded, "")) is None
