"""Cases in the FMI cross-check layout: a folder that holds, for the model
<Model> of the FMU,

  <Model>_ref.csv    the reference trace (required)
  <Model>_in.csv     input signals (optional); a row holds from its time on
  <Model>_ref.opt    StartTime, StopTime, StepSize, RelTol (optional: the
                     reference's first and last time, the FMU's default step);
                     CycleLengths: nominal (the default: every step StepSize
                     long) or recorded (one step from each reference row to
                     the next, as long as their times are apart)
  <Model>_start.csv  start values, one "name,value" line each (optional)
  <Model>_criteria.csv  per-signal criteria, one "signal,mode" line each:
                     a variable's name or an fnmatch pattern, "*" for the
                     rest; the mode as --signal writes it (optional)
  README.md          its first line describes the case (optional)

Every file is checked against the FMU before anything runs: a problem is
an InputError naming the file, line and column.
"""

import math
import os
from array import array
from os import PathLike
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ._comparison import Comparison, Mode, compare_traces, criteria_for, parse_mode
from ._errors import InputError, TraceError
from ._fmpy import Replay
from ._fmu import Fmu
from ._reading import absent, quoted
from .recordings._align import CYCLE_LENGTHS
from .recordings._timebase import decimal_resolution
from ._traces import data_lines, parse_number, read_text, read_trace, split_cells, steps_problem

OPTIONS = ("StartTime", "StopTime", "StepSize", "RelTol", "CycleLengths")
FILES = ("_ref.csv", "_in.csv", "_ref.opt", "_start.csv", "_criteria.csv", "README.md")


@dataclass
class Case:
    name: str  # its folder, relative to the folder searched
    model: str
    folder: Path
    options: dict  # StartTime, StopTime, StepSize, RelTol
    start_values: dict  # name -> value of the variable's type
    inputs: np.ndarray | None  # structured array, or None
    reference: np.ndarray  # structured array
    description: str = ""
    criteria: tuple = ()  # its own per-signal criteria: ((pattern, Mode), ...)

    @property
    def outputs(self):
        """The reference's signals: what is recorded and compared."""
        return [n for n in self.reference.dtype.names or () if n != "time"]

    def comparison(self, result, mode: Mode, discrete=frozenset()) -> Comparison:
        """The FMU's result against the reference, in mode with the case's
        own criteria (discrete: the FMU's discrete signals, Fmu.discrete_names)."""
        return compare_traces(result, self.reference, criteria_for(mode, self.criteria, discrete))


def read_options(path, text, reference, fmu):
    options = {"RelTol": 1e-6}
    for number, line in data_lines(text or "", path):
        cells = split_cells(line, ",")
        if len(cells) != 2:
            raise TraceError(path, number, 1, f"expected 'Name,value', found {quoted(line.strip())}")
        key, literal = cells
        if key not in OPTIONS:
            raise TraceError(path, number, 1, f"unknown option {quoted(key)} (known: {', '.join(OPTIONS)})")
        if key == "CycleLengths":
            if literal.strip() not in CYCLE_LENGTHS:
                raise TraceError(
                    path, number, 2, f"CycleLengths {quoted(literal)} is not one of {', '.join(CYCLE_LENGTHS)}"
                )
            options[key] = literal.strip()
            continue
        value = parse_number(literal)
        if value is None or not math.isfinite(value):
            raise TraceError(path, number, 2, f"{key} {quoted(literal)} is not a finite number")
        options[key] = value
    options.setdefault("StartTime", float(reference["time"][0]))
    options.setdefault("StopTime", float(reference["time"][-1]))
    if "StepSize" not in options:
        if fmu.default_step is None:
            raise InputError(
                f"{path}: no StepSize: the file is missing or has none, and {fmu.label} gives no default step size"
            )
        options["StepSize"] = fmu.default_step
    where = path if text is not None else f"{path} (defaults)"
    if not options["StepSize"] > 0:
        raise TraceError(where, 0, 0, f"StepSize {options['StepSize']!r} must be greater than 0")
    if not options["StopTime"] > options["StartTime"]:
        raise TraceError(
            where, 0, 0, f"StopTime {options['StopTime']!r} must be after StartTime {options['StartTime']!r}"
        )
    problem = steps_problem(options["StartTime"], options["StopTime"], options["StepSize"])
    if problem:
        raise TraceError(where, 0, 0, problem)
    return options


def recorded_steps(path, reference, options) -> Replay:
    """The Replay of a case whose _ref.opt says CycleLengths,recorded: each
    reference row from StartTime to StopTime is one execution of the OB,
    the first the initial state; step k runs from row k - 1's time for the
    interval to row k's, at the resolution the times were written in (the
    fewest decimals of a second that make every one whole: times in whole
    ms are whole ms), and its result stands at row k's time. TraceError
    (path: the reference) for times that do not make such steps."""
    times = reference["time"]
    start, stop = options["StartTime"], options["StopTime"]
    rows = times[(times >= start) & (times <= stop)]
    if len(rows) < 2 or rows[0] != start:
        raise TraceError(
            path,
            0,
            0,
            f"CycleLengths recorded runs a step from each of its rows to the next: StartTime {start!r} is "
            "not the time of one of them, or no row follows it",
        )
    back = np.flatnonzero(np.diff(rows) <= 0)
    if len(back):
        t = float(rows[back[0]])
        raise TraceError(
            path, 0, 0, f"CycleLengths recorded runs a step from each of its rows to the next: two rows at t={t!r} s"
        )
    digits = decimal_resolution(rows)
    if digits is None:
        raise TraceError(
            path,
            0,
            0,
            "CycleLengths recorded needs times of a resolution of 1 ns or coarser (a whole number of "
            "ns each): the step lengths are read from them",
        )
    ticks = np.rint(rows * 10.0**digits).astype(np.int64)
    return Replay(rows[:-1].copy(), np.diff(ticks) / 10.0**digits, rows.copy())


def read_start_values(path, text, fmu):
    """The start values of a "name,value" file, each checked against the
    FMU's variable (type, range)."""
    values = {}
    for number, line in data_lines(text or "", path):
        cells = split_cells(line, "," if line.count(",") else ";")
        if len(cells) != 2:
            raise TraceError(path, number, 1, f"expected 'name,value', found {quoted(line.strip())}")
        name, literal = cells
        if name not in fmu.variables:
            raise TraceError(path, number, 1, f"{quoted(name)} is not a variable of {fmu.label}")
        try:
            values[name] = fmu.start_value(name, literal)
        except InputError as error:
            raise TraceError(path, number, 2, str(error)) from None
    return values


def read_criteria(path, text, fmu) -> tuple:
    """The per-signal criteria of a "signal,mode" file, ((pattern, Mode), ...):
    a name without a pattern's characters must be a variable of the FMU."""
    pairs = []
    for number, line in data_lines(text or "", path):
        signal, sep, words = line.partition(",")
        signal = signal.strip().strip('"')
        if not sep or not signal:
            raise TraceError(path, number, 1, f"expected 'signal,mode', found {quoted(line.strip())}")
        if not any(c in signal for c in "*?[") and fmu.variable_problem(signal):
            raise TraceError(path, number, 1, fmu.variable_problem(signal))
        try:
            pairs.append((signal, parse_mode(words.strip().strip('"'))))
        except InputError as error:
            raise TraceError(path, number, 2, str(error)) from None
    return tuple(pairs)


def case_texts(folder, model):
    """{file name: text} of the case's files that exist (what a worker
    without this file system needs); a TraceError for one that is there
    and cannot be read (a dangling link, a FIFO, no permission): never
    taken as absent."""
    texts = {}
    for suffix in FILES:
        name = suffix if suffix == "README.md" else f"{model}{suffix}"
        path = os.path.join(folder, name)
        try:
            texts[name] = read_text(path)
        except TraceError:
            if not absent(path):
                raise
    return texts


def load_case(folder: str | PathLike, fmu: Fmu, name: str | None = None, texts: dict | None = None) -> Case:
    """The case in folder for fmu's model, checked against the FMU; the
    files' texts may be given (texts from case_texts), else they are read."""
    folder = Path(folder)
    model = fmu.model
    texts = case_texts(folder, model) if texts is None else texts

    def text(file_name):
        return texts.get(file_name)

    ref_name = f"{model}_ref.csv"
    if ref_name not in texts:
        raise TraceError(folder / ref_name, 0, 0, "no such file")
    reference = read_trace(folder / ref_name, fmu.variable_problem, text(ref_name))
    in_name = f"{model}_in.csv"
    inputs = read_trace(folder / in_name, fmu.input_problem, text(in_name)) if in_name in texts else None
    readme = (text("README.md") or "").strip().splitlines()
    return Case(
        name=name or folder.name,
        model=model,
        folder=folder,
        options=read_options(folder / f"{model}_ref.opt", text(f"{model}_ref.opt"), reference, fmu),
        start_values=read_start_values(folder / f"{model}_start.csv", text(f"{model}_start.csv"), fmu),
        inputs=inputs,
        reference=reference,
        description=readme[0].lstrip("# ").strip() if readme else "",
        criteria=read_criteria(folder / f"{model}_criteria.csv", text(f"{model}_criteria.csv"), fmu),
    )


class CaseList(Sequence):
    """(folder, name) of each case, sorted by name, kept compact for
    campaigns of many cases: a case costs its name's text and two bytes
    (which folder searched); its folder, the one searched joined with the
    name, is made again when asked for. The few cases whose folder is not
    that (a case folder given itself, a name prefixed) keep it as text."""

    def __init__(self, roots, names, root_of, folders):
        self.roots = roots  # the folders searched, as text
        self.names, self.root_of = names, root_of  # per case: its name, the index of its root
        self.folders = folders  # case index -> folder, where it is not root/name

    def __len__(self):
        return len(self.names)

    def __getitem__(self, index):
        if isinstance(index, slice):
            return [self[i] for i in range(*index.indices(len(self)))]
        folder, name = self.text(index)
        return Path(folder), name

    def text(self, index):
        """(folder, name) with the folder as text: Path interns every part
        of a path for good, a campaign of many cases must not."""
        name = self.names[index]
        folder = self.folders.get(index % len(self.names))  # (a negative index counts from the end)
        return (os.path.join(self.roots[self.root_of[index]], name) if folder is None else folder), name


def find_cases(paths: Sequence[str | PathLike], model: str) -> CaseList:
    """[(folder, name)] of the cases of model under paths, each a case
    folder itself or a folder searched recursively (through linked folders
    too, each folder once), sorted by name: the folder's path below the one
    searched (its own name for a case folder given itself). A CaseList."""
    target = f"{model}_ref.csv"
    seen: set[int] = set()
    found: list[str] = []  # each case's path below its root ('' for a root that is a case folder)
    found_in, roots = array("H"), []
    leaves = np.zeros(0, dtype=_LEAF)  # (grown as needed)
    for path in paths:
        root = os.fspath(path)
        if not os.path.isdir(root):
            raise InputError(f"{path}: no such folder")
        roots.append(root)
        for relative, leaf in _walk(root, "", target, seen):
            if len(found) == len(leaves):
                leaves = np.resize(leaves, max(1 << 16, 2 * len(leaves)))
            leaves[len(found)] = leaf
            found.append(relative)
            found_in.append(len(roots) - 1)
    del seen
    kept = _first_of_each_leaf(leaves[: len(found)])
    del leaves
    if kept is not None:
        found, found_in = [found[i] for i in kept], array("H", (found_in[i] for i in kept))
    names, folders = found, {}  # (the paths below the roots are the names, as a rule)
    root_names = [os.path.basename(os.path.realpath(root)) for root in roots]
    # names: only folders searched together can give one twice
    taken: set[str] | None = set() if len(paths) > 1 else None
    for i, relative in enumerate(found):
        name = relative or root_names[found_in[i]]
        if taken is not None:
            if name in taken:  # the same name below two folders given
                name = f"{root_names[found_in[i]]}/{name}"
            taken.add(name)
        if name != relative:  # its folder is not root/name
            folders[i] = os.path.join(roots[found_in[i]], relative) if relative else roots[found_in[i]]
            names[i] = name
    del taken
    if all(names[i] <= names[i + 1] for i in range(len(names) - 1)):  # (the walk's order mostly is)
        return CaseList(roots, names, found_in, folders)
    order = sorted(range(len(names)), key=names.__getitem__)
    return CaseList(
        roots,
        [names[i] for i in order],
        array("H", (found_in[i] for i in order)),
        {new: folders[old] for new, old in enumerate(order) if old in folders},
    )


_LEAF = np.dtype([("device", np.uint64), ("inode", np.uint64)])  # a folder without subfolders (0, 0: another)


def _first_of_each_leaf(leaves):
    """The cases to keep, in order, where a folder without subfolders was
    found twice (through a link, or a bind mount): its first; None where
    none was."""
    found = np.sort(leaves[leaves["inode"] != 0])  # (np.unique would import numpy.ma: 16 ms)
    if not (found[1:] == found[:-1]).any():
        return None
    kept_leaves, keep = set(), []
    for i, leaf in enumerate(leaves.tolist()):
        if leaf[1] == 0 or leaf not in kept_leaves:
            keep.append(i)
            kept_leaves.add(leaf)
    return keep


def _walk(folder, relative, file_name, seen):
    """(the path below the root (relative), its identity where the folder
    has no subfolders, else (0, 0)) of the folders from folder on that hold
    file_name. A folder with subfolders is walked once (seen: their
    identities), by the first path to it in sorted order, so that no link
    loops; a folder without, found twice, gives two (find_cases keeps the
    first): the set of identities grows with the folders that hold
    others, not with the cases (and with those whose identity _LEAF does
    not hold: a 128-bit inode, a negative device). Depth first, holding the names of one
    folder's subfolders per level: memory grows with the depth and the
    widest folder's names, not with the whole tree. A folder that cannot
    be searched, and a file_name that is no regular file (a FIFO, a device,
    a dangling link), is a case too: its reading makes it invalid, counted."""
    try:
        status = os.stat(folder)
        identity = (status.st_dev << 64) | status.st_ino
        if identity in seen:
            return
        with os.scandir(folder) as entries:
            subfolders = sorted(e.name for e in entries if e.name != file_name and _is_folder(e))
    except OSError:  # a folder that cannot be searched (no permission) may hold a case: one, whose reading says why
        yield relative, (0, 0)
        return
    leaf = (status.st_dev, status.st_ino)
    if subfolders or not (0 <= leaf[0] < 1 << 64 and 0 < leaf[1] < 1 << 64):  # (_LEAF's range; else remembered)
        seen.add(identity)
        leaf = (0, 0)
    if os.path.lexists(os.path.join(folder, file_name)):  # (a FIFO, a dangling link: a case, invalid when read)
        yield relative, leaf
    for name in subfolders:
        yield from _walk(os.path.join(folder, name), f"{relative}/{name}" if relative else name, file_name, seen)


def _is_folder(entry):
    try:
        return entry.is_dir()
    except OSError:
        return False
