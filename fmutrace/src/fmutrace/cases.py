"""Cases in the FMI cross-check layout: a folder that holds, for the model
<Model> of the FMU,

  <Model>_ref.csv    the reference trace (required)
  <Model>_in.csv     input signals (optional); a row holds from its time on
  <Model>_ref.opt    StartTime, StopTime, StepSize, RelTol (optional: the
                     reference's first and last time, the FMU's default step)
  <Model>_start.csv  start values, one "name,value" line each (optional)
  README.md          its first line describes the case (optional)

Every file is checked against the FMU before anything runs: a problem is
an InputError naming the file, line and column.
"""
from dataclasses import dataclass
from pathlib import Path

from .traces import InputError, TraceError, _lines, _split, parse_number, read_trace

OPTIONS = ("StartTime", "StopTime", "StepSize", "RelTol")


@dataclass
class Case:
    name: str               # its folder, relative to the folder searched
    model: str
    folder: Path
    options: dict           # StartTime, StopTime, StepSize, RelTol
    start_values: dict      # name -> value of the variable's type
    inputs: object          # structured array, or None
    reference: object       # structured array
    description: str = ""

    @property
    def id(self):
        return self.name

    @property
    def outputs(self):
        """The reference's signals: what is recorded and compared."""
        return [n for n in self.reference.dtype.names if n != "time"]


def read_options(path, reference, fmu):
    options = {"RelTol": 1e-6}
    if path.exists():
        for number, line in _lines(path):
            cells = _split(line, ",")
            if len(cells) != 2:
                raise TraceError(path, number, 1, f"expected 'Name,value', found {line.strip()!r}")
            key, literal = cells
            if key not in OPTIONS:
                raise TraceError(path, number, 1, f"unknown option {key!r} (known: {', '.join(OPTIONS)})")
            value = parse_number(literal)
            if value is None or value != value:
                raise TraceError(path, number, 2, f"{key} {literal!r} is not a number")
            options[key] = value
    options.setdefault("StartTime", float(reference["time"][0]))
    options.setdefault("StopTime", float(reference["time"][-1]))
    if "StepSize" not in options:
        if fmu.default_step is None:
            raise InputError(f"{path}: no StepSize: the file is missing or has none, and {fmu.label} gives no "
                             "default step size")
        options["StepSize"] = fmu.default_step
    where = path if path.exists() else f"{path} (defaults)"
    if not options["StepSize"] > 0:
        raise TraceError(where, 0, 0, f"StepSize {options['StepSize']!r} must be greater than 0")
    if not options["StopTime"] > options["StartTime"]:
        raise TraceError(where, 0, 0, f"StopTime {options['StopTime']!r} must be after StartTime "
                                      f"{options['StartTime']!r}")
    return options


def read_start_values(path, fmu):
    """The start values of a "name,value" file, each checked against the
    FMU's variable (type, range)."""
    values = {}
    if not path.exists():
        return values
    for number, line in _lines(path):
        cells = _split(line, "," if line.count(",") else ";")
        if len(cells) != 2:
            raise TraceError(path, number, 1, f"expected 'name,value', found {line.strip()!r}")
        name, literal = cells
        if name not in fmu.variables:
            raise TraceError(path, number, 1, f"{name!r} is not a variable of {fmu.label}")
        try:
            values[name] = fmu.start_value(name, literal)
        except InputError as error:
            raise TraceError(path, number, 2, str(error)) from None
    return values


def load_case(folder, fmu, name=None):
    """The case in folder for fmu's model, checked against the FMU."""
    folder = Path(folder)
    model = fmu.model
    reference = read_trace(folder / f"{model}_ref.csv", fmu.variable_problem)
    inputs_file = folder / f"{model}_in.csv"
    inputs = read_trace(inputs_file, fmu.input_problem) if inputs_file.exists() else None
    readme = folder / "README.md"
    description = ""
    if readme.exists():
        lines = readme.read_text(errors="replace").strip().splitlines()
        description = lines[0].lstrip("# ").strip() if lines else ""
    return Case(
        name=name or folder.name,
        model=model,
        folder=folder,
        options=read_options(folder / f"{model}_ref.opt", reference, fmu),
        start_values=read_start_values(folder / f"{model}_start.csv", fmu),
        inputs=inputs,
        reference=reference,
        description=description,
    )


def find_cases(paths, model):
    """[(folder, name)] of the cases of model under paths, each a case
    folder itself or a folder searched recursively, sorted by name: the
    folder's path below the one searched (its own name for a case folder
    given itself)."""
    found = {}
    for path in map(Path, paths):
        if not path.is_dir():
            raise InputError(f"{path}: no such folder")
        for reference in sorted(path.rglob(f"{model}_ref.csv")):
            folder = reference.parent.resolve()
            relative = reference.parent.relative_to(path).as_posix()
            name = path.resolve().name if relative == "." else relative
            if folder not in found:
                if name in found.values():  # the same name below two folders given
                    name = f"{path.resolve().name}/{name}"
                found[folder] = name
    return sorted(found.items(), key=lambda item: item[1])
