"""The source FMU: binaries removed, compiled by `fmpy compile` as an
importer on another platform would, gives the same bits as the shipped
binary."""
import sys
import zipfile

import numpy as np
import pytest

from support.fmu_driver import fmu_file
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
            assert np.array_equal(a[name], b[name], equal_nan=True), (scenario.id, name)
