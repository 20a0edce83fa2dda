"""FMI-LS-REF: the experiments an FMU carries (docs/fmi.md, "Reference
experiments"), read from its manifest (extra/org.fmi-standard.fmi-ls-ref/
fmi-ls-manifest.xml) and its MA-HS-Experiments files, checked against the
SHA-256 the manifest's fmutrace annotation gives, and written out as case
folders in the cross-check layout, which a campaign runs as any other:

  <folder>/<experiment file>/<experiment>/<Model>_ref.csv, _in.csv, _ref.opt,
  _start.csv (the .ssv's values), _criteria.csv (the annotation's criteria)

Any LS-REF FMU: roles experiment, experiment/smoke-test, experiment/validation;
stimuli and references as CSV, parameters as SSP .ssv; an FMU that carries
no checksums or criteria is read as it is (the campaign's mode judges it).
"""

import hashlib
import posixpath
import zipfile
from urllib.parse import unquote
from dataclasses import dataclass, field
from pathlib import Path
from xml.etree import ElementTree

from ._errors import InputError
from ._reading import check_entries, quoted
from ._traces import UNUSUAL_LINE_BREAKS
from ._report import file_name

FOLDER = "extra/org.fmi-standard.fmi-ls-ref/"
MANIFEST = FOLDER + "fmi-ls-manifest.xml"
LS_NAME = "org.fmi-standard.fmi-ls-ref"
LS = "{http://fmi-standard.org/fmi-ls-manifest}"
ANNOTATION = "org.fmutrace"
NS = "{urn:fmutrace:ls-ref:1}"
ROLES = ("smoke-test", "validation")
OPTIONS = (("startTime", "StartTime"), ("stopTime", "StopTime"), ("stepSize", "StepSize"), ("tolerance", "RelTol"))
XSD_WORDS = {"NaN": "nan", "INF": "inf", "-INF": "-inf"}


@dataclass
class Related:
    source: str  # its path in the FMU
    role: str
    sha256: str | None = None
    criteria: list = field(default_factory=list)  # [(signal, mode words)]


@dataclass
class Experiment:
    name: str  # <experiment file's stem>/<experiment's name>, each a safe file name, unique
    description: str
    options: dict  # cross-check option -> text
    files: dict  # "parameters", "stimuli", "references" -> path in the FMU


def manifest(fmu_zip: zipfile.ZipFile, label: str) -> list[Related]:
    """The manifest's related files; InputError if there is none or it is not one."""
    try:
        root = ElementTree.fromstring(bounded_read(fmu_zip, label, MANIFEST))
    except KeyError:
        raise InputError(
            f"{label} carries no FMI-LS-REF experiments (no {MANIFEST}): give case folders after it"
        ) from None
    except ElementTree.ParseError as error:
        raise InputError(f"{label}: {MANIFEST}: not XML ({error})") from None
    if root.tag != "fmiReferences" or root.get(f"{LS}fmi-ls-name") != LS_NAME:
        raise InputError(f"{label}: {MANIFEST}: not an FMI-LS-REF manifest (root fmiReferences, fmi-ls-name {LS_NAME})")
    found = []
    for number, element in enumerate(root.iterfind("Related"), 1):
        source, role = element.get("source"), element.get("role")
        if not source or not role:
            raise InputError(f"{label}: {MANIFEST}: Related element {number} has no source or no role")
        related = Related(_inside(label, FOLDER, source), role)
        for annotation in element.iterfind("Annotations/Annotation"):
            if annotation.get("type") != ANNOTATION:
                continue
            for entry in annotation.iterfind(f"{NS}File"):
                related.sha256 = entry.get("sha256")
            related.criteria += [
                tuple(one_line(label, MANIFEST, f"a criterion's {key}", c.get(key, "")) for key in ("signal", "mode"))
                for c in annotation.iterfind(f"{NS}Criterion")
            ]
        found.append(related)
    return found


def _inside(label, base, source):
    """source (relative to the folder base) as a path in the FMU; InputError
    for an absolute URI or one that leaves the FMU."""
    if "://" in source or source.startswith("/"):
        raise InputError(f"{label}: {source!r}: only files inside the FMU are read (a relative path)")
    path = posixpath.normpath(posixpath.join(base, unquote(source)))
    if path.startswith("../") or path == "..":
        raise InputError(f"{label}: {source!r} leaves the FMU")
    return path


def checked(fmu_zip, label, path, digests):
    """A file's bytes, its SHA-256 checked where the manifest gives one."""
    try:
        data = bounded_read(fmu_zip, label, path)
    except KeyError:
        raise InputError(f"{label}: {path}: named by the manifest or an experiment, and not in the FMU") from None
    expected = digests.get(path)
    if expected is not None and hashlib.sha256(data).hexdigest() != expected.lower():
        raise InputError(
            f"{label}: {path}: its SHA-256 is not the manifest's: the file was changed after the FMU was made"
        )
    return data


def bounded_read(fmu_zip, label, path) -> bytes:
    """An entry's bytes, refused before it is inflated when it would inflate
    to more than the read bound (a zip bomb); KeyError if there is none."""
    check_entries(fmu_zip, label, {fmu_zip.getinfo(path).filename})
    return fmu_zip.read(path)


def one_line(label, path, what, text: str) -> str:
    """text, which becomes a line's cell of a case file: InputError if it
    holds a line break (it would add a line of its own making)."""
    if any(c in text for c in "\r\n" + UNUSUAL_LINE_BREAKS):
        raise InputError(f"{label}: {path}: {what} {quoted(text)} holds a line break")
    return text


def wanted(role: str, chosen: str | None) -> bool:
    """Whether an experiment file of role is run for the role chosen (None:
    smoke tests and validations); an experiment without a sub-role is a
    smoke test (the standard); an uncertainty analysis is never run."""
    if role != "experiment" and not role.startswith("experiment/"):
        return False
    sub = role.partition("/")[2] or "smoke-test"
    return sub in ROLES and (chosen is None or sub == chosen)


def experiments(fmu_zip, label, role: str | None = None):
    """(experiments, criteria by reference path, digests) of the experiment
    files of role; every file in the manifest is checked against its SHA-256."""
    if role is not None and role not in ROLES:
        raise InputError(f"role must be {' or '.join(ROLES)}, not {role!r}")
    entries = manifest(fmu_zip, label)
    digests = {r.source: r.sha256 for r in entries if r.sha256}
    for path in digests:  # a tampered file fails whatever is run
        checked(fmu_zip, label, path, digests)
    criteria = {r.source: r.criteria for r in entries if r.criteria}
    found: list[Experiment] = []
    seen: set[tuple] = set()
    names: set[str] = set()
    for related in entries:
        if not wanted(related.role, role):
            continue
        data = checked(fmu_zip, label, related.source, digests)
        try:
            root = ElementTree.fromstring(data)
        except ElementTree.ParseError as error:
            raise InputError(f"{label}: {related.source}: not XML ({error})") from None
        stem = posixpath.splitext(posixpath.basename(related.source))[0]
        base = posixpath.dirname(related.source) + "/"
        for number, element in enumerate(root.iterfind("Experiment"), 1):
            name = element.get("name") or f"experiment{number}"
            files = {}
            for tag, key in (("Parameters", "parameters"), ("Stimuli", "stimuli"), ("References", "references")):
                child = element.find(tag)
                if child is not None and child.get("source"):
                    files[key] = _inside(label, base, child.get("source"))
            if "references" not in files:
                raise InputError(f"{label}: {related.source}: experiment {name!r} has no References")
            options = {
                key: one_line(label, related.source, f"experiment {quoted(name)}'s {attr}", element.get(attr, ""))
                for attr, key in OPTIONS
                if element.get(attr) is not None
            }
            identity = (name, tuple(options.items()), tuple(sorted(files.items())))
            if identity in seen:  # the smoke test's experiments are the validation's too
                continue
            seen.add(identity)
            folder = unique(f"{file_name(stem)}/{file_name(name)}", names)
            found.append(Experiment(folder, element.get("description", ""), options, files))
    if not found:
        raise InputError(f"{label} carries no experiment{f' of role {role}' if role else ''}")
    return found, criteria, digests


def unique(name, taken):
    """name, or name-2, name-3, ... if it is taken (two experiments of one name)."""
    candidate, n = name, 2
    while candidate in taken:
        candidate, n = f"{name}-{n}", n + 1
    taken.add(candidate)
    return candidate


def parameter_lines(label, path, data):
    """The "name,value" lines of an SSP parameter set's values."""
    try:
        root = ElementTree.fromstring(data)
    except ElementTree.ParseError as error:
        raise InputError(f"{label}: {path}: not XML ({error})") from None
    rows = []
    for parameter in root.iter():
        if not parameter.tag.endswith("}Parameter") and parameter.tag != "Parameter":
            continue
        value = next(iter(parameter), None)
        if value is None or value.get("value") is None:
            raise InputError(f"{label}: {path}: parameter {parameter.get('name')!r} has no value")
        literal = value.get("value", "")
        name = one_line(label, path, "a parameter's name", parameter.get("name") or "")
        rows.append(f"{name},{one_line(label, path, f'the value of {name}', XSD_WORDS.get(literal, literal))}\n")
    return "".join(rows)


def write_cases(fmu_path, model: str, label: str, role: str | None, folder: Path) -> Path:
    """The FMU's experiments of role as case folders of model under folder
    (made new); InputError for a bad manifest, experiment or checksum."""
    with zipfile.ZipFile(fmu_path) as fmu_zip:
        found, criteria, digests = experiments(fmu_zip, label, role)
        for experiment in found:
            case = folder / experiment.name
            case.mkdir(parents=True, exist_ok=True)
            files = experiment.files
            (case / f"{model}_ref.csv").write_bytes(checked(fmu_zip, label, files["references"], digests))
            if "stimuli" in files:
                (case / f"{model}_in.csv").write_bytes(checked(fmu_zip, label, files["stimuli"], digests))
            if experiment.options:
                opt = "".join(f"{k},{v}\n" for k, v in experiment.options.items())
                (case / f"{model}_ref.opt").write_text(opt)
            if "parameters" in files:
                data = checked(fmu_zip, label, files["parameters"], digests)
                (case / f"{model}_start.csv").write_text(parameter_lines(label, files["parameters"], data))
            pairs = criteria.get(files["references"])
            if pairs:
                (case / f"{model}_criteria.csv").write_text("".join(f"{s},{m}\n" for s, m in pairs))
            if experiment.description:
                (case / "README.md").write_text(experiment.description + "\n")
    return folder
