"""fmutrace's pytest plugin (registered by the package's pytest11 entry
point): `pytest --fmu FMU [--fmu FMU...] CASES...` collects every case
folder under CASES (a folder holding <Model>_ref.csv of an FMU's model) and
every recording named among them as one test item per FMU, named by the
case; an item runs the case as `fmutrace compare` does and fails with its
messages. Without --fmu (or the ini option fmutrace_fmus) it collects
nothing. pytest is no dependency of fmutrace: only pytest imports this."""

from pathlib import Path

import pytest

from . import Fmu, InputError, RunOptions, compare
from .recordings import is_recording

FMUS = "fmutrace_fmus"  # the ini option: FMU paths, one a line, relative to the ini file's folder


def pytest_addoption(parser):
    group = parser.getgroup("fmutrace", "fmutrace: trace cases as test items")
    group.addoption(
        "--fmu",
        action="append",
        default=[],
        metavar="PATH",
        help="an FMU to run every case folder and recording given on (repeat for several)",
    )
    parser.addini(FMUS, "FMUs to run the case folders and recordings on (as --fmu), one a line", type="paths")


def pytest_configure(config):
    paths = [Path(p) for p in config.getoption("fmu")] or list(config.getini(FMUS))
    if not paths:
        return
    fmus = []
    for path in paths:
        try:
            fmus.append(Fmu(path))
        except InputError as error:
            raise pytest.UsageError(f"--fmu: {error}") from None
    config.stash[_FMUS] = _tags(fmus)
    config.stash[_GIVEN] = {Path(a.split("::")[0]).resolve() for a in config.args}


_FMUS = pytest.StashKey[list]()  # [(tag, Fmu)]
_GIVEN = pytest.StashKey[set]()  # the paths on the command line (a recording is run when named)


def _tags(fmus):
    """[(its name in an item's, Fmu)]: <file stem>-fmi<version>, numbered if two are alike."""
    tagged: list = []
    for fmu in fmus:
        tag, n = f"{fmu.path.stem}-fmi{fmu.fmi_version}", 2
        while tag in (t for t, _ in tagged):
            tag, n = f"{fmu.path.stem}-fmi{fmu.fmi_version}-{n}", n + 1
        tagged.append((tag, fmu))
    return tagged


def pytest_collect_file(file_path: Path, parent):
    fmus = parent.config.stash.get(_FMUS, None)
    if not fmus:
        return None
    models = [(tag, fmu) for tag, fmu in fmus if file_path.name == f"{fmu.model}_ref.csv"]
    if models:
        return CaseFolder.from_parent(parent, path=file_path, fmus=models, case=file_path.parent)
    if file_path.resolve() in parent.config.stash[_GIVEN]:
        if is_recording(file_path):
            return CaseFolder.from_parent(parent, path=file_path, fmus=fmus, case=file_path)
    return None


class CaseFolder(pytest.File):
    """A case folder (collected by its <Model>_ref.csv) or a recording: an item per FMU."""

    def __init__(self, *, fmus, case: Path, **kwargs):
        super().__init__(**kwargs)
        self.fmus, self.case = fmus, case

    def collect(self):
        name = self.case.stem if self.case.is_file() else self.case.name  # (a recording by its name, not its file's)
        for tag, fmu in self.fmus:
            # (the id given whole: pytest reads the FMU's tag in brackets as a parametrized test's, as --lf does)
            yield CaseItem.from_parent(self, name=f"{name}[{tag}]", nodeid=f"{self.nodeid}::{name}[{tag}]", fmu=fmu)


class CaseFailed(Exception):
    """The case did not pass: its status and messages."""


class CaseItem(pytest.Item):
    """One case on one FMU, run and compared in this process as
    `fmutrace compare --jobs 1` runs it."""

    def __init__(self, *, fmu, **kwargs):
        super().__init__(**kwargs)
        self.fmu = fmu

    def runtest(self):
        case = self.parent.case  # type: ignore[union-attr]
        try:
            result = compare(self.fmu.path, case, run=RunOptions(jobs=1))
        except InputError as error:
            raise CaseFailed(f"fmutrace: error: {error}") from None
        # the case itself (a case folder may hold others: their own items run them)
        mine = [o for o in result.cases if o.case == case.name] or list(result.cases)
        failed = [o for o in mine if not o.passed]
        if failed:
            lines = []
            for o in failed:
                lines.append(f"{o.status.upper()}  {o.case} on {o.fmu}")
                lines += [f"      {m}" for m in o.messages]
            raise CaseFailed("\n".join(lines))

    def repr_failure(self, excinfo, style=None):
        if isinstance(excinfo.value, CaseFailed):
            return str(excinfo.value)
        return super().repr_failure(excinfo, style)

    def reportinfo(self):
        return self.path, None, self.name
