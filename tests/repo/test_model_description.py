"""The FMUs as an importer sees them: fmpy validate, the declared
capabilities, the TOML single source of truth against both model
descriptions and the compiled-in C table, exported symbols, sources."""

import math
import os
import re
import struct
import sys
import tomllib
import zipfile
from xml.etree import ElementTree

import pytest
from fmpy import read_model_description
from fmpy.validation import validate_fmu

from support.fmu_driver import MODELS, REPO, Instance, fmu_file, unzipped
from support.process import run as run_bounded

FMI3_TYPE = {"Real": "Float64", "Integer": "Int32", "Boolean": "Boolean", "Enumeration": "Enumeration"}
PLATFORM = {2: "linux64", 3: "x86_64-linux"}


# every FMU: FMI 2, FMI 3 Co-Simulation and Model Exchange, FMI 3 Scheduled Execution (the same binary)
VARIANTS = pytest.mark.parametrize(
    "version,scheduled", [(2, False), (3, False), (3, True)], ids=["fmi2", "fmi3", "fmi3-scheduled-execution"]
)


def toml(model):
    return tomllib.loads((REPO / "modelDescription" / f"{model}.toml").read_text())


@VARIANTS
@pytest.mark.parametrize("model", MODELS)
def test_fmpy_validate_finds_no_problem(model, version, scheduled):
    assert validate_fmu(str(fmu_file(model, version, scheduled))) == []


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("model", MODELS)
def test_capabilities(model, version):
    cs = read_model_description(str(fmu_file(model, version))).coSimulation
    assert cs.modelIdentifier == model
    assert cs.canHandleVariableCommunicationStepSize
    assert cs.canGetAndSetFMUstate
    assert cs.canSerializeFMUstate
    assert not cs.canBeInstantiatedOnlyOncePerProcess


@VARIANTS
@pytest.mark.parametrize("model", MODELS)
def test_each_fmu_declares_its_interfaces(model, version, scheduled):
    """The Co-Simulation and Model Exchange FMUs (FMI 2 and 3) declare no
    Scheduled Execution; the Scheduled Execution FMU declares it alone."""
    md = read_model_description(str(fmu_file(model, version, scheduled)))
    declared = [md.coSimulation is not None, md.modelExchange is not None, md.scheduledExecution is not None]
    assert declared == ([False, False, True] if scheduled else [True, True, False])
    if scheduled:
        se = md.scheduledExecution
        assert se.modelIdentifier == model
        assert se.canGetAndSetFMUstate and se.canSerializeFMUstate and not se.canBeInstantiatedOnlyOncePerProcess
        assert md.instantiationToken == read_model_description(str(fmu_file(model, 3))).instantiationToken


def same_start(declared, start):
    if declared is None:
        return start is None
    if isinstance(declared, bool):
        return start in ("true", "false", True, False) and (start in ("true", True)) == declared
    a = float(start)
    return (math.isnan(a) and math.isnan(declared)) or a == declared


@VARIANTS
@pytest.mark.parametrize("model", MODELS)
def test_model_description_is_the_toml(model, version, scheduled):
    source = toml(model)
    md = read_model_description(str(fmu_file(model, version, scheduled)))
    # the Scheduled Execution FMU's Clock is the generator's, not the TOML's (test_scheduled_execution.py); no
    # other FMU has one (FMI 3.0, 4.4: a Co-Simulation FMU with Clocks needs Event Mode)
    clocks = [v.name for v in md.modelVariables if v.type == "Clock"]
    assert clocks == (["cyclicInterrupt"] if scheduled else [])
    variables = [v for v in md.modelVariables if v.type != "Clock"]
    assert [v.name for v in variables] == [v["name"] for v in source["variable"]]
    for v, s in zip(variables, source["variable"], strict=True):
        assert v.valueReference == s["vr"]
        assert v.causality == s["causality"]
        assert v.variability == s["variability"]
        assert v.type == (s["type"] if version == 2 else FMI3_TYPE[s["type"]])
        assert (v.unit or (v.declaredType.unit if v.declaredType else None)) == s.get("unit")
        assert same_start(s.get("start"), v.start), (v.name, v.start, s.get("start"))
        if "declaredType" in s:
            assert v.declaredType.name == s["declaredType"]
    outputs = [v["vr"] for v in source["variable"] if v["causality"] == "output"]
    assert [u.variable.valueReference for u in md.outputs] == outputs


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("model", MODELS)
def test_compiled_variable_table_is_the_toml(model, version):
    """Start values read back from the binary equal the TOML's, and every
    output is readable, so the C table agrees with the model description."""
    fmu = Instance(model, version)
    try:
        if version == 2:
            fmu.fmu.setupExperiment(startTime=0.0)
            fmu.fmu.enterInitializationMode()
        else:
            fmu.fmu.enterInitializationMode(startTime=0.0)
        for s in toml(model)["variable"]:
            value = fmu.get(s["name"])
            if "start" in s:
                assert same_start(s["start"], value), (s["name"], value)
    finally:
        fmu.free()


@pytest.mark.parametrize("model", MODELS)
def test_the_cycle_input_takes_any_real_and_the_output_is_a_real_output(model):
    """fmu_core sets u and gets y as Reals without a table lookup: every
    model's input (the first argument of its FMU_MODEL, in its C file or in
    unified.h's UNIFIED_MAPPING) must be an unranged, non-fixed Real input
    and its output a Real output, as its TOML declares them."""
    source = (REPO / "fmu_src" / "models" / f"{model}.c").read_text()
    if "UNIFIED_MAPPING(" in source:
        source = (REPO / "fmu_src" / "models" / "unified.h").read_text()
    found = re.findall(r"^\s*FMU_MODEL\(VR_(\w+), VR_(\w+),", source, re.MULTILINE)
    assert len(found) == 1, found
    names = dict(zip(("input", "output"), found[0], strict=True))
    variables = {v["name"]: v for v in toml(model)["variable"]}
    u, y = variables[names["input"]], variables[names["output"]]
    assert (u["type"], u["causality"], u["variability"]) in {
        ("Real", "input", "discrete"),
        ("Real", "input", "continuous"),
    }, u
    assert "min" not in u and "max" not in u, u
    assert (y["type"], y["causality"]) == ("Real", "output"), y


@pytest.mark.parametrize("version,platform", [(2, "linux64"), (3, "x86_64-linux"), (3, "aarch64-linux")])
@pytest.mark.parametrize("model", MODELS)
@pytest.mark.skipif(
    os.environ.get("RL_SANITIZED") == "1",
    reason="sanitizer build: its binaries need libasan by design; the release build is checked",
)
def test_binary_exports_fmi_only_and_needs_libc_only(model, version, platform):
    binary = f"{unzipped(model, version)}/binaries/{platform}/{model}.so"
    symbols = run_bounded(["nm", "-D", "--defined-only", binary], timeout=60, what="nm", check=True)
    names = [line.split()[-1] for line in symbols.stdout.splitlines()]
    assert names and all(n.startswith(f"fmi{version}") for n in names), [n for n in names if not n.startswith("fmi")]
    dynamic = run_bounded(["readelf", "-d", binary], timeout=60, what="readelf", check=True).stdout
    needed = sorted(line.split("[")[1].rstrip("]") for line in dynamic.splitlines() if "(NEEDED)" in line)
    assert set(needed) <= {"libc.so.6", "libm.so.6"}


@VARIANTS
@pytest.mark.parametrize("model", MODELS)
def test_sources_are_shipped(model, version, scheduled):
    with zipfile.ZipFile(fmu_file(model, version, scheduled)) as z:
        names = set(z.namelist())
    md = read_model_description(str(fmu_file(model, version, scheduled)))
    files = md.buildConfigurations[0].sourceFileSets[0].sourceFiles
    assert files == [f"{model}_fmi{version}.c"]  # the FMU's one unit, which includes the rest (test_source_fmu.py)
    included = [
        "rate_limiter.c",
        f"{model}.c",
        "fmu_core.c",
        "fmu_model_exchange.c",
        "fmu_state.c",
        f"fmi{version}_glue.c",
    ]
    assert all(f"sources/{f}" in names for f in files + included)
    assert f"sources/{model}_variables.h" in names
    if version == 3:
        assert "sources/buildDescription.xml" in names


def png_size(data):
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    return struct.unpack(">II", data[16:24])


@VARIANTS
@pytest.mark.parametrize("model", MODELS)
def test_documentation_and_icon_are_inside(model, version, scheduled):
    """documentation/index.html (every variable, the status codes where the
    block has a status), the ramp plot it shows, and the model icon."""
    with zipfile.ZipFile(fmu_file(model, version, scheduled)) as z:
        page = z.read("documentation/index.html").decode()
        ramp = z.read("documentation/ramp.png")
        icon = z.read("model.png" if version == 2 else "terminalsAndIcons/icon.png")
    md = read_model_description(str(fmu_file(model, version, scheduled)))
    for v in md.modelVariables:
        assert f"<code>{v.name}</code>" in page, v.name
    if any(v.name == "status" for v in md.modelVariables):
        for code in ("16#8200", "16#8201", "16#8202", "16#8203", "16#8601"):
            assert code in page, code
    assert 'src="ramp.png"' in page
    width, height = png_size(ramp)
    assert width >= 400 and height >= 200
    assert png_size(icon) == (128, 128)


def start_attributes(xml, version):
    """Each variable's start attribute as the model description writes it."""
    variables = ElementTree.fromstring(xml).find("ModelVariables")
    if version == 2:
        return {v.get("name"): v[0].get("start") for v in variables if v[0].get("start") is not None}
    return {v.get("name"): v.get("start") for v in variables if v.get("start") is not None}


@VARIANTS
@pytest.mark.parametrize("model", MODELS)
def test_start_values_are_finite_or_a_nan_that_means_something(model, version, scheduled):
    """FMI Library and OMSimulator refuse INF start values: none in any
    model description (a "none" limit starts at the largest finite double,
    which the model reads as no limit). A NaN start is left only where NaN
    means something no finite value does (not connected: the parameter
    instead; no bypass value: the output follows the input), as the
    variable's description says."""
    with zipfile.ZipFile(fmu_file(model, version, scheduled)) as z:
        xml = z.read("modelDescription.xml").decode()
    starts = start_attributes(xml, version)
    assert starts and len(starts) == len([v for v in toml(model)["variable"] if "start" in v])
    descriptions = {v["name"]: v.get("description", "") for v in toml(model)["variable"]}
    for name, start in starts.items():
        assert "INF" not in start.upper(), (name, start)
        if start.lower() == "nan":
            assert re.search(r"\((NaN|null)[:,]", descriptions[name]), (name, descriptions[name])


def test_the_largest_finite_limits_are_no_limits():
    """RateLimiter's yMaxPar and yMinPar start at +-1.7976931348623157e308,
    read as no limit exactly as NaN and infinity are: the same outputs, the
    flags included, for an output driven to the largest finite double."""
    runs = []
    for high, low in ((sys.float_info.max, -sys.float_info.max), (math.inf, -math.inf), (math.nan, math.nan)):
        fmu = Instance("RateLimiter", 3)
        try:
            fmu.start(yMaxPar=high, yMinPar=low, rateUpPar=math.inf, rateDownPar=math.inf)
            outputs = []
            for u in (sys.float_info.max, -sys.float_info.max, 5.0):
                fmu.set(u=u)
                fmu.step(0.5)
                outputs.append(tuple(fmu.get(n) for n in ("y", "highLimit", "lowLimit", "rampActive", "status")))
            runs.append(outputs)
        finally:
            fmu.free()
    assert runs[0] == runs[1] == runs[2]
    assert runs[0][0] == (sys.float_info.max, False, False, False, 0)


def test_generator_refuses_an_infinite_start(tmp_path):
    toml_file = tmp_path / "Probe.toml"
    toml_file.write_text(
        '[model]\nidentifier = "Probe"\ndescription = "probe"\n'
        '[[variable]]\nname = "time"\nvr = 0\ntype = "Real"\ncausality = "independent"\n'
        'variability = "continuous"\n'
        '[[variable]]\nname = "limit"\nvr = 1\ntype = "Real"\ncausality = "parameter"\n'
        'variability = "tunable"\nstart = inf\n'
    )
    done = run_bounded(
        [sys.executable, str(REPO / "modelDescription" / "generate.py"), str(toml_file), str(tmp_path / "gen")],
        timeout=60,
        what="generate.py",
    )
    assert done.returncode != 0 and "infinite start value" in done.stderr


def test_docs_tables_are_generated_from_the_toml_files():
    """docs/models.md restates each model's variables: its tables must be
    what modelDescription/tables.py makes from the TOML files today."""
    tomls = [str(REPO / "modelDescription" / f"{m}.toml") for m in MODELS]
    done = run_bounded(
        [sys.executable, str(REPO / "modelDescription" / "tables.py"), str(REPO / "docs" / "models.md"), *tomls],
        timeout=60,
        what="tables.py (docs/models.md)",
    )
    assert done.returncode == 0, done.stdout + done.stderr
    text = (REPO / "docs" / "models.md").read_text()
    for model in MODELS:
        assert f"<!-- generated: variables {model} -->" in text


def generator_run(tmp_path, variables):
    """generate.py on a model of the given (name, causality) variables."""
    lines = ['[model]\nidentifier = "Probe"\ndescription = "probe"\n']
    for vr, (name, causality) in enumerate(variables):
        lines.append(
            f'[[variable]]\nname = "{name}"\nvr = {vr}\ntype = "Real"\ncausality = "{causality}"\n'
            f'variability = "{"continuous" if causality == "independent" else "discrete"}"\n'
            + ("start = 0.0\n" if causality == "input" else "")
        )
    toml = tmp_path / "Probe.toml"
    toml.write_text("\n".join(lines))
    return run_bounded(
        [sys.executable, str(REPO / "modelDescription" / "generate.py"), str(toml), str(tmp_path / "gen")],
        timeout=60,
        what="generate.py",
    )


def test_generator_refuses_a_model_without_time_at_value_reference_0(tmp_path):
    done = generator_run(tmp_path, [("u", "input"), ("time", "independent"), ("y", "output")])
    assert done.returncode != 0 and "value reference 0 must be the independent variable time" in done.stderr
    assert generator_run(tmp_path, [("time", "independent"), ("u", "input"), ("y", "output")]).returncode == 0


def test_generator_refuses_more_variables_than_the_core_holds(tmp_path):
    limit = int(re.search(r"#define FMU_MAX_VARIABLES (\d+)", (REPO / "fmu_src" / "model.h").read_text()).group(1))
    fits = [("time", "independent")] + [(f"u{i}", "input") for i in range(limit - 1)]
    assert generator_run(tmp_path, fits).returncode == 0
    done = generator_run(tmp_path, fits + [("y", "output")])
    assert done.returncode != 0 and f"the core's table holds {limit}" in done.stderr


def test_the_state_serialization_shows_no_expected_status_as_a_warning(tmp_path):
    """The build serializes a state of each FMU's first scenario; the
    advanced block's is an invalid call (16#8601 at every step, as its
    reference expects): that status is no warning in the build's output.
    A status the reference does not hold is still shown."""
    from support.fmu_driver import BUILD_DIR

    model = "LGF_LimRateOfChangeAdvancedCI"
    scenarios = REPO / "tests" / "scenarios" / model
    done = run_bounded(
        [
            sys.executable,
            REPO / "modelDescription" / "state.py",
            BUILD_DIR / "stage" / "fmi2" / model,  # (FMI 2's instance logs the status)
            "2",
            scenarios,
            tmp_path / "state.bin",
        ],
        timeout=300,
        what="state.py",
    )
    assert done.returncode == 0 and (tmp_path / "state.bin").stat().st_size > 0, done.stdout + done.stderr
    assert "WARNING" not in done.stdout, done.stdout
    sys.path.insert(0, str(REPO / "modelDescription"))
    try:
        import state
    finally:
        sys.path.pop(0)
    reference = tmp_path / "ref.csv"
    reference.write_text("time,y,status\n0,0,34305\n1,0,0\n")  # 34305: 16#8601
    log = "[WARNING] status 16#8601: no valid call\n[WARNING] status 16#8200: bad limits\n[ERROR] other\n"
    assert state.unexpected(log, reference) == ["[WARNING] status 16#8200: bad limits", "[ERROR] other"]
