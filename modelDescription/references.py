#!/usr/bin/env python3
"""Write the FMI-LS-REF folder of one FMU (docs/fmi.md, "Reference
experiments"): its model's reference scenarios (tests/scenarios/<Model>/)
as MA-HS-Experiments files, a smoke test and a validation set (whose
descriptions name the interfaces the scenarios were checked in: every one
the staged model description declares, as tests/fmu/test_reference.py,
test_model_exchange.py and test_scheduled_execution.py run each scenario
through each), each
scenario's stimuli, reference and parameter set (SSP 1.0 .ssv), the
manifest (fmi-ls-manifest.xml) that lists every file with its SHA-256 and
each reference's comparison criteria; then the FMU's sorted zip entries.

    references.py <Model>.toml <scenarios folder> <stage folder> <entries in> <entries out> [<state>]

<state>: the serialized state state.py wrote (after the first half of the
first scenario), carried with the role serialized-state.

The scenarios are the only source: the files are copied byte for byte
(the references are the hand-worked ones), the experiment's times come
from <Model>_ref.opt, its parameters from <Model>_start.csv.
"""

import hashlib
import math
import shutil
import sys
import tomllib
import xml.etree.ElementTree as ET
from pathlib import Path
from xml.sax.saxutils import quoteattr

FOLDER = "extra/org.fmi-standard.fmi-ls-ref"
MANIFEST = "fmi-ls-manifest.xml"
LS_VERSION = "1.0.0-alpha.1"  # the version the standard's schema and example name
ANNOTATION = "org.fmutrace"  # the annotation fmutrace writes and reads (docs/fmi.md)
NAMESPACE = "urn:fmutrace:ls-ref:1"
SMOKE_TESTS = 3  # the smoke test: the first scenarios by name
SSV = "http://ssp-standard.org/SSP1/SystemStructureParameterValues"
SSV_TYPES = {"Real": "Real", "Integer": "Integer", "Boolean": "Boolean", "String": "String"}
OPTIONS = {"StartTime": "startTime", "StopTime": "stopTime", "StepSize": "stepSize", "RelTol": "tolerance"}


def lines(path):
    """The "name,value" lines of a small CSV file, comments and blanks left out."""
    if not path.exists():
        return []
    rows = []
    for line in path.read_text().splitlines():
        line = line.strip()
        if line and not line.startswith("#"):
            name, _, value = line.partition(",")
            rows.append((name.strip(), value.strip()))
    return rows


def ssv_value(type_name, literal):
    """The SSV element of a start value's literal (xs:double spells NaN, INF)."""
    if type_name == "Real":
        value = float(literal)
        if math.isnan(value):
            literal = "NaN"
        elif math.isinf(value):
            literal = "INF" if value > 0 else "-INF"
    elif type_name == "Boolean":
        literal = literal.lower()
    return f"<ssv:{type_name} value={quoteattr(literal)}/>"


def parameter_set(name, values, types):
    rows = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        f'<ssv:ParameterSet xmlns:ssv="{SSV}" version="1.0" name={quoteattr(name)}>',
        "  <ssv:Parameters>",
    ]
    for variable, literal in values:
        type_name = SSV_TYPES.get(types[variable], "Integer")  # an enumeration: its integer
        rows.append(f"    <ssv:Parameter name={quoteattr(variable)}>{ssv_value(type_name, literal)}</ssv:Parameter>")
    return "\n".join(rows + ["  </ssv:Parameters>", "</ssv:ParameterSet>", ""])


def experiments(title, description, scenarios):
    rows = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        f"<Experiments name={quoteattr(title)} description={quoteattr(description)}>",
    ]
    for s in scenarios:
        times = "".join(f" {OPTIONS[k]}={quoteattr(v)}" for k, v in s["options"] if k in OPTIONS)
        rows.append(f"  <Experiment name={quoteattr(s['name'])} description={quoteattr(s['description'])}{times}>")
        if s["parameters"]:
            rows.append(f'    <Parameters type="application/x-ssp-parameter-set" source="{s["parameters"]}"/>')
        if s["stimuli"]:
            rows.append(f'    <Stimuli type="text/csv" source="{s["stimuli"]}"/>')
        rows.append(f'    <References type="text/csv" source="{s["reference"]}"/>')
        rows.append("  </Experiment>")
    return "\n".join(rows + ["</Experiments>", ""])


def related(source, role, description, digest, labels=(), criteria=(), extra=None):
    """A manifest entry: its labels, then the annotation with its SHA-256
    and, for a reference, each signal's criterion (extra: one more element)."""
    rows = [
        f'  <Related type="{media_type(source)}" source="{source}" role="{role}" description={quoteattr(description)}>'
    ]
    rows += [f"    <Label name={quoteattr(label)}/>" for label in labels]
    rows += [
        "    <Annotations>",
        f'      <Annotation type="{ANNOTATION}">',
        f'        <fmutrace:File xmlns:fmutrace="{NAMESPACE}" sha256="{digest}"/>',
    ]
    rows += [
        f'        <fmutrace:Criterion xmlns:fmutrace="{NAMESPACE}" signal={quoteattr(s)} mode={quoteattr(m)}/>'
        for s, m in criteria
    ]
    rows += [f"        {extra}"] if extra else []
    return rows + ["      </Annotation>", "    </Annotations>", "  </Related>"]


def media_type(source):
    return {
        ".exp": "application/x-ma-hs-experiments",
        ".ssv": "application/x-ssp-parameter-set",
        ".csv": "text/csv",
        ".fmustate": "application/octet-stream",
    }[Path(source).suffix]


def reference_criteria(reference, criteria_file):
    """Each reference signal's criterion: the scenario's <Model>_criteria.csv
    for the signals it names, exact (the scenarios' bit-for-bit comparison)
    for the others."""
    header = reference.read_text().splitlines()[0]
    signals = [n.strip().strip('"') for n in header.split(",")[1:]]
    given = dict(lines(criteria_file))
    default = given.pop("*", "exact")
    return [(name, given.pop(name, default)) for name in signals] + sorted(given.items())


def scenario_folders(scenarios_dir, model):
    """The model's scenario folders, by name: the smoke test's come first."""
    return sorted(p for p in Path(scenarios_dir).iterdir() if (p / f"{model}_ref.csv").exists())


def half_steps(options):
    """(start, step, steps of the first half, steps in all) of a scenario's
    options (_ref.opt): where the carried state is taken."""
    start, stop, step = (float(options[k]) for k in ("StartTime", "StopTime", "StepSize"))
    steps = round((stop - start) / step)
    return start, step, steps // 2, steps


def state_entry(scenario, state):
    """The carried state's file name, bytes and manifest entry."""
    start, step, half, steps = half_steps(dict(scenario["options"]))
    name = scenario["name"]
    source = f"serialized-state/{name}.fmustate"
    data = Path(state).read_bytes()
    time = start + half * step
    description = (
        f"{name}: the FMU's state after {half} of its {steps} communication steps (t = {time:g} s), "
        "serialized; deserialized, the second half meets the reference"
    )
    extra = f'<fmutrace:State xmlns:fmutrace="{NAMESPACE}" experiment="{name}" steps="{half}" time="{time!r}"/>'
    return (
        source,
        data,
        related(source, "serialized-state", description, sha256(data), [f"experiment:{name}"], (), extra),
    )


# the interface elements of a model description, as the experiments name them
INTERFACES = {
    "CoSimulation": "Co-Simulation",
    "ModelExchange": "Model Exchange",
    "ScheduledExecution": "Scheduled Execution",
}


def checked_in(model_description):
    """'Co-Simulation, Model Exchange and Scheduled Execution': the interfaces the FMU declares."""
    root = ET.parse(model_description).getroot()
    names = [name for tag, name in INTERFACES.items() if root.find(tag) is not None]
    return ", ".join(names[:-1]) + " and " + names[-1] if len(names) > 1 else names[0]


def write(toml, scenarios_dir, stage, entries_in, entries_out, state=None):
    spec = tomllib.loads(Path(toml).read_text())
    model = spec["model"]["identifier"]
    types = {v["name"]: v["type"] for v in spec["variable"]}
    out = Path(stage) / FOLDER
    shutil.rmtree(out, ignore_errors=True)
    out.mkdir(parents=True)
    files = {}  # source -> bytes

    scenarios = []
    for folder in scenario_folders(scenarios_dir, model):
        name = folder.name
        readme = folder / "README.md"
        first = readme.read_text().strip().splitlines()[0].lstrip("# ").strip() if readme.exists() else ""
        s = {"name": name, "description": first, "options": lines(folder / f"{model}_ref.opt")}
        s["reference"] = f"{name}/reference.csv"
        files[s["reference"]] = (folder / f"{model}_ref.csv").read_bytes()
        s["criteria"] = reference_criteria(folder / f"{model}_ref.csv", folder / f"{model}_criteria.csv")
        s["stimuli"] = None
        if (folder / f"{model}_in.csv").exists():
            s["stimuli"] = f"{name}/stimuli.csv"
            files[s["stimuli"]] = (folder / f"{model}_in.csv").read_bytes()
        start = lines(folder / f"{model}_start.csv")
        s["parameters"] = None
        if start:
            s["parameters"] = f"{name}/parameters.ssv"
            files[s["parameters"]] = parameter_set(name, start, types).encode()
        scenarios.append(s)

    checked = f"; each checked in {checked_in(Path(stage) / 'modelDescription.xml')}"
    roles = (
        (
            "smoke-test",
            f"{model}: smoke test, the first {SMOKE_TESTS} reference scenarios{checked}",
            scenarios[:SMOKE_TESTS],
        ),
        (
            "validation",
            f"{model}: validation, all {len(scenarios)} hand-worked reference scenarios{checked}",
            scenarios,
        ),
    )
    manifest = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        '<fmiReferences xmlns:fmi-ls="http://fmi-standard.org/fmi-ls-manifest"',
        '  fmi-ls:fmi-ls-name="org.fmi-standard.fmi-ls-ref"',
        f'  fmi-ls:fmi-ls-version="{LS_VERSION}"',
        '  fmi-ls:fmi-ls-description="Layered Standard providing information on related files included in an FMU.">',
    ]
    for role, description, chosen in roles:
        source = f"{role}.exp"
        files[source] = experiments(f"{model} {role}", description, chosen).encode()
        manifest += related(source, f"experiment/{role}", description, sha256(files[source]))
    for s in scenarios:
        label = [f"experiment:{s['name']}"]
        if s["parameters"]:
            digest = sha256(files[s["parameters"]])
            manifest += related(s["parameters"], "testcase", f"{s['name']}: parameters", digest, label)
        if s["stimuli"]:
            digest = sha256(files[s["stimuli"]])
            manifest += related(s["stimuli"], "testcase", f"{s['name']}: stimuli", digest, label)
        digest = sha256(files[s["reference"]])
        manifest += related(s["reference"], "result", f"{s['name']}: reference", digest, label, s["criteria"])
    if state:
        source, files[source], entry = state_entry(scenarios[0], state)
        manifest += entry
    manifest += ["</fmiReferences>", ""]
    files[MANIFEST] = "\n".join(manifest).encode()

    for source, data in files.items():
        path = out / source
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(data)
    entries = Path(entries_in).read_text().split()
    entries += [f"{FOLDER}/{source}" for source in files]
    Path(entries_out).write_text("".join(f"{e}\n" for e in sorted(entries)))


def sha256(data):
    return hashlib.sha256(data).hexdigest()


if __name__ == "__main__":
    if len(sys.argv) not in (6, 7):
        sys.exit(__doc__.split("\n\n")[1])
    write(*sys.argv[1:])
