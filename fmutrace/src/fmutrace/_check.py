"""`check`: the experiments an FMI-LS-REF FMU carries, run and compared as
`compare` runs case folders (docs/fmutrace.md, "FMUs that carry their
tests"). They are written out as case folders first (_lsref): into the
report folder's experiments/ when there is one (so that --resume finds
them again), else into a temporary folder."""

import shutil
import tempfile
from os import PathLike
from pathlib import Path

from ._campaign import Paths, compare
from ._errors import InputError
from ._fmu import Fmu
from ._lsref import write_cases
from ._outcome import CampaignResult

EXPERIMENTS = "experiments"


def check(fmus: Paths, *, role: str | None = None, report: str | PathLike | None = None, **options) -> CampaignResult:
    """Run every experiment the FMUs carry (role: 'smoke-test' or
    'validation'; None: every experiment file, each experiment once) and
    compare it with its reference, by the criteria the reference carries;
    a signal without one by the mode given (options: those of compare),
    else bit for bit. Returns compare's CampaignResult; InputError for an
    FMU without experiments, a bad manifest or experiment file, or a file
    whose SHA-256 is not the manifest's. Of several FMUs, one that
    cannot be checked so is left out, its message among the result's
    problems (exit code 2), and the others run; InputError if none can."""
    paths = [fmus] if isinstance(fmus, (str, PathLike)) else list(fmus)
    with tempfile.TemporaryDirectory(prefix="fmutrace-check-") as folder:
        target = Path(report) / EXPERIMENTS if report else Path(folder)
        if report:
            shutil.rmtree(target, ignore_errors=True)
        checked, folders, problems = _write(paths, role, target)
        result = compare(checked, folders, report=report, **options)
    result.problems += problems
    return result


def _write(paths, role, target):
    """(the FMUs with experiments, their case folders, the others'
    messages): one case folder per model (its FMUs, FMI 2 and 3, share
    them), every FMU's manifest checked."""
    folders: dict[str, Path] = {}
    checked, problems = [], []
    for path in paths:
        fmu = Fmu(path)
        folder = target / f"{len(folders)}-{fmu.model}" if fmu.model not in folders else None
        try:
            write_cases(path, fmu.model, str(path), role, folder or target / "checked")
        except InputError as problem:
            if len(paths) == 1:
                raise
            shutil.rmtree(folder or target / "checked", ignore_errors=True)  # (what it wrote before the error)
            problems.append(f"{problem}: not checked")
            continue
        checked.append(path)
        if folder:
            folders[fmu.model] = folder
    shutil.rmtree(target / "checked", ignore_errors=True)
    if not checked:
        raise InputError("; ".join(problems))
    return checked, list(folders.values()), problems
