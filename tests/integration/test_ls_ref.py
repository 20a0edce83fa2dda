"""Every FMU carries its model's reference scenarios as FMI-LS-REF
experiments (modelDescription/references.py, docs/fmi.md): a manifest
valid against the standard's schema, every file it lists with its SHA-256,
the scenarios' own bytes as stimuli and references, their start values as
SSP parameter sets, a smoke test and a validation set."""

import csv
import hashlib
import io
import math
import re
import struct
import zipfile

import pytest
from lxml import etree

from support.fmu_driver import MODELS, REPO, fmu_file
from support.ls_ref import EXAMPLE, FOLDER, manifest_schema, ssv_schema

NS = {"ft": "urn:fmutrace:ls-ref:1"}
SCENARIOS = REPO / "tests" / "scenarios"


@pytest.fixture(scope="module")
def schema():
    return manifest_schema()


# every FMU: FMI 2, FMI 3 Co-Simulation and Model Exchange, FMI 3 Scheduled Execution
VARIANTS = pytest.mark.parametrize(
    "version,scheduled", [(2, False), (3, False), (3, True)], ids=["fmi2", "fmi3", "fmi3-scheduled-execution"]
)


def carried(model, version, scheduled):
    with zipfile.ZipFile(fmu_file(model, version, scheduled)) as z:
        prefix = f"{FOLDER}/"
        return {n[len(prefix) :]: z.read(n) for n in z.namelist() if n.startswith(prefix)}


def scenario_names(model):
    return sorted(p.parent.name for p in (SCENARIOS / model).glob(f"*/{model}_ref.csv"))


def test_the_schema_accepts_the_standards_example_and_refuses_a_bad_role(schema):
    example = etree.parse(str(EXAMPLE))
    assert schema.validate(example), schema.error_log
    example.getroot()[0].set("role", "experiment/fast")  # not a role of the standard
    assert not schema.validate(example)


@VARIANTS
@pytest.mark.parametrize("model", MODELS)
def test_the_manifest_is_valid_and_its_checksums_hold(model, version, scheduled, schema):
    files = carried(model, version, scheduled)
    manifest = etree.fromstring(files.pop("fmi-ls-manifest.xml"))
    assert schema.validate(manifest), schema.error_log
    listed = {}
    for related in manifest.iterfind("Related"):
        (entry,) = related.iterfind("Annotations/Annotation/ft:File", NS)
        listed[related.get("source")] = entry.get("sha256")
    assert listed.keys() == files.keys()  # every file listed, nothing listed missing
    for source, digest in listed.items():
        assert hashlib.sha256(files[source]).hexdigest() == digest, source


@VARIANTS
@pytest.mark.parametrize("model", MODELS)
def test_the_experiments_are_the_scenarios_byte_for_byte(model, version, scheduled):
    files = carried(model, version, scheduled)
    names = scenario_names(model)
    validation = etree.fromstring(files["validation.exp"])
    smoke = etree.fromstring(files["smoke-test.exp"])
    # each says the interfaces its FMU declares, the ones the scenarios were checked in (tests/fmu)
    checked = "Scheduled Execution" if scheduled else "Co-Simulation and Model Exchange"
    for experiments in (validation, smoke):
        assert experiments.get("description").endswith(f"; each checked in {checked}"), experiments.get("description")
    assert [e.get("name") for e in validation.iterfind("Experiment")] == names
    assert [e.get("name") for e in smoke.iterfind("Experiment")] == names[:3]
    for experiment in validation.iterfind("Experiment"):
        folder = SCENARIOS / model / experiment.get("name")
        (reference,) = experiment.iterfind("References")
        assert files[reference.get("source")] == (folder / f"{model}_ref.csv").read_bytes()
        stimuli = experiment.find("Stimuli")
        inputs = folder / f"{model}_in.csv"
        assert (stimuli is not None) == inputs.exists()
        if stimuli is not None:
            assert files[stimuli.get("source")] == inputs.read_bytes()
        opt = dict(csv.reader(io.StringIO((folder / f"{model}_ref.opt").read_text())))
        assert float(experiment.get("startTime")) == float(opt["StartTime"])
        assert float(experiment.get("stopTime")) == float(opt["StopTime"])
        assert float(experiment.get("stepSize")) == float(opt["StepSize"])


@pytest.mark.parametrize("model", MODELS)
def test_the_parameter_sets_are_the_start_values(model):
    files = carried(model, 3, False)
    validator = ssv_schema()
    validation = etree.fromstring(files["validation.exp"])
    for experiment in validation.iterfind("Experiment"):
        start = SCENARIOS / model / experiment.get("name") / f"{model}_start.csv"
        parameters = experiment.find("Parameters")
        assert (parameters is not None) == (start.exists() and bool(start.read_text().strip()))
        if parameters is None:
            continue
        document = etree.fromstring(files[parameters.get("source")])
        assert validator.validate(document), validator.error_log
        values = {p.get("name"): p[0].get("value") for p in document.iter("{*}Parameter")}
        expected = dict(row for row in csv.reader(io.StringIO(start.read_text())) if row)
        assert values.keys() == expected.keys()
        for name, literal in expected.items():
            value = values[name]
            if re.fullmatch(r"true|false", literal, re.I):
                assert value == literal.lower()
            elif math.isnan(float(literal)):
                assert value == "NaN"
            else:
                assert float(value) == float(literal)


def test_every_reference_carries_each_signals_criterion():
    files = carried("RateLimiter", 3, False)
    manifest = etree.fromstring(files["fmi-ls-manifest.xml"])
    results = [r for r in manifest.iterfind("Related") if r.get("role") == "result"]
    assert len(results) == len(scenario_names("RateLimiter"))
    for related in results:
        header = files[related.get("source")].decode().splitlines()[0].split(",")[1:]
        criteria = {c.get("signal"): c.get("mode") for c in related.iterfind("Annotations/Annotation/ft:Criterion", NS)}
        assert criteria == dict.fromkeys(header, "exact")  # no scenario has its own: bit for bit


@VARIANTS
@pytest.mark.parametrize("model", MODELS)
def test_the_documentation_names_the_interfaces_and_the_experiments(model, version, scheduled):
    with zipfile.ZipFile(fmu_file(model, version, scheduled)) as z:
        page = z.read("documentation/index.html").decode()
        standalone = z.read("documentation/fmi-ls-ref.html").decode()  # where the standard recommends it
        description = etree.fromstring(z.read("modelDescription.xml"))
    kinds = [
        name
        for tag, name in (
            ("CoSimulation", "Co-Simulation"),
            ("ModelExchange", "Model Exchange"),
            ("ScheduledExecution", "Scheduled Execution"),
        )
        if description.find(tag) is not None
    ]
    # what every product model implements (docs/fmi.md); FMI 3's Scheduled Execution in an FMU of its own
    assert kinds == (["Scheduled Execution"] if scheduled else ["Co-Simulation", "Model Exchange"])
    assert (
        "It carries FMI 3.0 Scheduled Execution (the PLC cyclic interrupt OB as an input Clock),"
        if scheduled
        else f"It carries FMI {version}.0 Co-Simulation and Model Exchange,"
    ) in page
    assert f"<pre>fmutrace check {model}.fmu</pre>" in page
    assert '<a href="fmi-ls-ref.html">' in page
    for text in (page, standalone):
        assert f"<pre>fmutrace check {model}.fmu</pre>" in text
        for name in scenario_names(model):
            assert f"<li><code>{name}</code>" in text
        # a state of Co-Simulation's, which a Scheduled Execution instance refuses: not in its FMU
        assert (f"<code>serialized-state/{scenario_names(model)[0]}.fmustate</code>" in text) != scheduled


BUDGET = 64 * 1024  # what the experiments may add to an FMU (docs/fmi.md)


@VARIANTS
@pytest.mark.parametrize("model", MODELS)
def test_the_experiments_stay_within_their_size_budget(model, version, scheduled):
    path = fmu_file(model, version, scheduled)
    data = path.read_bytes()
    added = 0
    with zipfile.ZipFile(path) as z:
        for i in z.infolist():
            if i.filename.startswith(FOLDER):  # its bytes in the zip: local header, data, descriptor, central entry
                name_length, extra_length = struct.unpack_from("<HH", data, i.header_offset + 26)
                local = 30 + name_length + extra_length + i.compress_size + (16 if i.flag_bits & 8 else 0)
                added += local + 46 + len(i.orig_filename.encode()) + len(i.extra) + len(i.comment)
    assert 0 < added <= BUDGET, added
