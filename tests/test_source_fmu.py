"""The source FMU: binaries removed, compiled by `fmpy compile` as an
importer on another platform would, gives the same bits as the shipped
binary."""
import shutil
import subprocess
import sys
import zipfile

import numpy as np
import pytest

from fmu_driver import fmu_file
from reference import discover, simulate

SCENARIOS = [s for s in discover() if s.name in ("variable_steps", "duration_jump", "cycle_steps_of_2_5", "status_errors")]


def strip_binaries(source, target):
    with zipfile.ZipFile(source) as zin, zipfile.ZipFile(target, "w", zipfile.ZIP_DEFLATED) as zout:
        for item in zin.infolist():
            if not item.filename.startswith("binaries/"):
                zout.writestr(item, zin.read(item.filename))


@pytest.mark.parametrize("version", [2, 3])
def test_compiled_source_fmu_matches_shipped_binary(version, tmp_path):
    shipped = fmu_file("RateLimiter", version)
    source_only = tmp_path / "RateLimiter.fmu"
    strip_binaries(shipped, source_only)
    with zipfile.ZipFile(source_only) as z:
        assert not any(n.startswith("binaries/") for n in z.namelist())
    subprocess.run([sys.executable, "-m", "fmpy", "compile", str(source_only)], check=True,
                   capture_output=True, cwd=tmp_path)
    with zipfile.ZipFile(source_only) as z:
        assert any(n.startswith("binaries/") and n.endswith(".so") for n in z.namelist())
    assert SCENARIOS
    for scenario in SCENARIOS:
        a = simulate(scenario, shipped)
        b = simulate(scenario, source_only)
        for name in a.dtype.names:
            assert np.array_equal(a[name], b[name], equal_nan=True), (scenario.id, name)
