"""The source FMU: binaries removed, compiled by `fmpy compile` as an
importer on another platform would, gives the same bits as the shipped
binary."""
import sys
import zipfile
from pathlib import Path

import fmpy
import numpy as np
import pytest

from support.fmu_driver import REPO, fmu_file
from support.process import run as run_bounded
from support.scenarios import discover, simulate

SCENARIOS = discover()
MODELS = sorted({s.model for s in SCENARIOS})


def strip_binaries(source, target):
    with zipfile.ZipFile(source) as zin, zipfile.ZipFile(target, "w", zipfile.ZIP_DEFLATED) as zout:
        for item in zin.infolist():
            if not item.filename.startswith("binaries/"):
                zout.writestr(item, zin.read(item.filename))


@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("model", MODELS)
def test_compiled_source_fmu_matches_shipped_binary(model, version, tmp_path):
    shipped = fmu_file(model, version)
    source_only = tmp_path / f"{model}.fmu"
    strip_binaries(shipped, source_only)
    with zipfile.ZipFile(source_only) as z:
        assert not any(n.startswith("binaries/") for n in z.namelist())
    run_bounded([sys.executable, "-m", "fmpy", "compile", str(source_only)], check=True, cwd=tmp_path,
                timeout=300, what="fmpy compile (the source FMU)")
    with zipfile.ZipFile(source_only) as z:
        assert any(n.startswith("binaries/") and n.endswith(".so") for n in z.namelist())
    scenarios = [s for s in SCENARIOS if s.model == model]
    assert scenarios
    for scenario in scenarios:
        a = simulate(scenario, shipped)
        b = simulate(scenario, source_only)
        for name in a.dtype.names:
            assert np.array_equal(a[name], b[name], equal_nan=True), (scenario.name, name)


@pytest.mark.parametrize("portable", [False, True], ids=["hints", "no-hints"])
@pytest.mark.parametrize("version", [2, 3])
@pytest.mark.parametrize("model", MODELS)
def test_sources_are_strict_c99(model, version, portable, tmp_path):
    """The sources an importer gets compile as ISO C99 with every pedantic
    warning an error, with the compiler hints (FMU_NOINLINE, ...) and with
    them empty, as a compiler without GNU attributes sees them."""
    with zipfile.ZipFile(fmu_file(model, version)) as z:
        z.extractall(tmp_path)
    sources = sorted(str(p) for p in (tmp_path / "sources").glob("*.c"))
    assert sources
    headers = Path(fmpy.__file__).parent / "c-code"
    done = run_bounded(["cc", "-std=c99", "-pedantic-errors", "-Wall", "-Wextra", "-Werror", "-fPIC", "-shared",
                        *(["-DFMU_PORTABLE"] if portable else []), f"-I{tmp_path / 'sources'}", f"-I{headers}",
                        *sources, "-lm", "-o", str(tmp_path / "model.so")], timeout=120, what="cc -std=c99")
    assert done.returncode == 0, done.stdout + done.stderr
    assert (tmp_path / "model.so").stat().st_size > 0


def test_compiler_attributes_only_behind_the_portable_macros():
    """A bare __attribute__ would stop a compiler without GNU extensions."""
    for source in sorted((REPO / "fmu_src").rglob("*.[ch]")):
        for number, line in enumerate(source.read_text().splitlines(), 1):
            if "__attribute__" in line:
                assert line.startswith("#define FMU_"), f"{source.name}:{number}: {line}"
