"""`check`: the experiments an FMI-LS-REF FMU carries, run and compared as
`compare` runs case folders (docs/fmutrace.md, "FMUs that carry their
tests"). They are written out as case folders first (_lsref): into the
report folder's experiments/ when there is one (so that --resume finds
them again), else into a temporary folder."""

import os
import shutil
import tempfile
from os import PathLike
from pathlib import Path

from ._campaign import Paths, compare
from ._errors import InputError
from ._journal import ReportLock
from ._fmu import Fmu, unpack_root
from ._lsref import write_cases
from ._outcome import CampaignResult
from ._report import output_problem, write_junit, write_report

EXPERIMENTS = "experiments"
MARKER = ".fmutrace-experiments"  # in experiments/: the folder is a check's, to replace


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
    junit = options.pop("junit", None)  # (written below, once the FMUs left out are known)
    if report:
        lock = ReportLock(report)  # before anything in the folder is touched (compare's own is this one)
        try:
            target = _experiments_folder(report)
            if junit and output_problem(junit):  # (checked once the report folder is made: it may hold the file)
                raise InputError(output_problem(junit))
            checked, made, problems = _write(paths, role, target)
            result = compare(checked, list(made), report=report, **options)
            if problems:  # the report again, naming the FMUs left out
                result.problems += problems
                write_report(result, report)
            if junit:
                write_junit(result, junit)
            return result
        finally:
            lock.release()
    if junit and output_problem(junit):
        raise InputError(output_problem(junit))
    # in the command's own folder of unpacked FMUs: a check killed leaves it to the next command to remove
    with tempfile.TemporaryDirectory(prefix="check-", dir=unpack_root()) as folder:
        checked, folders, problems = _write(paths, role, Path(folder))
        result = compare(checked, list(folders), **options)
    result.problems += problems
    for case in result.cases:  # the folder is gone: its files are named by the FMU that carries them
        for root, fmu in folders.items():
            case.messages = [m.replace(f"{root}{os.sep}", f"{fmu}: experiment ") for m in case.messages]
    if junit:
        write_junit(result, junit)
    return result


def _experiments_folder(report) -> Path:
    """The report's experiments/, emptied for this check: only a folder a
    check made (its MARKER file inside) is replaced; a link, a file, or a
    folder of the user's is refused (InputError), nothing in it touched."""
    target = Path(report) / EXPERIMENTS
    if os.path.islink(target):
        raise InputError(f"{target}: a link in the report folder; remove it or choose another folder")
    if os.path.lexists(target):
        if not (target.is_dir() and os.path.isfile(target / MARKER) and not os.path.islink(target / MARKER)):
            raise InputError(
                f"{target}: not written by fmutrace check (no {MARKER} in it), so not replaced; "
                "move it away or choose another report folder"
            )
        shutil.rmtree(target)
    target.mkdir()
    (target / MARKER).write_text("written by fmutrace check: replaced by the next check into this report\n")
    return target


def _write(paths, role, target):
    """(the FMUs with experiments, {each case folder: the FMU whose
    experiments it holds}, the other FMUs' messages): one case folder per
    model (its FMUs, FMI 2 and 3, share them), every FMU's manifest checked."""
    folders: dict[str, Path] = {}
    made: dict[Path, str] = {}
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
            made[folder] = str(path)
    shutil.rmtree(target / "checked", ignore_errors=True)
    if not checked:
        raise InputError("; ".join(problems))
    return checked, made, problems
