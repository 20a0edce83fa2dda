"""What fmutrace needs to know of an FMU: its variables (to check a trace's
columns and start values before anything runs) and its default
experiment; and the FMU unpacked once per process for fmpy."""

import atexit
import hashlib
import io
import math
import os
import secrets
import shutil
import stat
import sys
from os import PathLike
import tempfile
import zipfile
from pathlib import Path

import fmpy
from fmpy import extract, read_model_description

from ._errors import InputError, TraceError
from ._reading import check_entries, open_regular, read_limit, too_large
from ._traces import BOOLEAN_WORDS, plain_float

INTEGER_RANGES = {
    "Integer": (-(2**31), 2**31 - 1),
    "Int8": (-(2**7), 2**7 - 1),
    "UInt8": (0, 2**8 - 1),
    "Int16": (-(2**15), 2**15 - 1),
    "UInt16": (0, 2**16 - 1),
    "Int32": (-(2**31), 2**31 - 1),
    "UInt32": (0, 2**32 - 1),
    "Int64": (-(2**63), 2**63 - 1),
    "UInt64": (0, 2**64 - 1),
}
REAL_TYPES = ("Real", "Float32", "Float64")  # FMI 2 and FMI 3 floating-point types
# FMI 2 and FMI 3 types of a PLC's BOOL, INT, DINT, WORD, enumerations and status words
DISCRETE_TYPES = ("Boolean", "Enumeration", *INTEGER_RANGES)


class Fmu:
    """An FMU file and its model description."""

    def __init__(self, path: str | PathLike, model_description=None):
        """path: the .fmu file; model_description: fmpy's, if read already
        (a worker has it from the unpacked FMU)."""
        self.path = Path(path)
        if model_description is None:
            if not os.path.lexists(self.path):
                raise InputError(f"{path}: no such FMU file")
            _check_size(path)
            try:
                model_description = read_model_description(str(self.path))
            except Exception as error:  # fmpy raises plain Exceptions for a bad zip or XML
                raise InputError(f"{path}: not an FMU ({error})") from None
        self.model_description = md = model_description
        if md.coSimulation is None:
            raise InputError(f"{path}: {md.modelName} has no Co-Simulation interface")
        self.model = md.modelName
        self.fmi_version = int(md.fmiVersion.split(".")[0])
        self.label = f"{self.model} (FMI {self.fmi_version})"
        self.variables = {v.name: v for v in md.modelVariables}
        experiment = md.defaultExperiment
        self.default_start = _float(experiment and experiment.startTime)
        self.default_stop = _float(experiment and experiment.stopTime)
        self.default_step = _float(experiment and experiment.stepSize)

    def binary_problem(self):
        """Why the FMU cannot run on this machine (no Co-Simulation binary for
        its platform), or None. Only where it runs: a cluster's workers may
        be of another platform than the command's."""
        fmi3 = self.fmi_version >= 3
        platform = fmpy.platform_tuple if fmi3 else fmpy.platform
        identifier = self.model_description.coSimulation.modelIdentifier
        binary = f"binaries/{platform}/{identifier}{fmpy.sharedLibraryExtension}"
        try:
            with zipfile.ZipFile(self.path) as archive:
                names = archive.namelist()
        except (OSError, zipfile.BadZipFile) as error:
            return f"{self.path}: not an FMU ({error})"
        if binary in names:
            return None
        present = sorted({n.split("/")[1] for n in names if n.startswith("binaries/") and n.count("/") > 1})
        return (
            f"{self.path}: {self.label} has no binary for this platform: no {binary} in the FMU "
            f"(it has binaries for: {', '.join(present) or 'none'})"
        )

    def discrete_names(self) -> frozenset:
        """The variables whose values are whole: compared exactly, never interpolated."""
        return frozenset(name for name, v in self.variables.items() if v.type in DISCRETE_TYPES)

    @property
    def outputs(self):
        return [v.name for v in self.model_description.modelVariables if v.causality == "output"]

    def input_problem(self, name):
        """Why name cannot be an input column (None if it can): fmpy sets
        inputs and tunable parameters from the input table."""
        variable = self.variables.get(name)
        if variable is None:
            return f"unknown column {name!r}: {self.label} has no variable of that name"
        if variable.causality != "input" and variable.variability != "tunable":
            return (
                f"column {name!r} is a {variable.variability} {variable.causality} of {self.label}: "
                "only inputs and tunable parameters can change during a run"
            )
        return None

    def variable_problem(self, name):
        """Why name cannot be a reference or output column (None if it can)."""
        if name not in self.variables:
            return f"column {name!r} is not a variable of {self.label}"
        return None

    def start_value(self, name, value):
        """value (text or a Python value) as the start value of variable
        name, checked against its type and range; InputError if not."""
        variable = self.variables.get(name)
        if variable is None:
            raise InputError(f"{name!r} is not a variable of {self.label}")
        if (
            variable.causality not in ("parameter", "structuralParameter", "input")
            or variable.variability == "constant"
        ):
            raise InputError(
                f"{name!r} is a {variable.variability} {variable.causality} of {self.label}: only "
                "parameters and inputs have start values to set"
            )
        text = str(value).strip()
        kind = variable.type
        if kind == "Boolean":
            word = text.lower()
            if word not in BOOLEAN_WORDS and word not in ("0", "1"):
                raise InputError(f"{name} is a Boolean: {text!r} is not true, false, 0 or 1")
            return word in ("true", "1")
        if kind == "String":
            return str(value)
        if kind in REAL_TYPES:
            try:
                number = plain_float(text)
            except ValueError:
                raise InputError(f"{name} is a {kind}: {text!r} is not a number") from None
            self._check_range(variable, number, text)
            return number
        try:
            number = plain_float(text)
        except ValueError:
            number = math.nan
        if not number.is_integer():
            raise InputError(f"{name} is an {kind}: {text!r} is not a whole number")
        number = int(number)
        if kind == "Enumeration":
            items = {int(item.value): item.name for item in variable.declaredType.items}
            if number not in items:
                raise InputError(
                    f"{name} is an enumeration {variable.declaredType.name}: {number} is not one of its "
                    f"values ({', '.join(f'{v} {n}' for v, n in sorted(items.items()))})"
                )
        else:
            low, high = INTEGER_RANGES.get(kind, (-math.inf, math.inf))
            if not low <= number <= high:
                raise InputError(f"{name} is an {kind}: {text} is outside its range [{low}, {high}]")
        self._check_range(variable, number, text)
        return number

    def _check_range(self, variable, number, text):
        declared = variable.declaredType
        low = _float(variable.min if variable.min is not None else declared and declared.min)
        high = _float(variable.max if variable.max is not None else declared and declared.max)
        if (
            (low is not None and number < low)
            or (high is not None and number > high)
            or (math.isnan(number) and (low is not None or high is not None))
        ):
            bounds = f"[{'-inf' if low is None else f'{low:g}'}, {'inf' if high is None else f'{high:g}'}]"
            raise InputError(f"{variable.name} = {text} is outside its range {bounds}")


def _check_size(path):
    """InputError for an FMU file that is no regular file, is larger than
    the read bound, or whose model description inflates to more (_reading):
    checked before fmpy reads it."""
    with open_regular(path) as file:
        size = os.fstat(file.fileno()).st_size
        if size > read_limit():
            raise TraceError(path, 0, 0, too_large(size))
        try:
            with zipfile.ZipFile(file) as archive:
                check_entries(archive, path, {"modelDescription.xml"})
        except (OSError, zipfile.BadZipFile, EOFError) as error:
            raise InputError(f"{path}: not an FMU ({error})") from None


def _float(value):
    if value is None or value == "":
        return None
    return float(value)


_unpacked: dict[str, tuple] = {}  # content hash -> (folder, model description, pid of the process that made it)
# the folder every unpacked FMU of a campaign goes into, its child processes' and local workers' too (they
# inherit it in their environment): made by the first process that unpacks, removed at that process's exit, so
# a child killed (a case over its timeout, a crash, a Dask worker stopped) leaves nothing behind
UNPACK_ROOT = "FMUTRACE_UNPACK_ROOT"


OWNER = ".owner"  # in a root: locked by the process that made it, as long as it lives
_owned: list = []  # this process's root's OWNER, open (and locked) until it ends


def unpack_root() -> str:
    """The folder this process and the processes it starts unpack FMUs into:
    its parent's (UNPACK_ROOT in its environment), else one of its own
    (mkdtemp, mode 0700, removed at exit), then set for its children. A new
    one first removes the roots whose makers died without removing theirs
    (killed: no exit to do it at)."""
    root = os.environ.get(UNPACK_ROOT)
    if not (root and os.path.isdir(root)):
        _remove_abandoned()
        if _lock is None:
            root = tempfile.mkdtemp(prefix="fmutrace-")
        else:  # named a root only once its OWNER is locked: another command's clean-up never takes it for dead
            making = tempfile.mkdtemp(prefix=".fmutrace-making-")
            _owned.append(open(os.path.join(making, OWNER), "w"))
            _lock(_owned[-1])
            root = _named_root(making)
        atexit.register(_remove, root, os.getpid())
        os.environ[UNPACK_ROOT] = root
    return root


def _named_root(making):
    """The folder making renamed to a root's name (fmutrace-<random>) that no other file has."""
    for _ in range(100):
        root = os.path.join(os.path.dirname(making), f"fmutrace-{secrets.token_hex(8)}")
        if os.path.lexists(root):
            continue
        try:
            os.rename(making, root)
        except OSError:  # (taken since: another name)
            continue
        return root
    raise InputError(f"{os.path.dirname(making)}: no free name for a folder of unpacked FMUs")


if sys.platform == "win32":
    _lock = None  # (a Windows root is removed at its maker's exit only)
else:
    import fcntl

    def _lock(file):
        """Locks the file without waiting; OSError if a live process holds it (the lock dies with it)."""
        fcntl.flock(file, fcntl.LOCK_EX | fcntl.LOCK_NB)


def _remove_abandoned():
    """Removes this user's roots in the temporary folder whose OWNER no live
    process holds. Only roots: a folder without OWNER (another version's,
    anyone else's) is left alone."""
    if _lock is None:
        return
    temporary = tempfile.gettempdir()
    try:
        names = [n for n in os.listdir(temporary) if n.startswith("fmutrace-")]  # (not one being made)
    except OSError:
        return
    for name in names:
        folder = os.path.join(temporary, name)
        try:
            status = os.lstat(folder)
            if not stat.S_ISDIR(status.st_mode) or status.st_uid != os.getuid():
                continue
            with open(os.path.join(folder, OWNER)) as owner:
                _lock(owner)  # OSError while its maker lives
        except OSError:
            continue
        shutil.rmtree(folder, ignore_errors=True)


# what an FMU needs to run: its description, its binaries, the resources its instance is given (an FMU
# carries more: sources, documentation, layered standards' extra/ files, a hundred files in ours)
RUN_FILES = ("modelDescription.xml", "binaries/", "resources/")


def unpacked(fmu_bytes):
    """(folder, model description) of an FMU given as bytes, its RUN_FILES
    unzipped once per process into a folder of its own: made fresh
    (mkdtemp, mode 0700, never found again by a name another user could
    plant) and removed at the process's exit."""
    key = hashlib.sha256(fmu_bytes).hexdigest()
    known = _unpacked.get(key)
    if known is None or known[2] != os.getpid():  # (a forked child makes its own: the parent removes its one)
        folder = tempfile.mkdtemp(prefix="fmu-", dir=unpack_root())
        atexit.register(_remove, folder, os.getpid())
        try:
            with zipfile.ZipFile(io.BytesIO(fmu_bytes)) as archive:
                check_entries(archive, "the FMU", [n for n in archive.namelist() if _runs_with(n)])
            extract(io.BytesIO(fmu_bytes), unzipdir=folder, include=_runs_with)
            known = (folder, read_model_description(folder), os.getpid())
        except InputError:
            _remove(folder, os.getpid())
            raise
        except Exception as error:  # fmpy raises plain Exceptions for a bad zip or XML
            _remove(folder, os.getpid())
            raise InputError(f"the FMU cannot be unpacked ({error})") from None
        _unpacked[key] = known
    return known[:2]


def _runs_with(name: str) -> bool:
    return name == RUN_FILES[0] or name.startswith(RUN_FILES[1:])


def _remove(folder, owner):
    """An unpacked FMU's folder (or the root of them), at the exit of the process that made it."""
    if os.getpid() == owner:
        shutil.rmtree(folder, ignore_errors=True)


def is_fmu_file(path):
    path = Path(path)
    return path.is_file() and path.suffix.lower() == ".fmu" and zipfile.is_zipfile(path)
