"""The source FMU: compiled from what its description says (FMI 2: the
model description's SourceFiles; FMI 3: sources/buildDescription.xml) as
C99 and as C++, by `fmpy compile` as an importer on another platform would,
and every model of an FMI version linked into one executable, each with
its own function prefix, as tools that compile source FMUs link them
(docs/fmi.md, Source FMUs). Each build runs the model's reference
scenarios and gives their hand-worked references."""

import os
import sys
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import fmpy
import numpy as np
import pytest
from fmpy import read_model_description
from fmpy.model_description import read_build_description

from support.fmu_driver import BUILD_DIR, REPO, fmu_file
from support.process import run as run_bounded
from support.run_trace import reference_script
from support.scenarios import discover, simulate

SCENARIOS = discover()
MODELS = sorted({s.model for s in SCENARIOS})
PLATFORM = {2: "linux64", 3: "x86_64-linux"}
FMPY_HEADERS = Path(fmpy.__file__).parent / "c-code"
# fmpy's fmi2Functions.h ignores FMI2_FUNCTION_PREFIX; the build tree has the standard's (cmake/TestTools.cmake)
STANDARD_HEADERS = BUILD_DIR / "fmi_headers"
STRICT = ["-pedantic-errors", "-Wall", "-Wextra", "-Werror"]
# the sources as C99, with the compiler hints and without them (FMU_PORTABLE: as a compiler without GNU
# attributes sees them), and as C++
LANGUAGES = {"C99": ["cc", "-std=c99"], "C++11": [os.environ.get("RL_CXX") or "g++", "-x", "c++", "-std=c++11"]}
BUILDS = [("C99", False), ("C99", True), ("C++11", False)]
sanitized = pytest.mark.skipif(
    os.environ.get("RL_SANITIZED") == "1", reason="run_trace is built in the release tree only"
)


def strip_binaries(source, target):
    with zipfile.ZipFile(source) as zin, zipfile.ZipFile(target, "w", zipfile.ZIP_DEFLATED) as zout:
        for item in zin.infolist():
            if not item.filename.startswith("binaries/"):
                zout.writestr(item, zin.read(item.filename))


def unpacked(model, version, folder):
    with zipfile.ZipFile(fmu_file(model, version)) as z:
        z.extractall(folder)
    return folder, read_model_description(str(folder / "modelDescription.xml"))


def described_build(folder, version, model):
    """What the FMU's description says to compile: (language, source files, include directories,
    preprocessor definitions), the paths under sources/."""
    if version == 2:
        root = ET.parse(folder / "modelDescription.xml").getroot()
        files = [f.get("name") for f in root.findall("CoSimulation/SourceFiles/File")]
        return "C99", files, [], {}
    configurations = read_build_description(str(folder), validate=True)  # against the standard's schema
    assert [c.modelIdentifier for c in configurations] == [model]
    [file_set] = configurations[0].sourceFileSets
    definitions = {d.name: d.value for d in file_set.preprocessorDefinitions if not d.optional}
    return file_set.language, file_set.sourceFiles, file_set.includeDirectories, definitions


def compile_command(language, folder, version, model, portable=False, prefix=None):
    """The compiler command for the FMU unpacked in folder as its description says, in language,
    strict; prefix: FMIx_FUNCTION_PREFIX (then the standard's FMI 2 header)."""
    described, files, includes, definitions = described_build(folder, version, model)
    assert described == "C99" and files
    sources = folder / "sources"
    headers = ([STANDARD_HEADERS] if prefix and version == 2 else []) + [FMPY_HEADERS]
    if prefix:
        definitions = dict(definitions, **{f"FMI{version}_FUNCTION_PREFIX": prefix})
    if portable:
        definitions = dict(definitions, FMU_PORTABLE="1")
    return (
        LANGUAGES[language]
        + STRICT
        + ["-O2", "-ffp-contract=off", "-fPIC"]
        + [f"-D{name}" if value is None else f"-D{name}={value}" for name, value in definitions.items()]
        + [f"-I{sources / d}" for d in includes]
        + [f"-I{sources}"]
        + [f"-I{h}" for h in headers]
        + [str(sources / f) for f in files]
    )


def run_scenarios(model, version, md, harness, library, tmp_path, prefix=None):
    """Every reference scenario of model through the C harness run_trace on the FMU's library ("-":
    linked into the harness, its functions named with prefix)."""
    scenarios = [s for s in SCENARIOS if s.model == model]
    assert scenarios
    options = (["--fmi2"] if version == 2 else []) + (["--prefix", prefix] if prefix else [])
    for scenario in scenarios:
        text, check = reference_script(scenario, md)
        (tmp_path / "script").write_text(text)
        with open(tmp_path / "script") as script_file:
            done = run_bounded(
                [str(harness)] + options + [str(library), md.guid],
                timeout=300,
                stdin=script_file,
                what=f"{scenario.name} (FMI {version})",
                cwd=tmp_path,
            )
        assert done.returncode == 0, done.stderr
        check([line.strip() for line in done.stdout.splitlines()])


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("model", MODELS)
def test_compiled_source_fmu_matches_shipped_binary(model, version, tmp_path):
    shipped = fmu_file(model, version)
    source_only = tmp_path / f"{model}.fmu"
    strip_binaries(shipped, source_only)
    with zipfile.ZipFile(source_only) as z:
        assert not any(n.startswith("binaries/") for n in z.namelist())
    run_bounded(
        [sys.executable, "-m", "fmpy", "compile", str(source_only)],
        check=True,
        cwd=tmp_path,
        timeout=300,
        what="fmpy compile (the source FMU)",
    )
    with zipfile.ZipFile(source_only) as z:
        assert any(n.startswith("binaries/") and n.endswith(".so") for n in z.namelist())
    scenarios = [s for s in SCENARIOS if s.model == model]
    assert scenarios
    for scenario in scenarios:
        a = simulate(scenario, shipped)
        b = simulate(scenario, source_only)
        for name in a.dtype.names:
            assert np.array_equal(a[name], b[name], equal_nan=True), (scenario.name, name)


@pytest.mark.parametrize("version", [2, 3])
def test_the_description_lists_the_one_unit(version, tmp_path):
    """The sources are compiled as one translation unit, <Model>_fmi<version>.c, which includes the
    rest; the FMI 2 SourceFiles and the FMI 3 build description list it alone, in C99, with no
    definition an importer must set and no include directory (sources/ holds every file)."""
    for model in MODELS:
        folder, _ = unpacked(model, version, tmp_path / model)
        language, files, includes, definitions = described_build(folder, version, model)
        assert (language, files, includes, definitions) == ("C99", [f"{model}_fmi{version}.c"], [], {})
        unit = (folder / "sources" / files[0]).read_text()
        assert "#define RL_UNIT\n" in unit
        included = [line.split('"')[1] for line in unit.splitlines() if line.startswith("#include")]
        assert included == [
            "rate_limiter.c",
            f"{model}.c",
            "fmu_core.c",
            "fmu_model_exchange.c",
            "fmu_state.c",
            f"fmi{version}_glue.c",
        ]
        assert sorted(p.name for p in (folder / "sources").glob("*.c")) == sorted(included + files)


@sanitized
@pytest.mark.parametrize("language,portable", BUILDS, ids=["C99", "C99-no-hints", "C++11"])
@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("model", MODELS)
def test_compiled_from_its_description_gives_the_references(model, version, language, portable, tmp_path):
    """Exactly what the description lists, compiled strictly (ISO C99 or C++11, every pedantic warning
    an error) into the FMU's shared library with no undefined symbol, runs every reference scenario of
    the model to its hand-worked reference (through the C harness run_trace)."""
    folder, md = unpacked(model, version, tmp_path / "fmu")
    library = tmp_path / "lib.so"
    done = run_bounded(
        compile_command(language, folder, version, model, portable)
        + ["-shared", "-Wl,-z,defs", "-lm", "-o", str(library)],
        timeout=300,
        what=language,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    symbols = defined_globals(library, dynamic=True, strong=True)
    assert symbols and all(name.startswith(f"fmi{version}") for name in symbols), symbols
    run_scenarios(model, version, md, BUILD_DIR / "run_trace", library, tmp_path)


def defined_globals(binary, dynamic=False, strong=False):
    """{name: nm type} of the symbols binary defines with external linkage (dynamic: exported); strong:
    without C++'s vague linkage (weak template instances that any number of units may define)."""
    out = run_bounded(
        ["nm", "--defined-only", "-g"] + (["-D"] if dynamic else []) + [str(binary)], timeout=60, what="nm", check=True
    ).stdout
    symbols = {line.split()[-1]: line.split()[-2] for line in out.splitlines() if line.strip()}
    return {n: t for n, t in symbols.items() if not (strong and t in "WVuv")}


@sanitized
@pytest.mark.parametrize("language", ["C99", "C++11"])
@pytest.mark.parametrize("version", [2, 3])
def test_every_model_links_into_one_binary(version, language, tmp_path):
    """Every model of the FMI version from its unpacked sources/, compiled as its description says with
    FMI<version>_FUNCTION_PREFIX <Model>_, linked with the C harness into one executable: nothing but
    the prefixed fmi functions has external linkage, and through each model's prefix every reference
    scenario of it gives its hand-worked reference."""
    objects, descriptions = [], {}
    for model in MODELS:
        folder, descriptions[model] = unpacked(model, version, tmp_path / model)
        obj = tmp_path / f"{model}.o"
        done = run_bounded(
            compile_command(language, folder, version, model, prefix=f"{model}_") + ["-c", "-o", str(obj)],
            timeout=300,
            what=f"{language} {model}",
        )
        assert done.returncode == 0, done.stdout + done.stderr
        symbols = defined_globals(obj, strong=True)
        assert symbols and all(n.startswith(f"{model}_fmi{version}") for n in symbols), symbols
        objects.append(str(obj))
    harness = tmp_path / "run_trace.o"
    run_bounded(
        [
            "cc",
            "-std=c99",
            "-O2",
            "-c",
            f"-I{FMPY_HEADERS}",
            str(REPO / "tests" / "c" / "run_trace.c"),
            "-o",
            str(harness),
        ],
        timeout=120,
        what="cc run_trace",
        check=True,
    )
    binary = tmp_path / "one_binary"
    linker = LANGUAGES[language][0]  # C++ units may need the C++ runtime
    done = run_bounded(
        [linker, "-rdynamic", str(harness), *objects, "-ldl", "-lm", "-o", str(binary)],
        timeout=120,
        what="linking one binary",
    )
    assert done.returncode == 0, done.stdout + done.stderr
    symbols = defined_globals(binary, strong=True)
    ours = {n for n in symbols if n.startswith(("rl_", "fmu_", "fmuModel", "fmi"))}
    assert not ours, ours  # no kernel, core or model symbol, no unprefixed fmi function
    for model in MODELS:
        assert f"{model}_fmi{version}DoStep" in symbols
        run_scenarios(model, version, descriptions[model], binary, "-", tmp_path, prefix=f"{model}_")


def test_compiler_attributes_only_behind_the_portable_macros():
    """A bare __attribute__ would stop a compiler without GNU extensions."""
    for source in sorted((REPO / "fmu_src").rglob("*.[ch]")):
        for number, line in enumerate(source.read_text().splitlines(), 1):
            if "__attribute__" in line:
                assert line.startswith("#define FMU_"), f"{source.name}:{number}: {line}"
